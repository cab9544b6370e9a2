"""Interval matrices and vectors: point matrices, and products enclosing every exact product.

An interval matrix is an ``Interval`` of shape ``(..., n, n)`` and a vector one of shape
``(..., n)``; leading dimensions are a batch and broadcast.  A float ``ndarray`` stands for the
exact (point) matrix of its binary values.  Every function loops only over the matrix dimension
(small), never over the batch.

``matmul``/``matvec``: the exact product lies in the result (interval accumulation of interval
products, each operation rounded outward).
"""
from __future__ import annotations

import numpy as np

from .interval import Interval, mul
from .rounding import down, down_sum, up, up_sum


def identity(n: int, batch=()) -> Interval:
    """The exact ``n x n`` identity as a degenerate interval matrix of shape ``batch + (n, n)``."""
    eye = np.broadcast_to(np.eye(n), tuple(batch) + (n, n))
    return Interval.from_bounds(eye.copy(), eye.copy())


def point(M) -> Interval:
    """A float array (exact binary values) as a degenerate ``Interval``."""
    if isinstance(M, Interval):
        return M
    M = _check_float(M)
    return Interval.from_bounds(M, M.copy())


def _check_float(M) -> np.ndarray:
    M = np.asarray(M, dtype=np.float64)
    if not np.all(np.isfinite(M)):
        raise ValueError("a point matrix/vector must have finite entries")
    return M


def operand(M):
    """An ``Interval`` or a finite float ndarray (exact)."""
    if isinstance(M, Interval):
        return M
    return _check_float(M)


def _take(M, idx):
    """``M[..., idx]`` for a float array or an Interval (plain slicing / indexing)."""
    if isinstance(M, Interval):
        return Interval.from_bounds(M.lo[idx], M.hi[idx])
    return M[idx]


def product_bounds(a, b):
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


def accumulate(terms):
    """Outward-rounded sum of an iterable of (lo, hi) enclosures."""
    s_lo = s_hi = None
    for lo, hi in terms:
        if s_lo is None:
            s_lo, s_hi = lo, hi
        else:
            s_lo = down_sum(s_lo + lo)
            s_hi = up_sum(s_hi + hi)
    return s_lo, s_hi


def matmul(A, B) -> Interval:
    """Enclosure of ``A @ B`` for ``A (..., n, k)``, ``B (..., k, m)`` (Interval or float).

    Each entry is the outward-rounded interval sum of ``k`` interval products
    (``interval.mul``, or two float products with sign selection when one
    factor is a point), so it contains ``sum_j a_ij b_jl`` for every real
    ``a_ij in A_ij``, ``b_jl in B_jl``.  Batch dimensions broadcast.
    """
    A = operand(A)
    B = operand(B)
    k = A.shape[-1]
    if B.shape[-2] != k:
        raise ValueError(f"matmul: inner dimensions differ ({A.shape} @ {B.shape})")
    if k == 0:
        shape = np.broadcast_shapes(A.shape[:-2], B.shape[:-2]) + (A.shape[-2], B.shape[-1])
        return Interval.from_bounds(np.zeros(shape), np.zeros(shape))
    lo, hi = accumulate(
        product_bounds(_take(A, (..., slice(None), slice(j, j + 1))), _take(B, (..., slice(j, j + 1), slice(None))))
        for j in range(k))
    return Interval.from_bounds(lo, hi)


def matvec(A, x) -> Interval:
    """Enclosure of ``A @ x`` for ``A (..., n, k)``, ``x (..., k)`` (Interval or float); see ``matmul``."""
    A = operand(A)
    x = operand(x)
    k = A.shape[-1]
    if x.shape[-1] != k:
        raise ValueError(f"matvec: dimensions differ ({A.shape} @ {x.shape})")
    if k == 0:
        shape = np.broadcast_shapes(A.shape[:-2], x.shape[:-1]) + (A.shape[-2],)
        return Interval.from_bounds(np.zeros(shape), np.zeros(shape))
    lo, hi = accumulate(
        product_bounds(_take(A, (..., slice(None), j)), _take(x, (..., slice(j, j + 1)))) for j in range(k))
    return Interval.from_bounds(lo, hi)
