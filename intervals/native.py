"""Machine-code kernels (numba) for the hot loops of the solvers: one box per iteration.

The batched numpy operations of ``intervals`` make one pass over memory per
operation; these kernels do all the operations of one box in registers.  They
use the same outward rounding (``intervals.rounding``): every operation is
IEEE 754 double precision rounded to nearest (numba's default, ``fastmath``
off), and each rounded result is widened by the same ``up``/``down`` steps,
so the argument of ``docs/soundness.md`` §1 holds unchanged.  Sums whose
error is bounded a priori (midpoint-radius products, Higham 2002, eq. 3.5)
hold for any order of summation and for fused multiply-adds, so nothing
depends on how the compiler schedules them.

Boxes with a non-finite input are left as they are (no contraction, not
empty): a sound answer, which the numpy reference gives as well up to its own
NaN conventions.  ``tests/test_native.py`` compares every kernel with its
numpy reference on random inputs.

Kernels are compiled on first use and cached on disk (``cache=True``), with numba's ``numpy``
error model: a float division by zero gives inf or NaN instead of raising, so no test of the
divisor is compiled in (every division here has a divisor proved nonzero, or tested first).
"""
from __future__ import annotations

import numpy as np
from numba import njit

MAX = float(np.finfo(np.float64).max)
_REL = 2.0 ** -52
_ABS = 2.0 ** -1022
_U = 2.0 ** -53
_ETA = 2.0 ** -1022
INF = np.inf


# ----------------------------------------------------------------- rounding (intervals.rounding)
@njit(cache=True, error_model="numpy")
def up(c):
    """``rounding.up``: an upper bound of every real within half a spacing of ``c``."""
    if c < -MAX:
        c = -MAX
    return c + (abs(c) * _REL + _ABS)


@njit(cache=True, error_model="numpy")
def down(c):
    """``rounding.down``."""
    if c > MAX:
        c = MAX
    return c - (abs(c) * _REL + _ABS)


@njit(cache=True, error_model="numpy")
def up_sum(c):
    """``rounding.up_sum``: ``up`` for the result of a sum or difference."""
    if c < -MAX:
        c = -MAX
    return c + abs(c) * _REL


@njit(cache=True, error_model="numpy")
def down_sum(c):
    """``rounding.down_sum``."""
    if c > MAX:
        c = MAX
    return c - abs(c) * _REL


@njit(cache=True, error_model="numpy")
def upper(x, k):
    """``midrad.upper``: a bound of a non-negative exact value whose float evaluation with at most
    ``k`` roundings gave ``x``."""
    return (x + k * _ETA) * (1.0 + (2 * k + 6) * _U)


@njit(cache=True, error_model="numpy")
def midrad(lo, hi):
    """``midrad.midrad``: (m, r) with [lo, hi] ⊆ [m − r, m + r]."""
    m = 0.5 * lo + 0.5 * hi
    return m, up(max(hi - m, m - lo))


SPLIT = 134217729.0          # rounding.SPLIT, EXACT_LOW, EXACT_HIGH
EXACT_LOW = 2.0 ** -800
EXACT_HIGH = 2.0 ** 800


@njit(cache=True, error_model="numpy")
def square_exact(a, p):
    """``rounding.square_exact``: a = 0, or a has at most 26 significant bits (Veltkamp's split leaves
    no low part: the same verdict as the fraction-bit test for such p) and EXACT_LOW ≤ p ≤ MAX."""
    if a == 0.0:
        return True
    if not (p >= EXACT_LOW and p <= MAX):
        return False
    t = SPLIT * a
    return a - (t - (t - a)) == 0.0


@njit(cache=True, error_model="numpy")
def up_square(a, p):
    """``rounding.up_square``: p where a² = p exactly, else ``up(p)``."""
    return p if square_exact(a, p) else up(p)


@njit(cache=True, error_model="numpy")
def down_square(a, p):
    """``rounding.down_square``."""
    return p if square_exact(a, p) else down(p)


# ----------------------------------------------------------------- interval operations on (lo, hi)
@njit(cache=True, error_model="numpy")
def sqr(lo, hi):
    """``interval.sqr``: [max(down(mig²), 0), up(mag²)], a bound not widened where its square is
    exact (``up_square``)."""
    mig = 0.0 if (lo <= 0.0 and hi >= 0.0) else min(abs(lo), abs(hi))
    mag = max(abs(lo), abs(hi))
    return max(down_square(mig, mig * mig), 0.0), up_square(mag, mag * mag)


@njit(cache=True, error_model="numpy")
def scale(lo, hi, k):
    """``x * k`` for a float k > 0 (``interval.mul`` with the point [k, k])."""
    return down(lo * k), up(hi * k)


