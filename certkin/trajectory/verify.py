"""Certified trajectory feasibility (seed 000 ch. 1, with the digest's corrections).

A path (``trajectory.path``) is a polyline of poses; on segment k the pose is
P_k + t (P_{k+1} − P_k), t ∈ [0, 1], and the global parameter is s = k + t.

The shared engine bisects t; each t-interval is decided by
``trajectory.constraints.Constraints`` (every constraint instance proved
satisfied, proved violated over the whole interval, or unknown).  Boxes are
split while some instance is unknown (down to ``min_width``) or while a
satisfied instance could still lower its certified minimum margin by more
than the tolerance.  Verdicts:

- ``feasible``: every instance is proved satisfied on every leaf and det(A)
  has one proved sign along the whole path; margins are certified enclosures
  of the minimum over the path;
- ``infeasible``: an instance is proved violated on some leaf, or det(A) has
  proved opposite signs at two instants (so it vanishes between them);
  ``violations`` lists, per instance, t-intervals whose union contains every
  instant where it may fail;
- ``undecided``: neither could be proved within the budget (the t-ranges left
  are listed).

A segment whose pose does not move (start = goal, or repeated waypoints) is not bisected past its
first evaluation: every sub-interval has the same pose, so an unknown constraint there stays unknown
(an undecided leaf, nothing claimed) instead of spending the box budget.
"""
from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

import numpy as np

from intervals import Interval
from intervals.rounding import down, sum_bounds, up

from ..engine import EXCLUDED, OPEN, PROVED, UNDECIDED, Budget, Decisions, budgets, interrupt, search
from ..engine.budgets import Clock, make_budget, positive_number, progress_callback
from ..display import counted, size_bound
from ..errors import InputError, shown
from ..quiet import quiet
from ..robots import as_robot
from ..robots.poses import unmasked
from .constraints import Constraints, piece_plan
from .crossings import crossing_points
from .families.base import SATISFIED, UNKNOWN, VIOLATED
from .path import Path, angle_step, parse_path
from .result import TrajectoryResult, conclude

FIRST_BATCH = 256    # constant orientation: about this many initial sub-intervals in all (2 to 16 per segment)
MARGIN_RTOL = 1e-4   # relative tolerance of the certified minimum margins
SEARCH_SHARE = 0.4   # of max_memory, for the search's records: the leaves' states and the result take about
                     # as much again after it (a path singular everywhere: 2.05 times the records at the peak)
INDEX_STEPS = 64     # sub-intervals per segment for the mean indices
INDEX_SEGMENTS = 8   # segments evaluated at once for them
PIECE_BATCH = 256    # boxes decided at once with a moving orientation (each holds its polynomials' products; about
                     # 0.3 s a batch for the MEL robot: a Ctrl-C, checked between batches, stops the search that soon)
PIECE_BYTES = 8 * 2 ** 10    # held per piece and constraint with a moving orientation, at most (the MEL robot,
                             # 22 constraints, 301 segments of 8 pieces: 0.45 GiB at the peak, 6.7 KiB each)
SEED_POINTS = 128    # instants evaluated at once by ``seed_best`` (the clock is read between them)
SEED_SHARE = 0.25    # of the time left, at most, for ``seed_best``: once all of it, and the search's first batch
                     # came on top (3000 segments, max_seconds=5: 6.3 s)
PIECE_SECONDS = 130e-6       # to build the polynomials of a piece and constraint before the search starts (the
                             # MEL robot: 121 segments of 16 pieces, 22 constraints, 5.5 s; 421 segments, 30 s)
LINEAR_SECONDS = 50e-6       # per segment and constraint with a constant orientation: its polynomials, first cuts,
                             # estimates and first evaluation, none of them stopped by the clock (the MEL robot, 22
                             # constraints: 3000 segments, 4.0 s; 20 000 segments, 18.6 s, once for max_seconds=1)
