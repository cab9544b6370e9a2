"""Batched polynomials in one variable with interval coefficients, and their ranges.

A ``Poly`` holds coefficient enclosures ``lo``, ``hi`` of shape S + (n + 1,):
it stands for every polynomial p(t) = Σ_k c_k t^k with c_k in its intervals.
Sums and products are computed coefficient-wise with outward rounding, so the
result's intervals contain the coefficients of the exact sum or product of any
members of the operands (inclusion property).  Mixed operations with
``Interval`` (constants, broadcast over the batch shape) are supported.

Truncation (``degree_limit``): inside ``with degree_limit(d):`` products keep
degree ≤ d and move each higher term c_k t^k into the constant coefficient as
c_k·[0, 1] (hull with 0), which encloses it for t ∈ [0, 1] only.  The
coefficient intervals then mean "for each t ∈ [0, 1], the value is that of
some member", a property kept by sums and products and by the range bound;
truncated polynomials must only be bounded on sub-intervals of [0, 1].
``cos``/``sin`` of a polynomial of degree ≤ 1 are such truncated expansions
with a Lagrange remainder.

``Poly.range(tlo, thi)`` encloses {p(t) : t ∈ [tlo, thi]} by the Bernstein
form: with t = tlo + s h, s ∈ [0, 1], q(s) = p(tlo + s h) = Σ_j b_j B_j,n(s)
where the Bernstein polynomials B_j,n are ≥ 0 on [0, 1] and sum to 1, so
min_j b_j ≤ q(s) ≤ max_j b_j (Farouki & Rajan 1987; Garloff 1986,
"Convergent bounds for the range of multivariate polynomials").  The bound
converges quadratically in h and is exact when the b_j are monotone (then
b_0 = p(tlo) and b_n = p(thi) are the extremes).

>>> from intervals import Interval
>>> p = Poly.from_coefficients([Interval(-1), Interval(0), Interval(1)])   # t² − 1
>>> r = p.range(0.5, 2.0)
>>> bool(r.lo <= -0.75 and r.hi >= 3.0 and r.hi - r.lo < 3.76)
True
"""
from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from fractions import Fraction
from math import comb, factorial

import numpy as np

from . import elementary as _el
from .interval import Interval, as_interval, mul
from .rounding import down, down_sum, enclose_fraction, sum_bounds, up, up_sum


def _operand(x):
    """(lo, hi) coefficient arrays of a Poly, or of a constant as a degree-0 polynomial."""
    if isinstance(x, Poly):
        return x.lo, x.hi
    iv = as_interval(x)
    return np.asarray(iv.lo)[..., None], np.asarray(iv.hi)[..., None]


def padded(a, n):
    """Coefficient array ``a`` padded with zeros to n + 1 coefficients."""
    extra = n + 1 - a.shape[-1]
    if extra == 0:
        return a
    out = np.zeros(a.shape[:-1] + (n + 1,))
    out[..., :a.shape[-1]] = a
    return out


_BERNSTEIN = {}
_TO_POWERS: dict = {}    # order -> _taylor_to_powers(order)
_HALF = Interval(0.5)
_LIMIT = ContextVar("degree_limit", default=None)   # degree limit of products (``degree_limit``), None: exact


@contextmanager
def degree_limit(d: int):
    """Products made inside keep degree ≤ d (terms above folded into c_0, valid for t ∈ [0, 1]).

    The limit belongs to the thread (the context) that set it: products computed meanwhile by
    other threads keep their own limit, or none."""
    token = _LIMIT.set(d)
    try:
        yield
    finally:
        _LIMIT.reset(token)


def _fold(lo, hi, d):
    """Terms of degree > d folded into c_0: Σ_{k>d} c_k t^k ∈ Σ_{k>d} hull(0, c_k) for t ∈ [0, 1]."""
    if lo.shape[-1] <= d + 1:
        return lo, hi
    extra_lo = np.minimum(lo[..., d + 1:], 0.0)
    extra_hi = np.maximum(hi[..., d + 1:], 0.0)
    lo, hi = lo[..., :d + 1].copy(), hi[..., :d + 1].copy()
    for k in range(extra_lo.shape[-1]):
        lo[..., 0] = down_sum(lo[..., 0] + extra_lo[..., k])
        hi[..., 0] = up_sum(hi[..., 0] + extra_hi[..., k])
    return lo, hi


