"""Forward kinematics: every real assembly mode, each in a box proved to hold exactly one.

The equations (``robots.fk_systems``: platform origin and frame axes as
unknowns, quadratic, covering every real posture) are solved by the shared
engine; each box is decided by

0. ``hc4``: one forward-backward pass over every equation (``fk_hc4``), then
   ``position``: a Gauss-Seidel sweep on the position, which is linear given
   the rotation; either may empty the box (``hc4-empty``, ``position-empty``)
   or shrink it (a contraction, recorded in the tree);
1. ``equation``: the enclosure of one equation over the box misses 0 — no
   solution in the box;
2. ``krawczyk-empty``: K(X) ∩ X = ∅ — no solution (Krawczyk 1969; Moore 1977);
3. ``krawczyk-unique``: K(X*) ⊂ int X* for a box X* ⊇ X — exactly one
   solution in X*, hence at most one in X (X* is X itself, or for small
   boxes X inflated around a Newton iterate: ε-inflation, Rump 1983);
4. ``krawczyk`` contraction: the solutions in X lie in K(X) ∩ X, which
   replaces X (widened by a relative 2⁻²⁰ so that an independent
   re-computation still fits inside) when it is substantially smaller;
5. otherwise X is bisected, along the rotation unknown where the equations
   vary most (planar) or the widest scaled side (spatial: in practice a
   quaternion unknown); the position follows from the rotation by steps 0
   and 4.

K(X) = c − C f(c) + (I − C J(X))(X − c) with c the midpoint and C the
float inverse of the midpoint Jacobian (Neumaier 1990, ch. 5).  For the
spatial robots steps 2 and 4 use a slope matrix S, about half as wide as
J(X), and the Hansen-Sengupta operator (one preconditioned Gauss-Seidel
sweep on C S (x − c) = −C f(c): ``slope_boxes``; ``slope-gs-empty`` and
``slope-gs``), and a box whose image lies inside it goes to the test of
step 3 with J(X).

Each proved box's root is then enclosed tightly: Krawczyk iterates from
X*, then an ε-inflated box R with K(R) ⊂ int R, which proves exactly one
root in R.  Proved boxes whose R lie in one another's X* share their root;
roots whose R are pairwise disjoint are distinct.  Boxes left undecided
(near a singular configuration or at the resolution limit) are grouped into
``unresolved`` clusters: never reported as two roots, nor as none.
``complete`` is true only when every box of the domain was excluded or
proved and every root's R lies inside the domain.

For a quaternion, the HC4 pass, the position step, the slope step and the
Hansen-Sengupta sweep run box by box in machine code (``fk_native``,
``intervals.native``): the same operations as the numpy versions they are
tested against.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import time

import numpy as np

from intervals import Interval, linalg, sqr
from intervals.rounding import down, down_sum, enclose_plain, up, up_sum

from . import budgets
from .engine import EXCLUDED, OPEN, PROVED, UNDECIDED, Budget, Decisions, search
from .errors import InputError
from .fk_hc4 import hc4

MARGIN = 2.0 ** -30      # uniqueness requires K inside X shrunk by this relative margin
WIDEN = 2.0 ** -20       # contracted boxes are widened by this fraction of the parent's width
SHRINK = 0.05            # a contraction is kept when some side shrinks by this fraction
INFLATE_BELOW = 2.0 ** -12  # scaled width under which ε-inflation around a Newton iterate is tried
POSITION_SCALE = 8.0     # position sides count this much less than rotation sides when bisecting
KRAWCZYK_BELOW = 0.1     # the Krawczyk step is tried on boxes whose rotation sides are below this (scaled)
AGAIN = 0.2              # a Krawczyk contraction this strong is followed by a second Krawczyk step,
AGAIN_MIN = 64           # when at least this many boxes of the batch had one,
AGAIN_SHARE = 2          # or at least half of the boxes still open did,
AGAIN_STEPS = 3          # at most this many times
SMALL_BATCH = 512        # batches of at most this many boxes use the stacked evaluation (fk_stacked)
INITIAL_SPLITS = 6       # every domain is halved this often before the first batch (it is never decided whole)
ROTATION_FIRST = 16.0    # only rotation unknowns are bisected while the position is at most this much wider (scaled)


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
        fc = system.equations(Interval._raw(c, c.copy()), L)
    if C is None:
        C = float_inverse(J.mid())[0]
        if compact:
            C = _compact(C)
    K = linalg._krawczyk_image(fc, J, X, c, C)
    return (K, C, J) if with_jacobian else (K, C)


def float_inverse(M):
    """(C, failed): the float inverse of each matrix M (..., n, n), ``linalg.mid_inverse``'s only
    where a plain inverse is singular or not finite.  A preconditioner, not a proof: the Krawczyk
    test is valid with any float C (a poor C only makes it fail)."""
    with np.errstate(all="ignore"):
        try:
            C = np.linalg.inv(M)
            if np.isfinite(C).all():
                return C, np.zeros(M.shape[:-2], dtype=bool)
        except np.linalg.LinAlgError:
            pass
    return linalg.mid_inverse(M)


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
        from .fk_native import float_inverse as inverse, slope_quaternion
        if drbs is None:
            with np.errstate(invalid="ignore", over="ignore"):
                Y = Interval._raw(down(0.5 * down_sum(X.lo + c)), up(0.5 * up_sum(X.hi + c)))   # ∋ (x + c)/2
            drbs = system._rotated_derivatives_midrad(Y)
        f64 = np.ascontiguousarray
        Slo, Shi, flo, fhi = slope_quaternion(f64(X.lo), f64(X.hi), f64(c), f64(rb.lo), f64(rb.hi), f64(rbc.lo),
                                              f64(rbc.hi), f64(drbs[0]), f64(drbs[1]), system.a.lo, system.a.hi,
                                              f64(L.lo, dtype=np.float64), f64(L.hi, dtype=np.float64), system.n_pos)
        S, fc = Interval._raw(Slo, Shi), Interval._raw(flo, fhi)
        C, failed = inverse(Slo, Shi, compact)
        if failed.any():
            Cf = linalg.mid_inverse(S[failed].mid())[0]
            C[failed] = _compact(Cf) if compact else Cf
    else:
        fc = system.equations(Interval._raw(c, c.copy()), L, rb=rbc)
        S = system.slope(X, c, rb=rb, rbc=rbc, drbs=drbs)
        C = float_inverse(S.mid())[0]
        if compact:
            C = _compact(C)
    H, empty = linalg.hansen_sengupta(fc, S, X, c, C)
    return H, C, S, empty


def _for_batch(system, n_box):
    """The equations for a batch of n_box boxes: the stacked twin for small batches (the same
    enclosures, bit for bit, in fewer and larger operations: ``robots/fk_stacked.py``)."""
    if n_box > SMALL_BATCH:
        return system
    from .robots.fk_stacked import StackedFKSystem
    return StackedFKSystem.of(system)


def fk_system(robot):
    """The ``FKSystem`` of a robot, built once per geometry and kept on the robot object.

    The cache is keyed by the robot's kind and exact geometry texts (compared on every call), so a
    robot whose ``base`` or ``platform`` was changed gets a new system built from its current
    geometry (its cached parameter enclosures are dropped first), never a stale one.
    """
    from .robots.fk_systems import FKSystem
    key = (robot.kind, tuple(map(tuple, robot.base)), tuple(map(tuple, robot.platform)))
    cached = robot.__dict__.get("_fk_system")
    if cached is not None and cached[0] == key:
        return cached[1]
    robot.__dict__.pop("parameters", None)      # re-enclose the current geometry texts
    system = FKSystem(robot)
    robot.__dict__["_fk_system"] = (key, system)
    return system


def _compact(M):
    """M rounded to float32 values (held as float64): evidence matrices are stored as float32."""
    with np.errstate(over="ignore"):
        return np.where(np.abs(M) < 2.0 ** 127, M, 0.0).astype(np.float32).astype(np.float64)


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
    known ``rb`` take the machine-code twin (``fk_native.position_gauss_seidel``, the same bounds).
    """
    p = system.n_pos
    if p == 3 and rb is not None:     # spatial: the machine-code twin (fk_native.position_gauss_seidel)
        from .fk_native import position_gauss_seidel
        k = system.__dict__.get("_position_constants")
        if k is None:
            k = system._position_constants = system.norm_a2 + system.norm_b2
        f64 = np.ascontiguousarray
        new_lo, new_hi, empty, P = position_gauss_seidel(
            f64(X.lo, dtype=np.float64), f64(X.hi, dtype=np.float64), f64(rb.lo), f64(rb.hi), system.a.lo,
            system.a.hi, k.lo, k.hi, f64(L.lo, dtype=np.float64), f64(L.hi, dtype=np.float64))
        new = Interval._raw(new_lo, new_hi)
    else:
        new, empty, P = _position_gauss_seidel(system, X, L, rb)
    w = (X.hi[:, :p] - X.lo[:, :p]) * WIDEN  # room for an independent re-computation
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
    P = _compact(np.where(np.isfinite(P), P, 0.0))   # float32 values: any float P keeps the solutions
    with np.errstate(invalid="ignore", over="ignore"):   # P [D | g] (the products P D, P g) in midpoint-radius
        Dm, Dr = linalg.midrad(np.concatenate([D.lo, g.lo[..., None]], -1),   # form: a float matrix product and
                               np.concatenate([D.hi, g.hi[..., None]], -1))   # its proved bound (product_midrad)
        m, r = linalg.product_midrad(P, None, Dm, Dr)
        Ab = Interval._raw(down(m - r), up(m + r))
        bad = ~(np.isfinite(Ab.lo) & np.isfinite(Ab.hi))
        if bad.any():
            Ab = Interval._raw(np.where(bad, -np.inf, Ab.lo), np.where(bad, np.inf, Ab.hi))
    A, b = Ab[..., :p], Ab[..., p]
    box = Interval._raw(X.lo[:, :p], X.hi[:, :p])
    new, empty = linalg.gauss_seidel(A, b, box, C=False)
    return new, empty, P


