"""Interval arithmetic on numpy arrays, with its own outward rounding (docs/soundness.md §12).

An ``Iv`` holds two float64 arrays ``lo`` ≤ ``hi`` of any (broadcastable) shape, a batch of intervals; every operation
returns an enclosure of the exact range of the operation over its operands (§12 argues each).  A NaN bound means
"nothing known": every predicate that proves something (``> 0``, inside, disjoint, empty) is a comparison that is
false on NaN, and ``np.minimum``/``np.maximum`` propagate NaN rather than drop it."""
from __future__ import annotations

from fractions import Fraction
from math import factorial

import numpy as np
from mpmath import iv, mp

TINY, INF = 2.0 ** -1022, np.inf
PHI = 2.0 ** -53 + 2.0 ** -105   # u (1 + 2u)


def dn(x):
    """A float ≤ every real whose round-to-nearest is x: pred(x), or one float lower (§12)."""
    return x - (np.abs(x) * PHI + TINY)


def up(x):
    """A float ≥ every real whose round-to-nearest is x: succ(x), or one float higher (§12)."""
    return x + (np.abs(x) * PHI + TINY)


def enclose_fraction(q: Fraction):
    """(lo, hi) floats with lo ≤ q ≤ hi (float(Fraction) rounds correctly; the test is exact)."""
    try:
        f = float(q)
    except OverflowError:
        return (float(np.finfo(float).max), INF) if q > 0 else (-INF, -float(np.finfo(float).max))
    return (f, f) if Fraction(f) == q else (f, float(np.nextafter(f, INF))) if Fraction(f) < q else (float(np.nextafter(f, -INF)), f)


class Iv:
    """A batch of intervals [lo, hi] (numpy arrays); see the module docstring."""

    __slots__ = ("lo", "hi")
    __array_priority__ = 1000           # numpy arrays defer to Iv in mixed operations

    def __init__(self, lo, hi=None):
        self.lo = np.asarray(lo, dtype=np.float64)
        self.hi = self.lo if hi is None else np.asarray(hi, dtype=np.float64)

    @staticmethod
    def const(q):
        """The tightest enclosure of an exact rational (``Fraction``, int)."""
        return Iv(*enclose_fraction(Fraction(q)))

    def __getitem__(self, k):
        return Iv(self.lo[k], self.hi[k])

    def __setitem__(self, k, v):
        v = v if isinstance(v, Iv) else Iv(v)
        self.lo[k], self.hi[k] = v.lo, v.hi

    @property
    def shape(self):
        return np.broadcast_shapes(self.lo.shape, self.hi.shape)

    def copy(self):
        return Iv(np.array(self.lo, copy=True), np.array(self.hi, copy=True))

    def __neg__(self):
        return Iv(-self.hi, -self.lo)

    def __add__(self, o):
        if not isinstance(o, _OPERANDS):
            return NotImplemented
        olo, ohi = (o.lo, o.hi) if isinstance(o, Iv) else (o, o)
        return Iv(dn(self.lo + olo), up(self.hi + ohi))

    __radd__ = __add__

    def __sub__(self, o):
        return self + (-o) if isinstance(o, _OPERANDS) else NotImplemented

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if not isinstance(o, _OPERANDS):
            return NotImplemented
        if not isinstance(o, Iv):       # exact float(s): two products
            a, b = self.lo * o, self.hi * o
            return Iv(dn(np.minimum(a, b)), up(np.maximum(a, b)))
        p = (self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi)
        lo = np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3]))
        hi = np.maximum(np.maximum(p[0], p[1]), np.maximum(p[2], p[3]))
        return Iv(dn(lo), up(hi))

    __rmul__ = __mul__

    def __truediv__(self, o):
        """Division; where the divisor holds 0 the result is [−∞, ∞] (a valid enclosure)."""
        o = o if isinstance(o, Iv) else Iv(o)
        zero = ~((o.lo > 0) | (o.hi < 0))
        with np.errstate(all="ignore"):
            q = (self.lo / o.lo, self.lo / o.hi, self.hi / o.lo, self.hi / o.hi)
        lo = dn(np.minimum(np.minimum(q[0], q[1]), np.minimum(q[2], q[3])))
        hi = up(np.maximum(np.maximum(q[0], q[1]), np.maximum(q[2], q[3])))
        return Iv(np.where(zero, -INF, lo), np.where(zero, INF, hi))

    def sqr(self):
        """[mig², mag²]: the exact range of x² over the interval, rounded outward."""
        mig = np.where(self.lo > 0, self.lo, np.where(self.hi < 0, -self.hi, 0.0 * self.lo))
        mag = np.maximum(np.abs(self.lo), np.abs(self.hi))
        return Iv(np.maximum(dn(mig * mig), 0.0), up(mag * mag))

    def sqrt(self):
        """√ of the non-negative part (NaN where the interval is wholly negative)."""
        with np.errstate(invalid="ignore"):
            return Iv(np.maximum(dn(np.sqrt(np.maximum(self.lo, 0.0))), 0.0), up(np.sqrt(self.hi)))

    def sum(self, axis=-1):
        return Iv(*_sum_bounds(self.lo, self.hi, axis))

    def meet(self, o):
        """Intersection (``empty()`` where it is empty)."""
        return Iv(np.maximum(self.lo, o.lo), np.minimum(self.hi, o.hi))

    def empty(self):
        return self.lo > self.hi

    def pos(self):
        return self.lo > 0

    def neg(self):
        return self.hi < 0

    def sign(self):
        """1 where > 0, −1 where < 0, 0 where undecided."""
        return np.where(self.lo > 0, 1, np.where(self.hi < 0, -1, 0))

    def mag(self):
        return np.maximum(np.abs(self.lo), np.abs(self.hi))


