"""The branch-and-bound search of forward kinematics: every box of the domain decided or split.

The equations (``fk.system``: platform origin and frame axes as
unknowns, quadratic, covering every real posture) are solved by the shared
engine; each box is decided by

−1. ``cm-bernstein-empty`` (6-6 Gough-Stewart robots, exact lengths): no rotation of the box fits
   four legs — a Cayley-Menger polynomial in the quaternion alone keeps one sign on the box
   (``fk.cayley_menger``); else ``cm-combination-empty``: a combination of the 15 polynomials with
   no first-order part at the box's centre does (it excludes the boxes in the tubes along nearly
   self-moving postures, where each polynomial alone vanishes close by: Dietmaier's robot 303 378
   boxes -> 62 832);
0. ``hc4``: one forward-backward pass over every equation (``fk.contract``; spatial robots: a
   second pass on the boxes the first shrank by ``HC4_AGAIN``), then
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

The steps themselves are in ``fk.step``; the proved leaves become distinct
roots in ``fk.api``.

For a quaternion, the HC4 pass, the position step, the slope step and the
Hansen-Sengupta sweep run box by box in machine code (``fk.kernels``,
``intervals.native``): the same operations as the numpy versions they are
tested against.
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, linalg

from ..engine import EXCLUDED, OPEN, PROVED, UNDECIDED, Budget, Decisions, search
from .contract import gap_splits, hc4
from .step import SMALL_BATCH, contract_position, for_batch, fragile, krawczyk_boxes, room, shrink, \
    slope_boxes, unique_in

SHRINK = 0.05            # a contraction is kept when some side shrinks by this fraction
INFLATE_BELOW = 2.0 ** -12  # scaled width under which ε-inflation around a Newton iterate is tried
POSITION_SCALE = 8.0     # position sides count this much less than rotation sides when bisecting
KRAWCZYK_BELOW = 0.1     # the Krawczyk step is tried on boxes whose rotation sides are below this (scaled)
AGAIN = 0.2              # a Krawczyk contraction this strong is followed by a second Krawczyk step,
AGAIN_MIN = 64           # when at least this many boxes of the batch had one,
AGAIN_SHARE = 2          # or at least half of the boxes still open did,
FORMS_KEPT = 1024         # Cayley-Menger forms kept (instances), 40 KB each
QUAD_ORDER = np.arange(15)  # the quads tried in this order (the first that proves a box is its evidence)
AGAIN_STEPS = 3          # at most this many times
INITIAL_SPLITS = 6       # every domain is halved this often before the first batch (it is never decided whole)
ROTATION_FIRST = 16.0    # only rotation unknowns are bisected while the position is at most this much wider (scaled)
POSITION_GEOMETRIC = 7.0  # Gough: position side k scaled by this times √(W_k max|b_i|), W_k its domain width
CAYLEY_MENGER_ROTATION_FIRST = 16.0   # and this many times more where the Cayley-Menger rule applies
GAP = 0.5                # a gap between the two branches of an HC4 square root spanning this much of a side splits it
HC4_PASSES = 2           # slope systems: at most this many HC4 passes per box, each on the box the one before
HC4_AGAIN = 0.2          # contracted, when it shrank a side by this fraction or more
SPREAD_INFLATE = 2.0     # uncertain lengths: ε-inflation once every side is within this times the root's spread,
GIVE_UP_WIDTH = 2.0 ** -8  # and the box is within Newton's reach (``newton_reach`` below 1) or this narrow (scaled)


def search_instances(system, L: Interval, lo, hi, budget: Budget, progress=None, record_limit=None, record_sink=None,
                     independent: bool = False):
    """One engine search over the domains [lo, hi] (M, n) of M instances, squared leg lengths L
    (M, legs): the engine's ``SearchResult`` (its tree holds one root per instance).  ``independent``:
    each instance is searched as if alone (the engine's ``independent``; ``FKProblem`` decides a box
    from that box and its instance only), ``budget.max_boxes`` each.

    Sides are scaled by the domain's extent; position sides count ``POSITION_SCALE`` times less, so
    the rotation is bisected first (the position follows from it); a quaternion's components are
    scaled alike, by the extent of the unit sphere (seed 002 full domain: −22 % boxes).  For a Gough
    robot the position side k counts as its width over ``POSITION_GEOMETRIC`` √(W_k max|b_i|), W_k
    the domain's width: a rotation moves the platform points by about max|b_i| times its change,
    and the position follows it with a lever arm that grows with the workspace (fitted on the
    seed 002, main gauche, MEL and micro-manipulator robots: main gauche at home 2.09 M -> 0.92 M
    boxes, the others within ±2 % or fewer).  Where the Cayley-Menger rule applies (6 legs, exact
    lengths: it excludes a box on its rotation alone) the position counts
    ``CAYLEY_MENGER_ROTATION_FIRST`` times less again (every Gough robot of ``examples/robots`` at
    home: 22 to 65 % fewer boxes; with length ranges, up to 8 times more: not there).  Heuristics
    only: any scale is sound."""
    scale = hi - lo if independent else np.max(hi - lo, axis=0)     # (each instance's own, or the widest)
    scale = np.where(scale > 0, scale, 1.0)
    p = system.n_pos
    if system.kind == "gough-stewart":
        b = float(np.max(np.sqrt(np.sum(system.b.mid() ** 2, axis=1))))
        exact = ~uncertain(L) & (system.legs == 6)       # the Cayley-Menger rule's instances
        factor = np.where(exact, CAYLEY_MENGER_ROTATION_FIRST, 1.0)[:, None] if independent else \
            CAYLEY_MENGER_ROTATION_FIRST if exact.all() else 1.0
        scale[..., :p] = factor * POSITION_GEOMETRIC * np.sqrt(scale[..., :p] * max(b, 1e-300))
    else:
        scale[..., :p] *= POSITION_SCALE
    if system.kind != "planar-3rpr":
        scale[..., p:] = 2.0
    problem = FKProblem(system, L, scale, slopes=system.kind != "planar-3rpr")
    return search(problem, lo, hi, scale=scale, budget=budget, batch=max(8192, 256 * (1 if independent else len(lo))),
                  progress=progress, initial_splits=INITIAL_SPLITS, record_limit=record_limit, record_sink=record_sink,
                  independent=independent)


def uncertain(L: Interval):
    """Per instance, whether its squared leg lengths ``L`` (M, legs) are ranges, not just the
    enclosure of a decimal: its roots then move with the lengths."""
    return np.any(L.hi - L.lo > 2.0 ** -40 * np.maximum(np.abs(L.hi), 1.0), axis=1)


def newton_reach(C, J: Interval):
    """Per box, the largest row sum of |I − C J| (float arithmetic: a heuristic, no claim rests on it),
    J an interval matrix (N, n, n).  Below 1 the box is within Newton's reach: the Krawczyk operator
    contracts it, and the root's spread over uncertain leg lengths, |C| rad f, says how far its roots
    move.  Far above 1 (beside a nearly singular Jacobian) |C| may be large for want of a root: such
    a box is given up as a cluster only once it is ``GIVE_UP_WIDTH`` narrow, else bisected (seed 002,
    lengths within 1e-4: 39 boxes 0.02 to 0.06 wide (scaled) were given up with reach 2 000 to 2 000 000,
    the other 47 804 cluster leaves are within 0.0005 with reach below 0.7; its 24 postures lay in 11
    unique boxes and 16 clusters up to 1.7 wide, holding up to 4 each; after, in 13 unique boxes and
    13 clusters 0.005 to 0.25 wide, holding at most one each; within 1e-3: one cluster before, 21
    after, all but one holding one posture, and 416 042 boxes instead of 325 080)."""
    with np.errstate(all="ignore"):
        mid, rad = 0.5 * (J.lo + J.hi), 0.5 * (J.hi - J.lo)
        M = np.abs(np.eye(C.shape[-1]) - np.einsum("nij,njk->nik", C, mid)) + np.einsum("nij,njk->nik", np.abs(C), rad)
        reach = np.max(np.sum(M, axis=2), axis=1)
    return np.where(np.isfinite(reach), reach, np.inf)


class _Batch:
    """The working state of one ``FKProblem.decide``: the boxes (contracted in place, one row per
    box), the verdicts and evidence so far, and the contraction stages recorded in the tree."""

    def __init__(self, lo, hi, L: Interval):
        N, n = lo.shape
        self.lo, self.hi, self.L = lo.copy(), hi.copy(), L
        self.status = np.full(N, OPEN, dtype=np.int8)
        self.reason = np.zeros(N, dtype=np.int64)
        self.creason = np.zeros(N, dtype=np.int64)      # the first stage's reason: "hc4" or "position"
        self.cev = {}                                   # and its evidence
        self.evidence = {}
        self.C_rows = np.zeros((N, n, n))               # the Krawczyk matrix of each decided box
        self.C_mask = np.zeros(N, dtype=bool)
        self.star_mask = np.zeros(N, dtype=bool)        # boxes proved in an inflated box X* ⊇ X
        self.stars = np.zeros((N, n, 2))
        self.split = np.full(N, -1)
        self.split_at = np.full(N, np.nan)             # a cut point on ``split`` (a gap of HC4's roots)
        self.hc4_boxes = []                             # the boxes after each HC4 pass (slope systems)
        self.stages = []                                # ((lo, hi), evidence, reasons) of each Krawczyk contraction

    def decisions(self, slopes: bool) -> Decisions:
        N = len(self.lo)
        self.evidence["C"] = (self.C_mask, self.C_rows[self.C_mask].astype(np.float32))
        if self.star_mask.any():
            self.evidence["star"] = (self.star_mask, self.stars[self.star_mask])
        stages = [(self.lo, self.hi)] + [box for box, _, _ in self.stages]
        reasons = [self.creason] + [r for _, _, r in self.stages]
        stage_evidence = [self.cev] + [ev for _, ev, _ in self.stages]
        if slopes:      # "hc4" passes (no evidence), then "position" (P), then the slope steps
            stages[:0] = self.hc4_boxes
            reasons[:0] = [np.full(N, 7)] * len(self.hc4_boxes)
            stage_evidence[:0] = [{}] * len(self.hc4_boxes)
        return Decisions(self.status, self.reason, self.evidence, contracted=stages, contraction_reason=reasons,
                         contraction_evidence=stage_evidence, split=self.split, split_at=self.split_at)


class FKProblem:
    """Decides boxes of FK unknowns for a batch of instances (one root box per instance)."""

    reasons = ("equation", "krawczyk-empty", "krawczyk-unique", "krawczyk", "position-empty", "position",
               "hc4-empty", "hc4", "slope-empty", "slope", "slope-gs-empty", "slope-gs", "cluster",
               "krawczyk-empty, C kept", "krawczyk, C kept", "slope-gs-empty, C kept", "slope-gs, C kept",
               "cm-bernstein-empty", "cm-combination-empty")
    CLUSTER = 12             # given up: within a root's spread over uncertain lengths, no uniqueness box
    CAYLEY_MENGER = 17       # no rotation of the box fits 4 legs (``fk.cayley_menger``)
    COMBINED = 18            # nor a combination of the 15 quads' conditions

    def __init__(self, system, L: Interval, scale, slopes: bool = False):
        self.system = system
        self.slopes = slopes                # exclusion and contraction by the slope form (slope_boxes)
        # working memory of a batch, per box (tracemalloc, batches of 7 000 boxes: 12.4 KB Gough, 2.2 KB planar)
        self.bytes_per_box = 16384 if slopes else 4096
        self.L = L                          # (M, legs) squared leg lengths, one row per instance
        self.uncertain_rows = uncertain(L)     # leg-length ranges: roots move with the lengths
        self.uncertain = bool(self.uncertain_rows.any())
        self.scale = scale                  # (n,), or (M, n): one row per instance
        self._stacked = None
        # the Cayley-Menger forms of the instances with exact lengths, computed when first needed (the
        # oldest dropped past FORMS_KEPT: time, not the answer, depends on it)
        self._forms = {} if system.kind == "gough-stewart" and system.legs == 6 else None

    def _system(self, n_box):
        if n_box > SMALL_BATCH:
            return self.system
        if self._stacked is None:
            self._stacked = for_batch(self.system, 0)
        return self._stacked

    def _scales(self, roots):
        """The scale of the unknowns of boxes of ``roots``: (n,), or one row per box."""
        return self.scale[roots] if self.scale.ndim == 2 else self.scale

    def _L(self, roots):
        return Interval.from_bounds(self.L.lo[roots], self.L.hi[roots])

    def decide(self, lo, hi, roots) -> Decisions:
        """Steps 0-4 of the module docstring on a batch of boxes, each on the boxes the steps before
        left open; every contraction is a stage of the tree with its reason and evidence."""
        system = self._system(len(lo))
        b = _Batch(lo, hi, self._L(roots))
        if self._forms is not None:
            self._cayley_menger(b, roots)
        kept, hc4_moved = self._hc4(system, b, roots)
        # steps 1 and 2 evaluate only the boxes HC4 left (``live``): the others are decided
        live = np.nonzero(b.status == OPEN)[0]
        Xl, Ll = Interval.from_bounds(b.lo[live], b.hi[live]), Interval.from_bounds(b.L.lo[live], b.L.hi[live])
        rb, rbl, parts = self._rotated(system, b, live, Xl, kept)
        pempty = P = None
        if system.n_pos:
            pempty, P = self._position(system, b, live, Xl, Ll, rbl, hc4_moved)
        self._equations(system, b, live, Ll, rbl, pempty, P)
        self._krawczyk(system, b, live, rb, parts, roots)
        self._gaps(system, b)
        return b.decisions(self.slopes)

    def _cayley_menger(self, b: _Batch, roots):
        """Step 0 for a 6-6 Gough-Stewart robot: the boxes whose rotation fits no four legs
        (``fk.cayley_menger``) are excluded, with the evidence 4·quad + chart.  Instances with length
        ranges are left to the other steps (the rule holds for them, but seldom concludes)."""
        from . import cayley_menger         # (machine code: numba is imported by spatial searches only)
        p = self.system.n_pos
        found = np.full(len(b.lo), -1, np.int64)
        weights = np.zeros((len(b.lo), 15), np.float32)
        open_ = b.status == OPEN
        for r in np.unique(roots):
            if self.uncertain_rows[r]:
                continue
            if r not in self._forms:          # the forms of at most FORMS_KEPT instances (40 KB each)
                if len(self._forms) >= FORMS_KEPT:
                    self._forms.pop(next(iter(self._forms)))
                self._forms[r] = cayley_menger.forms(self.system.a, self.system.b,
                                                      Interval.from_bounds(self.L.lo[r], self.L.hi[r]))
            sel = np.nonzero((roots == r) & open_)[0]
            w = np.zeros((len(sel), 15), np.float32)
            found[sel] = cayley_menger.excluded(*cayley_menger.charts(*self._forms[r]), np.ascontiguousarray(b.lo[sel, p:p + 4]),
                                                np.ascontiguousarray(b.hi[sel, p:p + 4]), QUAD_ORDER, w)
            weights[sel] = w
        one, combined = (found >= 0) & (found < 60), found >= 60
        b.status[one | combined] = EXCLUDED
        b.reason[one], b.reason[combined] = self.CAYLEY_MENGER, self.COMBINED
        b.evidence["cm"] = (one | combined, np.where(combined, found - 60, found)[one | combined].astype(np.int8))
        b.evidence["weights"] = (combined, weights[combined])

    def _gaps(self, system, b: _Batch):
        """Open boxes split in the widest gap of HC4's two-branch square roots (``contract.gap_splits``)."""
        open_ = np.nonzero(b.status == OPEN)[0]
        if len(open_):
            lo, hi = b.stages[-1][0] if b.stages else (b.lo, b.hi)
            dim, at = gap_splits(system, lo[open_], hi[open_], Interval.from_bounds(b.L.lo[open_], b.L.hi[open_]), GAP)
            use = dim >= 0
            b.split[open_[use]], b.split_at[open_[use]] = dim[use], at[use]

    def _hc4(self, system, b: _Batch, roots):
        """Step 0: forward-backward (HC4) passes over every equation (``fk.contract``): boxes a pass
        empties are excluded, boxes it shrinks enough are replaced by the contraction, widened
        so that an independent re-computation still fits.  Slope systems: a box the pass shrank by
        ``HC4_AGAIN`` or more gets another pass on the contracted box (up to ``HC4_PASSES``), each
        pass its own "hc4" stage of the tree; not where the Cayley-Menger rule applies (it excludes
        more of the boxes a second pass would shrink: Dietmaier 7 % less time, seed 002 2.5 %).
        Returns (the centred form of R b_i each box's last pass computed, quaternion, or None; the
        rotation sides (lo, hi) it was computed over; the mask of the boxes the passes moved)."""
        lo, hi = b.lo, b.hi
        p = system.n_pos
        form = over = None
        rows = np.nonzero(b.status == OPEN)[0]
        moved = np.zeros(len(lo), dtype=bool)
        once = ~self.uncertain_rows[roots] if self._forms is not None else np.zeros(len(lo), dtype=bool)
        for k in range(HC4_PASSES if self.slopes else 1):
            if not len(rows):
                break
            L = Interval.from_bounds(b.L.lo[rows], b.L.hi[rows])
            plo, phi = lo[rows], hi[rows]
            kept = {}
            hlo, hhi, hempty = hc4(system, plo, phi, L, keep=kept)
            if "form" in kept:      # the form over the pass's given box: depends on its rotation sides only
                if form is None:    # (full-length arrays: the first pass may see only some boxes)
                    form = [np.zeros((len(lo),) + w.shape[1:], dtype=w.dtype) for w in kept["form"]]
                    for v, w in zip(form, kept["form"]):
                        v[rows] = w
                    over = (lo[:, p:].copy(), hi[:, p:].copy())
                else:
                    for v, w in zip(form, kept["form"]):
                        v[rows] = w
                    over[0][rows], over[1][rows] = plo[:, p:], phi[:, p:]
            b.status[rows[hempty]], b.reason[rows[hempty]] = EXCLUDED, 6
            w = room(plo, phi, self._unit(system))       # room for an independent re-computation
            hlo, hhi = np.maximum(plo, hlo - w), np.minimum(phi, hhi + w)
            cut = shrink(plo, phi, hlo, hhi)
            step = ~hempty & (cut >= SHRINK)
            lo[rows[step]], hi[rows[step]] = hlo[step], hhi[step]
            moved[rows[step]] = True
            if self.slopes:
                b.hc4_boxes.append((lo.copy(), hi.copy()))
            rows = rows[step & (cut >= HC4_AGAIN) & ~once[rows]]
        b.creason[moved] = 7
        return (form, over), moved

    def _rotated(self, system, b: _Batch, live, Xl, kept):
        """R b_i over the boxes HC4 left, final for this batch (the rotation moves no more): for a
        quaternion the natural enclosure ∩ the centred one (the centred form an HC4 pass computed
        over the same rotation sides is the same floats; it is computed again for the others), with
        its parts at the midpoints for the slope step.
        Returns (R b_i for every box (zero rows where decided), R b_i of ``live``, the parts or None)."""
        N = len(b.lo)
        parts = None
        if self.slopes:
            form, over = kept
            if form is not None:
                p = system.n_pos
                form = tuple(v[live] for v in form)
                again = np.any((over[0][live] != Xl.lo[:, p:]) | (over[1][live] != Xl.hi[:, p:]), axis=1)
                if again.any():
                    for v, w in zip(form, system.centred_form(Interval.from_bounds(Xl.lo[again], Xl.hi[again]))):
                        v[again] = w
            rbl, rbcl, drbl = system.rotated_centred(Xl, parts=True, form=form)
            parts = (rbcl, drbl)
        else:
            rbl = system.rotated(system.rotation(Xl))
        rb = Interval.from_bounds(np.zeros((N,) + rbl.shape[1:]), np.zeros((N,) + rbl.shape[1:]))
        rb.lo[live], rb.hi[live] = rbl.lo, rbl.hi
        return rb, rbl, parts

    def _position(self, system, b: _Batch, live, Xl, Ll, rbl, hc4_moved):
        """Step 1: the position is linear given the rotation: a Gauss-Seidel contraction
        (``step.contract_position``).  After HC4 it is one "hc4" contraction with the evidence P;
        for spatial robots its own "position" contraction after the "hc4" one.  Returns (the boxes
        it proved empty, P for every box)."""
        lo, hi, status = b.lo, b.hi, b.status
        N = len(lo)
        pl, ph, pe, Pl = contract_position(system, Xl, Ll, rb=rbl)
        plo, phi, pempty, P = lo.copy(), hi.copy(), np.zeros(N, dtype=bool), np.zeros((N,) + Pl.shape[1:])
        plo[live], phi[live], pempty[live], P[live] = pl, ph, pe, Pl
        pempty &= status == OPEN
        status[pempty] = EXCLUDED
        b.reason[pempty] = 4
        moved = ~pempty & (shrink(lo, hi, plo, phi) >= SHRINK) & (status == OPEN)
        lo[moved], hi[moved] = plo[moved], phi[moved]
        b.creason[moved & ~hc4_moved] = 5
        if self.slopes:
            b.creason[moved] = 5
        b.cev["P"] = (moved, P[moved].astype(np.float32))
        return pempty, P

    def _equations(self, system, b: _Batch, live, Ll, rbl, pempty, P):
        """Step 2: a box where the enclosure of one equation misses 0 holds no solution."""
        N, n = b.lo.shape
        if self.slopes:     # a quaternion: the machine-code twin (the same floats)
            from .centred import equations_quaternion      # numba: imported by the spatial searches only
            f64 = np.ascontiguousarray
            Fl = Interval.from_bounds(*equations_quaternion(
                f64(b.lo[live]), f64(b.hi[live]), f64(rbl.lo), f64(rbl.hi), system.a.lo, system.a.hi,
                f64(Ll.lo, dtype=np.float64), f64(Ll.hi, dtype=np.float64), system.n_pos))
        else:
            Fl = system.equations(Interval.from_bounds(b.lo[live], b.hi[live]), Ll, rb=rbl)
        out = np.zeros((N, n), dtype=bool)
        out[live] = (Fl.lo > 0) | (Fl.hi < 0)
        excluded = out.any(axis=1) & (b.status == OPEN)
        b.status[excluded] = EXCLUDED
        b.reason[excluded] = 0
        b.evidence["equation"] = (excluded, np.argmax(out[excluded], axis=1).astype(np.int8))
        if system.n_pos and pempty.any():
            b.evidence["P"] = (pempty, P[pempty].astype(np.float32))

    def _krawczyk(self, system, b: _Batch, live, rb, parts, roots):
        """Steps 3 and 4 on the open boxes narrow enough in the rotation (on boxes still wide there it
        never succeeds: those are bisected): empty, unique, or a contraction; then more rounds on
        the boxes it shrank a lot, and ε-inflation on small boxes still open."""
        lo, hi = b.lo, b.hi
        rest = np.nonzero(b.status == OPEN)[0]
        pn = system.n_pos
        wide = np.max((hi[rest, pn:] - lo[rest, pn:]) / self._scales(roots[rest])[..., pn:], axis=1) > KRAWCZYK_BELOW
        rest = rest[~wide]
        sc = self._scales(roots[rest])
        lo2, hi2 = lo.copy(), hi.copy()
        if not len(rest):
            b.stages.append(((lo2, hi2), {}, self._stage_reasons(len(lo))))
            return
        rlo, rhi = lo[rest], hi[rest]
        X = Interval.from_bounds(rlo, rhi)
        Lr = Interval.from_bounds(b.L.lo[rest], b.L.hi[rest])
        if self.slopes:
            rbcl, drbl = parts
            at = np.searchsorted(live, rest)    # R b_i at the midpoints, derivatives: the rotation is unchanged
            K, C, J, empty = slope_boxes(system, X, Lr, rb=rb[rest], compact=True, rbc=rbcl[at],
                                         drbs=(drbl[0][at], drbl[1][at]))
        else:
            K, C, J = krawczyk_boxes(system, X, Lr, with_jacobian=True, rb=rb[rest], compact=True)
            empty = None
            b.split[rest] = self._planar_split(system, J, rlo, rhi, sc)
        done, keep, nlo, nhi, kept = self._round(system, b, rest, X, Lr, K, C, empty, J)
        k = rest[keep]
        lo2[k], hi2[k] = nlo[keep], nhi[keep]
        kmask = np.zeros(len(lo), dtype=bool)
        kmask[k] = True
        b.stages.append(((lo2, hi2), {"C": (kmask, C[keep].astype(np.float32))},
                         self._stage_reasons(len(lo), k[kept[keep]])))
        self._again(system, b, k[shrink(rlo[keep], rhi[keep], nlo[keep], nhi[keep]) >= AGAIN], lo2, hi2, roots)
        flo, fhi = b.stages[-1][0][0][rest], b.stages[-1][0][1][rest]   # after the last Krawczyk round
        width = np.max((fhi - flo) / sc, axis=1)
        # small boxes still open, contracted or not (a box HC4 made a sliver around a root is proved
        # only by inflation: K of a sliver rarely fits inside it), inflated from their last contraction
        # (from the box before it, a root next to a singular one was left a cluster at the resolution)
        small = ~done & (width < INFLATE_BELOW) & (b.status[rest] == OPEN)
        within = np.zeros(len(rest), dtype=bool)
        if self.uncertain:   # a box about as narrow as the root's spread over the lengths: inflate now
            radL = np.zeros(rlo.shape)
            radL[:, :system.legs] = 0.5 * (Lr.hi - Lr.lo)
            within = np.all(rhi - rlo <= SPREAD_INFLATE * np.einsum("nij,nj->ni", np.abs(C), radL), axis=1)
            within &= (newton_reach(C, J) < 1.0) | (np.max((rhi - rlo) / sc, axis=1) <= GIVE_UP_WIDTH)
            within &= self.uncertain_rows[roots[rest]]
            small |= ~done & ~keep & within
        if small.any():      # small open boxes: ε-inflation around a Newton iterate
            sm = rest[small]
            proved, slo, shi, Cs = self._inflate(flo[small], fhi[small], roots[sm], (rlo[small], rhi[small]))
            b.status[sm[proved]], b.reason[sm[proved]] = PROVED, 2
            given_up = (within & ~keep)[small] & ~proved   # no box holding the root's spread is proved unique:
            b.status[sm[given_up]], b.reason[sm[given_up]] = UNDECIDED, self.CLUSTER   # a cluster
            b.star_mask[sm[proved]] = True
            b.stars[sm[proved]] = np.stack([slo[proved], shi[proved]], axis=-1)
            b.C_rows[sm[proved]] = Cs[proved]
            b.C_mask[sm[proved]] = True

    def _planar_split(self, system, J, rlo, rhi, sc):
        """Planar: bisect where the equations vary most, the largest sum_i |J_ij| w_j ("smear",
        Kearfott 1996), among the rotation unknowns (HC4 and Gauss-Seidel then narrow the position)
        unless the position is much wider (scaled) than the rotation.  (Spatial robots take the
        widest scaled side, the engine's choice: fewer boxes than the smear there.)"""
        smear = np.sum(J.mag(), axis=1) * (rhi - rlo)
        smear = np.where(np.isfinite(smear), smear, np.inf)
        pn = system.n_pos
        if pn:
            scaled = (rhi - rlo) / sc
            rot_first = np.max(scaled[:, :pn], axis=1) <= ROTATION_FIRST * np.max(scaled[:, pn:], axis=1)
            smear[:, :pn] = np.where(rot_first[:, None], -1.0, smear[:, :pn])
        return np.argmax(smear, axis=1)

    def _stage_reasons(self, N, stored=()):
        """The reasons of a Krawczyk (slope) contraction stage of N boxes: those ``stored`` keep their C
        in the certificate (``step.fragile``), the others' the checker rebuilds."""
        reasons = np.full(N, 11 if self.slopes else 3)
        reasons[stored] = 16 if self.slopes else 14
        return reasons

    @staticmethod
    def _unit(system):
        """Per unknown, the scale of its rounding (``step.room``): 0 for the position, 1 for the rotation."""
        return (np.arange(system.n) >= system.n_pos).astype(float)

    def _round(self, system, b: _Batch, rows, X: Interval, L: Interval, K: Interval, C, empty, M):
        """The verdicts of one Krawczyk (or slope) image K on the boxes X, rows ``rows`` of the batch:
        empty (``empty``, or K ∩ X = ∅ when None), unique (K(X) ⊂ int X; for a slope image the
        Krawczyk test proper with the Jacobian decides), and the contraction K(X) ∩ X widened and
        kept inside X.  An empty box whose C is ``step.fragile`` (for M, the matrix C inverts) is
        excluded for a reason that keeps its C in the certificate.  Returns (decided, contraction
        kept, its lo, its hi, C fragile), per row."""
        if empty is None:
            finite = np.all(np.isfinite(K.lo) & np.isfinite(K.hi), axis=1)
            empty = np.any((K.hi < X.lo) | (K.lo > X.hi), axis=1) & finite
        unique = unique_in(K, X.lo, X.hi) & ~empty
        if self.slopes:     # a slope image inside X: the Krawczyk test proper (with the Jacobian) decides
            unique = self._unique(system, X.lo, X.hi, L, C, unique)
        b.status[rows[empty]], b.reason[rows[empty]] = EXCLUDED, 10 if self.slopes else 1
        kept = fragile(C, M) if (empty.any() or not unique.all()) else np.zeros(len(rows), dtype=bool)
        b.reason[rows[empty & kept]] = 15 if self.slopes else 13
        b.status[rows[unique]], b.reason[rows[unique]] = PROVED, 2
        done = empty | unique
        b.C_rows[rows[done]] = C[done]
        b.C_mask[rows[done]] = True
        w = room(X.lo, X.hi, self._unit(system))
        nlo = np.maximum(X.lo, np.where(np.isfinite(K.lo), K.lo - w, -np.inf))
        nhi = np.minimum(X.hi, np.where(np.isfinite(K.hi), K.hi + w, np.inf))
        keep = ~done & np.all(nlo <= nhi, axis=1) & (shrink(X.lo, X.hi, nlo, nhi) >= SHRINK)
        return done, keep, nlo, nhi, kept

    def _again(self, system, b: _Batch, strong, lo, hi, roots):
        """Boxes that Krawczyk shrank by ``AGAIN`` or more (near a root: quadratic convergence) get up
        to ``AGAIN_STEPS`` more rounds, each on the box the round before contracted: empty, unique,
        or a further contraction (when they are many, or most of the open boxes: an evaluation
        costs about as much for a few boxes as for a hundred, a round of bisection much more).
        Counted per root (instance), so that an instance's boxes are decided as if it were alone."""
        _, inst = np.unique(roots, return_inverse=True)
        m = int(inst.max()) + 1 if len(inst) else 0
        for _ in range(AGAIN_STEPS):
            many = np.bincount(inst[strong], minlength=m)
            still = np.bincount(inst[b.status == OPEN], minlength=m)
            strong = strong[((many >= AGAIN_MIN) | (AGAIN_SHARE * many >= still))[inst[strong]]]
            if not len(strong):
                break
            X = Interval.from_bounds(lo[strong], hi[strong])
            L = Interval.from_bounds(b.L.lo[strong], b.L.hi[strong])
            if self.slopes:     # ell(X) from the centred R b_i (its parts at c serve the slope too)
                rb, rbc, drb = system.rotated_centred(X, parts=True)
                K, C, M, empty = slope_boxes(system, X, L, rb=rb, compact=True, rbc=rbc, drbs=drb)
            else:
                K, C, M = krawczyk_boxes(system, X, L, compact=True, with_jacobian=True)
                empty = None
            _, keep, nlo, nhi, kept = self._round(system, b, strong, X, L, K, C, empty, M)
            lo, hi = lo.copy(), hi.copy()
            lo[strong[keep]], hi[strong[keep]] = nlo[keep], nhi[keep]
            kmask = np.zeros(len(lo), dtype=bool)
            kmask[strong[keep]] = True
            b.stages.append(((lo, hi), {"C": (kmask, C[keep].astype(np.float32))},
                             self._stage_reasons(len(lo), strong[keep][kept[keep]])))
            strong = strong[keep][shrink(X.lo[keep], X.hi[keep], nlo[keep], nhi[keep]) >= AGAIN]

    def _unique(self, system, lo, hi, L: Interval, C, candidates):
        """The candidates (slope image inside X) for which K(X) ⊂ int X with the Jacobian and the
        same C: exactly one root in X (the test of ``krawczyk_boxes``)."""
        out = np.zeros(len(lo), dtype=bool)
        k = np.nonzero(candidates)[0]
        if len(k):
            K, _ = krawczyk_boxes(for_batch(system, len(k)), Interval.from_bounds(lo[k], hi[k]),
                                  Interval.from_bounds(L.lo[k], L.hi[k]), C=C[k])
            out[k] = unique_in(K, lo[k], hi[k])
        return out

    def _inflate(self, lo, hi, roots, within=None):
        """Try X* = Newton iterate ± r (⊇ X); returns (proved mask, X* lo, X* hi, C).  With uncertain
        leg lengths r covers the root's spread |C| rad L (3 times, else 2 times): X* then holds the
        root for every length vector, and the root box of any other leaf of the same root.  An iterate
        outside ``within`` (the box before X's contraction: a root of X lies in it) is not trusted: X*
        would reach a root of another box: X* is then centred on X's midpoint if the iterate lies
        within one width of ``within`` (a root on its face), else not tried (Newton left X: in the
        tubes around nearly singular postures, nearly every box: the rows whose first step leaves it so
        take no more steps).  Not so with uncertain lengths: the iterate (the root for the middle
        lengths) may then lie outside X's box, within the root's spread."""
        system = self._system(len(lo))
        L, sc, unc = self._L(roots), self._scales(roots), self.uncertain_rows[roots]
        x, L2 = 0.5 * (lo + hi), 0.5 * (L.lo + L.hi)
        tried = np.ones(len(lo), dtype=bool)
        if within is not None:              # an iterate next to it (a root on its face): from the midpoint
            near = (within[0] - (within[1] - within[0]), within[1] + (within[1] - within[0]))
        with np.errstate(all="ignore"):   # near a singular root Newton may run away: a guess only
            C, _ = linalg.float_inverse(system.float_system(x, L2)[1])
            for _ in range(3):  # float Newton steps (a guess only: the proof is the Krawczyk test below)
                k = np.nonzero(tried)[0]
                x[k] = x[k] - np.einsum("nij,nj->ni", C[k], system.float_system(x[k], L2[k])[0])
                lost = ~np.all(np.isfinite(x), axis=1) | np.any(np.abs(x - 0.5 * (lo + hi)) > 1e3 * (hi - lo + sc), axis=1)
                if within is not None:
                    tried &= unc | ~lost & ~np.any((x < near[0]) | (x > near[1]), axis=1)
            if within is not None:
                lost |= ~unc & np.any((x < within[0]) | (x > within[1]), axis=1)
            x[lost] = 0.5 * (lo[lost] + hi[lost])
        radL = np.zeros(lo.shape)   # how far the lengths' ranges move the root
        radL[:, :system.legs] = 0.5 * (L.hi - L.lo)
        spread = np.einsum("nij,nj->ni", np.abs(C), radL)
        base = np.maximum(np.abs(x - 0.5 * (lo + hi)), hi - lo) + 1e-12 * sc
        N, n = lo.shape
        best = [np.zeros(N, dtype=bool), lo.copy(), hi.copy(), np.zeros((N, n, n))]
        # exact lengths: r = base; uncertain: 3 times the spread, then 2 times where that failed
        for factor, rows in ((0.0, ~unc), (3.0, unc), (2.0, unc)):
            rows = np.nonzero(rows & tried & ~best[0])[0]
            if not len(rows):
                continue
            r = np.maximum(base[rows], factor * spread[rows])
            slo, shi = np.minimum(lo[rows], x[rows] - r), np.maximum(hi[rows], x[rows] + r)
            with np.errstate(all="ignore"):    # a non-finite image proves nothing: the test fails
                K, Cs = krawczyk_boxes(self._system(len(rows)), Interval.from_bounds(slo, shi),
                                       Interval.from_bounds(L.lo[rows], L.hi[rows]), compact=True)
                ok = unique_in(K, slo, shi)
            use = rows[ok]
            best[0][use], best[1][use], best[2][use], best[3][use] = True, slo[ok], shi[ok], Cs[ok]
        return tuple(best)