class FKProblem:
    """Decides boxes of FK unknowns for a batch of instances (one root box per instance)."""

    reasons = ("equation", "krawczyk-empty", "krawczyk-unique", "krawczyk", "position-empty", "position",
               "hc4-empty", "hc4", "slope-empty", "slope", "slope-gs-empty", "slope-gs")

    def __init__(self, system, L: Interval, scale, slopes: bool = False):
        self.system = system
        self.slopes = slopes                # exclusion and contraction by the slope form (slope_boxes)
        self.L = L                          # (M, legs) squared leg lengths, one row per instance
        self.scale = scale
        self._stacked = None

    def _system(self, n_box):
        if n_box > SMALL_BATCH:
            return self.system
        if self._stacked is None:
            self._stacked = _for_batch(self.system, 0)
        return self._stacked

    def _L(self, roots):
        return Interval._raw(self.L.lo[roots], self.L.hi[roots])

    def decide(self, lo, hi, roots) -> Decisions:
        n_box, n = lo.shape
        system = self._system(n_box)
        L = self._L(roots)
        status = np.full(n_box, OPEN, dtype=np.int8)
        reason = np.zeros(n_box, dtype=np.int64)
        creason = np.zeros(n_box, dtype=np.int64)
        cev = {}
        lo, hi = lo.copy(), hi.copy()
        # 0. forward-backward (HC4) contraction of every equation (fk_hc4), kept when it shrinks a side
        kept = {}
        hlo, hhi, hempty = hc4(system, lo, hi, L, keep=kept)
        status[hempty], reason[hempty] = EXCLUDED, 6
        w = (hi - lo) * WIDEN  # room for an independent re-computation
        hlo, hhi = np.maximum(lo, hlo - w), np.minimum(hi, hhi + w)
        hc4_moved = ~hempty & (_shrink(lo, hi, hlo, hhi) >= SHRINK)
        lo[hc4_moved], hi[hc4_moved] = hlo[hc4_moved], hhi[hc4_moved]
        creason[hc4_moved] = 7
        # 1. the position is linear given the rotation: Gauss-Seidel contraction (after HC4: one
        #    "hc4" contraction with the evidence P; spatial robots: its own "position" contraction
        #    after the "hc4" one, on the centred enclosure of R b_i over the box after HC4)
        #    (steps 1 and 2 evaluate only the boxes HC4 left, ``live``: the others are decided)
        position_moved = np.zeros(n_box, dtype=bool)
        live = np.nonzero(~hempty)[0]
        Xl, Ll = Interval._raw(lo[live], hi[live]), Interval._raw(L.lo[live], L.hi[live])
        if self.slopes:
            hc4_box = (lo.copy(), hi.copy())
            form = kept.get("form")     # HC4's centred form over the given boxes: the same for those it left
            if form is not None:
                form = tuple(v[live] for v in form)
                again = hc4_moved[live]
                if again.any():
                    for v, w in zip(form, system.centred_form(Interval._raw(Xl.lo[again], Xl.hi[again]))):
                        v[again] = w
            rbl, rbcl, drbl = system.rotated_centred(Xl, parts=True, form=form)   # the rotation is final now
        else:
            rbl = system.rotated(system.rotation(Xl))        # the rotation is final now
        rb = Interval._raw(np.zeros((n_box,) + rbl.shape[1:]), np.zeros((n_box,) + rbl.shape[1:]))
        rb.lo[live], rb.hi[live] = rbl.lo, rbl.hi
        if system.n_pos:
            pl, ph, pe, Pl = contract_position(system, Xl, Ll, rb=rbl)
            plo, phi_, pempty, P = lo.copy(), hi.copy(), np.zeros(n_box, dtype=bool), np.zeros((n_box,) + Pl.shape[1:])
            plo[live], phi_[live], pempty[live], P[live] = pl, ph, pe, Pl
            pempty &= status == OPEN
            status[pempty] = EXCLUDED
            reason[pempty] = 4
            shrink = _shrink(lo, hi, plo, phi_)
            position_moved = ~pempty & (shrink >= SHRINK) & (status == OPEN)
            lo[position_moved], hi[position_moved] = plo[position_moved], phi_[position_moved]
            creason[position_moved & ~hc4_moved] = 5
            if self.slopes:
                creason[position_moved] = 5
            cev["P"] = (position_moved, P[position_moved].astype(np.float32))
            P_empty = P
        # 2. exclusion by one equation
        Fl = system.equations(Interval._raw(lo[live], hi[live]), Ll, rb=rbl)
        out = np.zeros((n_box, n), dtype=bool)
        out[live] = (Fl.lo > 0) | (Fl.hi < 0)
        excluded = out.any(axis=1) & (status == OPEN)
        status[excluded] = EXCLUDED
        reason[excluded] = 0
        evidence = {"equation": (excluded, np.argmax(out[excluded], axis=1).astype(np.int8))}
        if system.n_pos and pempty.any():
            evidence["P"] = (pempty, P_empty[pempty].astype(np.float32))
        # 3. Krawczyk: empty, unique, or a contraction (not on boxes still wide in the rotation,
        #    where it never succeeds: those are bisected)
        rest = np.nonzero(status == OPEN)[0]
        pn = system.n_pos
        wide = np.max((hi[rest, pn:] - lo[rest, pn:]) / self.scale[pn:], axis=1) > KRAWCZYK_BELOW
        rest = rest[~wide]
        lo2, hi2, cev2, more = lo.copy(), hi.copy(), {}, []
        C_rows = np.zeros((n_box, n, n))
        C_mask = np.zeros(n_box, dtype=bool)
        star_mask = np.zeros(n_box, dtype=bool)
        stars = np.zeros((n_box, n, 2))
        split = np.full(n_box, -1)
        if len(rest):
            rlo, rhi = lo[rest], hi[rest]
            Lr = Interval._raw(L.lo[rest], L.hi[rest])
            if self.slopes:
                at = np.searchsorted(live, rest)    # R b_i at the midpoints, derivatives: the rotation is unchanged
                K, C, J, kempty = slope_boxes(system, Interval._raw(rlo, rhi), Lr, rb=rb[rest], compact=True,
                                              rbc=rbcl[at], drbs=(drbl[0][at], drbl[1][at]))
            else:
                K, C, J = krawczyk_boxes(system, Interval._raw(rlo, rhi), Lr, with_jacobian=True, rb=rb[rest],
                                         compact=True)
            C_rows[rest] = C
            # planar: bisect where the equations vary most: the largest sum_i |J_ij| w_j ("smear", Kearfott
            # 1996), among the rotation unknowns (HC4 and Gauss-Seidel then narrow the position) unless the
            # position is much wider (scaled) than the rotation; spatial (quaternion): the widest scaled
            # side, the engine's choice (fewer boxes than the smear there)
            if not self.slopes:
                smear = np.sum(J.mag(), axis=1) * (rhi - rlo)
                smear = np.where(np.isfinite(smear), smear, np.inf)
                pn = system.n_pos
                if pn:
                    scaled = (rhi - rlo) / self.scale
                    rot_first = np.max(scaled[:, :pn], axis=1) <= ROTATION_FIRST * np.max(scaled[:, pn:], axis=1)
                    smear[:, :pn] = np.where(rot_first[:, None], -1.0, smear[:, :pn])
                split[rest] = np.argmax(smear, axis=1)
            finite = np.all(np.isfinite(K.lo) & np.isfinite(K.hi), axis=1)
            empty = kempty if self.slopes else np.any((K.hi < rlo) | (K.lo > rhi), axis=1) & finite
            unique = unique_in(K, rlo, rhi) & ~empty
            if self.slopes:     # a slope image inside X: the Krawczyk test proper (with the Jacobian) decides
                unique = self._unique(system, rlo, rhi, Lr, C, unique)
            status[rest[empty]], reason[rest[empty]] = EXCLUDED, 10 if self.slopes else 1
            status[rest[unique]], reason[rest[unique]] = PROVED, 2
            C_mask[rest[empty | unique]] = True
            open_ = ~(empty | unique)
            # contraction K(X) ∩ X, widened, kept inside X: a second contraction, after the first
            w = (rhi - rlo) * WIDEN
            nlo = np.maximum(rlo, np.where(np.isfinite(K.lo), K.lo - w, -np.inf))
            nhi = np.minimum(rhi, np.where(np.isfinite(K.hi), K.hi + w, np.inf))
            keep = open_ & np.all(nlo <= nhi, axis=1) & (_shrink(rlo, rhi, nlo, nhi) >= SHRINK)
            k = rest[keep]
            lo2[k], hi2[k] = nlo[keep], nhi[keep]
            kmask = np.zeros(n_box, dtype=bool)
            kmask[k] = True
            cev2["C"] = (kmask, C[keep].astype(np.float32))
            # boxes that Krawczyk shrank by half or more (near a root: quadratic convergence) get up to
            # AGAIN_STEPS more Krawczyk steps, each on the box the step before contracted: empty, unique,
            # or a further contraction (when they are many, or most of the open boxes: an evaluation costs
            # about as much for a few boxes as for a hundred, a round of bisection much more)
            strong = k[_shrink(rlo[keep], rhi[keep], nlo[keep], nhi[keep]) >= AGAIN]
            cur_lo, cur_hi = lo2, hi2
            for _ in range(AGAIN_STEPS):
                if not len(strong) or (len(strong) < AGAIN_MIN
                                       and AGAIN_SHARE * len(strong) < np.count_nonzero(status == OPEN)):
                    break
                X2 = Interval._raw(cur_lo[strong], cur_hi[strong])
                L2 = Interval._raw(L.lo[strong], L.hi[strong])
                if self.slopes:     # ell(X) from the centred R b_i (its parts at c serve the slope too)
                    rb2, rbc2, drb2 = system.rotated_centred(X2, parts=True)
                    K2, C2, _, empty2 = slope_boxes(system, X2, L2, rb=rb2, compact=True, rbc=rbc2, drbs=drb2)
                else:
                    K2, C2 = krawczyk_boxes(system, X2, L2, compact=True)
                    finite2 = np.all(np.isfinite(K2.lo) & np.isfinite(K2.hi), axis=1)
                    empty2 = np.any((K2.hi < X2.lo) | (K2.lo > X2.hi), axis=1) & finite2
                unique2 = unique_in(K2, X2.lo, X2.hi) & ~empty2
                if self.slopes:
                    unique2 = self._unique(system, X2.lo, X2.hi, L2, C2, unique2)
                status[strong[empty2]], reason[strong[empty2]] = EXCLUDED, 10 if self.slopes else 1
                status[strong[unique2]], reason[strong[unique2]] = PROVED, 2
                C_rows[strong[empty2 | unique2]] = C2[empty2 | unique2]
                C_mask[strong[empty2 | unique2]] = True
                w2 = (X2.hi - X2.lo) * WIDEN
                nlo2 = np.maximum(X2.lo, np.where(np.isfinite(K2.lo), K2.lo - w2, -np.inf))
                nhi2 = np.minimum(X2.hi, np.where(np.isfinite(K2.hi), K2.hi + w2, np.inf))
                keep2 = ~(empty2 | unique2) & np.all(nlo2 <= nhi2, axis=1) & (_shrink(X2.lo, X2.hi, nlo2, nhi2) >= SHRINK)
                lo3, hi3 = cur_lo.copy(), cur_hi.copy()
                lo3[strong[keep2]], hi3[strong[keep2]] = nlo2[keep2], nhi2[keep2]
                k3 = np.zeros(n_box, dtype=bool)
                k3[strong[keep2]] = True
                more.append(((lo3, hi3), {"C": (k3, C2[keep2].astype(np.float32))}))
                strong = strong[keep2][_shrink(X2.lo[keep2], X2.hi[keep2], nlo2[keep2], nhi2[keep2]) >= AGAIN]
                cur_lo, cur_hi = lo3, hi3
            # small open boxes: ε-inflation around a Newton iterate
            width = np.max((rhi - rlo) / self.scale, axis=1)
            small = open_ & ~keep & (width < INFLATE_BELOW)
            if small.any():
                sm = rest[small]
                proved, slo, shi, Cs = self._inflate(rlo[small], rhi[small], roots[sm])
                status[sm[proved]], reason[sm[proved]] = PROVED, 2
                star_mask[sm[proved]] = True
                stars[sm[proved]] = np.stack([slo[proved], shi[proved]], axis=-1)
                C_rows[sm[proved]] = Cs[proved]
                C_mask[sm[proved]] = True
        evidence["C"] = (C_mask, C_rows[C_mask].astype(np.float32))
        if star_mask.any():
            evidence["star"] = (star_mask, stars[star_mask])
        kcode = 11 if self.slopes else 3
        stages = [(lo, hi), (lo2, hi2)] + [box for box, _ in more]
        reasons = [creason] + [np.full(n_box, kcode)] * (1 + len(more))
        stage_evidence = [cev, cev2] + [ev for _, ev in more]
        if self.slopes:      # "hc4" (no evidence), then "position" (P), then the slope steps
            stages.insert(0, hc4_box)
            reasons.insert(0, np.full(n_box, 7))
            stage_evidence.insert(0, {})
        return Decisions(status, reason, evidence, contracted=stages, contraction_reason=reasons,
                         contraction_evidence=stage_evidence, split=split)

    def _unique(self, system, lo, hi, L: Interval, C, candidates):
        """The candidates (slope image inside X) for which K(X) ⊂ int X with the Jacobian and the
        same C: exactly one root in X (the test of ``krawczyk_boxes``)."""
        out = np.zeros(len(lo), dtype=bool)
        k = np.nonzero(candidates)[0]
        if len(k):
            K, _ = krawczyk_boxes(_for_batch(system, len(k)), Interval._raw(lo[k], hi[k]),
                                  Interval._raw(L.lo[k], L.hi[k]), C=C[k])
            out[k] = unique_in(K, lo[k], hi[k])
        return out

    def _inflate(self, lo, hi, roots):
        """Try X* = Newton iterate ± r (⊇ X); returns (proved mask, X* lo, X* hi, C)."""
        system = self._system(len(lo))
        L = self._L(roots)
        x = 0.5 * (lo + hi)
        J = system.jacobian(Interval._raw(lo, hi))
        C, _ = float_inverse(J.mid())
        for _ in range(3):  # float Newton steps (a guess only: the proof is the Krawczyk test below)
            f = system.equations(Interval._raw(x, x.copy()), L)
            x = x - np.einsum("nij,nj->ni", C, 0.5 * (f.lo + f.hi))
        r = np.maximum(np.abs(x - 0.5 * (lo + hi)), hi - lo) + 1e-12 * self.scale
        slo, shi = np.minimum(lo, x - r), np.maximum(hi, x + r)
        K, Cs = krawczyk_boxes(system, Interval._raw(slo, shi), L, compact=True)
        return unique_in(K, slo, shi), slo, shi, Cs