@njit(cache=True, error_model="numpy")
def mul(alo, ahi, blo, bhi):
    """``interval.mul`` for finite operands: the hull of the four corner products, rounded outward."""
    p1 = alo * blo
    p2 = alo * bhi
    p3 = ahi * blo
    p4 = ahi * bhi
    return down(min(min(p1, p2), min(p3, p4))), up(max(max(p1, p2), max(p3, p4)))


@njit(cache=True, error_model="numpy")
def div_regular(alo, ahi, blo, bhi):
    """``interval.div`` for finite operands and a divisor without 0."""
    q1 = alo / blo
    q2 = alo / bhi
    q3 = ahi / blo
    q4 = ahi / bhi
    return down(min(min(q1, q2), min(q3, q4))), up(max(max(q1, q2), max(q3, q4)))


@njit(cache=True, error_model="numpy")
def gs_update(nlo, nhi, dlo, dhi, xlo, xhi):
    """``linalg._gs_update`` for finite operands: [xlo, xhi] ∩ {t : d t = v, d ∈ [dlo, dhi],
    v ∈ [nlo, nhi]} (extended division when 0 ∈ d; Hansen & Sengupta 1981).  Empty: lo > hi."""
    if dlo > 0.0 or dhi < 0.0:
        qlo, qhi = div_regular(nlo, nhi, dlo, dhi)
        return max(xlo, qlo), min(xhi, qhi)
    pos = nlo > 0.0
    neg = nhi < 0.0
    if not (pos or neg):
        return xlo, xhi
    # left piece (-inf, a], right piece [b, inf); an absent piece has a = -inf / b = inf
    if pos:
        has_left, has_right = dlo < 0.0, dhi > 0.0
        a = up(nlo / dlo) if has_left else -INF
        b = down(nlo / dhi) if has_right else INF
    else:
        has_left, has_right = dhi > 0.0, dlo < 0.0
        a = up(nhi / dhi) if has_left else -INF
        b = down(nhi / dlo) if has_right else INF
    l_hi = min(xhi, a)
    r_lo = max(xlo, b)
    l_ok = has_left and xlo <= l_hi
    r_ok = has_right and r_lo <= xhi
    lo = xlo if l_ok else (r_lo if r_ok else INF)
    hi = xhi if r_ok else (l_hi if l_ok else -INF)
    return lo, hi


# ----------------------------------------------------------------- float linear algebra (preconditioners)
@njit(cache=True, error_model="numpy")
def gauss_jordan(A, n):
    """Reduce the augmented matrix A (n, n + k) in place, with partial pivoting, so that its first n
    columns become the identity and its last k the solution of the system; False where a pivot is 0
    or not finite (A is then meaningless).  Plain floats: for preconditioners only."""
    width = A.shape[1]
    for col in range(n):
        piv = col
        best = abs(A[col, col])
        for r in range(col + 1, n):
            if abs(A[r, col]) > best:
                best = abs(A[r, col])
                piv = r
        if not (best > 0.0) or not np.isfinite(best):
            return False
        if piv != col:
            for j in range(width):
                A[col, j], A[piv, j] = A[piv, j], A[col, j]
        inv = 1.0 / A[col, col]
        for j in range(width):
            A[col, j] *= inv
        for r in range(n):
            if r != col:
                f = A[r, col]
                if f != 0.0:
                    for j in range(width):
                        A[r, j] -= f * A[col, j]
    return True


@njit(cache=True, error_model="numpy")
def float_inverse(Mlo, Mhi, compact):
    """(C, failed): the float inverse of each midpoint matrix 0.5 lo + 0.5 hi (N, n, n) by Gauss-Jordan
    elimination with partial pivoting, rounded to float32 values where ``compact``; the identity where
    a pivot vanishes or the result is not finite (``failed``).  A preconditioner: any C keeps the
    Krawczyk and Hansen-Sengupta steps sound."""
    N, n, _ = Mlo.shape
    C = np.empty((N, n, n))
    failed = np.zeros(N, dtype=np.bool_)
    A = np.empty((n, 2 * n))
    for b in range(N):
        for i in range(n):
            for j in range(n):
                A[i, j] = 0.5 * Mlo[b, i, j] + 0.5 * Mhi[b, i, j]
                A[i, n + j] = 1.0 if i == j else 0.0
        ok = gauss_jordan(A, n)
        for i in range(n):
            for j in range(n):
                v = A[i, n + j] if ok else (1.0 if i == j else 0.0)
                if not np.isfinite(v):
                    ok = False
                C[b, i, j] = v
        if not ok:
            failed[b] = True
            for i in range(n):
                for j in range(n):
                    C[b, i, j] = 1.0 if i == j else 0.0
        if compact:
            for i in range(n):
                for j in range(n):
                    v = C[b, i, j]
                    C[b, i, j] = np.float64(np.float32(v)) if abs(v) < 2.0 ** 127 else 0.0
    return C, failed