def _bernstein_matrix(n):
    """Enclosure of T[j, k] = C(j, k) / C(n, k) (k ≤ j), the power-to-Bernstein map on [0, 1]."""
    if n not in _BERNSTEIN:
        lo = np.zeros((n + 1, n + 1))
        hi = np.zeros((n + 1, n + 1))
        for j in range(n + 1):
            for k in range(j + 1):
                lo[j, k], hi[j, k] = enclose_fraction(Fraction(comb(j, k), comb(n, k)))
        _BERNSTEIN[n] = (lo, hi)
    return _BERNSTEIN[n]


class Poly:
    """Polynomials in t with interval coefficients, batched over a shape S."""

    __slots__ = ("lo", "hi")
    __array_ufunc__ = None
    takes_interval_operands = True      # Interval's operators defer to ours

    def __init__(self, lo, hi):
        self.lo = np.asarray(lo, dtype=np.float64)
        self.hi = np.asarray(hi, dtype=np.float64)

    @classmethod
    def from_coefficients(cls, coefficients) -> "Poly":
        """Σ_k coefficients[k] t^k (a list of Intervals or numbers of one batch shape)."""
        ivs = [as_interval(c) for c in coefficients]
        shape = np.broadcast_shapes(*(np.shape(c.lo) for c in ivs))
        return cls(np.stack([np.broadcast_to(c.lo, shape) for c in ivs], -1),
                   np.stack([np.broadcast_to(c.hi, shape) for c in ivs], -1))

    @property
    def degree(self) -> int:
        return self.lo.shape[-1] - 1

    @property
    def shape(self):
        return self.lo.shape[:-1]

    @property
    def ndim(self):
        return self.lo.ndim - 1

    def __getitem__(self, index):
        """Indexing over the batch axes (the coefficient axis is kept)."""
        index = index if isinstance(index, tuple) else (index,)
        if any(i is Ellipsis for i in index):
            raise IndexError("Poly indexing takes batch indices only (no Ellipsis)")
        return Poly(self.lo[index], self.hi[index])

    def coefficient(self, k) -> Interval:
        return Interval.from_bounds(self.lo[..., k], self.hi[..., k])

    def __repr__(self):
        return f"Poly(degree={self.degree}, shape={self.shape})"

    # ----- arithmetic (outward rounded) -----------------------------------------------
    def __neg__(self):
        return Poly(-self.hi, -self.lo)

    def __pos__(self):
        return self

    def __add__(self, other):
        blo, bhi = _operand(other)
        n = max(self.degree, blo.shape[-1] - 1)
        return Poly(down_sum(padded(self.lo, n) + padded(blo, n)), up_sum(padded(self.hi, n) + padded(bhi, n)))

    __radd__ = __add__

    def __sub__(self, other):
        blo, bhi = _operand(other)
        n = max(self.degree, blo.shape[-1] - 1)
        return Poly(down_sum(padded(self.lo, n) - padded(bhi, n)), up_sum(padded(self.hi, n) - padded(blo, n)))

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, other):
        blo, bhi = _operand(other)
        p, q = self.lo.shape[-1], blo.shape[-1]
        if p == 1 or q == 1:                     # a constant factor: coefficient-wise
            r = mul(Interval.from_bounds(self.lo, self.hi), Interval.from_bounds(blo, bhi))
            return Poly(r.lo, r.hi)
        P = mul(Interval.from_bounds(self.lo[..., :, None], self.hi[..., :, None]),
                Interval.from_bounds(blo[..., None, :], bhi[..., None, :]))          # (S, p, q): c_i d_j
        shape = P.lo.shape[:-2] + (p + q - 1,)
        lo = np.zeros(shape)
        hi = np.zeros(shape)
        lo[..., :q] = P.lo[..., 0, :]
        hi[..., :q] = P.hi[..., 0, :]
        for i in range(1, p):                    # Σ_{i+j=k} c_i d_j, each addition rounded outward
            lo[..., i:i + q] = down_sum(lo[..., i:i + q] + P.lo[..., i, :])
            hi[..., i:i + q] = up_sum(hi[..., i:i + q] + P.hi[..., i, :])
        if (limit := _LIMIT.get()) is not None:
            lo, hi = _fold(lo, hi, limit)
        return Poly(lo, hi)

    __rmul__ = __mul__

    def sum(self, axis) -> "Poly":
        """Sum over a batch axis, rounded outward (``rounding.sum_bounds``)."""
        axis = axis if axis >= 0 else axis - 1          # the coefficient axis stays last
        return Poly(*sum_bounds(self.lo, self.hi, axis))

    # ----- range over an interval of t ------------------------------------------------
    def range(self, tlo, thi) -> Interval:
        """Enclosure of {p(t) : t ∈ [tlo, thi]} (``tlo``, ``thi`` broadcast against the batch)."""
        b = self.bernstein(tlo, thi)
        return Interval.from_bounds(b.lo.min(axis=-1), b.hi.max(axis=-1))

    def bernstein(self, tlo, thi, weights=None) -> Interval:
        """Enclosures (…, n + 1) of the Bernstein coefficients of p on [tlo, thi].
        ``weights``: ``bernstein_weights(tlo, thi, degree)`` when already computed (tlo ≥ 0)."""
        n = self.degree
        a = np.asarray(tlo, dtype=np.float64)
        b = np.asarray(thi, dtype=np.float64)
        shape = np.broadcast_shapes(self.shape, a.shape, b.shape)
        lo = np.broadcast_to(self.lo, shape + (n + 1,))
        hi = np.broadcast_to(self.hi, shape + (n + 1,))
        if n == 0:
            return Interval.from_bounds(lo.copy(), hi.copy())
        if weights is not None or np.all(a >= 0):
            return _bernstein_nonnegative(lo, hi, a, b, n, weights)
        return _bernstein_taylor(lo, hi, np.broadcast_to(a, shape), np.broadcast_to(b, shape), n)