_OPERANDS = (Iv, int, float, np.ndarray, np.floating)


def stack(parts, axis=-1) -> Iv:
    return Iv(np.stack([p.lo if isinstance(p, Iv) else np.asarray(p, float) for p in parts], axis),
              np.stack([p.hi if isinstance(p, Iv) else np.asarray(p, float) for p in parts], axis))


def _bound(total_abs, m):
    """An upper bound of γ_{m−1}·Σ|x| from the float sum ``total_abs`` of the |x| (§12)."""
    return total_abs * ((m + 2) * 2.0 ** -53) + TINY


def _sum_bounds(lo, hi, axis):
    """Bounds of Σ lo, Σ hi along an axis (float sums ± the a-priori error bound)."""
    m = np.shape(lo)[axis]
    if m == 1:
        return np.take(lo, 0, axis), np.take(hi, 0, axis)
    return (dn(np.sum(lo, axis) - _bound(np.sum(np.abs(lo), axis), m)),
            up(np.sum(hi, axis) + _bound(np.sum(np.abs(hi), axis), m)))


def pmatmul(P, B: Iv) -> Iv:
    """P @ B for a float matrix P (..., n, k) and an interval matrix B (..., k, m): [Σ P⁺ B̲ + P⁻ B̄,
    Σ P⁺ B̄ + P⁻ B̲], two float matrix products widened by the bound of their rounding error (§12)."""
    Q = np.concatenate([np.maximum(P, 0.0), np.minimum(P, 0.0)], -1)
    Qa = np.abs(Q)
    lo_ops, hi_ops = np.concatenate([B.lo, B.hi], -2), np.concatenate([B.hi, B.lo], -2)
    m = 2 * P.shape[-1]
    with np.errstate(all="ignore"):
        lo = dn(Q @ lo_ops - _bound(Qa @ np.abs(lo_ops), m))
        hi = up(Q @ hi_ops + _bound(Qa @ np.abs(hi_ops), m))
    return Iv(lo, hi)


def pmatvec(P, b: Iv) -> Iv:
    """P @ b for a float matrix P (..., n, k) and an interval vector b (..., k)."""
    r = pmatmul(P, Iv(b.lo[..., None], b.hi[..., None]))
    return Iv(r.lo[..., 0], r.hi[..., 0])


# π ∈ [PI_A, PI_B] (rationals 2⁻²⁰⁰ apart, from mpmath's rigorous interval π); π/2 = H + M + T with
# H of 30 significant bits (k·H is exact for |k| < 2²³), M = fl(π/2 − H) and T ∈ [T̲, T̄] tiny
def _pi_bounds():
    """π ∈ [A, B]: the ends of mpmath's rigorous interval π at 220 bits, as exact rationals."""
    saved = iv.prec, mp.prec
    iv.prec = mp.prec = 220
    try:
        pi = iv.pi
        return [Fraction(man) * Fraction(2) ** exp for man, exp in (mp.mpf(pi.a).man_exp, mp.mpf(pi.b).man_exp)]
    finally:
        iv.prec, mp.prec = saved