def _shrink(lo, hi, nlo, nhi):
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
        K, _ = krawczyk_boxes(system, Interval._raw(lo, hi), L)
        nlo, nhi = np.maximum(lo, K.lo), np.minimum(hi, K.hi)
        ok = np.all(nlo <= nhi, axis=1)
        before = np.max(hi - lo, axis=1)
        lo[ok], hi[ok] = nlo[ok], nhi[ok]
        if np.all(np.max(hi - lo, axis=1) > 0.5 * before):  # no longer contracting: converged
            break
    w = 0.5 * (hi - lo) + (np.abs(lo) + np.abs(hi)) * 2.0 ** -45 + 1e-300
    rlo, rhi = np.maximum(lo - w, star_lo), np.minimum(hi + w, star_hi)
    K, C = krawczyk_boxes(system, Interval._raw(rlo, rhi), L)
    good = unique_in(K, rlo, rhi)
    if not good.all():
        K2, C2 = krawczyk_boxes(system, Interval._raw(star_lo, star_hi), L)
        rlo[~good], rhi[~good], C[~good] = star_lo[~good], star_hi[~good], C2[~good]
    return rlo, rhi, C


def root_boxes(system, star_lo, star_hi, L: Interval, newton_steps: int = 6):
    """Tight boxes R ⊆ X*, each proved to hold a root (hence X*'s unique root), and their C.

    A guess x* from float Newton iterations started at the midpoint of X*
    (``FKSystem.float_system``: plain floats, never a proof), the box
    R = x* ± r with r twice a float estimate of how far the Krawczyk image of
    R reaches (|C| (|f(x*)| + the rounding of the interval evaluation of f)),
    cut to X*, and one Krawczyk test K(R) ⊂ int R (outward rounded: the proof).
    Rows that fail get ``enclose_roots`` (Krawczyk iterations from X*).  Batched.
    """
    N, n = star_lo.shape
    if not N:
        return star_lo.copy(), star_hi.copy(), np.zeros((0, n, n))
    L2 = 0.5 * L.lo + 0.5 * L.hi
    x = 0.5 * star_lo + 0.5 * star_hi
    with np.errstate(all="ignore"):
        size = np.maximum(np.abs(star_hi - star_lo), 1e-300)
        for _ in range(newton_steps):
            f, J = system.float_system(x, L2)
            ok = np.all(np.isfinite(J), axis=(1, 2)) & (np.abs(np.linalg.det(J)) > 0)
            step = np.linalg.solve(np.where(ok[:, None, None], J, np.eye(n)), f[..., None])[..., 0]
            step = np.where(ok[:, None] & np.isfinite(step), step, 0.0)
            x = x - step
            # converged (a guess: the proof is below): steps at the rounding level of x or of X*'s width
            if np.all(np.abs(step) <= 2.0 ** -40 * np.maximum(size, np.abs(x))):
                break
        f, J = system.float_system(x, L2)
        C, failed = float_inverse(J)
        a, b = system.float_geometry()
        p = system.n_pos
        # each leg equation sums terms of magnitude <= 3 (|p|² + |a_i|² + |b_i|²) + ρ_i²
        p2 = np.sum(x[:, :p] ** 2, -1, keepdims=True) if p else 0.0
        terms = np.concatenate([3.0 * (p2 + np.sum(a * a, -1) + np.sum(b * b, -1)) + L2, np.full((N, 1), 2.0)], -1)
        r = 2.0 * (np.abs(C) @ (np.abs(f) + 2.0 ** -49 * terms)[..., None])[..., 0] + 2.0 ** -50 * np.abs(x) + 1e-300
        good = ~failed & np.all(np.isfinite(r) & np.isfinite(x), axis=1)
        good &= np.all((x >= star_lo) & (x <= star_hi), axis=1)
    rlo = np.where(good[:, None], np.maximum(x - r, star_lo), star_lo)
    rhi = np.where(good[:, None], np.minimum(x + r, star_hi), star_hi)
    K, C = krawczyk_boxes(_for_batch(system, N), Interval._raw(rlo, rhi), L)
    good &= unique_in(K, rlo, rhi)
    if not good.all():
        bad = ~good
        Lb = Interval._raw(L.lo[bad], L.hi[bad])
        rlo[bad], rhi[bad], C[bad] = enclose_roots(_for_batch(system, int(bad.sum())), star_lo[bad], star_hi[bad], Lb)
    return rlo, rhi, C