PATH_SECONDS = 250e-6        # per path and constraint: to conclude a path's answer from its leaves after the search
                             # (measured: the MEL robot, 22 constraints, 5 ms a path; the planar planning robot, 4, 1 ms)


class TrajectoryProblem:
    """Decides t-intervals of many segments at once (roots = pieces of segments)."""

    reasons = ("every constraint decided on the interval",
               "the pose is the same at every instant of the segment: splitting t decides nothing more")

    def __init__(self, constraints: Constraints, P0, D, piece_segment, segment_path, n_paths, rtol=MARGIN_RTOL,
                 min_width=1e-9, linear=False, clock=None):
        """``clock``: with a moving orientation, the polynomials are built while it has time left;
        ``complete`` is false when it ran out first (the problem must then not be searched)."""
        self.c = constraints
        self.P0, self.D = P0, D
        self.still = np.all((D.lo == 0) & (D.hi == 0), axis=1)     # segments whose pose does not move
        self.piece_segment = piece_segment
        self.segment_path = segment_path
        self.best = np.full((n_paths, constraints.K), np.inf)
        self.refine_cols = constraints.refinable()
        self.rtol = rtol
        self.linear = constraints.linear_data(P0, D) if linear is False else linear
        self.pieces = self.linear is None           # moving orientation: one expansion per piece
        self.n_pieces, degree = piece_plan(angle_step(constraints.robot, D)) if self.pieces else (1, None)
        if not self.pieces:
            self.polys = constraints.polynomials(self.linear, P0)
        else:
            S, n = P0.shape[0], self.n_pieces
            seg = np.repeat(np.arange(S), n)
            k = np.tile(np.arange(n), S)
            self.polys = constraints.piece_polynomials(P0[seg], D[seg], k / n, np.full(len(k), 1.0 / n), degree,
                                                       stop=clock and clock.out)
        self.complete = self.polys is None or self.polys["pose"].legs[0].shape[0] == P0.shape[0] * self.n_pieces
        self.crossings = None if self.polys is None else constraints.crossing_polynomials(self.polys)
        self.delta = 0.25 * min_width       # cuts at t* ± delta leave [t* − delta, t* + delta] as the last piece

    def _local(self, tlo, thi, segment):
        """Rows of the polynomials and the local parameter: (rows, τlo, τhi, a, h) with t = a + h τ
        (per segment: τ = t; per piece k of width 1/n: τ = (t − k/n)·n, enclosed)."""
        tlo, thi = np.asarray(tlo, dtype=np.float64), np.asarray(thi, dtype=np.float64)
        if not self.pieces:
            return segment, tlo, thi, np.zeros_like(tlo), np.ones_like(tlo)
        n = self.n_pieces
        k = np.clip(np.floor(0.5 * (tlo + thi) * n), 0, n - 1)
        a = k / n
        if np.any(tlo < a) or np.any(thi > a + 1.0 / n):
            raise ValueError("a t-interval straddles two pieces")
        taulo = np.maximum(down((tlo - a) * n), 0.0)
        tauhi = np.minimum(up((thi - a) * n), 1.0)
        return segment * n + k.astype(np.int64), taulo, tauhi, a, np.full_like(a, 1.0 / n)

    def evaluate(self, tlo, thi, segment, upper=True):
        P0, D = self.P0[segment], self.D[segment]
        if self.polys is not None:
            rows, taulo, tauhi, _, _ = self._local(tlo, thi, segment)
            return self.c.evaluate(P0, D, taulo, tauhi, polys=self.polys, rows=rows, upper=upper)
        return self.c.evaluate(P0, D, tlo, thi, self.c.rows_of(self.linear, segment), upper=upper)

    def decide(self, lo, hi, roots):
        seg = self.piece_segment[roots]
        state, mlo, mhi = self.evaluate(lo[:, 0], hi[:, 0], seg, upper=self.rtol is not None)
        path = self.segment_path[seg]
        # every evaluated interval's upper bound (whatever its state) bounds the minimum over the path
        np.fmin.at(self.best, path, mhi)
        best = self.best[path]
        if self.rtol is None:                  # feasibility only: no margin refinement
            refine = np.zeros_like(state, dtype=bool)
        else:
            with np.errstate(invalid="ignore"):
                refine = (state == SATISFIED) & self.refine_cols & (mlo < best - (self.rtol * np.abs(best) + 1e-12))
        still = self.still[seg]          # (a still segment's states are those of every sub-interval)
        unknown = (state == UNKNOWN).any(axis=1)
        status = np.where((unknown | refine.any(axis=1)) & ~still, OPEN,
                          np.where(unknown, UNDECIDED, np.where((state == VIOLATED).any(axis=1), EXCLUDED, PROVED)))
        return Decisions(status=status.astype(np.int8), reason=(unknown & still).astype(np.int64),
                         evidence={"state": state, "mlo": mlo, "mhi": mhi}, split_at=self._cuts(lo, hi, seg, state, refine),
                         keep_narrow_evidence=True)

    def _estimates(self, lo, hi, seg, cols, cands, reach=0.0):
        """Float crossing estimates t (segment's t) and half-widths d = max(δ, 2·error) of the
        candidate polynomials ``cands`` of column ``cols[i]`` on box i (``crossing_points``),
        looked for ``reach`` beyond each box; (items, len(cands)) arrays, NaN where none."""
        coefficients, radii = self.crossings
        rows, ta, tb, base, h = self._local(lo, hi, seg)
        k, w = len(cands), coefficients.shape[-1]
        pick = (rows[:, None], np.asarray(cols)[:, None], np.asarray(cands)[None, :])
        r = reach / h
        t, err = crossing_points(coefficients[pick].reshape(-1, w), np.repeat(ta - r, k), np.repeat(tb + r, k),
                                 radii=radii[pick].reshape(-1, w))
        t = base[:, None] + h[:, None] * t.reshape(-1, k)
        d = np.maximum(self.delta, 2.0 * h[:, None] * np.nan_to_num(err.reshape(-1, k)))
        return t, d

    def presplit(self, lo, hi, seg):
        """Initial pieces cut again at t* ± d around every estimated crossing of a column inside
        them (as ``_cuts`` would after a first evaluation), so that most pieces are decided in
        the first round.  Returns the new (lo, hi, segment of each piece); they tile the old ones."""
        if self.crossings is None:
            return lo, hi, seg
        K = self.crossings[0].shape[1]
        B = len(lo)
        t, d = self._estimates(np.repeat(lo[:, 0], K), np.repeat(hi[:, 0], K), np.repeat(seg, K),
                               np.tile(np.arange(K), B), [0, 1])
        t, d = t.reshape(B, 2 * K), d.reshape(B, 2 * K)
        a, b = lo[:, :1], hi[:, :1]
        cuts = np.concatenate([t - d, t + d], axis=1)
        cuts = np.where((cuts - a >= 1.5 * self.delta) & (b - cuts >= 1.5 * self.delta), cuts, np.nan)
        if np.all(np.isnan(cuts)):
            return lo, hi, seg
        points = np.sort(np.concatenate([a, cuts, b], axis=1), axis=1)        # NaN last
        pieces = np.isfinite(points[:, 1:]) & (points[:, 1:] > points[:, :-1])
        box, k = np.nonzero(pieces)
        return points[box, k][:, None], points[box, k + 1][:, None], seg[box]

    def seed_best(self, lo, hi, seg, clock=None):
        """Start each path's refinement target ``best`` from point evaluations: at the ends of the
        segments and at the estimated minima of the margins inside the pieces (``crossing_polynomials``:
        stationary points of ρ² and E/Δ).  The upper bound of a margin at any instant bounds its
        minimum over the path, so ``best`` stays an upper bound; the intervals far from the minimum
        are then settled at once instead of after the minimum's interval has been narrowed.  The points
        are evaluated ``SEED_POINTS`` at a time while ``clock`` (if any) has time left."""
        if self.rtol is None:
            return
        segments = np.unique(seg)
        t, s = [np.zeros(len(segments)), np.ones(len(segments))], [segments, segments]
        if self.crossings is not None:
            K, B = self.c.K, len(lo)
            est, _ = self._estimates(np.repeat(lo[:, 0], K), np.repeat(hi[:, 0], K), np.repeat(seg, K),
                                     np.tile(np.arange(K), B), [2])
            est, where = est.reshape(-1), np.repeat(seg, K)
            found = np.isfinite(est)
            t.append(est[found])
            s.append(where[found])
        points = np.unique(np.stack([np.concatenate(s).astype(np.float64), np.concatenate(t)], axis=1), axis=0)
        for k in range(0, len(points), SEED_POINTS):
            if clock is not None and clock.out():
                break
            S, T = points[k:k + SEED_POINTS, 0].astype(np.int64), points[k:k + SEED_POINTS, 1]
            _, _, mhi = self.evaluate(T, T, S, upper=True)
            np.fmin.at(self.best, self.segment_path[S], mhi)

    def _cuts(self, lo, hi, seg, state, refine):
        """Per box, a cut near an estimated crossing of an unknown column, or else around an
        estimated extremum of a margin being refined (``Constraints.crossing_polynomials``).
        A crossing is looked for slightly beyond the box too, and the piece kept around it is
        wider than the estimate's error, so that the rest of the box is clear of it."""
        if self.crossings is None:
            return None
        out = np.full(len(lo), np.inf)
        for mask, cands, eps in ((refine & ~(state == UNKNOWN).any(axis=1)[:, None], [2], 2.0 ** -10),
                                 (state == UNKNOWN, [0, 1], 0.0)):
            box, col = np.nonzero(mask)
            if not len(box):
                continue
            a, b = lo[box, 0], hi[box, 0]
            t, d = self._estimates(a, b, seg[box], col, cands, reach=4.0 * self.delta)
            first = np.argmin(np.where(np.isnan(t), np.inf, t), axis=1)
            pick = np.arange(len(box))
            t = t[pick, first]
            d = np.maximum(d[pick, first], eps * (b - a))
            cut = np.where(t - d > a + 1.5 * self.delta, t - d, t + d)
            useful = (cut - a >= 1.5 * self.delta) & (b - cut >= 1.5 * self.delta)   # not a crossing at an end
            np.minimum.at(out, box, np.where(np.isnan(t) | ~useful, np.inf, cut))
        return np.where(np.isfinite(out), out, np.nan)


