"""Certified trajectory feasibility (seed 000 ch. 1, with the digest's corrections).

A path is a polyline of poses P_0 … P_n; on segment k the pose is
P_k + t (P_{k+1} − P_k), t ∈ [0, 1]: a straight line in position and a linear
interpolation of the pose angles (seed 000 eq. 1.82–1.83; constant orientation
when the angles are equal).  The global parameter is s = k + t.

The shared engine bisects t; each t-interval is decided by
``trajectory_constraints.Constraints`` (every constraint instance proved
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
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
import math
import time

import numpy as np

from intervals import Interval
from intervals.rounding import down, sum_bounds, up

from . import budgets
from .engine.search import OPEN, PROVED, EXCLUDED, Budget, search
from .errors import InputError
from .poses import parse_pose
from .trajectory_constraints import SATISFIED, UNKNOWN, VIOLATED, Constraints, crossing_points, piece_plan

FIRST_BATCH = 256    # constant orientation: about this many initial sub-intervals in all (2 to 16 per segment)
MARGIN_RTOL = 1e-4   # relative tolerance of the certified minimum margins
INDEX_STEPS = 64     # sub-intervals per segment for the mean indices


@dataclass
class Path:
    """A polyline of poses (exact texts and their enclosures)."""

    texts: list
    poses: Interval                      # (n + 1, d)

    @property
    def segments(self) -> int:
        return self.poses.shape[0] - 1

    def start_and_step(self):
        """Per segment, P_k and P_{k+1} − P_k; a coordinate whose exact text is the same at
        both ends has a step of exactly 0 (so constant angles give the constant-orientation path)."""
        P0 = self.poses[:-1]
        D = self.poses[1:] - self.poses[:-1]
        same = np.array([[a == b for a, b in zip(p, q)] for p, q in zip(self.texts[:-1], self.texts[1:])])
        if same.any():
            D = Interval._raw(np.where(same, 0.0, D.lo), np.where(same, 0.0, D.hi))
        return P0, D


def angle_step(robot, D: Interval) -> float:
    """The largest change of a pose angle along one segment (radians; 0 without angles)."""
    cols = [k for k, name in enumerate(robot.pose_names) if name in robot.angle_names]
    if not cols:
        return 0.0
    return float(np.max(np.maximum(np.abs(D.lo[:, cols]), np.abs(D.hi[:, cols]))))


def parse_path(robot, start, goal, waypoints=()) -> Path:
    """``start``, ``goal`` and optional ``waypoints`` (pose texts or sequences) -> ``Path``."""
    items = [("--from", start)] + [(f"--via[{k}]", w) for k, w in enumerate(waypoints or ())] + [("--to", goal)]
    ivs, texts = [], []
    for option, pose in items:
        iv, t = parse_pose(pose, robot, option)
        ivs.append(iv)
        texts.append(t)
    lo = np.stack([i.lo for i in ivs])
    hi = np.stack([i.hi for i in ivs])
    return Path(texts, Interval._raw(lo, hi))


class TrajectoryProblem:
    """Decides t-intervals of many segments at once (roots = pieces of segments)."""

    reasons = ("every constraint decided on the interval",)

    def __init__(self, constraints: Constraints, P0, D, piece_segment, segment_path, n_paths, rtol=MARGIN_RTOL,
                 min_width=1e-9, linear=False):
        self.c = constraints
        self.P0, self.D = P0, D
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
            self.polys = constraints.piece_polynomials(P0[seg], D[seg], k / n, np.full(len(k), 1.0 / n), degree)
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
        from .engine.search import Decisions
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
        unknown = (state == UNKNOWN).any(axis=1) | refine.any(axis=1)
        status = np.where(unknown, OPEN, np.where((state == VIOLATED).any(axis=1), EXCLUDED, PROVED)).astype(np.int8)
        return Decisions(status=status, reason=np.zeros(len(lo), dtype=np.int64),
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

    def seed_best(self, lo, hi, seg):
        """Start each path's refinement target ``best`` from point evaluations: at the ends of the
        segments and at the estimated minima of the margins inside the pieces (``crossing_polynomials``:
        stationary points of ρ² and E/Δ).  The upper bound of a margin at any instant bounds its
        minimum over the path, so ``best`` stays an upper bound; the intervals far from the minimum
        are then settled at once instead of after the minimum's interval has been narrowed."""
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
        S, T = points[:, 0].astype(np.int64), points[:, 1]
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


@dataclass
class TrajectoryResult:
    """The verdict on one path, with the leaves that prove it."""

    robot: object
    path: Path
    constraints: Constraints
    status: str = "undecided"
    leaves: dict = field(default_factory=dict)    # segment, tlo, thi (arrays), state (L, K), mlo, mhi
    margins: list = field(default_factory=list)
    violations: list = field(default_factory=list)
    undecided: list = field(default_factory=list)
    det_sign: int = 0
    stats: dict = field(default_factory=dict)
    indices: list | None = None

    def to_json(self) -> dict:
        c = self.constraints
        out = {"problem": "trajectory", "status": self.status,
               "path": [dict(zip(self.robot.pose_names, t)) for t in self.path.texts],
               "constraints": sorted({i.constraint for i in c.instances}),
               "skipped": dict(c.skipped),
               "margins": self.margins,
               "violations": self.violations,
               "undecided": self.undecided,
               "stats": self.stats}
        if c.det is not None:
            out["det_sign"] = self.det_sign
        if self.indices is not None:
            out["indices"] = self.indices
        return out

    def certificate(self) -> dict:
        from .certificates import trajectory_certificate
        return trajectory_certificate([self])