@dataclass
class FKResult:
    """All real assembly modes for one set of leg lengths."""

    robot: object
    system: object
    lengths: list                       # exact texts
    domain: tuple                       # (lo, hi) of the unknowns searched
    solutions: list = field(default_factory=list)    # dicts: box (Interval of unknowns), pose, platform_points
    unresolved: list = field(default_factory=list)
    complete: bool = False
    tree: object = None
    node: int = 0
    leaf_proofs: dict = field(default_factory=dict)     # proved leaf -> {star, solution/twin | outside | undecided}
    boxes: int = 0
    seconds: float = 0.0
    tracked: bool = False
    user_domain: bool = False                           # a user --domain narrowed the search
    track_C: np.ndarray | None = None                   # the Krawczyk matrix of a tracking proof
    all_solutions: list = field(default_factory=list)   # every proved root of the searched box (certificate order)
    filtered: list = field(default_factory=list)        # solutions outside a user domain (pose filter)

    @property
    def status(self) -> str:
        return "complete" if self.complete else "incomplete"

    def to_json(self) -> dict:
        def entry(s, with_status):
            e = {"pose": {k: [float(v.lo), float(v.hi)] for k, v in s["pose"].items()},
                 "platform_points": [[[float(c.lo), float(c.hi)] for c in p] for p in s["platform_points"]]}
            return {"status": "unique", **e} if with_status else e
        out = {"problem": "forward-kinematics", "robot": self.robot.name, "kind": self.robot.kind,
               "lengths": self.lengths, "complete": self.complete,
               "solutions": [entry(s, True) for s in self.solutions],
               "unresolved": [entry(s, False) for s in self.unresolved],
               "stats": {"boxes": self.boxes, "seconds": round(self.seconds, 6)}}
        if self.tracked:
            out["tracked"] = True
        return out

    def certificate(self) -> dict:
        from .certificates import fk_certificate
        return fk_certificate(self)