PI_BELOW, PI_ABOVE = _pi_bounds()           # exact rationals, PI_BELOW < π < PI_ABOVE (220 bits)
_H = float(np.ldexp(np.floor(np.ldexp(float(PI_BELOW / 2), 29)), -29))
_M = float(PI_BELOW / 2 - Fraction(_H))
_T = Iv(Iv.const(PI_BELOW / 2 - Fraction(_H) - Fraction(_M)).lo, Iv.const(PI_ABOVE / 2 - Fraction(_H) - Fraction(_M)).hi)
PI = Iv(Iv.const(PI_BELOW).lo, Iv.const(PI_ABOVE).hi)
PIO2 = Iv(Iv.const(PI_BELOW / 2).lo, Iv.const(PI_ABOVE / 2).hi)
_SIN = [Iv.const(Fraction((-1) ** j, factorial(2 * j + 1))) for j in range(11)]   # r^(2j+1) terms
_COS = [Iv.const(Fraction((-1) ** j, factorial(2 * j))) for j in range(11)]       # r^(2j) terms
_REM_SIN = float(Fraction(2, factorial(23)))   # |r|^23/23! ≤ |r| · this, for |r| ≤ 1
_REM_COS = float(Fraction(2, factorial(22)))   # |r|^22/22! ≤ r² · this


def _poly(s: Iv, coefs):
    p = coefs[-1]
    for c in coefs[-2::-1]:
        p = p * s + c
    return p


def _sincos_points(x):
    """(sin x, cos x) enclosures at the float points x: reduction x = kπ/2 + r, then Taylor in r."""
    x = np.asarray(x, dtype=np.float64)
    with np.errstate(all="ignore"):
        k = np.rint(x / _H)
        ok = np.isfinite(x) & (np.abs(k) < 2.0 ** 22)
        k = np.where(ok, k, 0.0)
        r = (Iv(x) - Iv(k * _H)) - Iv(k) * (_T + _M)
        r = Iv(np.where(k == 0, x, r.lo), np.where(k == 0, x, r.hi))      # no reduction: r = x exactly
        s = r.sqr()
        rem_s, rem_c = up(r.mag() * _REM_SIN), up(s.hi * _REM_COS)
        sin_r = r + ((r * s) * _poly(s, _SIN[1:]) + Iv(-rem_s, rem_s))   # r + r³(−1/6 + ...): the
        cos_r = 1.0 + (s * _poly(s, _COS[1:]) + Iv(-rem_c, rem_c))        # rounding acts on the small terms
    q = np.mod(k, 4).astype(np.int64)
    choose = lambda parts: Iv(np.choose(q, [p.lo for p in parts]), np.choose(q, [p.hi for p in parts]))  # noqa: E731
    sn = choose([sin_r, cos_r, -sin_r, -cos_r])
    cs = choose([cos_r, -sin_r, -cos_r, sin_r])
    bad = ~ok | (r.mag() > 1.0)
    one = lambda v: Iv(np.where(bad, -1.0, np.maximum(v.lo, -1.0)), np.where(bad, 1.0, np.minimum(v.hi, 1.0)))  # noqa: E731
    return one(sn), one(cs)


def _extremes(x: Iv, residue_max, residue_min):
    """Masks: the interval may hold a point nπ/2 with n ≡ residue_max (resp. residue_min) mod 4."""
    q = x / PIO2
    lo, hi = np.ceil(q.lo), np.floor(q.hi)
    wide = ~(hi - lo < 3)               # four consecutive integers (or NaN): every residue
    has_max, has_min = wide.copy(), wide.copy()
    for j in range(3):
        n = lo + j
        inside = n <= hi
        has_max |= inside & (np.mod(n, 4) == residue_max)
        has_min |= inside & (np.mod(n, 4) == residue_min)
    return has_max, has_min


def sincos(x: Iv):
    """(range of sin, range of cos) over each interval: the enclosures at both ends, and ±1 where an
    extremum (a multiple of π/2 of the right residue mod 4) may lie inside."""
    a = _sincos_points(x.lo)
    b = a if np.array_equal(x.lo, x.hi) else _sincos_points(x.hi)
    out = []
    for which, residues in ((0, (1, 3)), (1, (0, 2))):
        va, vb = a[which], b[which]
        has_max, has_min = _extremes(x, *residues)
        out.append(Iv(np.where(has_min, -1.0, np.minimum(va.lo, vb.lo)), np.where(has_max, 1.0, np.maximum(va.hi, vb.hi))))
    return tuple(out)

