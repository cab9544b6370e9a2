"""The interval steps on boxes of FK unknowns: Krawczyk, slopes and Hansen-Sengupta, the position
sweep, and the tight enclosure of a proved root.

Used by the search (``fk.search``) and by tracking (``fk.tracking``); every step keeps each root
of the box it is given (docs/soundness.md §8), and the uniqueness test ``unique_in`` is the one
proof of "exactly one root here":

- ``krawczyk_boxes``: K(X) = c − C f(c) + (I − C J(X))(X − c), c the midpoint, C the float
  inverse of the midpoint Jacobian (Krawczyk 1969; Moore 1977; Neumaier 1990, ch. 5):
  K(X) ∩ X = ∅ proves no root, K(X*) ⊂ int X* exactly one;
- ``slope_boxes``: the Hansen-Sengupta operator with a slope matrix S, about half as wide as
  J(X) (``FKSystem.slope``): no root lost, an empty image proves none;
- ``contract_position``: preconditioned Gauss-Seidel on the position, linear given the rotation;
- ``root_boxes``/``enclose_roots``: a tight box R ⊆ X* proved to hold X*'s root (Newton guess,
  then one Krawczyk test; Krawczyk iterations and ε-inflation, Rump 1983, where that fails).

For a quaternion, the slope step and the position sweep run box by box in machine code
(``fk.kernels``): the same operations as the numpy versions they are tested against.
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, linalg
from intervals.rounding import down, down_sum, up, up_sum

from .stacked import StackedFKSystem

MARGIN = 2.0 ** -30      # uniqueness requires K inside X shrunk by this relative margin

WIDEN = 2.0 ** -20       # contracted boxes are widened by this fraction of the parent's width
ROOM = 2.0 ** -40        # and by this fraction of their bounds' magnitude (``room``)

KAPPA = 1e5              # a preconditioner with ||C|| ||mid M|| above this is stored in the certificate
RESIDUAL = 2.0 ** -6     # and one with a diagonal entry of C mid M this far from 1 (no inverse: ``fragile``)

ROOT_FACTORS = (1.25, 2.0)   # root boxes: x* ± this times the estimated reach of the Krawczyk image
SMALL_BATCH = 512        # batches of at most this many boxes use the stacked evaluation (fk.stacked)


def _inner(lo, hi, rel=MARGIN):
    w = (hi - lo) * rel
    return lo + w, hi - w


def krawczyk_boxes(system, X: Interval, L: Interval, C=None, with_jacobian=False, rb=None, compact=False):
    """(K, C[, J]) for the boxes X (N, n) with squared leg lengths L (N, legs); c = midpoint
    (``rb``: the enclosures R b_i over X, if known; ``compact``: C rounded to float32 values,
    which any C may be, so that the search tree stores it in half the memory)."""
    if rb is None and hasattr(system, "krawczyk_data"):   # boxes and midpoints in one stacked evaluation
        fc, J, c = system.krawczyk_data(X, L)
    else:
        J = system.jacobian(X, rb=rb)
        c = X.mid()
        fc = system.equations(Interval.from_bounds(c, c.copy()), L)
    if C is None:
        C = linalg.float_inverse(J.mid())[0]
        if compact:
            C = to_float32(C)
    K = linalg.krawczyk_image(fc, J, X, c, C)
    return (K, C, J) if with_jacobian else (K, C)


def slope_boxes(system, X: Interval, L: Interval, rb=None, compact=False, rbc=None, drbs=None):
    """(H, C, S, empty): the Hansen-Sengupta operator with a slope matrix S of the equations at the
    midpoint c (``linalg.hansen_sengupta``): one Gauss-Seidel sweep on C S(X, c) (x − c) = −C f(c),
    C ≈ mid(S)⁻¹ (float32 values with ``compact``).  Every root in X satisfies f(x) = f(c) +
    S (x − c) for some S in S(X, c), so it stays in H ⊆ X: ``empty`` proves X root-free and H is a
    contraction; uniqueness is not proved (``krawczyk_boxes`` does that).  S is about half as wide
    as J(X) (``FKSystem.slope``; docs/soundness.md §8)."""
    c = X.mid()
    if rbc is None:
        rbc = system.rotated_at_points(c)
    if system.kind != "planar-3rpr" and rb is not None:    # quaternion: the machine-code twins
        if drbs is None:
            with np.errstate(invalid="ignore", over="ignore"):
                Y = Interval.from_bounds(down(0.5 * down_sum(X.lo + c)), up(0.5 * up_sum(X.hi + c)))   # ∋ (x + c)/2
            drbs = system.rotated_derivatives_midrad(Y)
        from .centred import slope_quaternion     # numba: imported by the spatial searches only
        f64 = np.ascontiguousarray
        Slo, Shi, flo, fhi = slope_quaternion(f64(X.lo), f64(X.hi), f64(c), f64(rb.lo), f64(rb.hi), f64(rbc.lo),
                                              f64(rbc.hi), f64(drbs[0]), f64(drbs[1]), system.a.lo, system.a.hi,
                                              f64(L.lo, dtype=np.float64), f64(L.hi, dtype=np.float64), system.n_pos)
        S, fc = Interval.from_bounds(Slo, Shi), Interval.from_bounds(flo, fhi)
        C, failed = linalg.native().float_inverse(Slo, Shi, compact)
        if failed.any():
            Cf = linalg.mid_inverse(S[failed].mid())[0]
            C[failed] = to_float32(Cf) if compact else Cf
    else:
        fc = system.equations(Interval.from_bounds(c, c.copy()), L, rb=rbc)
        S = system.slope(X, c, rb=rb, rbc=rbc, drbs=drbs)
        C = linalg.float_inverse(S.mid())[0]
        if compact:
            C = to_float32(C)
    H, empty = linalg.hansen_sengupta(fc, S, X, c, C)
    return H, C, S, empty


def for_batch(system, n_box):
    """The equations for a batch of n_box boxes: the stacked twin for small batches (the same
    enclosures, bit for bit, in fewer and larger operations: ``fk.stacked``)."""
    if n_box > SMALL_BATCH:
        return system
    return StackedFKSystem.of(system)


def to_float32(M):
    """M rounded to float32 values (held as float64): evidence matrices are stored as float32."""
    with np.errstate(over="ignore"):
        return np.where(np.abs(M) < 2.0 ** 127, M, 0.0).astype(np.float32).astype(np.float64)


def room(lo, hi, unit=0.0):
    """How far a contraction of the boxes [lo, hi] is widened (inside them) so that the checker's own
    step, rounded its own way, still fits inside: ``WIDEN`` of the width, and ``ROOM`` of the bounds'
    magnitude or of ``unit``, whichever is larger (near a singular posture the two were seen 27 units
    in the last place apart on an HC4 pass over a box 6e-10 wide, 2 units on a Krawczyk step over a box
    4e-15 wide: more than the first term alone).  ``unit`` (per column): the scale the equations'
    rounding is relative to, 1 for the rotation's unit complex number or quaternion: a quaternion
    component near 0 (q1 = q2 = 0 at a home pose) is known only to the equations' rounding of |q| = 1,
    and a step over a box 1e-15 wide there is decided by that rounding (a checker's own evaluation
    was seen 4 % of the width apart on a spherical robot's home)."""
    return (hi - lo) * WIDEN + np.maximum(np.maximum(np.abs(lo), np.abs(hi)), unit) * ROOM


def fragile(C, M: Interval):
    """Per box, whether C ≈ mid(M)⁻¹ is too ill-conditioned for the checker to rebuild: ||C||∞ ||mid M||∞
    > ``KAPPA``.  The checker rebuilds the C of an emptiness or contraction step from its own M (a few
    units in the last place apart from ours) and rounds it to float32 as we do; near a singular
    posture the two float64 inverses differ by about the condition number times 2⁻⁵³, enough to turn
    a float32 value the other way, and a C entry one float32 unit off moves C M by about the
    condition number times 2⁻²⁴: a verdict our C reached may fail with the checker's.  Such a C is
    written in the certificate instead (``certificates.fk``); the others are rebuilt.  Measured
    (docs/certificates.md, "Rebuilt preconditioners"): float32 values differ from 10⁵ on, verdicts
    failed from 10⁷ on.  A C that is not an inverse of mid M at all is written too (the pseudo-inverse
    or identity ``linalg.mid_inverse`` gives where the midpoint is singular, or where a plain inverse
    failed elsewhere in the batch): its norm says nothing of the conditioning, and the checker's own
    inverse may be another matrix entirely (seen on a self-motion, cond 10¹⁵: our truncated
    pseudo-inverse contracted, the checker's inverse did not).  The test is on the diagonal of
    C mid M, 1 for an inverse: a pseudo-inverse gives I - V Vᵀ (V: an orthonormal basis of the null
    space), whose diagonal is at most 1 - 1/n somewhere; off by more than ``RESIDUAL``, C is kept."""
    if not len(C):
        return np.zeros(0, dtype=bool)
    with np.errstate(all="ignore"):
        m = 0.5 * M.lo + 0.5 * M.hi
        kappa = np.abs(C).sum(axis=2).max(axis=1) * np.abs(m).sum(axis=2).max(axis=1)
        residual = np.abs(np.einsum("nij,nji->ni", C, m) - 1.0).max(axis=1)
    return ~(kappa <= KAPPA) | ~(residual <= RESIDUAL)


def unique_in(K: Interval, lo, hi):
    """K strictly inside [lo, hi] shrunk by the relative margin (all coordinates)."""
    ilo, ihi = _inner(lo, hi)
    return np.logical_and.reduce((K.lo > ilo) & (K.hi < ihi), axis=-1)


def contract_position(system, X: Interval, L: Interval, rb=None):
    """Preconditioned Gauss-Seidel on the position, linear given the rotation.

    The differences of leg equations give D(X) p = g(X) (``FKSystem.position_system``);
    with P ≈ pinv(mid D) every solution's p satisfies (P D) p = P g, and one
    Gauss-Seidel sweep on that square system keeps every such p
    (``linalg.gauss_seidel``).  Returns (new lo, new hi, empty mask, P).  Spatial robots with a
    known ``rb`` take the machine-code twin (``kernels.position_gauss_seidel``, the same bounds).
    """
    p = system.n_pos
    if p == 3 and rb is not None:     # spatial: the machine-code twin (kernels.position_gauss_seidel)
        from .kernels import position_gauss_seidel      # numba: imported by the spatial searches only
        k = system.norm_ab2
        f64 = np.ascontiguousarray
        new_lo, new_hi, empty, P = position_gauss_seidel(
            f64(X.lo, dtype=np.float64), f64(X.hi, dtype=np.float64), f64(rb.lo), f64(rb.hi), system.a.lo,
            system.a.hi, k.lo, k.hi, f64(L.lo, dtype=np.float64), f64(L.hi, dtype=np.float64))
        new = Interval.from_bounds(new_lo, new_hi)
    else:
        new, empty, P = _position_gauss_seidel(system, X, L, rb)
    w = room(X.lo[:, :p], X.hi[:, :p])      # room for an independent re-computation
    lo, hi = X.lo.copy(), X.hi.copy()
    lo[:, :p] = np.where(empty[:, None], X.lo[:, :p], np.maximum(X.lo[:, :p], new.lo - w))
    hi[:, :p] = np.where(empty[:, None], X.hi[:, :p], np.minimum(X.hi[:, :p], new.hi + w))
    return lo, hi, empty, P


def _position_gauss_seidel(system, X: Interval, L: Interval, rb):
    """``contract_position``'s sweep in batched numpy operations: (new position, empty, P)."""
    p = system.n_pos
    D, g = system.position_system(X, L, rb=rb)
    Dm = 0.5 * D.lo + 0.5 * D.hi
    Dt = np.swapaxes(Dm, -1, -2)
    with np.errstate(all="ignore"):  # P = (Dᵀ D)⁻¹ Dᵀ: a heuristic; any float P keeps the solutions
        G = Dt @ Dm + 1e-300 * np.eye(p)
        try:
            P = np.linalg.solve(G, Dt)
        except np.linalg.LinAlgError:
            P = np.linalg.pinv(Dm)
    P = to_float32(np.where(np.isfinite(P), P, 0.0))   # float32 values: any float P keeps the solutions
    with np.errstate(invalid="ignore", over="ignore"):   # P [D | g] (the products P D, P g) in midpoint-radius
        Dm, Dr = linalg.midrad(np.concatenate([D.lo, g.lo[..., None]], -1),   # form: a float matrix product and
                               np.concatenate([D.hi, g.hi[..., None]], -1))   # its proved bound (product_midrad)
        m, r = linalg.product_midrad(P, None, Dm, Dr)
        Ab = Interval.from_bounds(down(m - r), up(m + r))
        bad = ~(np.isfinite(Ab.lo) & np.isfinite(Ab.hi))
        if bad.any():
            Ab = Interval.from_bounds(np.where(bad, -np.inf, Ab.lo), np.where(bad, np.inf, Ab.hi))
    A, b = Ab[..., :p], Ab[..., p]
    box = Interval.from_bounds(X.lo[:, :p], X.hi[:, :p])
    new, empty = linalg.gauss_seidel(A, b, box, C=False)
    return new, empty, P


def shrink(lo, hi, nlo, nhi):
    """The largest fraction of a side removed by a contraction, per box."""
    w = np.maximum(hi - lo, 1e-300)
    with np.errstate(all="ignore"):  # rows of boxes proved empty may hold inf
        return np.max(((nlo - lo) + (hi - nhi)) / w, axis=1)


def enclose_roots(system, star_lo, star_hi, L: Interval, steps: int = 8):
    """Tight boxes R, each proved to hold exactly one root (the unique root of its X*), and their C.

    Krawczyk iterates X ← K(X) ∩ X from X*, then ε-inflation (Rump 1983):
    R = X widened by half its width and 2⁻⁴⁵ of its magnitude on each side,
    kept if K(R) ⊂ int R and R ⊆ X*; otherwise R = X* itself.  Batched over rows.
    """
    lo, hi = star_lo.copy(), star_hi.copy()
    for _ in range(steps):
        K, _ = krawczyk_boxes(system, Interval.from_bounds(lo, hi), L)
        nlo, nhi = np.maximum(lo, K.lo), np.minimum(hi, K.hi)
        ok = np.all(nlo <= nhi, axis=1)
        before = np.max(hi - lo, axis=1)
        lo[ok], hi[ok] = nlo[ok], nhi[ok]
        if np.all(np.max(hi - lo, axis=1) > 0.5 * before):  # no longer contracting: converged
            break
    w = 0.5 * (hi - lo) + (np.abs(lo) + np.abs(hi)) * 2.0 ** -45 + 1e-300
    rlo, rhi = np.maximum(lo - w, star_lo), np.minimum(hi + w, star_hi)
    K, C = krawczyk_boxes(system, Interval.from_bounds(rlo, rhi), L)
    good = unique_in(K, rlo, rhi)
    if not good.all():
        K2, C2 = krawczyk_boxes(system, Interval.from_bounds(star_lo, star_hi), L)
        rlo[~good], rhi[~good], C[~good] = star_lo[~good], star_hi[~good], C2[~good]
    return rlo, rhi, C


def root_boxes(system, star_lo, star_hi, L: Interval, newton_steps: int = 6):
    """Tight boxes R ⊆ X*, each proved to hold a root (hence X*'s unique root), and their C.

    A guess x* from float Newton iterations started at the midpoint of X*
    (``FKSystem.float_system``: plain floats, never a proof), the box
    R = x* ± r with r a float estimate of how far the Krawczyk image of R reaches
    (|C| (|f(x*)| + rad L + the rounding of the interval evaluation of f); rad L: uncertain leg
    lengths move the root that far), times 1.25, else 2 (``ROOT_FACTORS``), cut to X*, and one
    Krawczyk test K(R) ⊂ int R (outward rounded: the proof).  With uncertain leg lengths R then
    holds, for every length vector, that vector's root, and is about 1.25 times as wide as the
    set of those roots.
    Rows that fail get ``enclose_roots`` (Krawczyk iterations from X*).  Batched.
    """
    N, n = star_lo.shape
    if not N:
        return star_lo.copy(), star_hi.copy(), np.zeros((0, n, n))
    L2 = 0.5 * L.lo + 0.5 * L.hi
    x = 0.5 * star_lo + 0.5 * star_hi
    with np.errstate(all="ignore"):
        size = np.maximum(np.abs(star_hi - star_lo), 1e-300)
        going = np.ones(N, dtype=bool)          # rows not converged yet (each row on its own: its guess
        for _ in range(newton_steps):           # does not depend on the other rows)
            f, J = system.float_system(x, L2)
            ok = np.all(np.isfinite(J), axis=(1, 2)) & (np.abs(np.linalg.det(J)) > 0)
            step = np.linalg.solve(np.where(ok[:, None, None], J, np.eye(n)), f[..., None])[..., 0]
            step = np.where((going & ok)[:, None] & np.isfinite(step), step, 0.0)
            x = x - step
            # converged (a guess: the proof is below): steps at the rounding level of x or of X*'s width
            going &= ~np.all(np.abs(step) <= 2.0 ** -40 * np.maximum(size, np.abs(x)), axis=1)
            if not going.any():
                break
        f, J = system.float_system(x, L2)
        C, failed = linalg.float_inverse(J)
        a, b = system.float_geometry()
        p = system.n_pos
        # each leg equation sums terms of magnitude <= 3 (|p|² + |a_i|² + |b_i|²) + ρ_i²
        p2 = np.sum(x[:, :p] ** 2, -1, keepdims=True) if p else 0.0
        terms = np.concatenate([3.0 * (p2 + np.sum(a * a, -1) + np.sum(b * b, -1)) + L2, np.full((N, 1), 2.0)], -1)
        radL = np.zeros((N, n))
        radL[:, :system.legs] = 0.5 * (L.hi - L.lo)
        reach = (np.abs(C) @ (np.abs(f) + radL + 2.0 ** -49 * terms)[..., None])[..., 0]
        candidate = ~failed & np.all(np.isfinite(reach) & np.isfinite(x), axis=1)
        candidate &= np.all((x >= star_lo) & (x <= star_hi), axis=1)
    good = np.zeros(N, dtype=bool)
    rlo, rhi, C = star_lo.copy(), star_hi.copy(), np.zeros((N, n, n))
    for factor in ROOT_FACTORS:
        todo = np.nonzero(candidate & ~good)[0]
        if not len(todo):
            break
        r = factor * reach[todo] + 2.0 ** -50 * np.abs(x[todo]) + 1e-300
        tlo, thi = np.maximum(x[todo] - r, star_lo[todo]), np.minimum(x[todo] + r, star_hi[todo])
        K, Ct = krawczyk_boxes(for_batch(system, len(todo)), Interval.from_bounds(tlo, thi),
                               Interval.from_bounds(L.lo[todo], L.hi[todo]))
        ok = unique_in(K, tlo, thi)
        rlo[todo[ok]], rhi[todo[ok]], C[todo[ok]] = tlo[ok], thi[ok], Ct[ok]
        good[todo[ok]] = True
    if not good.all():
        bad = ~good
        Lb = Interval.from_bounds(L.lo[bad], L.hi[bad])
        rlo[bad], rhi[bad], C[bad] = enclose_roots(for_batch(system, int(bad.sum())), star_lo[bad], star_hi[bad], Lb)
    return rlo, rhi, C