@quiet
def verify_trajectories(robot, paths, constraints=None, budget: Budget | None = None, progress=None,
                        indices: bool = True, rtol: float = MARGIN_RTOL, *, max_boxes=None, max_seconds=None,
                        min_width=None, max_memory=None, refuse_slow: bool = True) -> list[TrajectoryResult]:
    """Verify many paths in one search (the batch path).

    ``robot``: a robot or a robot file's path.  ``paths``: a list whose items are each a ``Path``,
    a pair ``(start, goal)`` or a sequence ``(start, via..., goal)`` of poses (texts such as
    ``"-69,-50,500,85deg,10deg,0"`` or sequences of exact values), or a mapping with ``start``,
    ``goal`` and optional ``via``; a numpy masked array of poses is taken only with nothing masked
    (``robots.poses.unmasked``).  ``constraints``: names (``"leg-length"``,
    ``"leg-length,joints"`` or a list; default all).  The budget (``budget`` or the keywords)
    bounds the whole call: when it runs out the t-ranges left are ``undecided``; segments with a moving
    orientation whose polynomials would take longer to build than ``max_seconds`` (and 1 s), or more paths
    than the answers of ``max_seconds`` can be concluded in after the search (``PATH_SECONDS`` a path and
    constraint, kept from the search's time), are refused (``InputError`` naming max_seconds) unless
    ``refuse_slow`` is false (``plan``: its own clock decides).  ``progress``: None or a callable
    (else ``InputError``)."""
    progress = progress_callback(progress)
    if not isinstance(indices, (bool, np.bool_)):
        raise InputError("indices", "", f"expected True or False, got {shown(indices)}")
    robot = as_robot(robot)
    paths = [as_path(robot, p, k) for k, p in enumerate(_path_list(paths))]
    if not paths:
        return []
    if rtol is not None:
        rtol = positive_number(rtol, "rtol")
    budget = make_budget(budgets.TRAJECTORY, budget, max_boxes=max_boxes, max_seconds=max_seconds,
                         min_width=min_width, max_memory=max_memory)
    cons = constraints if isinstance(constraints, Constraints) else Constraints.of(robot, constraints)
    if cons.K == 0:
        raise InputError("constraints", "", "no constraint can be checked: " +
                         "; ".join(f"{k}: {v}" for k, v in cons.skipped.items()))
    reserve = len(paths) * cons.K * PATH_SECONDS          # the paths' answers, after the search
    if refuse_slow and reserve > budget.max_seconds:
        raise InputError("max_seconds", "", f"{len(paths)} paths of {cons.K} constraints take about {reserve:.3g} s to "
                                            f"conclude (their answers, after the search), more than the time budget "
                                            f"({budget.max_seconds:g} s): give more, or verify fewer paths at a time")
    clock = Clock(budget.max_seconds)
    P0s, Ds, seg_path = [], [], []
    for p_index, path in enumerate(paths):
        P0, D = path.start_and_step()
        P0s.append(P0)
        Ds.append(D)
        seg_path += [p_index] * path.segments
    P0 = Interval.from_bounds(np.concatenate([p.lo for p in P0s]), np.concatenate([p.hi for p in P0s]))
    D = Interval.from_bounds(np.concatenate([p.lo for p in Ds]), np.concatenate([p.hi for p in Ds]))
    seg_path = np.asarray(seg_path, dtype=np.int64)
    n_seg = len(seg_path)
    linear = cons.linear_data(P0, D)
    pieces = piece_plan(angle_step(robot, D))[0] if linear is None else \
        int(2 ** np.clip(np.round(np.log2(FIRST_BATCH / n_seg)), 1, 4))
    edges = np.linspace(0.0, 1.0, pieces + 1)          # exact binary fractions
    piece_segment = np.repeat(np.arange(n_seg), pieces)
    if linear is None and n_seg * pieces * cons.K * PIECE_BYTES > budget.max_memory * (1 - SEARCH_SHARE):
        need = Fraction(n_seg * pieces * cons.K * PIECE_BYTES) / Fraction(1 - SEARCH_SHARE)   # the least max_memory
                                                                                              # the test above takes
        raise InputError("max_memory", "", f"{counted(n_seg, 'segment')} with a moving orientation need a max_memory "
                                           f"of at least {size_bound(need)} (their polynomials, held while the paths "
                                           f"are verified; {size_bound(budget.max_memory, up=False)} given): give more, "
                                           "or verify fewer segments at a time")
    prepare = n_seg * cons.K * (pieces * PIECE_SECONDS if linear is None else LINEAR_SECONDS)
    if refuse_slow and prepare > max(budget.max_seconds, 1.0):      # (built before the search: no clock stops it)
        moving = " with a moving orientation" if linear is None else ""
        raise InputError("max_seconds", "", f"{n_seg} segments{moving} take about {prepare:.3g} s to "
                                            f"prepare (their polynomials), more than the time budget "
                                            f"({budget.max_seconds:g} s): give more, or verify fewer segments at a time")
    lo = np.tile(edges[:-1], n_seg)[:, None]
    hi = np.tile(edges[1:], n_seg)[:, None]
    problem = TrajectoryProblem(cons, P0, D, piece_segment, seg_path, len(paths), rtol, budget.min_width, linear, clock)
    (segment, tlo, thi, state, mlo, mhi), boxes, exhausted = _solved(problem, lo, hi, budget, clock, progress, rtol,
                                                                     reserve)
    results = []
    for p_index, path in enumerate(paths):
        segs = np.nonzero(seg_path == p_index)[0]
        mine = np.isin(segment, segs)
        local = segs.searchsorted(segment[mine])
        order = np.lexsort((tlo[mine], local))
        r = TrajectoryResult(robot, path, cons)
        r.leaves = {"segment": local[order], "tlo": tlo[mine][order], "thi": thi[mine][order],
                    "state": state[mine][order], "mlo": mlo[mine][order], "mhi": mhi[mine][order]}
        conclude(r, problem.best[p_index])
        if indices and not interrupt.requested():         # (Ctrl-C in this call; not one of an earlier command)
            r.indices = _mean_indices(problem, cons, segs, clock)
        r.stats = {"boxes": int(boxes), "leaves": int(mine.sum()), "seconds": round(clock.elapsed(), 6),
                   "budget_exhausted": bool(exhausted or clock.out())}
        results.append(r)
    return results