def _taylor_to_powers(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Enclosure of M[k, j] = C(k, j) (−1/2)^(k−j) / k!: Σ_k a_k (t − 1/2)^k / k! = Σ_j (Σ_k a_k M[k, j]) t^j."""
    if order not in _TO_POWERS:
        lo = np.zeros((order + 1, order + 1))
        hi = np.zeros((order + 1, order + 1))
        for k in range(order + 1):
            for j in range(k + 1):
                lo[k, j], hi[k, j] = enclose_fraction(Fraction(comb(k, j) * (-1) ** (k - j), 2 ** (k - j) * factorial(k)))
        _TO_POWERS[order] = (lo, hi)
    return _TO_POWERS[order]


def _trig(x: Poly, kind: str, order: int) -> Poly:
    """cos or sin of x(t) = c_0 + c_1 t for t ∈ [0, 1]: Taylor expansion at t = 1/2,
    f(m + s) = Σ_{k≤order} f⁽ᵏ⁾(m) s^k / k! + R with s = c_1 (t − 1/2), m = c_0 + c_1/2 and
    |R| ≤ |s|^(order+1)/(order+1)! ≤ (|c_1|/2)^(order+1)/(order+1)! (Lagrange; |f⁽ᵏ⁾| ≤ 1).
    The coefficient of t^j is Σ_k f⁽ᵏ⁾(m) c_1^k M[k, j] with the enclosed constants M of
    ``_taylor_to_powers``: one outward-rounded product and sum for all of them.
    ``order`` None: the least order whose remainder bound is below 2⁻⁶⁰ (at most 12); the
    bound actually added is computed with upward rounding either way."""
    if x.degree > 1:
        raise NotImplementedError("cos/sin of a polynomial of degree above 1")
    c0 = x.coefficient(0)
    c1 = x.coefficient(1) if x.degree == 1 else Interval.from_bounds(np.zeros_like(x.lo[..., 0]), np.zeros_like(x.lo[..., 0]))
    m = c0 + mul(c1, _HALF)
    mag = np.maximum(np.abs(c1.lo), np.abs(c1.hi))
    r = float(np.max(mag, initial=0.0)) / 2
    if order is None:         # the least order whose remainder is below 2⁻⁶⁰ (at most 12)
        order = next((k for k in range(1, 12) if r ** (k + 1) / factorial(k + 1) <= 2.0 ** -60), 12)
    cm, sm = _el.cos(m), _el.sin(m)
    shape = np.broadcast_shapes(np.shape(cm.lo), np.shape(c1.lo))
    # f⁽ᵏ⁾(m) for k = 0..order (the cycle cos, −sin, −cos, sin or sin, cos, −sin, −cos) and c_1^k
    cycle = [cm, -sm, -cm, sm] if kind == "cos" else [sm, cm, -sm, -cm]
    order_k = np.arange(order + 1) % 4
    dlo = np.stack([np.broadcast_to(v.lo, shape) for v in cycle], -1)[..., order_k]
    dhi = np.stack([np.broadcast_to(v.hi, shape) for v in cycle], -1)[..., order_k]
    plo, phi = np.ones(shape + (order + 1,)), np.ones(shape + (order + 1,))
    power = Interval.from_bounds(plo[..., 0], phi[..., 0])
    for k in range(1, order + 1):
        power = mul(power, c1)
        plo[..., k], phi[..., k] = power.lo, power.hi
    a = mul(Interval.from_bounds(dlo, dhi), Interval.from_bounds(plo, phi))
    Mlo, Mhi = _taylor_to_powers(order)
    terms = mul(Interval.from_bounds(a.lo[..., :, None], a.hi[..., :, None]), Interval.from_bounds(Mlo, Mhi))   # (..., k, j)
    lo, hi = sum_bounds(terms.lo, terms.hi, axis=-2)
    rem = up(mag * 0.5)                                    # (|c_1|/2)^(order+1)/(order+1)!, rounded up
    bound = rem
    for _ in range(order):
        bound = up(bound * rem)
    bound = up(bound / float(factorial(order + 1)))        # exact divisor (order ≤ 12)
    lo[..., 0] = down_sum(lo[..., 0] - bound)
    hi[..., 0] = up_sum(hi[..., 0] + bound)
    if (limit := _LIMIT.get()) is not None:
        lo, hi = _fold(lo, hi, limit)
    return Poly(lo, hi)


def cos(x: Poly, order: int | None = None) -> Poly:
    """cos of a polynomial of degree ≤ 1, as a polynomial valid for t ∈ [0, 1] (see ``_trig``)."""
    return _trig(x, "cos", order)


def sin(x: Poly, order: int | None = None) -> Poly:
    """sin of a polynomial of degree ≤ 1, as a polynomial valid for t ∈ [0, 1] (see ``_trig``)."""
    return _trig(x, "sin", order)


def sqr(x: Poly) -> Poly:
    return x * x


def pown(x: Poly, n: int) -> Poly:
    out = Poly.from_coefficients([Interval(1.0)]) if n == 0 else x
    for _ in range(n - 1):
        out = out * x
    return out


def ratio_range(p: Interval, q: Interval) -> Interval:
    """Enclosure of the range of p/q over an interval from the Bernstein coefficients
    (…, n + 1) of p and q on it (same degree): when every coefficient of q is > 0,
    p/q = Σ_j w_j (p_j / q_j) with weights w_j = q_j B_j / Σ_k q_k B_k ≥ 0 summing
    to 1, so p/q lies between the extreme ratios (Narkawicz, Garloff, Smith & Muñoz
    2012, "Bounding the range of a rational function over a box").  Elsewhere the
    quotient of the two ranges."""
    r = p / q
    positive = np.all(q.lo > 0, axis=-1)
    ranged = Interval.from_bounds(p.lo.min(axis=-1), p.hi.max(axis=-1)) / Interval.from_bounds(q.lo.min(axis=-1), q.hi.max(axis=-1))
    lo = np.where(positive, r.lo.min(axis=-1), ranged.lo)
    hi = np.where(positive, r.hi.max(axis=-1), ranged.hi)
    return Interval.from_bounds(lo, hi)


_U = 2.0 ** -53          # unit roundoff


def bernstein_weights(a, b, n):
    """Enclosures (W_lo, W_hi), both ≥ 0, shape (..., n+1, n+1), of the map c -> Bernstein
    coefficients on [a, b] (a ≥ 0): W[i, j] = Σ_k T[i, k] h^k C(j, k) a^(j−k), h = b − a.
    Every factor is ≥ 0, so products and sums of lower (upper) bounds are lower (upper) bounds."""
    d = b - a
    base_lo = np.stack([np.asarray(a, dtype=np.float64), np.maximum(down_sum(d), 0.0)])   # (2, ...): a, h
    base_hi = np.stack([np.asarray(a, dtype=np.float64), up_sum(d)])
    pow_lo, pow_hi = [np.ones_like(base_lo)], [np.ones_like(base_hi)]
    for _ in range(n):                        # a^k and h^k, k = 0..n, rounded outward step by step
        pow_lo.append(np.maximum(down(pow_lo[-1] * base_lo), 0.0))
        pow_hi.append(up(pow_hi[-1] * base_hi))
    pow_lo, pow_hi = np.stack(pow_lo, -1), np.stack(pow_hi, -1)   # (2, ..., n + 1)
    C, jmk, upper = _shift_tables(n)
    # S[k, j] = h^k C(j, k) a^(j−k) for k ≤ j, else 0
    S_lo = np.maximum(down(down(C * pow_lo[0][..., jmk]) * pow_lo[1][..., :, None]), 0.0) * upper
    S_hi = up(up(C * pow_hi[0][..., jmk]) * pow_hi[1][..., :, None]) * upper
    Tlo, Thi = _bernstein_matrix(n)
    d = 4.0 * (n + 1) * _U          # sums of n + 1 nonnegative products: |fl − exact| ≤ γ_{n+1} exact
    return np.maximum(down((Tlo @ S_lo) * (1.0 - d)), 0.0), up((Thi @ S_hi) * (1.0 + d))


_SHIFT = {}


def _shift_tables(n):
    """C(j, k), the index j − k (clipped at 0) and the mask k ≤ j, as (n+1, n+1) arrays [k, j]."""
    if n not in _SHIFT:
        k, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        C = np.array([[float(comb(jj, kk)) for jj in range(n + 1)] for kk in range(n + 1)])
        _SHIFT[n] = (C, np.maximum(j - k, 0), (k <= j).astype(np.float64))
    return _SHIFT[n]


def _bernstein_nonnegative(lo, hi, a, b, n, weights=None):
    """Bernstein range on [a, b] ⊂ [0, ∞): b_j = Σ_k W[j, k] c_k with W ≥ 0, so
    b_j ≥ Σ_k (W_lo c_lo⁺ + W_hi c_lo⁻) and b_j ≤ Σ_k (W_hi c_hi⁺ + W_lo c_hi⁻); each
    sum has terms of one sign, so its float value is within γ_{n+1} = (n+1)u/(1 − (n+1)u)
    relative of the exact one (Higham 2002, §3.1, any order of summation, with or without
    FMA); the bound is applied as a factor 1 ∓ 4(n+1)u and the result rounded outward."""
    if weights is None:
        a, b = np.broadcast_arrays(a, b)
        weights = bernstein_weights(a, b, n)           # (t's shape, n+1, n+1): broadcast like t
    Wlo, Whi = weights
    Wl, Wh = np.swapaxes(Wlo, -1, -2), np.swapaxes(Whi, -1, -2)
    cl_p, cl_n = np.maximum(lo, 0.0), np.minimum(lo, 0.0)
    ch_p, ch_n = np.maximum(hi, 0.0), np.minimum(hi, 0.0)
    d = 4.0 * (n + 1) * _U          # sums of n + 1 products of one sign: |fl − exact| ≤ γ_{n+1} |exact|
    blo = down_sum(down(_vecmat(cl_p, Wl) * (1.0 - d)) + down(_vecmat(cl_n, Wh) * (1.0 + d)))
    bhi = up_sum(up(_vecmat(ch_p, Wh) * (1.0 + d)) + up(_vecmat(ch_n, Wl) * (1.0 - d)))
    return Interval.from_bounds(blo, bhi)


def _vecmat(c, W):
    """c (…, n+1) times W (…, n+1, n+1), broadcast over the leading axes."""
    if W.ndim >= 3 and W.ndim == c.ndim + 1 and W.shape[-3] == 1 and c.shape[:-2] == W.shape[:-3]:
        return np.matmul(c, W[..., 0, :, :])          # one W per row of polynomials: a batched product
    return np.matmul(c[..., None, :], W)[..., 0, :]


def _bernstein_taylor(lo, hi, a, b, n):
    """Bernstein range on any [a, b], in interval arithmetic: Taylor shift by a (Horner's
    synthetic division), scaling by h^k, then the Bernstein map."""
    c = [Interval.from_bounds(lo[..., k], hi[..., k]) for k in range(n + 1)]
    A = Interval.from_bounds(a, a)
    for i in range(n):
        for j in range(n - 1, i - 1, -1):
            c[j] = c[j] + A * c[j + 1]
    d = b - a
    h = Interval.from_bounds(np.maximum(down_sum(d), 0.0), up_sum(d))
    hk = h
    for k in range(1, n + 1):
        c[k] = c[k] * hk
        if k < n:
            hk = hk * h
    Tlo, Thi = _bernstein_matrix(n)
    blo = np.repeat(c[0].lo[..., None], n + 1, axis=-1)
    bhi = np.repeat(c[0].hi[..., None], n + 1, axis=-1)
    for k in range(1, n + 1):
        t = mul(Interval.from_bounds(Tlo[k:, k], Thi[k:, k]), Interval.from_bounds(c[k].lo[..., None], c[k].hi[..., None]))
        blo[..., k:] = down_sum(blo[..., k:] + t.lo)
        bhi[..., k:] = up_sum(bhi[..., k:] + t.hi)
    return Interval.from_bounds(blo, bhi)
