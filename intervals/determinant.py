"""Enclosures of determinants of interval matrices.

``det``: the exact determinant of every real matrix in the argument lies in the result (cofactor
expansion up to 3 × 3, LU-preconditioned interval elimination beyond, always within Hadamard's
bound); ``laplace_det``: the cofactor expansion on any objects with + − × (``autodiff.Dual``
entries give the gradient of det as well).

The independent checker repeats both methods in its own arithmetic (``proofs/det.py``) on purpose:
it imports neither ``certkin`` nor ``intervals``, so a fault here cannot hide a fault there.
"""
from __future__ import annotations

import numpy as np

from .interval import Interval, mul
from .matrix import accumulate, matmul, point
from .rounding import INF, up


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
        s = accumulate((sq_j, sq_j) for sq_j in np.moveaxis(sq, axis, 0))[1]
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
                f = S[..., 1:, 0] / Interval.from_bounds(piv.lo[..., None], piv.hi[..., None])
                S = S[..., 1:, 1:] - mul(Interval.from_bounds(f.lo[..., :, None], f.hi[..., :, None]),
                                         Interval.from_bounds(S.lo[..., None, 0, 1:], S.hi[..., None, 0, 1:]))
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
        return Interval.from_bounds(one, one.copy())
    with np.errstate(invalid="ignore", over="ignore"):
        if n <= 3:
            D = _det_small(A)
            fail = np.zeros(A.shape[:-2], dtype=bool)
        else:
            perm, sign, L = _float_lu(A.mid())
            X = _unit_lower_inverse(L)
            PA = Interval.from_bounds(np.take_along_axis(A.lo, perm[..., None], axis=-2),
                               np.take_along_axis(A.hi, perm[..., None], axis=-2))
            Y = matmul(X, PA)
            D, fail = _det_gauss(Y)
            D = Interval.from_bounds(np.where(sign > 0, D.lo, -D.hi), np.where(sign > 0, D.hi, -D.lo))
    fail = fail | np.isnan(D.lo) | np.isnan(D.hi)
    lo = np.where(fail, -H, np.maximum(D.lo, -H))
    hi = np.where(fail, H, np.minimum(D.hi, H))
    return Interval.from_bounds(lo, hi)


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