def _solved(problem, lo, hi, budget, clock, progress, rtol, reserve=0.0):
    """Search the pieces ``[lo, hi]`` (one per row of ``problem.piece_segment``): the leaves' (segment,
    t bounds, states, margin bounds), the boxes decided and whether a budget ran out.  When the time
    budget ran out while the polynomials were built (``problem.complete`` false), nothing is searched:
    every piece is a leaf with every constraint ``unknown`` and unbounded margins.  ``reserve``: seconds
    kept from the search for the answers built after it."""
    K = problem.c.K
    if not problem.complete:
        n = len(lo)
        return (problem.piece_segment, lo[:, 0], hi[:, 0], np.full((n, K), UNKNOWN, dtype=np.int8),
                np.full((n, K), -np.inf), np.full((n, K), np.inf)), 0, True
    lo, hi, piece_segment = problem.presplit(lo, hi, problem.piece_segment)
    problem.piece_segment = piece_segment
    problem.seed_best(lo, hi, piece_segment, Clock(SEED_SHARE * max(clock.left() - reserve, 0.0)))
    searched = replace(budget.within(clock.left() - reserve), max_memory=max(1, int(budget.max_memory * SEARCH_SHARE)))
    batch = {"batch": PIECE_BATCH} if problem.pieces else {}    # moving orientation: about 0.4 MiB a box while decided
    found = search(problem, lo, hi, scale=np.ones(1), budget=searched, progress=progress, min_batch=64, max_rounds=5,
                   **batch)
    leaves = _leaf_states(problem, found.tree, piece_segment, K, rtol, clock)[1:]
    return leaves, found.boxes, found.exhausted