# ----------------------------------------------------------------- Hansen-Sengupta (linalg.hansen_sengupta)
@njit(cache=True, error_model="numpy")
def hansen_sengupta(flo, fhi, Jlo, Jhi, xlo, xhi, c, C):
    """``linalg.hansen_sengupta`` box by box: (lo, hi, empty) for f (N, n), J (N, n, n), x (N, n),
    c (N, n), C (N, n, n).  The same midpoint-radius bounds (Higham 2002, eq. 3.5, any order of
    summation), the same sweep order; boxes with a non-finite input or intermediate keep x."""
    N, n = xlo.shape
    lo = xlo.copy()
    hi = xhi.copy()
    empty = np.zeros(N, dtype=np.bool_)
    Gm = np.empty((n, n))
    Gr = np.empty((n, n))
    Jm = np.empty((n, n))
    Jw = np.empty((n, n))
    rlo = np.empty(n)
    rhi = np.empty(n)
    ylo = np.empty(n)
    yhi = np.empty(n)
    ym = np.empty(n)
    w1 = np.empty(n)
    w2 = np.empty(n)
    fw = np.empty(n)
    fm = np.empty(n)
    k = 4 * n + 4
    g = (n + 1) * _U
    for b in range(N):
        finite = True
        for i in range(n):
            finite &= np.isfinite(flo[b, i]) and np.isfinite(fhi[b, i])
            finite &= np.isfinite(xlo[b, i]) and np.isfinite(xhi[b, i]) and np.isfinite(c[b, i])
            for j in range(n):
                finite &= np.isfinite(Jlo[b, i, j]) and np.isfinite(Jhi[b, i, j]) and np.isfinite(C[b, i, j])
        if not finite:
            continue
        for i in range(n):
            m, r = midrad(flo[b, i], fhi[b, i])
            fm[i] = m
            fw[i] = g * abs(m) + r
            for j in range(n):
                m, r = midrad(Jlo[b, i, j], Jhi[b, i, j])
                Jm[i, j] = m
                Jw[i, j] = g * abs(m) + r
        # G = C J in [Gm ± Gr], −C f(c) in [rlo, rhi] (``midrad.product_midrad``)
        for i in range(n):
            sm = 0.0
            sr = 0.0
            for l in range(n):
                sm += C[b, i, l] * fm[l]
                sr += abs(C[b, i, l]) * fw[l]
            sr = upper(sr, k) + n * _ETA
            rlo[i] = down(-sm - sr)
            rhi[i] = up(sr - sm)
            for j in range(n):
                sm = 0.0
                sr = 0.0
                for l in range(n):
                    sm += C[b, i, l] * Jm[l, j]
                    sr += abs(C[b, i, l]) * Jw[l, j]
                Gm[i, j] = sm
                Gr[i, j] = upper(sr, k) + n * _ETA
        # y = x − c, then one Gauss-Seidel sweep
        for i in range(n):
            ylo[i] = down_sum(xlo[b, i] - c[b, i])
            yhi[i] = up_sum(xhi[b, i] - c[b, i])
            m, r = midrad(ylo[i], yhi[i])
            ym[i] = m
            w1[i] = g * abs(m) + r
            w2[i] = abs(m) + r
        ok = True
        for i in range(n):
            sm = 0.0
            sr = 0.0
            for j in range(n):
                if j != i:
                    sm += Gm[i, j] * ym[j]
                    sr += abs(Gm[i, j]) * w1[j] + Gr[i, j] * w2[j]
            sr = upper(sr, k) + n * _ETA
            nlo = down_sum(rlo[i] - up_sum(sm + sr))
            nhi = up_sum(rhi[i] - down_sum(sm - sr))
            dlo = down(Gm[i, i] - Gr[i, i])
            dhi = up(Gm[i, i] + Gr[i, i])
            if not (np.isfinite(nlo) and np.isfinite(nhi) and np.isfinite(dlo) and np.isfinite(dhi)):
                ok = False
                break
            nl, nh = gs_update(nlo, nhi, dlo, dhi, ylo[i], yhi[i])
            ylo[i], yhi[i] = nl, nh
            if nl > nh:
                empty[b] = True
                break
            m = 0.5 * nl + 0.5 * nh
            r = up(max(nh - m, m - nl))
            ym[i] = m
            w1[i] = g * abs(m) + r
            w2[i] = abs(m) + r
        if not ok or empty[b]:
            continue
        for i in range(n):
            lo[b, i] = max(xlo[b, i], down_sum(ylo[i] + c[b, i]))
            hi[b, i] = min(xhi[b, i], up_sum(yhi[i] + c[b, i]))
            if lo[b, i] > hi[b, i]:
                empty[b] = True
    return lo, hi, empty
