"""Batched interval linear algebra: preconditioners, Gauss-Seidel, Krawczyk, Hansen-Sengupta.

Products (``matrix``) and determinants (``determinant``) have modules of their own; their names
are re-exported here.  An interval matrix is an ``Interval`` of shape ``(..., n, n)`` and a vector
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

import importlib
from typing import NamedTuple

import numpy as np

from .determinant import det, hadamard_bound, laplace_det
from .interval import Interval, as_interval, div
from .matrix import accumulate, identity, matmul, matvec, operand, point, product_bounds
from .midrad import ETA, U, midrad, product_midrad, upper
from .rounding import INF, down, down_sum, up, up_sum

__all__ = [
    "identity", "point", "matmul", "matvec", "det", "hadamard_bound", "mid_inverse",
    "float_inverse", "gauss_seidel", "hansen_sengupta", "krawczyk", "krawczyk_image", "KrawczykResult", "laplace_det",
]


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


def float_inverse(M):
    """(C, failed): the float inverse of each matrix M (..., n, n), ``mid_inverse``'s only where a
    plain inverse is singular or not finite.  A preconditioner, not a proof: the Krawczyk test is
    valid with any float C (a poor C only makes it fail)."""
    with np.errstate(all="ignore"):
        try:
            C = np.linalg.inv(M)
            if np.isfinite(C).all():
                return C, np.zeros(M.shape[:-2], dtype=bool)
        except np.linalg.LinAlgError:
            pass
    return mid_inverse(M)


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
        q = div(num, Interval.from_bounds(np.where(regular, den.lo, 1.0), np.where(regular, den.hi, 1.0)))
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
    return Interval.from_bounds(out_lo, out_hi)


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
    A = operand(A)
    b = operand(b)
    x = as_interval(x)
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
    G = Interval.from_bounds(np.broadcast_to(G.lo, shape + (n,)), np.broadcast_to(G.hi, shape + (n,)))
    r = Interval.from_bounds(np.broadcast_to(r.lo, shape), np.broadcast_to(r.hi, shape))
    empty = np.zeros(shape[:-1], dtype=bool)
    with np.errstate(all="ignore"):
        for i in range(n):
            cur = Interval.from_bounds(lo, hi)
            others = [j for j in range(n) if j != i]
            if others:
                s_lo, s_hi = accumulate(product_bounds(G[..., i, j], cur[..., j]) for j in others)
                num = r[..., i] - Interval.from_bounds(s_lo, s_hi)
            else:
                num = r[..., i]
            new = _gs_update(num, G[..., i, i], cur[..., i])
            lo[..., i] = new.lo
            hi[..., i] = new.hi
            empty |= new.lo > new.hi
    return Interval.from_bounds(lo, hi), empty


# ----------------------------------------------------------------- Krawczyk
_EYES = {}


def _eye(n: int) -> np.ndarray:
    """The identity of order n (one shared read-only array per n)."""
    eye = _EYES.get(n)
    if eye is None:
        eye = _EYES[n] = np.eye(n)
        eye.setflags(write=False)
    return eye


def krawczyk_image(f, J, x, c, C):
    """K = c - C f + (I - C J)(x - c) in midpoint-radius form (see ``krawczyk``)."""
    n = x.shape[-1]
    Jm, Jr = midrad(J.lo, J.hi) if isinstance(J, Interval) else (J, None)
    CJm, CJr = product_midrad(C, None, Jm, Jr)
    Rm = _eye(n) - CJm                                     # one rounding: error <= u |Rm|
    Rr = upper(CJr + U * np.abs(Rm), 3)
    v = Interval.from_bounds(down_sum(x.lo - c), up_sum(x.hi - c))
    vm, vr = midrad(v.lo, v.hi)
    Rvm, Rvr = product_midrad(Rm, Rr, vm[..., None], vr[..., None])
    fm, fr = midrad(f.lo, f.hi)
    Cfm, Cfr = product_midrad(C, None, fm[..., None], fr[..., None])
    Rvm, Rvr, Cfm, Cfr = Rvm[..., 0], Rvr[..., 0], Cfm[..., 0], Cfr[..., 0]
    Km = (c - Cfm) + Rvm                                   # two roundings: <= 2u (|c| + |Cfm| + |Rvm|)
    Kr = upper(Cfr + Rvr + 2 * U * (np.abs(c) + np.abs(Cfm) + np.abs(Rvm)), 8)
    lo, hi = down(Km - Kr), up(Km + Kr)
    with np.errstate(invalid="ignore"):
        bad = ~np.logical_and.reduce(np.isfinite(lo) & np.isfinite(hi), axis=-1)
    if bad.any():
        lo = np.where(bad[..., None], -INF, lo)
        hi = np.where(bad[..., None], INF, hi)
    return Interval.from_bounds(lo, hi)


def hansen_sengupta(f, J, x, c, C):
    """The Hansen-Sengupta operator: one Gauss-Seidel sweep on the preconditioned linear system.

    ``f`` (Interval ``(N, n)``) encloses f(c) at the float points ``c`` in the boxes ``x``, ``J``
    (Interval ``(N, n, n)``) holds for every zero x* in ``x`` a matrix A with
    f(x*) − f(c) = A (x* − c) (a Jacobian enclosure over ``x`` or a slope enclosure at ``c``), ``C``
    is any float matrix.  Then y* = x* − c solves (C A) y* = −C f(c), with C A in G = [Gm ± Gr]
    and −C f(c) in r, both enclosed in midpoint-radius form (``product_midrad``).  From y = x − c
    (outward rounded), for i = 1..n in turn: y_i ← y_i ∩ {t : g t = v, g ∈ G_ii,
    v ∈ r_i − Σ_{j≠i} G_ij y_j} (``_gs_update``), the sum enclosed in midpoint-radius form too
    (the row of G with its diagonal entry set to 0, times y: ``product_midrad``).  Each update
    keeps y* (Hansen & Sengupta 1981; Neumaier, "Interval methods for systems of equations" 1990,
    §4.3 and ch. 5); its sequential updates and divisions usually give a narrower box than the
    Krawczyk image with the same C.

    Returns ``(H, empty)``: ``H`` ⊆ ``x`` holds every zero of f in ``x``; where ``empty`` there is
    none (``H`` is then meaningless).  No uniqueness is claimed.

    Batches (N, n) run box by box in machine code (``native.hansen_sengupta``: the same bounds);
    other shapes, and the tests' reference, take the numpy version (``_hansen_sengupta_numpy``).
    """
    if isinstance(J, Interval) and x.lo.ndim == 2 and J.lo.shape == x.lo.shape + x.lo.shape[-1:]:
        N, n = x.lo.shape
        f64 = lambda a, shape: np.ascontiguousarray(np.broadcast_to(a, shape), dtype=np.float64)   # noqa: E731
        vec, mat = (N, n), (N, n, n)
        lo, hi, empty = native().hansen_sengupta(f64(f.lo, vec), f64(f.hi, vec), f64(J.lo, mat), f64(J.hi, mat),
                                               f64(x.lo, vec), f64(x.hi, vec), f64(c, vec), f64(C, mat))
        return Interval.from_bounds(lo, hi), empty
    return _hansen_sengupta_numpy(f, J, x, c, C)


def native():
    """The machine-code kernels (``intervals.native``), imported on first use: importing numba costs
    about half a second, which only the searches that call a kernel pay."""
    return importlib.import_module("intervals.native")


def _hansen_sengupta_numpy(f, J, x, c, C):
    """``hansen_sengupta`` in batched numpy operations (any leading shape; the reference of the
    native kernel)."""
    n = x.shape[-1]
    Jm, Jr = midrad(J.lo, J.hi) if isinstance(J, Interval) else (J, None)
    fm, fr = midrad(f.lo, f.hi)
    with np.errstate(invalid="ignore", over="ignore"):
        Gm, Gr = product_midrad(C, None, Jm, Jr)                            # (N, n, n)
        rm, rr = product_midrad(C, None, fm[..., None], fr[..., None])
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
        w1 = (n + 1) * U * aym + yr        # the factors of |G| and Gr in the bound below, per column j,
        w2 = aym + yr                       # updated with y_j
        for i in range(n):
            # Σ_{j≠i} G_ij y_j ⊆ [sm ± sr]: ``product_midrad``'s bound, its sums taken elementwise (the
            # bound holds for any order of summation)
            sm = np.add.reduce(Gm[..., i, :] * ym, axis=-1)
            sr = np.add.reduce(aGm[..., i, :] * w1 + Gr[..., i, :] * w2, axis=-1)
            sr = upper(sr, 4 * n + 4) + n * ETA
            num = Interval.from_bounds(down_sum(rlo[..., i] - up_sum(sm + sr)), up_sum(rhi[..., i] - down_sum(sm - sr)))
            new = _gs_update(num, Interval.from_bounds(dlo[..., i], dhi[..., i]), Interval.from_bounds(ylo[..., i], yhi[..., i]))
            ylo[..., i], yhi[..., i] = new.lo, new.hi
            empty |= new.lo > new.hi
            m = 0.5 * new.lo + 0.5 * new.hi
            ym[..., i], yr[..., i] = m, up(np.maximum(new.hi - m, m - new.lo))
            am = np.abs(m)
            w1[..., i] = (n + 1) * U * am + yr[..., i]
            w2[..., i] = am + yr[..., i]
        lo = np.fmax(x.lo, down_sum(ylo + c))     # fmax/fmin: a NaN bound (nothing known) keeps x
        hi = np.fmin(x.hi, up_sum(yhi + c))
    return Interval.from_bounds(lo, hi), empty | np.any(lo > hi, axis=-1)


class KrawczykResult(NamedTuple):
    K: Interval          # the Krawczyk image (not intersected with x)
    unique: np.ndarray   # K in interior(x): exactly one zero of f in x
    empty: np.ndarray    # K and x disjoint: no zero of f in x
    C: np.ndarray        # the float preconditioner used


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
    proved bound on their rounding errors (``product_midrad``) instead of
    interval matrix products; rows with a non-finite input get the entire K.
    """
    x = as_interval(x)
    J = operand(J)
    f_mid = as_interval(f_mid)
    if c is None:
        c = x.mid()
    c = np.asarray(c, dtype=np.float64)
    if C is None:
        C, _ = mid_inverse(J)
    K = krawczyk_image(f_mid, J, x, c, C)
    with np.errstate(invalid="ignore"):
        c_in = np.all((c >= x.lo) & (c <= x.hi), axis=-1)
        bounded = np.all(np.isfinite(x.lo) & np.isfinite(x.hi), axis=-1)
        unique = np.all(K.interior(x), axis=-1) & c_in & bounded
        empty = np.any(K.disjoint(x), axis=-1) & c_in
    return KrawczykResult(K, unique, empty, C)