def _leaf_states(problem, tree, piece_segment, K, rtol, clock, chunk: int = 256):
    """Per leaf of the search: (ids, segment, t bounds, states, margin bounds).  Leaves never
    evaluated (a budget ran out) are evaluated now while the time budget lasts and no Ctrl-C came,
    by chunks; the rest stay ``unknown`` with unbounded margins (sound: nothing is claimed about them)."""
    leaves = tree.leaves()
    segment = piece_segment[tree.root[leaves]]
    tlo, thi = tree.lo[leaves, 0], tree.hi[leaves, 0]
    state = np.full((len(leaves), K), UNKNOWN, dtype=np.int8)
    mlo, mhi = np.full((len(leaves), K), -np.inf), np.full((len(leaves), K), np.inf)
    known = tree.evidence_rows["state"][leaves] >= 0 if "state" in tree.evidence_rows else np.zeros(len(leaves), bool)
    if known.any():
        ids = leaves[known]
        state[known] = tree.evidence_values("state", ids)
        mlo[known], mhi[known] = tree.evidence_values("mlo", ids), tree.evidence_values("mhi", ids)
    todo = np.nonzero(~known)[0]
    for k in range(0, len(todo), chunk):
        if clock.out():
            break
        if interrupt.requested():           # (leaves never evaluated: the search itself was cut short)
            interrupt.cut()
            break
        part = todo[k:k + chunk]
        state[part], mlo[part], mhi[part] = problem.evaluate(tlo[part], thi[part], segment[part], upper=rtol is not None)
    return leaves, segment, tlo, thi, state, mlo, mhi