def _clusters(lo, hi, limit: int = 2000):
    """Group boxes that touch or overlap (union-find); returns the hull of each group.

    Beyond ``limit`` boxes (a search stopped by its budget) the boxes are
    merged greedily along the first coordinate: fewer, larger clusters, still
    covering every box.
    """
    n = len(lo)
    if n > limit:
        order = np.argsort(lo[:, 0], kind="stable")
        chunks = np.array_split(order, limit)
        return [(lo[c].min(axis=0), hi[c].max(axis=0)) for c in chunks if len(c)]
    parent = np.arange(n)

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    touch = np.all((lo[:, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[:, None, :]), axis=-1)
    for i, j in zip(*np.nonzero(np.triu(touch, 1))):
        parent[find(i)] = find(j)
    roots = np.array([find(i) for i in range(n)])
    return [(lo[roots == r].min(axis=0), hi[roots == r].max(axis=0)) for r in np.unique(roots)]


def forward_kinematics(robot, lengths, domain=None, budget: Budget | None = None, progress=None, track=None):
    """All real FK postures for the leg lengths ``lengths``.

    ``lengths``: one set (sequence or "l1,l2,..." text), or a 2-D array with
    one row per instance (then a list of results is returned; the instances
    are searched together, as one batch).  ``domain``: optional box of pose
    variables (``"x=a:b,..."``); position ranges narrow the search, angle
    ranges filter the solutions.  ``track``: a previous pose; the unique
    posture near it is proved directly when possible (``result.tracked``),
    else the full search runs; with a 2-D ``lengths`` the rows are a
    sequence, tracked one after another from ``track`` (``track_sequence``).
    Each solution is proved unique in its box; ``complete`` means the rest of
    the domain is proved empty.
    """
    if track is not None and not isinstance(lengths, str) and np.asarray(lengths, dtype=object).ndim == 2:
        return track_sequence(robot, lengths, track, budget=budget)
    system = fk_system(robot)
    rho, texts, batch_input = _length_enclosures(robot, lengths)
    M = len(texts)
    L = sqr(rho)
    if track is not None and not batch_input:
        result = _track(robot, system, texts[0], L, track)
        if result is not None:
            return result
    lo, hi = system.domain(rho)
    angle_filter = None
    if domain is not None:
        lo, hi, angle_filter = _apply_domain(robot, system, domain, lo, hi)
    feasible = np.all(lo <= hi, axis=1)
    scale = np.max(np.where(feasible[:, None], hi - lo, 0.0), axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    scale[:system.n_pos] *= POSITION_SCALE  # bisect the rotation first: the position follows from it
    if system.kind != "planar-3rpr":    # the quaternion's components alike (q0's range is half the others'):
        scale[system.n_pos:] = 2.0      # the extent of the unit sphere (seed 002 full domain: −22 % boxes)
    if budget is None:
        budget = Budget(**{**budgets.FORWARD_KINEMATICS,
                           "max_boxes": max(budgets.FORWARD_KINEMATICS["max_boxes"], 20_000 * M)})
    t0 = time.perf_counter()
    idx = np.nonzero(feasible)[0]
    problem = FKProblem(system, Interval._raw(L.lo[idx], L.hi[idx]), scale, slopes=system.kind != "planar-3rpr")
    res = search(problem, lo[idx], hi[idx], scale=scale, budget=budget, batch=max(8192, 256 * len(idx)),
                 progress=progress, initial_splits=INITIAL_SPLITS) if len(idx) else None
    out = _collect(robot, system, texts, lo, hi, L, feasible, idx, res, angle_filter)
    for r in out:
        r.user_domain = domain is not None
    seconds = time.perf_counter() - t0
    for r in out:
        r.seconds = seconds / M
    if not batch_input:
        out[0].boxes = res.boxes if res else 0
        return out[0]
    return out


def _collect(robot, system, texts, lo, hi, L, feasible, idx, res, angle_filter):
    """Results per instance from the search tree (solutions merged, undecided boxes clustered)."""
    M = len(texts)
    results = [FKResult(robot, system, texts[i], (lo[i], hi[i])) for i in range(M)]
    for i in np.nonzero(~feasible)[0]:
        results[i].complete = True          # the leg-length balls do not meet: no posture at all
    if res is None:
        return results
    tree = res.tree
    proved = tree.leaves(kind=PROVED)
    slo, shi = tree.lo[proved].copy(), tree.hi[proved].copy()
    rows = tree.evidence_rows.get("star")
    if rows is not None:
        has = rows[proved] >= 0
        st = tree.evidence["star"][rows[proved[has]]]
        slo[has], shi[has] = st[..., 0], st[..., 1]
    inst = idx[tree.root[proved]]
    Lp = Interval._raw(L.lo[inst], L.hi[inst])
    if len(proved):
        rlo, rhi, rC = root_boxes(system, slo, shi, Lp)
    else:
        rlo, rhi, rC = slo, shi, np.zeros((0, system.n, system.n))
    undecided = tree.leaves(kind=UNDECIDED)
    nodes = np.bincount(tree.root, minlength=len(idx))
    by_root = np.argsort(tree.root[proved], kind="stable")
    starts = np.searchsorted(tree.root[proved][by_root], np.arange(len(idx) + 1))
    und_sorted = undecided[np.argsort(tree.root[undecided], kind="stable")]
    und_starts = np.searchsorted(tree.root[und_sorted], np.arange(len(idx) + 1))
    pendings = []
    for k, i in enumerate(idx):
        r = results[i]
        r.tree, r.node, r.boxes = tree, k, int(nodes[k])
        sel = by_root[starts[k]:starts[k + 1]]
        pending = [(tree.lo[j], tree.hi[j]) for j in und_sorted[und_starts[k]:und_starts[k + 1]]]
        _merge(r, system, proved[sel], slo[sel], shi[sel], rlo[sel], rhi[sel], rC[sel], lo[i], hi[i], pending)
        pendings.append(pending)
    # poses and platform points of every solution of every instance in one evaluation
    counts = [len(results[i].solutions) for i in idx]
    computed = [None] * len(idx)
    if sum(counts):
        boxes = [s["box"] for i in idx for s in results[i].solutions]
        B = Interval._raw(np.stack([b.lo for b in boxes]), np.stack([b.hi for b in boxes]))
        poses, pts = system.pose(B), system.points(B)
        first = np.concatenate([[0], np.cumsum(counts)])
        computed = [({name: v[first[k]:first[k + 1]] for name, v in poses.items()}, pts[first[k]:first[k + 1]])
                    for k in range(len(idx))]
    for k, i in enumerate(idx):
        _finish(results[i], system, pendings[k], angle_filter, computed[k])
    return results


def _meets(alo, ahi, blo, bhi):
    return bool(np.all(alo <= bhi) and np.all(blo <= ahi))


def _merge(result, system, leaves, slo, shi, rlo, rhi, rC, dlo, dhi, pending):
    """Distinct roots (postures) from the proved leaves of one instance.

    A leaf joins the root of an earlier group when that group's root box lies
    in the leaf's uniqueness box X* (or, for a quaternion, the root box with q
    negated: the same posture, a ``twin``); otherwise it starts a group with
    its own root box.  Groups whose boxes lie in the domain and are disjoint
    from every other group's box (and its negation) are the solutions.
    """
    spatial = system.kind != "planar-3rpr"
    p = system.n_pos
    groups = []                              # (lo, hi, C) of each group's root box
    member = []                              # per leaf: (group, twin)
    n_leaves = len(leaves)
    glo_all, ghi_all = np.empty((n_leaves, system.n)), np.empty((n_leaves, system.n))  # rows of the groups so far
    for a in range(n_leaves):
        found = None
        g_n = len(groups)
        if g_n:
            Glo, Ghi = glo_all[:g_n], ghi_all[:g_n]
            direct = np.all((Glo >= slo[a]) & (Ghi <= shi[a]), axis=1)
            hit = direct
            if spatial:
                Nlo = np.concatenate([Glo[:, :p], -Ghi[:, p:]], axis=1)
                Nhi = np.concatenate([Ghi[:, :p], -Glo[:, p:]], axis=1)
                hit = direct | np.all((Nlo >= slo[a]) & (Nhi <= shi[a]), axis=1)
            if hit.any():                    # the first group holding the leaf's root (direct before twin)
                g = int(np.argmax(hit))
                found = (g, not bool(direct[g]))
        if found is None:
            groups.append((rlo[a], rhi[a], rC[a]))
            glo_all[g_n], ghi_all[g_n] = rlo[a], rhi[a]
            found = (g_n, False)
        member.append(found)
    status = []                              # per group: "solution", "outside" or "ambiguous"
    G = len(groups)
    Glo, Ghi = glo_all[:G], ghi_all[:G]
    meets = np.all((Glo[:, None, :] <= Ghi[None, :, :]) & (Glo[None, :, :] <= Ghi[:, None, :]), axis=-1)
    if spatial:
        Nlo = np.concatenate([Glo[:, :p], -Ghi[:, p:]], axis=1)
        Nhi = np.concatenate([Ghi[:, :p], -Glo[:, p:]], axis=1)
        meets |= np.all((Glo[:, None, :] <= Nhi[None, :, :]) & (Nlo[None, :, :] <= Ghi[:, None, :]), axis=-1)
    np.fill_diagonal(meets, False)
    outside = np.any(Ghi < dlo, axis=1) | np.any(Glo > dhi, axis=1)
    inside = np.all(Glo >= dlo, axis=1) & np.all(Ghi <= dhi, axis=1)
    for g in range(G):
        if outside[g]:
            status.append("outside")
        else:
            status.append("ambiguous" if (not inside[g] or meets[g].any()) else "solution")
    index = {}
    for g, st in enumerate(status):
        glo, ghi, gC = groups[g]
        if st == "solution":
            index[g] = len(result.solutions)
            result.solutions.append({"status": "unique", "box": Interval._raw(glo.copy(), ghi.copy()), "C": gC})
        elif st == "ambiguous":
            pending.append((glo, ghi))
    for a, leaf in enumerate(leaves):
        g, twin = member[a]
        entry = {"star": (slo[a], shi[a])}
        if status[g] == "solution":
            entry.update(solution=index[g], twin=twin)
        elif status[g] == "outside" and not twin and not _meets(groups[g][0], groups[g][1], *leaf_box(result, leaf)):
            entry.update(outside=groups[g])  # the root of X* is outside the domain, so not in this leaf
        else:
            entry.update(undecided=True)
            if status[g] == "outside":
                pending.append(leaf_box(result, leaf))
        result.leaf_proofs[int(leaf)] = entry
    result.complete = not pending


def leaf_box(result, leaf):
    return result.tree.lo[leaf], result.tree.hi[leaf]


def _finish(result, system, pending, angle_filter, computed=None):
    """Poses and platform points of the solutions; undecided boxes clustered; the angle filter.

    ``computed``: (poses, points) of the solution boxes, if already evaluated (batched)."""
    result.all_solutions = list(result.solutions)
    if result.solutions:
        if computed is None:
            R = Interval._raw(np.stack([s["box"].lo for s in result.solutions]),
                              np.stack([s["box"].hi for s in result.solutions]))
            computed = system.pose(R), system.points(R)
        poses, pts = computed
        kept = []
        for j, s in enumerate(result.solutions):
            s["pose"] = _pose_names(result.robot, {k: v[j] for k, v in poses.items()})
            s["platform_points"] = [[pts[j, i, c] for c in range(pts.shape[2])] for i in range(pts.shape[1])]
            verdict = _in_filter(s["pose"], angle_filter)
            if verdict is True:
                kept.append(s)
            elif verdict is False:
                result.filtered.append(s)
            else:
                pending.append((s["box"].lo, s["box"].hi))
        result.solutions = kept
    if pending:
        hull = _clusters(np.array([p[0] for p in pending]), np.array([p[1] for p in pending]))
        B = Interval._raw(np.stack([h[0] for h in hull]), np.stack([h[1] for h in hull]))
        poses = system.pose(B)
        pts = system.points(B)
        for j in range(len(hull)):
            result.unresolved.append({"box": B[j], "pose": _pose_names(result.robot, {k: v[j] for k, v in poses.items()}),
                                      "platform_points": [[pts[j, i, c] for c in range(pts.shape[2])]
                                                          for i in range(pts.shape[1])]})
        result.complete = False
    result.solutions.sort(key=lambda s: [float(v.lo) for v in s["pose"].values()])


def _pose_names(robot, pose):
    """The pose in the robot's own variables (tilt-and-torsion: sigma = phi1 + phi3)."""
    if "sigma" in robot.pose_names:
        return {"phi1": pose["phi1"], "phi2": pose["phi2"], "sigma": pose["phi1"] + pose["phi3"]}
    return pose


def _in_filter(pose, angle_filter):
    """True (inside every angle range), False (outside one), None (cannot tell)."""
    if not angle_filter:
        return True
    verdict = True
    for name, (a, b) in angle_filter.items():
        v = pose[name]
        if float(v.hi) < a or float(v.lo) > b:
            return False
        if not (float(v.lo) >= a and float(v.hi) <= b):
            verdict = None
    return verdict


def _apply_domain(robot, system, spec, lo, hi):
    """Narrow the position unknowns to a user box; angle ranges become a solution filter."""
    from .poses import parse_box
    box, _ = parse_box(spec, robot, "--domain")
    lo, hi = lo.copy(), hi.copy()
    angles = {}
    for k, name in enumerate(robot.pose_names):
        if name in robot.angle_names:
            angles[name] = (float(box.lo[k]), float(box.hi[k]))
        else:
            j = system.unknowns.index(name)
            lo[:, j] = np.maximum(lo[:, j], box.lo[k])
            hi[:, j] = np.minimum(hi[:, j], box.hi[k])
    return lo, hi, angles


def _track(robot, system, texts, L, previous):
    """Prove the unique posture near a previous pose (seed 002 §4), or None to fall back.

    Float Newton iterations from the previous pose give a guess x*; a box
    around the previous pose and x* must pass the Krawczyk test K(X) ⊂ int X
    (exactly one posture there), and a narrow box around x* inside it too (the
    posture is there); see ``certkin.tracking``.
    """
    from .tracking import track_one
    return track_one(robot, system, texts, L, previous)


def track_sequence(robot, lengths_rows, start_pose, fallback: bool = True, budget: Budget | None = None):
    """Track the posture through a sequence of leg-length sets from ``start_pose``: one result per
    row, each step proved unique near the previous step's posture (``result.tracked``), all proofs
    in one batched evaluation; steps that are not proved get the full search (``fallback``) or are
    reported not proved.  See ``certkin.tracking.track_sequence``."""
    from .tracking import track_sequence as _track_sequence
    return _track_sequence(robot, lengths_rows, start_pose, fallback=fallback, budget=budget)


def _length_enclosures(robot, lengths):
    """(enclosures (M, legs), rows of exact texts, whether the input was a batch): ``_parse_lengths``
    as arrays, with a direct path for one set of floats or plain decimal texts (a float stands for
    its text repr(v), as there; anything else, or any doubt, takes ``_parse_lengths``)."""
    items = lengths.split(",") if isinstance(lengths, str) else lengths
    if isinstance(items, (list, tuple)) and len(items) == robot.n_legs:
        lo, hi, texts = [], [], []
        for v in items:
            if isinstance(v, float):
                t = repr(float(v))
            elif isinstance(v, str):
                t = v.strip()
            else:
                break
            ab = enclose_plain(t)
            if ab is None or not (ab[0] >= 0 and ab[1] < np.inf):
                break
            a, b = ab
            lo.append(a)
            hi.append(b)
            texts.append(t)
        else:
            return Interval._raw(np.array([lo]), np.array([hi])), [texts], False
    rows, texts, batch = _parse_lengths(robot, lengths)
    return (Interval._raw(np.array([[float(v.lo) for v in r] for r in rows]),
                          np.array([[float(v.hi) for v in r] for r in rows])), texts, batch)


def _parse_lengths(robot, lengths):
    """(rows of enclosures, rows of exact texts, whether the input was a batch)."""
    from .robots.base import parse_number
    if isinstance(lengths, str):
        lengths = [p.strip() for p in lengths.split(",")]
    arr = np.asarray(lengths, dtype=object)
    batch = arr.ndim == 2
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != robot.n_legs or arr.shape[0] == 0:
        raise InputError("--lengths", "", f"expected {robot.n_legs} leg lengths per instance")
    rows, texts = [], []
    for i, row in enumerate(arr):
        ivs, ts = [], []
        for j, v in enumerate(row):
            if isinstance(v, (float, np.floating)):
                v = repr(float(v))  # a float is its exact binary value; keep that text
            field_name = f"[{i}][{j}]" if batch else f"leg {j + 1}"
            try:
                iv, t = parse_number(v, "--lengths", field_name)
            except InputError as exc:
                raise InputError("--lengths", exc.field, exc.problem) from None
            if float(iv.lo) < 0:
                raise InputError("--lengths", field_name, f"a leg length cannot be negative ({t})")
            ivs.append(iv)
            ts.append(str(t))
        rows.append(ivs)
        texts.append(ts)
    return rows, texts, batch
