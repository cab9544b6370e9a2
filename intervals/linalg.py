"""Batched interval linear algebra: products, determinants, Gauss-Seidel, Krawczyk.

An interval matrix is an ``Interval`` of shape ``(..., n, n)`` and a vector
one of shape ``(..., n)``; leading dimensions are a batch and broadcast.  A
float ``ndarray`` stands for the exact (point) matrix of its binary values.
Every function loops only over the matrix dimension (small), never over the
batch.

Guarantees (for every real matrix/vector in the arguments):

* ``matmul``/``matvec``: the exact product lies in the result (interval
  accumulation of interval products, each operation rounded outward);
* ``det``: the exact determinant lies in the result;
* ``gauss_seidel``: no solution inside ``x`` is lost;
* ``krawczyk``: ``unique`` proves exactly one zero in ``x``, ``empty``
  proves none;
* ``hansen_sengupta``: no zero in ``x`` is lost; ``empty`` proves none.

``mid_inverse`` is a heuristic preconditioner; nothing rigorous depends on
its accuracy.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .interval import Interval, _as_interval, div, mul
from .rounding import INF, down, down_sum, up, up_sum

__all__ = [
    "identity", "point", "matmul", "matvec", "det", "hadamard_bound", "mid_inverse",
    "gauss_seidel", "hansen_sengupta", "krawczyk", "KrawczykResult", "laplace_det",
]


# ----------------------------------------------------------------- helpers
def identity(n: int, batch=()) -> Interval:
    """The exact ``n x n`` identity as a degenerate interval matrix of shape ``batch + (n, n)``."""
    eye = np.broadcast_to(np.eye(n), tuple(batch) + (n, n))
    return Interval._raw(eye.copy(), eye.copy())


def point(M) -> Interval:
    """A float array (exact binary values) as a degenerate ``Interval``."""
    if isinstance(M, Interval):
        return M
    M = _check_float(M)
    return Interval._raw(M, M.copy())


def _check_float(M) -> np.ndarray:
    M = np.asarray(M, dtype=np.float64)
    if not np.all(np.isfinite(M)):
        raise ValueError("a point matrix/vector must have finite entries")
    return M


def _operand(M):
    """An ``Interval`` or a finite float ndarray (exact)."""
    if isinstance(M, Interval):
        return M
    return _check_float(M)


def _take(M, idx):
    """``M[..., idx]`` for a float array or an Interval (plain slicing / indexing)."""
    if isinstance(M, Interval):
        return Interval._raw(M.lo[idx], M.hi[idx])
    return M[idx]


def _prod(a, b):
    """Enclosure (lo, hi) of the elementwise product; float operands are exact points."""
    a_iv = isinstance(a, Interval)
    b_iv = isinstance(b, Interval)
    if a_iv and b_iv:
        p = mul(a, b)
        nan = np.isnan(p.lo)
        if np.any(nan):
            # interval.mul leaves [0, 0] * [-inf, inf] as NaN ("unknown"); it is exactly 0
            zero = ((a.lo == 0) & (a.hi == 0)) | ((b.lo == 0) & (b.hi == 0))
            fix = nan & zero
            return np.where(fix, 0.0, p.lo), np.where(fix, 0.0, p.hi)
        return p.lo, p.hi
    if not a_iv and not b_iv:
        p = a * b
        return down(p), up(p)
    if not a_iv:
        a, b = b, a  # a interval, b float
    with np.errstate(invalid="ignore"):
        lo = a.lo * b
        hi = a.hi * b
    lo, hi = np.fmin(lo, hi), np.fmax(lo, hi)  # fmin/fmax skip the NaN of 0 * inf
    nan = np.isnan(lo)
    if np.any(nan):
        # the point 0 times anything (an infinite endpoint is a bound, not a value) is 0
        fix = nan & (b == 0)
        lo = np.where(fix, 0.0, lo)
        hi = np.where(fix, 0.0, hi)
    return down(lo), up(hi)


def _accumulate(terms):
    """Outward-rounded sum of an iterable of (lo, hi) enclosures."""
    s_lo = s_hi = None
    for lo, hi in terms:
        if s_lo is None:
            s_lo, s_hi = lo, hi
        else:
            s_lo = down_sum(s_lo + lo)
            s_hi = up_sum(s_hi + hi)
    return s_lo, s_hi


# ----------------------------------------------------------------- products
def matmul(A, B) -> Interval:
    """Enclosure of ``A @ B`` for ``A (..., n, k)``, ``B (..., k, m)`` (Interval or float).

    Each entry is the outward-rounded interval sum of ``k`` interval products
    (``interval.mul``, or two float products with sign selection when one
    factor is a point), so it contains ``sum_j a_ij b_jl`` for every real
    ``a_ij in A_ij``, ``b_jl in B_jl``.  Batch dimensions broadcast.
    """
    A = _operand(A)
    B = _operand(B)
    k = A.shape[-1]
    if B.shape[-2] != k:
        raise ValueError(f"matmul: inner dimensions differ ({A.shape} @ {B.shape})")
    if k == 0:
        shape = np.broadcast_shapes(A.shape[:-2], B.shape[:-2]) + (A.shape[-2], B.shape[-1])
        return Interval._raw(np.zeros(shape), np.zeros(shape))
    lo, hi = _accumulate(
        _prod(_take(A, (..., slice(None), slice(j, j + 1))), _take(B, (..., slice(j, j + 1), slice(None))))
        for j in range(k))
    return Interval._raw(lo, hi)


def matvec(A, x) -> Interval:
    """Enclosure of ``A @ x`` for ``A (..., n, k)``, ``x (..., k)`` (Interval or float); see ``matmul``."""
    A = _operand(A)
    x = _operand(x)
    k = A.shape[-1]
    if x.shape[-1] != k:
        raise ValueError(f"matvec: dimensions differ ({A.shape} @ {x.shape})")
    if k == 0:
        shape = np.broadcast_shapes(A.shape[:-2], x.shape[:-1]) + (A.shape[-2],)
        return Interval._raw(np.zeros(shape), np.zeros(shape))
    lo, hi = _accumulate(
        _prod(_take(A, (..., slice(None), j)), _take(x, (..., slice(j, j + 1)))) for j in range(k))
    return Interval._raw(lo, hi)


# ----------------------------------------------------------------- determinant
def hadamard_bound(A) -> np.ndarray:
    """Upper bound of ``|det M|`` over ``M in A``: Hadamard's inequality, rows and columns.

    ``|det M| <= prod_i ||M_i,:||_2`` (and likewise for columns), with
    ``|M_ij| <= mag(A_ij)``; every float step is rounded upward.  NaN -> inf.
    """
    A = point(A)
    m = A.mag()
    n = m.shape[-1]
    sq = up(m * m)

    def prod_norms(axis):
        s = _accumulate((sq_j, sq_j) for sq_j in np.moveaxis(sq, axis, 0))[1]
        r = up(np.sqrt(s))
        out = np.ones(r.shape[:-1])
        for i in range(n):
            out = up(out * r[..., i])
        return np.maximum(out, 0.0)

    if n == 0:
        return np.ones(A.shape[:-2])
    h = np.minimum(prod_norms(-1), prod_norms(-2))
    return np.where(np.isnan(h), INF, h)


def _det_small(A: Interval) -> Interval:
    n = A.shape[-1]
    a = lambda i, j: A[..., i, j]  # noqa: E731
    if n == 1:
        return a(0, 0)
    if n == 2:
        return a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)
    # n == 3: cofactor expansion along the first row
    return (a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
            - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
            + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0)))


def _float_lu(M):
    """Batched partial-pivoting LU of float ``M``: (perm, sign, L) with ``M[perm] ~ L U``.

    Heuristic only (a preconditioner for ``det``): zero or non-finite pivots
    are replaced by 1 so that ``L`` stays finite.
    """
    n = M.shape[-1]
    batch = M.shape[:-2]
    U = np.array(M, dtype=np.float64, copy=True)
    U[~np.isfinite(U)] = 0.0
    L = np.zeros_like(U)
    perm = np.broadcast_to(np.arange(n), batch + (n,)).copy()
    sign = np.ones(batch)
    rows = np.arange(n)
    for k in range(n):
        p = np.argmax(np.abs(U[..., k:, k]), axis=-1) + k  # (batch)
        idx = np.broadcast_to(rows, batch + (n,)).copy()
        np.put_along_axis(idx, p[..., None], k, axis=-1)
        idx[..., k] = p
        U = np.take_along_axis(U, idx[..., None], axis=-2)
        L = np.take_along_axis(L, idx[..., None], axis=-2)
        perm = np.take_along_axis(perm, idx, axis=-1)
        sign = np.where(p != k, -sign, sign)
        piv = U[..., k, k]
        piv = np.where((piv == 0) | ~np.isfinite(piv), 1.0, piv)
        with np.errstate(over="ignore", invalid="ignore"):
            f = U[..., k + 1:, k] / piv[..., None]
            f = np.where(np.isfinite(f), f, 0.0)
            L[..., k + 1:, k] = f
            U[..., k + 1:, :] -= f[..., None] * U[..., k:k + 1, :]
            U[~np.isfinite(U)] = 0.0
    return perm, sign, L + np.eye(n)


def _unit_lower_inverse(L):
    """Float approximate inverse of a unit lower-triangular ``L``, *exactly* unit lower triangular.

    The diagonal is set to exactly 1 and the upper part to exactly 0, so its
    determinant is exactly 1 whatever the rounding errors.
    """
    n = L.shape[-1]
    X = np.zeros_like(L)
    with np.errstate(over="ignore", invalid="ignore"):
        for i in range(n):
            row = np.zeros(L.shape[:-2] + (n,))
            row[..., i] = 1.0
            for j in range(i):
                row -= L[..., i, j, None] * X[..., j, :]
            X[..., i, :] = row
    bad = ~np.all(np.isfinite(X), axis=(-2, -1))
    X = np.where(bad[..., None, None], 0.0, X)
    return np.tril(X, -1) + np.eye(n)


def _det_gauss(Y: Interval):
    """Interval Gaussian elimination without pivoting: (prod of pivots, fail mask).

    For every real ``M in Y`` the real elimination pivots lie in the interval
    pivots (inclusion isotonicity); if none of the first n - 1 (the divisors)
    contains 0 the real elimination succeeds and ``det M`` = product of its
    pivots lies in the product (the last pivot may contain 0).
    """
    n = Y.shape[-1]
    fail = np.zeros(Y.shape[:-2], dtype=bool)
    S = Y
    d = None
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for k in range(n):
            piv = S[..., 0, 0]
            d = piv if d is None else d * piv
            if k < n - 1:  # the last pivot divides nothing: it may contain 0
                fail |= piv.contains_zero()
                f = S[..., 1:, 0] / Interval._raw(piv.lo[..., None], piv.hi[..., None])
                S = S[..., 1:, 1:] - mul(Interval._raw(f.lo[..., :, None], f.hi[..., :, None]),
                                         Interval._raw(S.lo[..., None, 0, 1:], S.hi[..., None, 0, 1:]))
    return d, fail


def det(A) -> Interval:
    """Enclosure of ``det M`` for every real ``M in A`` (``A`` of shape ``(..., n, n)``).

    * ``n <= 3``: cofactor expansion in interval arithmetic.
    * ``n >= 4``: a float LU with partial pivoting of ``mid(A)`` gives a
      permutation ``P`` (sign ``s``) and ``L``; ``X`` is an approximate
      inverse of ``L`` forced to be *exactly* unit lower triangular, so
      ``det X = 1`` and ``det M = s * det(X P M)``.  ``Y = X P A`` is
      enclosed by ``matmul`` (nearly upper triangular) and ``det Y`` by
      interval Gaussian elimination without pivoting (product of the pivot
      intervals).  (LU preconditioning of the midpoint, cf. Rump,
      "Verification methods", Acta Numerica 19 (2010); only the left factor
      is used, so no second determinant must be enclosed.)
      If a pivot interval contains 0 the elimination proves nothing and the
      Hadamard bound is used instead.

    Every result is intersected with ``[-H, H]``, ``H = hadamard_bound(A)``.
    """
    A = point(A)
    n = A.shape[-1]
    if A.shape[-2] != n:
        raise ValueError(f"det needs square matrices, got shape {A.shape}")
    H = hadamard_bound(A)
    if n == 0:
        one = np.ones(A.shape[:-2])
        return Interval._raw(one, one.copy())
    with np.errstate(invalid="ignore", over="ignore"):
        if n <= 3:
            D = _det_small(A)
            fail = np.zeros(A.shape[:-2], dtype=bool)
        else:
            perm, sign, L = _float_lu(A.mid())
            X = _unit_lower_inverse(L)
            PA = Interval._raw(np.take_along_axis(A.lo, perm[..., None], axis=-2),
                               np.take_along_axis(A.hi, perm[..., None], axis=-2))
            Y = matmul(X, PA)
            D, fail = _det_gauss(Y)
            D = Interval._raw(np.where(sign > 0, D.lo, -D.hi), np.where(sign > 0, D.hi, -D.lo))
    fail = fail | np.isnan(D.lo) | np.isnan(D.hi)
    lo = np.where(fail, -H, np.maximum(D.lo, -H))
    hi = np.where(fail, H, np.minimum(D.hi, H))
    return Interval._raw(lo, hi)


def laplace_det(M):
    """Cofactor (Laplace) expansion of ``det M`` along the rows, minors shared.

    ``M`` is a list of rows of any objects with ``+ - *`` (``Interval``,
    ``autodiff.Dual``): with ``Dual`` entries it gives the enclosure of the
    gradient of det, which ``det`` cannot.  The minors of the lower rows are
    memoised by their column set, so a 6x6 costs 192 products, not 720 x 5.
    Each operation encloses, so the result encloses det M for every M in M.
    """
    n = len(M)
    memo = {}

    def minor(cols):
        if len(cols) == 1:
            return M[n - 1][cols[0]]
        if cols not in memo:
            r = n - len(cols)
            total = None
            for k, j in enumerate(cols):
                term = M[r][j] * minor(cols[:k] + cols[k + 1:])
                total = term if total is None else (total - term if k % 2 else total + term)
            memo[cols] = total
        return memo[cols]

    return minor(tuple(range(n)))


# ----------------------------------------------------------------- preconditioner
def mid_inverse(A, rcond: float | None = None):
    """Float inverse of the midpoint matrix (a preconditioner, not rigorous).

    Returns ``(C, failed)``: ``C`` of shape ``(..., n, n)``, always finite,
    and a boolean mask ``failed`` where ``mid(A)`` is singular, non-finite or
    ill conditioned (estimated reciprocal 1-norm condition number below
    ``rcond``, default ``n * 2**-52``, or ``|C mid(A) - I| >= 1/2``).  There
    ``C`` is the pseudo-inverse, or the identity if that is zero or not finite.
    """
    M = A.mid() if isinstance(A, Interval) else np.asarray(A, dtype=np.float64)
    n = M.shape[-1]
    if rcond is None:
        rcond = n * 2.0 ** -52
    batch = M.shape[:-2]
    eye = np.eye(n)
    finite = np.all(np.isfinite(M), axis=(-2, -1))
    M0 = np.where(finite[..., None, None], M, eye)
    with np.errstate(all="ignore"):
        try:
            C = np.linalg.inv(M0)
        except np.linalg.LinAlgError:
            C = np.linalg.pinv(M0)
        ok = finite & np.all(np.isfinite(C), axis=(-2, -1))
        norm_m = np.max(np.sum(np.abs(M0), axis=-2), axis=-1)
        norm_c = np.max(np.sum(np.abs(C), axis=-2), axis=-1)
        est = 1.0 / (norm_m * norm_c)
        ok &= (est >= rcond) & (norm_m > 0)
        resid = np.max(np.abs(C @ M0 - eye), axis=(-2, -1))
        ok &= resid < 0.5  # catches pseudo-inverses of singular matrices
    failed = ~ok
    if np.any(failed):
        with np.errstate(all="ignore"):
            C = np.array(np.broadcast_to(C, batch + (n, n)), copy=True)
            try:
                P = np.linalg.pinv(M0[failed])
            except np.linalg.LinAlgError:
                P = np.broadcast_to(eye, (int(failed.sum()), n, n))
            good_p = np.all(np.isfinite(P), axis=(-2, -1)) & np.any(P != 0, axis=(-2, -1))
            C[failed] = np.where(good_p[..., None, None], P, eye)
    return C, failed


# ----------------------------------------------------------------- Gauss-Seidel
def _gs_update(num: Interval, den: Interval, xi: Interval) -> Interval:
    """``xi`` intersected with ``{t : d t = v, d in den, v in num}`` (extended division).

    If ``den`` excludes 0 this is ``num / den``.  If ``den`` contains 0 and
    ``num`` excludes 0 the set is one or two half-lines (Hansen & Sengupta
    1981; Neumaier 1990, sec. 4.3) and the hull of their intersections with
    ``xi`` is returned.  If both contain 0 (or anything is NaN) every ``t``
    qualifies: ``xi`` is returned unchanged.
    """
    with np.errstate(all="ignore"):
        regular = ~den.contains_zero()
        # used only where `regular`: elsewhere divide by 1 (no extended division needed there)
        q = div(num, Interval._raw(np.where(regular, den.lo, 1.0), np.where(regular, den.hi, 1.0)))
        out_lo = np.fmax(xi.lo, q.lo)
        out_hi = np.fmin(xi.hi, q.hi)
        nl, nh, dl, dh = num.lo, num.hi, den.lo, den.hi
        pos = nl > 0
        neg = nh < 0
        known = ~(np.isnan(nl) | np.isnan(nh) | np.isnan(dl) | np.isnan(dh))
        ext = ~regular & (pos | neg) & known
        if np.any(ext):
            # left piece (-inf, a], right piece [b, inf); absent pieces have a = -inf / b = inf
            has_left = np.where(pos, dl < 0, dh > 0)
            has_right = np.where(pos, dh > 0, dl < 0)
            a = up(np.where(pos, nl / dl, nh / dh))
            b = down(np.where(pos, nl / dh, nh / dl))
            a = np.where(has_left, a, -INF)
            b = np.where(has_right, b, INF)
            a = np.where(np.isnan(a), INF, a)  # unknown -> keep everything
            b = np.where(np.isnan(b), -INF, b)
            # intersections [xl, min(xh, a)] and [max(xl, b), xh]
            l_lo, l_hi = xi.lo, np.minimum(xi.hi, a)
            r_lo, r_hi = np.maximum(xi.lo, b), xi.hi
            l_ok = has_left & (l_lo <= l_hi)
            r_ok = has_right & (r_lo <= r_hi)
            e_lo = np.where(l_ok, l_lo, np.where(r_ok, r_lo, INF))
            e_hi = np.where(r_ok, r_hi, np.where(l_ok, l_hi, -INF))
            out_lo = np.where(ext, e_lo, out_lo)
            out_hi = np.where(ext, e_hi, out_hi)
        keep = (~regular & ~ext) | ~known
        out_lo = np.where(keep, xi.lo, out_lo)
        out_hi = np.where(keep, xi.hi, out_hi)
    return Interval._raw(out_lo, out_hi)


def gauss_seidel(A, b, x, C=None):
    """One sweep of the preconditioned interval Gauss-Seidel operator for ``A x = b``.

    ``A (..., n, n)``, ``b (..., n)``, ``x (..., n)``; ``C`` (float) defaults
    to ``mid_inverse(A)``; ``C=False`` uses ``A`` and ``b`` as they are.  With ``G = C A`` and ``r = C b`` (enclosed), for
    ``i = 1..n``: ``x_i <- x_i  cap  (r_i - sum_{j != i} G_ij x_j) / G_ii``,
    using the already updated ``x_j`` (``_gs_update`` handles ``0 in G_ii``).
    Every solution ``x* in x`` of ``M x* = beta`` with ``M in A``,
    ``beta in b`` stays in the result (Neumaier, "Interval methods for
    systems of equations", 1990, sec. 4.3).

    Returns ``(x_new, is_empty)``; where ``is_empty`` the box holds no
    solution and ``x_new`` is meaningless there.
    """
    A = _operand(A)
    b = _operand(b)
    x = _as_interval(x)
    if C is False:      # the system is already preconditioned: G = A, r = b
        G, r = point(A), point(b)
    else:
        if C is None:
            C, _ = mid_inverse(A)
        G = matmul(C, A)
        r = matvec(C, b)
    n = x.shape[-1]
    shape = np.broadcast_shapes(G.shape[:-1], r.shape, x.shape)
    lo = np.array(np.broadcast_to(x.lo, shape), dtype=np.float64, copy=True)
    hi = np.array(np.broadcast_to(x.hi, shape), dtype=np.float64, copy=True)
    G = Interval._raw(np.broadcast_to(G.lo, shape + (n,)), np.broadcast_to(G.hi, shape + (n,)))
    r = Interval._raw(np.broadcast_to(r.lo, shape), np.broadcast_to(r.hi, shape))
    empty = np.zeros(shape[:-1], dtype=bool)
    with np.errstate(all="ignore"):
        for i in range(n):
            cur = Interval._raw(lo, hi)
            others = [j for j in range(n) if j != i]
            if others:
                s_lo, s_hi = _accumulate(_prod(G[..., i, j], cur[..., j]) for j in others)
                num = r[..., i] - Interval._raw(s_lo, s_hi)
            else:
                num = r[..., i]
            new = _gs_update(num, G[..., i, i], cur[..., i])
            lo[..., i] = new.lo
            hi[..., i] = new.hi
            empty |= new.lo > new.hi
    return Interval._raw(lo, hi), empty


# ----------------------------------------------------------------- Krawczyk
_EYES = {}


def _eye(n: int) -> np.ndarray:
    """The identity of order n (one shared read-only array per n)."""
    eye = _EYES.get(n)
    if eye is None:
        eye = _EYES[n] = np.eye(n)
        eye.setflags(write=False)
    return eye


def _krawczyk_image(f, J, x, c, C):
    """K = c - C f + (I - C J)(x - c) in midpoint-radius form (see ``krawczyk``)."""
    n = x.shape[-1]
    Jm, Jr = midrad(J.lo, J.hi) if isinstance(J, Interval) else (J, None)
    CJm, CJr = _product_midrad(C, None, Jm, Jr)
    Rm = _eye(n) - CJm                                     # one rounding: error <= u |Rm|
    Rr = _upper(CJr + _U * np.abs(Rm), 3)
    v = Interval._raw(down_sum(x.lo - c), up_sum(x.hi - c))
    vm, vr = midrad(v.lo, v.hi)
    Rvm, Rvr = _product_midrad(Rm, Rr, vm[..., None], vr[..., None])
    fm, fr = midrad(f.lo, f.hi)
    Cfm, Cfr = _product_midrad(C, None, fm[..., None], fr[..., None])
    Rvm, Rvr, Cfm, Cfr = Rvm[..., 0], Rvr[..., 0], Cfm[..., 0], Cfr[..., 0]
    Km = (c - Cfm) + Rvm                                   # two roundings: <= 2u (|c| + |Cfm| + |Rvm|)
    Kr = _upper(Cfr + Rvr + 2 * _U * (np.abs(c) + np.abs(Cfm) + np.abs(Rvm)), 8)
    lo, hi = down(Km - Kr), up(Km + Kr)
    with np.errstate(invalid="ignore"):
        bad = ~np.logical_and.reduce(np.isfinite(lo) & np.isfinite(hi), axis=-1)
    if bad.any():
        lo = np.where(bad[..., None], -INF, lo)
        hi = np.where(bad[..., None], INF, hi)
    return Interval._raw(lo, hi)


def hansen_sengupta(f, J, x, c, C):
    """The Hansen-Sengupta operator: one Gauss-Seidel sweep on the preconditioned linear system.

    ``f`` (Interval ``(N, n)``) encloses f(c) at the float points ``c`` in the boxes ``x``, ``J``
    (Interval ``(N, n, n)``) holds for every zero x* in ``x`` a matrix A with
    f(x*) − f(c) = A (x* − c) (a Jacobian enclosure over ``x`` or a slope enclosure at ``c``), ``C``
    is any float matrix.  Then y* = x* − c solves (C A) y* = −C f(c), with C A in G = [Gm ± Gr]
    and −C f(c) in r, both enclosed in midpoint-radius form (``_product_midrad``).  From y = x − c
    (outward rounded), for i = 1..n in turn: y_i ← y_i ∩ {t : g t = v, g ∈ G_ii,
    v ∈ r_i − Σ_{j≠i} G_ij y_j} (``_gs_update``), the sum enclosed in midpoint-radius form too
    (the row of G with its diagonal entry set to 0, times y: ``_product_midrad``).  Each update
    keeps y* (Hansen & Sengupta 1981; Neumaier, "Interval methods for systems of equations" 1990,
    §4.3 and ch. 5); its sequential updates and divisions usually give a narrower box than the
    Krawczyk image with the same C.

    Returns ``(H, empty)``: ``H`` ⊆ ``x`` holds every zero of f in ``x``; where ``empty`` there is
    none (``H`` is then meaningless).  No uniqueness is claimed.

    Batches (N, n) run box by box in machine code (``native.hansen_sengupta``: the same bounds);
    other shapes, and the tests' reference, take the numpy version (``_hansen_sengupta_numpy``).
    """
    if isinstance(J, Interval) and x.lo.ndim == 2 and J.lo.shape == x.lo.shape + x.lo.shape[-1:]:
        from . import native
        N, n = x.lo.shape
        f64 = lambda a, shape: np.ascontiguousarray(np.broadcast_to(a, shape), dtype=np.float64)   # noqa: E731
        vec, mat = (N, n), (N, n, n)
        lo, hi, empty = native.hansen_sengupta(f64(f.lo, vec), f64(f.hi, vec), f64(J.lo, mat), f64(J.hi, mat),
                                               f64(x.lo, vec), f64(x.hi, vec), f64(c, vec), f64(C, mat))
        return Interval._raw(lo, hi), empty
    return _hansen_sengupta_numpy(f, J, x, c, C)


def _hansen_sengupta_numpy(f, J, x, c, C):
    """``hansen_sengupta`` in batched numpy operations (any leading shape; the reference of the
    native kernel)."""
    n = x.shape[-1]
    Jm, Jr = midrad(J.lo, J.hi) if isinstance(J, Interval) else (J, None)
    fm, fr = midrad(f.lo, f.hi)
    with np.errstate(invalid="ignore", over="ignore"):
        Gm, Gr = _product_midrad(C, None, Jm, Jr)                            # (N, n, n)
        rm, rr = _product_midrad(C, None, fm[..., None], fr[..., None])
        rm, rr = rm[..., 0], rr[..., 0]
        rlo, rhi = down(-rm - rr), up(rr - rm)                              # −C f(c)
        diag = np.arange(n)
        dm, dr = Gm[..., diag, diag], Gr[..., diag, diag]
        dlo, dhi = down(dm - dr), up(dm + dr)                                # G_ii
        Gm, Gr = Gm.copy(), Gr.copy()
        Gm[..., diag, diag] = 0.0                                            # the rows without G_ii
        Gr[..., diag, diag] = 0.0
        ylo, yhi = down_sum(x.lo - c), up_sum(x.hi - c)
        ym, yr = midrad(ylo, yhi)
        empty = np.zeros(x.shape[:-1], dtype=bool)
        aGm = np.abs(Gm)
        aym = np.abs(ym)
        w1 = (n + 1) * _U * aym + yr        # the factors of |G| and Gr in the bound below, per column j,
        w2 = aym + yr                       # updated with y_j
        for i in range(n):
            # Σ_{j≠i} G_ij y_j ⊆ [sm ± sr]: ``_product_midrad``'s bound, its sums taken elementwise (the
            # bound holds for any order of summation)
            sm = np.add.reduce(Gm[..., i, :] * ym, axis=-1)
            sr = np.add.reduce(aGm[..., i, :] * w1 + Gr[..., i, :] * w2, axis=-1)
            sr = _upper(sr, 4 * n + 4) + n * _ETA
            num = Interval._raw(down_sum(rlo[..., i] - up_sum(sm + sr)), up_sum(rhi[..., i] - down_sum(sm - sr)))
            new = _gs_update(num, Interval._raw(dlo[..., i], dhi[..., i]), Interval._raw(ylo[..., i], yhi[..., i]))
            ylo[..., i], yhi[..., i] = new.lo, new.hi
            empty |= new.lo > new.hi
            m = 0.5 * new.lo + 0.5 * new.hi
            ym[..., i], yr[..., i] = m, up(np.maximum(new.hi - m, m - new.lo))
            am = np.abs(m)
            w1[..., i] = (n + 1) * _U * am + yr[..., i]
            w2[..., i] = am + yr[..., i]
        lo = np.fmax(x.lo, down_sum(ylo + c))     # fmax/fmin: a NaN bound (nothing known) keeps x
        hi = np.fmin(x.hi, up_sum(yhi + c))
    return Interval._raw(lo, hi), empty | np.any(lo > hi, axis=-1)


class KrawczykResult(NamedTuple):
    K: Interval          # the Krawczyk image (not intersected with x)
    unique: np.ndarray   # K in interior(x): exactly one zero of f in x
    empty: np.ndarray    # K and x disjoint: no zero of f in x
    C: np.ndarray        # the float preconditioner used


# midpoint-radius products with an a-priori rounding-error bound (docs/soundness.md, "midrad")
_U = 2.0 ** -53
_ETA = 2.0 ** -1022


def _upper(x, k: int):
    """An upper bound of a nonnegative exact value whose float evaluation, with at most
    ``k`` roundings (+ and x of nonnegative numbers), gave ``x``:
    E <= (x + k 2^-1022)(1 + 2k u); two more roundings are covered by 2k + 6."""
    return (x + k * _ETA) * (1.0 + (2 * k + 6) * _U)


def midrad(lo, hi):
    """(m, r) with [lo, hi] inside [m - r, m + r] (finite endpoints)."""
    m = 0.5 * lo + 0.5 * hi
    return m, up(np.maximum(hi - m, m - lo))


def _product_midrad(am, ar, bm, br):
    """Enclosure (mid, rad) of A B for every A in [am +- ar], B in [bm +- br] (ar, br may be None).

    |A B - fl(am bm)| <= |am| br + ar (|bm| + br) + gamma_n |am||bm| + n eta (Higham 2002,
    eq. 3.5, any summation order), with gamma_n <= (n + 1) u; the right side is
    evaluated in floats and bounded by ``_upper`` (k = 4n + 4 roundings).
    """
    n = am.shape[-1]
    mid = am @ bm
    abm = np.abs(bm)
    inner = (n + 1) * _U * abm if br is None else (n + 1) * _U * abm + br
    rad = np.abs(am) @ inner
    if ar is not None:
        rad = rad + ar @ (abm if br is None else abm + br)
    return mid, _upper(rad, 4 * n + 4) + n * _ETA


def product_midrad(am, ar, bm, br):
    """Enclosure (mid, rad) of A B for every A in [am ± ar], B in [bm ± br] (float arrays;
    ``ar``/``br`` None for points): the bound of ``_product_midrad`` (Higham 2002, eq. 3.5)."""
    return _product_midrad(am, ar, bm, br)


def krawczyk(f_mid, J, x, c=None, C=None) -> KrawczykResult:
    """Krawczyk operator ``K = c - C f(c) + (I - C J)(x - c)``, batched.

    ``f_mid`` (Interval ``(..., n)``) encloses ``f(c)``; ``J`` (Interval
    ``(..., n, n)``) encloses the Jacobian of ``f`` over the box ``x``
    ``(..., n)``; ``c`` (float, default ``x.mid()``, which ``f_mid`` must
    then be evaluated at) must lie in ``x``; ``C`` defaults to
    ``mid_inverse(J)``.

    Every zero of ``f`` in ``x`` lies in ``K`` (mean value theorem), so
    ``K cap x = {}`` proves there is none (``empty``).  ``K`` inside the
    interior of ``x`` proves ``f`` has exactly one zero in ``x`` (Krawczyk
    1969 for existence; Moore 1977 and Neumaier, "Interval methods for
    systems of equations" 1990, ch. 5, for uniqueness: ``C`` and every matrix in ``J`` are then nonsingular);
    ``unique`` is also required to have ``c in x`` and a bounded ``x``.
    The next Krawczyk iterate is ``K.intersect(x)``.

    Computed in midpoint-radius form (Rump, "Fast and parallel interval
    arithmetic", BIT 39, 1999): a few batched float matrix products and a
    proved bound on their rounding errors (``_product_midrad``) instead of
    interval matrix products; rows with a non-finite input get the entire K.
    """
    x = _as_interval(x)
    J = _operand(J)
    f_mid = _as_interval(f_mid)
    if c is None:
        c = x.mid()
    c = np.asarray(c, dtype=np.float64)
    if C is None:
        C, _ = mid_inverse(J)
    K = _krawczyk_image(f_mid, J, x, c, C)
    with np.errstate(invalid="ignore"):
        c_in = np.all((c >= x.lo) & (c <= x.hi), axis=-1)
        bounded = np.all(np.isfinite(x.lo) & np.isfinite(x.hi), axis=-1)
        unique = np.all(K.interior(x), axis=-1) & c_in & bounded
        empty = np.any(K.disjoint(x), axis=-1) & c_in
    return KrawczykResult(K, unique, empty, C)