def _path_list(paths):
    """The items of ``paths`` (a list, or an array of shape (paths, poses, d); a masked array only
    with nothing masked)."""
    paths = unmasked(paths, "paths")
    if isinstance(paths, (str, Path)) or isinstance(paths, dict):
        raise InputError("paths", "", "expected a list of paths (each a Path, (start, goal) or (start, via..., goal))")
    try:
        return list(paths)
    except TypeError:
        raise InputError("paths", "", f"expected a list of paths, got {type(paths).__name__}") from None


def as_path(robot, item, k: int = 0) -> Path:
    """One path of ``verify_trajectories`` (see there); errors name ``paths[k]``."""
    if isinstance(item, Path):
        return item
    try:
        if isinstance(item, dict):
            unknown = set(item) - {"start", "goal", "via"}
            if unknown or "start" not in item or "goal" not in item:
                raise InputError("", "", "expected the keys start, goal and optional via")
            return parse_path(robot, item["start"], item["goal"], item.get("via"))
        poses = list(item) if not isinstance(item, str) else None
        if poses is None or len(poses) < 2 or any(np.ndim(p) == 0 and not isinstance(p, str) for p in poses):
            raise InputError("", "", "expected (start, goal) or (start, via..., goal): two poses or more")
        return parse_path(robot, poses[0], poses[-1], poses[1:-1])
    except InputError as exc:
        field = ": ".join(f for f in (exc.source, exc.field) if f)
        raise InputError(f"paths[{k}]", field, exc.problem) from None
    except TypeError:
        raise InputError(f"paths[{k}]", "", "expected (start, goal) or (start, via..., goal)") from None