def _runs(mask_sorted, s_lo, s_hi):
    """Maximal runs of consecutive True leaves -> list of (first, last) indices."""
    idx = np.nonzero(mask_sorted)[0]
    if not len(idx):
        return []
    breaks = np.nonzero((np.diff(idx) > 1) | (s_lo[idx[1:]] > s_hi[idx[:-1]]))[0]
    starts = np.concatenate([[idx[0]], idx[breaks + 1]])
    ends = np.concatenate([idx[breaks], [idx[-1]]])
    return list(zip(starts.tolist(), ends.tolist()))


def _interval(lo, hi):
    """[lo, hi] for JSON; an infinite bound (not computed) is null."""
    return [float(lo) if np.isfinite(lo) else None, float(hi) if np.isfinite(hi) else None]


def verify_trajectories(robot, paths, constraints=None, budget: Budget | None = None, progress=None,
                        indices: bool = True, rtol: float = MARGIN_RTOL) -> list[TrajectoryResult]:
    """Verify many paths in one search (the batch path).  ``paths``: list of ``Path``."""
    if not paths:
        return []
    budget = budget or Budget(**budgets.TRAJECTORY)
    cons = constraints if isinstance(constraints, Constraints) else Constraints.of(robot, constraints)
    if cons.K == 0:
        raise InputError("--constraints", "", "no constraint can be checked: " +
                         "; ".join(f"{k}: {v}" for k, v in cons.skipped.items()))
    t0 = time.perf_counter()
    P0s, Ds, seg_path = [], [], []
    for p_index, path in enumerate(paths):
        P0, D = path.start_and_step()
        P0s.append(P0)
        Ds.append(D)
        seg_path += [p_index] * path.segments
    P0 = Interval._raw(np.concatenate([p.lo for p in P0s]), np.concatenate([p.hi for p in P0s]))
    D = Interval._raw(np.concatenate([p.lo for p in Ds]), np.concatenate([p.hi for p in Ds]))
    seg_path = np.asarray(seg_path, dtype=np.int64)
    n_seg = len(seg_path)
    linear = cons.linear_data(P0, D)
    pieces = piece_plan(angle_step(robot, D))[0] if linear is None else \
        int(2 ** np.clip(np.round(np.log2(FIRST_BATCH / n_seg)), 1, 4))
    edges = np.linspace(0.0, 1.0, pieces + 1)          # exact binary fractions
    piece_segment = np.repeat(np.arange(n_seg), pieces)
    lo = np.tile(edges[:-1], n_seg)[:, None]
    hi = np.tile(edges[1:], n_seg)[:, None]
    problem = TrajectoryProblem(cons, P0, D, piece_segment, seg_path, len(paths), rtol, budget.min_width, linear)
    lo, hi, piece_segment = problem.presplit(lo, hi, piece_segment)
    problem.piece_segment = piece_segment
    problem.seed_best(lo, hi, piece_segment)
    found = search(problem, lo, hi, scale=np.ones(1), budget=budget, progress=progress, min_batch=64, max_rounds=5)
    tree = found.tree
    leaves = tree.leaves()
    segment = piece_segment[tree.root[leaves]]
    tlo, thi = tree.lo[leaves, 0], tree.hi[leaves, 0]
    state = np.zeros((len(leaves), cons.K), dtype=np.int8)
    mlo, mhi = np.empty((len(leaves), cons.K)), np.empty((len(leaves), cons.K))
    known = tree.evidence_rows["state"][leaves] >= 0 if "state" in tree.evidence_rows else np.zeros(len(leaves), bool)
    if known.any():
        ids = leaves[known]
        state[known] = tree.evidence_values("state", ids)
        mlo[known], mhi[known] = tree.evidence_values("mlo", ids), tree.evidence_values("mhi", ids)
    if (~known).any():                # leaves never evaluated (budget): evaluated now
        state[~known], mlo[~known], mhi[~known] = problem.evaluate(tlo[~known], thi[~known], segment[~known],
                                                                   upper=rtol is not None)
    results = []
    for p_index, path in enumerate(paths):
        segs = np.nonzero(seg_path == p_index)[0]
        mine = np.isin(segment, segs)
        local = segs.searchsorted(segment[mine])
        order = np.lexsort((tlo[mine], local))
        r = TrajectoryResult(robot, path, cons)
        r.leaves = {"segment": local[order], "tlo": tlo[mine][order], "thi": thi[mine][order],
                    "state": state[mine][order], "mlo": mlo[mine][order], "mhi": mhi[mine][order]}
        _conclude(r, problem.best[p_index])
        if indices:
            r.indices = _mean_indices(problem, cons, segs)
        r.stats = {"boxes": int(found.boxes), "leaves": int(mine.sum()), "seconds": round(time.perf_counter() - t0, 6),
                   "budget_exhausted": bool(found.exhausted)}
        results.append(r)
    return results