@quiet
def verify_trajectory(robot, start, goal, waypoints=(), constraints=None, budget: Budget | None = None,
                      progress=None, indices: bool = True, *, max_boxes=None, max_seconds=None, min_width=None,
                      max_memory=None) -> TrajectoryResult:
    """Is the straight (or polyline) motion from ``start`` to ``goal`` feasible?  See the module docstring.

    ``robot``: a robot or a robot file's path; ``start``, ``goal``, ``waypoints``: poses (texts or
    sequences of exact values); ``constraints`` and ``progress`` as in ``verify_trajectories``."""
    progress = progress_callback(progress)
    robot = as_robot(robot)
    path = parse_path(robot, start, goal, waypoints)
    return verify_trajectories(robot, [path], constraints, budget, progress, indices, max_boxes=max_boxes,
                               max_seconds=max_seconds, min_width=min_width, max_memory=max_memory)[0]


def _mean_indices(problem, cons, segs, clock) -> list | None:
    """Certified enclosures of the mean margin over the path (∫ margin ds / segments),
    from INDEX_STEPS sub-intervals per segment: each contributes width × [min, max].
    None (no indices) when ``clock`` runs out first (it is read between chunks of segments)."""
    edges = np.linspace(0.0, 1.0, INDEX_STEPS + 1)
    total = None
    for k in range(0, len(segs), INDEX_SEGMENTS):      # a few segments at a time: bounded memory
        if clock.out():
            return None
        part = segs[k:k + INDEX_SEGMENTS]
        seg = np.repeat(part, INDEX_STEPS)
        _, mlo, mhi = problem.evaluate(np.tile(edges[:-1], len(part)), np.tile(edges[1:], len(part)), seg)
        chunk = Interval.from_bounds(*sum_bounds(mlo, mhi, axis=0))         # every column at once
        total = chunk if total is None else total + chunk
    mean = total / Interval(INDEX_STEPS * len(segs))
    out = []
    for k, inst in enumerate(cons.instances):
        if k == cons.det_column:
            continue
        out.append({**inst.to_json(), "mean_margin": [float(mean.lo[k]), float(mean.hi[k])]})
    return out