def verify_trajectory(robot, start, goal, waypoints=(), constraints=None, budget: Budget | None = None,
                      progress=None, indices: bool = True) -> TrajectoryResult:
    """Is the straight (or polyline) motion from ``start`` to ``goal`` feasible?  See the module docstring."""
    path = parse_path(robot, start, goal, waypoints)
    return verify_trajectories(robot, [path], constraints, budget, progress, indices)[0]


def _conclude(r: TrajectoryResult, best=None) -> None:
    """The verdict, margins and violations of a path from its leaves; ``best``: upper bounds of
    the minimum margins found during the search (intervals or instants evaluated), per column."""
    c = r.constraints
    L = r.leaves
    s_lo = L["segment"] + L["tlo"]
    s_hi = L["segment"] + L["thi"]
    state = L["state"]
    dcol = c.det_column
    certain = False
    lo_min, hi_min = L["mlo"].min(axis=0), L["mhi"].min(axis=0)
    if best is not None:
        hi_min = np.minimum(hi_min, best)
    open_cols = (state != SATISFIED).any(axis=0)
    for k, inst in enumerate(c.instances):
        if k == dcol:
            continue
        entry = inst.to_json()
        entry["margin"] = _interval(lo_min[k], hi_min[k])
        r.margins.append(entry)
        if not open_cols[k]:
            continue
        for a, b in _runs(state[:, k] != SATISFIED, s_lo, s_hi):
            sure = bool((state[a:b + 1, k] == VIOLATED).any())
            certain |= sure
            r.violations.append({**inst.to_json(), **_where(L, a, b), "certain": sure})
    if dcol is not None:
        sign = np.where(L["mlo"][:, dcol] > 0, 1, np.where(L["mhi"][:, dcol] < 0, -1, 0))
        mig = np.where(sign > 0, L["mlo"][:, dcol], np.where(sign < 0, -L["mhi"][:, dcol], 0.0))
        mag = np.maximum(np.abs(L["mlo"][:, dcol]), np.abs(L["mhi"][:, dcol]))
        signs = set(sign[sign != 0].tolist())
        entry = c.instances[dcol].to_json()
        entry["margin"] = _interval(mig.min(), mag.min())      # min over the path of |det A|
        entry["sign"] = signs.pop() if len(signs) == 1 and (sign != 0).all() else 0
        r.det_sign = entry["sign"]
        r.margins.append(entry)
        crossing = len(set(sign[sign != 0].tolist())) > 1
        certain |= crossing
        for a, b in _runs(sign == 0, s_lo, s_hi):
            before = sign[a - 1] if a > 0 else 0
            after = sign[b + 1] if b + 1 < len(sign) else 0
            sure = bool(before and after and before != after)
            r.violations.append({**c.instances[dcol].to_json(), **_where(L, a, b), "certain": sure})
    unknown = (state == UNKNOWN).any(axis=1)
    if certain:
        r.status = "infeasible"
    elif not unknown.any() and not r.violations:
        r.status = "feasible"
    else:
        r.status = "undecided"
    for a, b in _runs(unknown, s_lo, s_hi):
        r.undecided.append(_where(L, a, b))


def _where(L, a, b) -> dict:
    """The t-range of leaves a..b: local t when in one segment, and the global s."""
    s0 = float(L["segment"][a] + L["tlo"][a])      # k + t may round: widen outward by one ulp if so
    s1 = float(L["segment"][b] + L["thi"][b])
    if Fraction(s0) > Fraction(int(L["segment"][a])) + Fraction(float(L["tlo"][a])):
        s0 = math.nextafter(s0, -math.inf)
    if Fraction(s1) < Fraction(int(L["segment"][b])) + Fraction(float(L["thi"][b])):
        s1 = math.nextafter(s1, math.inf)
    out = {"s": [s0, s1]}
    if L["segment"][a] == L["segment"][b]:
        out["segment"] = int(L["segment"][a])
        out["t"] = [float(L["tlo"][a]), float(L["thi"][b])]
    return out


def _mean_indices(problem, cons, segs) -> list:
    """Certified enclosures of the mean margin over the path (∫ margin ds / segments),
    from INDEX_STEPS sub-intervals per segment: each contributes width × [min, max]."""
    edges = np.linspace(0.0, 1.0, INDEX_STEPS + 1)
    seg = np.repeat(segs, INDEX_STEPS)
    tlo = np.tile(edges[:-1], len(segs))
    thi = np.tile(edges[1:], len(segs))
    _, mlo, mhi = problem.evaluate(tlo, thi, seg)
    mean = Interval._raw(*sum_bounds(mlo, mhi, axis=0)) / Interval(INDEX_STEPS * len(segs))   # every column at once
    out = []
    for k, inst in enumerate(cons.instances):
        if k == cons.det_column:
            continue
        out.append({**inst.to_json(), "mean_margin": [float(mean.lo[k]), float(mean.hi[k])]})
    return out
