"""Forward-kinematics tracking: the posture near a previous one, proved unique (seed 002 §4).

For new leg lengths and a previous posture x0 (unknowns of ``fk.system``):

1. a guess x* from float Newton iterations started at x0 (``FKSystem.float_system``:
   plain float64, never used as a proof);
2. two boxes, tested together in one stacked interval evaluation
   (``StackedFKSystem.krawczyk_data``, outward rounded, then the Krawczyk operator
   of ``intervals.linalg``):

   - the *tracking box* B = hull(x0, x*) widened by a fraction of the move:
     K(B) ⊂ int B proves that B holds exactly one posture;
   - the *root box* R ⊂ B, x* ± ε with ε a float estimate of the error of x* and
     of the rounding of f(x*): K(R) ⊂ int R proves that R holds a posture — the
     one of B; R is the reported enclosure;

3. rows that fail get up to two more rounds, each one stacked evaluation of
   the failed rows only: the tracking box ε-inflated around its Krawczyk image
   (Rump 1983: hull(x0, x*, K(B)) widened by a quarter of its width; this
   adapts the box's shape to the Jacobian) and, in the first retry, a smaller
   box (another posture may be near); the root box widened by 2¹⁰ per round,
   kept inside a proved B.  A proved B whose R still fails reports R = B.  A
   step that is still not proved is never reported as tracked: the full search
   runs instead (or, on request, the step is reported not proved).

The certificate of a tracked step is the one of ``forward_kinematics(track=)``:
the domain B with one ``krawczyk-unique`` leaf (its matrix C) and the solution
R with its own matrix; ``proofs`` re-checks both Krawczyk inclusions.

``track_sequence`` follows a sequence of leg-length sets (a trajectory of FK
queries): the float Newton iterations run step after step, each started from
the previous step's posture (extrapolated linearly), then every step's proof
runs in one batched evaluation, so the interval work per step is small.
"""
from __future__ import annotations

from dataclasses import dataclass
import math
import time

import numpy as np

from intervals import Interval, linalg, sqr
from intervals.rounding import enclose_plain

from ..robots.poses import float_length_rows, parse_lengths, parse_pose
from .result import FKResult, described
from .stacked import StackedFKSystem
from .step import unique_in
from .system import fk_system

GROWS = (0.5, 0.25)          # tracking box: hull(x0, x*) widened by grow × the move (first try, smaller retry)
INFLATE = 0.25               # retries: hull(x0, x*, K(B)) widened by this fraction of its width
ROUNDS = 3                   # stacked evaluations at most (the first and two retries)
NEWTON_STEPS = 12            # float Newton iterations per step at most
CONVERGED = 2.0 ** -26       # a (scaled) Newton step below this ends the iteration: by quadratic convergence
                             # the error left is near rounding; the root box is sized from the residual anyway
ROOT_SLACK = 2.0             # root box radius: this many times the float error estimate of x*
ROOT_RETRY = 2.0 ** 10       # the root box is widened by this factor when its first test fails


def _scale(system):
    """Size of each unknown: the robot's size for positions, 1 for rotation unknowns (computed once
    per system; read only)."""
    return system.memo("tracking_scale", lambda: np.concatenate([np.full(system.n_pos, system.size),
                                                                  np.ones(system.n - system.n_pos)]))


def newton(system, x, L2, scale, steps: int = NEWTON_STEPS, model: list | None = None):
    """Float Newton iterations from ``x`` (n,) for float squared lengths ``L2`` (legs,).

    Returns ``(x*, converged)``; a guess only (the proof is the Krawczyk test).  ``model``: a list
    that receives, on convergence, the last step's linear model at x*: (f + J (x* − x), J, x* − x)
    with f, J at the last iterate x (for ``_root_radius``, instead of evaluating f and J at x*).
    """
    if system.kind == "planar-3rpr":
        return _newton_planar(system, x, L2, scale, steps, model)
    with np.errstate(all="ignore"):
        for _ in range(steps):
            f, J = system.float_system(x, L2)
            try:
                dx = np.linalg.solve(J, f)
            except np.linalg.LinAlgError:
                return x, False
            size = (np.abs(dx) / scale).max()
            if not size < np.inf:          # inf or NaN
                return x, False
            x = x - dx
            if size <= CONVERGED:
                if model is not None:
                    model[:] = [f - J @ dx, J, -dx]
                return x, True
    return x, False


def _planar_float_system(g, x, L2):
    """(f, J) of the planar equations at x = (x, y, c, s) as Python floats: leg i is
    |(x, y) + c b_i + s (−b_iy, b_ix) − a_i|² − ρ_i², then c² + s² − 1 (``FKSystem.float_system``'s
    equations, without numpy's cost per call on a 4 × 4 system).  ``g``: rows (a_x, a_y, b_x, b_y)."""
    px, py, c, s = x
    f, J = [], []
    for (ax, ay, bx, by), l2 in zip(g, L2):
        ex = px + c * bx - s * by - ax
        ey = py + c * by + s * bx - ay
        f.append(ex * ex + ey * ey - l2)
        J.append([2.0 * ex, 2.0 * ey, 2.0 * (ex * bx + ey * by), 2.0 * (ey * bx - ex * by)])
    f.append(c * c + s * s - 1.0)
    J.append([0.0, 0.0, 2.0 * c, 2.0 * s])
    return f, J


def _gauss_jordan(J, B):
    """J⁻¹ B (row lists of Python floats) by Gauss-Jordan elimination with partial pivoting on [J | B]
    (the steps of ``intervals.native.gauss_jordan``, in Python: on a system this small it is as quick,
    and a tracked step does not pay the half second of importing numba); None if J is singular or the
    result is not finite.  An estimate, never a proof."""
    n = len(J)
    A = [list(row) + list(extra) for row, extra in zip(J, B)]
    for col in range(n):
        piv, best = col, abs(A[col][col])
        for r in range(col + 1, n):
            if abs(A[r][col]) > best:
                piv, best = r, abs(A[r][col])
        if not (best > 0.0) or not math.isfinite(best):
            return None
        A[col], A[piv] = A[piv], A[col]
        inv = 1.0 / A[col][col]
        pivot_row = A[col] = [v * inv for v in A[col]]
        for r in range(n):
            f = A[r][col]
            if r != col and f != 0.0:
                A[r] = [v - f * p for v, p in zip(A[r], pivot_row)]
    out = [row[n:] for row in A]
    return out if all(math.isfinite(v) for row in out for v in row) else None


def _solve(J, f):
    """J⁻¹ f (Python floats); None if J is singular or the result is not finite."""
    out = _gauss_jordan(J, [[v] for v in f])
    return None if out is None else [row[0] for row in out]


def _newton_planar(system, x, L2, scale, steps, model):
    """``newton`` for the planar robot, in Python floats (the same iteration and stopping rule)."""
    a, b = system.float_geometry()
    g = np.concatenate([a, b], -1).tolist()
    L2 = [float(v) for v in L2]
    inv_scale = [1.0 / float(v) for v in scale]
    x = [float(v) for v in x]
    for _ in range(steps):
        f, J = _planar_float_system(g, x, L2)
        dx = _solve(J, f)
        if dx is None:
            return np.array(x), False
        size = max(abs(d) * w for d, w in zip(dx, inv_scale))
        x = [v - d for v, d in zip(x, dx)]
        if size <= CONVERGED:
            if model is not None:
                f, J, dx = np.array(f), np.array(J), np.array(dx)
                model[:] = [f - J @ dx, J, -dx]
            return np.array(x), True
    return np.array(x), False


def _root_radius(system, x, L2, model=None):
    """Float estimate (N, n) of how far the Krawczyk image of x* ± r reaches: |C| (|f(x*)| + the
    rounding of the interval evaluation of f), C ≈ J(x*)⁻¹, times ``ROOT_SLACK``.  Not a bound: a
    wrong estimate only makes the Krawczyk test fail (infinite where J(x*) is singular).
    ``model``: (f, J, d) of ``newton``'s last step (rows of N), used instead of f(x*), J(x*): f(x*)
    is then estimated as |f| plus the quadratic term (1 + |b_i|)² |d|₁² the model leaves out."""
    p = system.n_pos
    geometry, curve = system.memo("radius_terms", lambda: _radius_terms(system))
    with np.errstate(all="ignore"):
        if model is None:
            f, J = system.float_system(x, L2)
            f = np.abs(f)
        else:
            f, J, d = model
            f = np.abs(f) + curve * np.sum(np.abs(d), -1, keepdims=True) ** 2
        C, failed = linalg.float_inverse(J)
        # each leg equation sums terms of magnitude <= 3 (|p|² + |a_i|² + |b_i|²) + ρ_i²; the norm's, 2
        terms = np.concatenate([L2, np.zeros((len(x), 1))], -1) + geometry
        if p:
            terms[:, :-1] += 3.0 * np.sum(x[:, :p] ** 2, -1, keepdims=True)
        err = f + 2.0 ** -49 * terms
        rad = ROOT_SLACK * (np.abs(C) @ err[..., None])[..., 0] + 2.0 ** -50 * np.abs(x) + 1e-300
    rad[failed] = np.inf
    return np.where(np.isfinite(rad), rad, np.inf)


def _root_radius_one(system, x, L2, model):
    """``_root_radius`` for one step with ``newton``'s model, in Python floats (C by Gauss-Jordan
    elimination; None where that fails: then ``_root_radius`` decides)."""
    geometry, curve = system.memo("radius_terms", lambda: _radius_terms(system))
    f, J, d = model
    n, p = len(x), system.n_pos
    x, L2 = x.tolist(), L2.tolist()
    d1 = sum(abs(v) for v in d[0].tolist())
    p2 = 3.0 * sum(v * v for v in x[:p])
    err = [abs(fi) + ci * d1 * d1 + 2.0 ** -49 * (gi + ((li + p2) if k < n - 1 else 0.0))
           for k, (fi, ci, gi, li) in enumerate(zip(f[0].tolist(), curve.tolist(), geometry.tolist(),
                                                    L2 + [0.0]))]
    Jinv = _gauss_jordan(J[0].tolist(), [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)])
    if Jinv is None:
        return None
    rad = [ROOT_SLACK * sum(abs(c) * e for c, e in zip(row, err)) + 2.0 ** -50 * abs(xi) + 1e-300
           for row, xi in zip(Jinv, x)]
    return np.array(rad) if all(math.isfinite(r) for r in rad) else None


def _radius_terms(system):
    """(3 (|a_i|² + |b_i|²) per leg and 2 for the norm, (1 + |b_i|)² per leg and 1 for the norm):
    the robot's part of ``_root_radius``'s estimate, computed once per system."""
    a, b = system.float_geometry()
    b2 = np.sum(b * b, -1)
    return (np.concatenate([3.0 * (np.sum(a * a, -1) + b2), [2.0]]),
            np.concatenate([(1.0 + np.sqrt(b2)) ** 2, [1.0]]))


def krawczyk(system: StackedFKSystem, lo, hi, L: Interval, points: bool = False):
    """(K, C[, platform points]) for the boxes [lo, hi] (N, n): one stacked evaluation of f at the
    midpoints and of J over the boxes, then the Krawczyk image (C ≈ inverse of the midpoint
    Jacobian; the tests K ⊂ int X are made by the caller)."""
    X = Interval.from_bounds(lo, hi)
    f, J, c, *pts = system.krawczyk_data(X, L, points=points)
    C, _ = linalg.float_inverse(J.mid())
    return (linalg.krawczyk_image(f, J, X, c, C), C, *pts)


@dataclass
class Proofs:
    """Per step: ``ok``, the tracking box B (``blo``, ``bhi``, ``bC``) and the root box R ⊂ B
    (``rlo``, ``rhi``, ``rC``); both passed K ⊂ int (with the margin of ``step.unique_in``) where ok."""

    ok: np.ndarray
    blo: np.ndarray
    bhi: np.ndarray
    bC: np.ndarray
    rlo: np.ndarray
    rhi: np.ndarray
    rC: np.ndarray
    points: Interval | None = None      # system.points of the root boxes, where ``has_points``
    has_points: np.ndarray | None = None


def prove(system: StackedFKSystem, x0, x, L: Interval, L2, model=None) -> Proofs:
    """Krawczyk proofs for the steps x0 -> x* (rows of (N, n)); L (N, legs) squared leg lengths
    (enclosures), L2 their float midpoints (``model``: ``newton``'s last step, see
    ``_root_radius``).  Every round is one stacked evaluation of the boxes of the rows not yet
    proved (see the module docstring)."""
    N, n = x.shape
    scale = _scale(system)
    core_lo, core_hi = np.minimum(x0, x), np.maximum(x0, x)
    move = np.maximum.reduce((core_hi - core_lo) / scale, axis=1, keepdims=True) + 1e-12

    def grown(grow, rows):
        r = grow * (core_hi[rows] - core_lo[rows]) + 0.5 * grow * move[rows] * scale
        return (np.minimum(core_lo[rows] - r, rlo[rows]), np.maximum(core_hi[rows] + r, rhi[rows]))

    rad = _root_radius_one(system, x[0], L2[0], model) if N == 1 and model is not None else None
    rad = _root_radius(system, x, L2, model) if rad is None else rad[None]
    rlo, rhi = x - rad, x + rad
    blo, bhi = grown(GROWS[0], slice(None))
    # the first round (usually the only one): every tracking box and every root box
    los, his = np.concatenate([blo, rlo]), np.concatenate([bhi, rhi])
    K, C, pts = krawczyk(system, los, his, Interval.from_bounds(np.concatenate([L.lo, L.lo]), np.concatenate([L.hi, L.hi])),
                         points=True)
    good = unique_in(K, los, his)
    okB, okR = good[:N].copy(), good[N:].copy()
    has_points = okR.copy()                            # the platform points of these root boxes are known
    pts = pts[N:]
    bC, rC = C[:N].copy(), C[N:].copy()                # read only where proved
    first_K = (np.arange(N), K.lo[:N], K.hi[:N])       # the previous round's first tracking boxes
    for round_ in range(1, ROUNDS):
        if okB.all() and okR.all():
            break
        # this round: ε-inflation of the tracking box around its Krawczyk image (Rump 1983), in the
        # second round also a smaller box (another posture may be near); a root box widened, inside B
        rows, klo, khi = first_K
        keep = ~okB[rows] & np.logical_and.reduce(np.isfinite(klo) & np.isfinite(khi), axis=1)
        rows, klo, khi = rows[keep], klo[keep], khi[keep]
        hlo = np.minimum(np.minimum(core_lo[rows], klo), rlo[rows])
        hhi = np.maximum(np.maximum(core_hi[rows], khi), rhi[rows])
        w = INFLATE * (hhi - hlo) + 1e-12 * scale
        b_tries = [(rows, hlo - w, hhi + w)]           # (rows, lo, hi): tracking boxes to test, in order
        if round_ == 1:
            small = np.nonzero(~okB)[0]
            b_tries.append((small, *grown(GROWS[1], small)))
        rows = np.nonzero(~okR)[0]
        wide = ROOT_RETRY ** round_ * rad[rows]
        inside = okB[rows, None]
        r_tries = (rows, np.maximum(x[rows] - wide, np.where(inside, blo[rows], -np.inf)),
                   np.minimum(x[rows] + wide, np.where(inside, bhi[rows], np.inf)))
        tries = b_tries + [r_tries]
        idx = np.concatenate([t[0] for t in tries])
        if not len(idx):
            break
        los, his = np.concatenate([t[1] for t in tries]), np.concatenate([t[2] for t in tries])
        K, C = krawczyk(system, los, his, Interval.from_bounds(L.lo[idx], L.hi[idx]))
        good = unique_in(K, los, his)
        at = 0
        for t, (rows, tlo, thi) in enumerate(b_tries):   # the first proved box of each row, in order
            sel = slice(at, at + len(rows))
            at += len(rows)
            take = good[sel] & ~okB[rows]
            blo[rows[take]], bhi[rows[take]], bC[rows[take]] = tlo[take], thi[take], C[sel][take]
            okB[rows[take]] = True
            if t == 0:
                first_K = (rows, K.lo[sel], K.hi[sel])
        rows, tlo, thi = r_tries
        take = good[at:]
        rlo[rows[take]], rhi[rows[take]], rC[rows[take]] = tlo[take], thi[take], C[at:][take]
        okR[rows[take]] = True
        has_points[rows[take]] = False
    # the root box must lie in the tracking box; otherwise the proved tracking box is the root box
    use_b = okB & ~(okR & np.logical_and.reduce((rlo >= blo) & (rhi <= bhi), axis=1))
    rlo[use_b], rhi[use_b], rC[use_b] = blo[use_b], bhi[use_b], bC[use_b]
    has_points &= ~use_b
    return Proofs(okB, blo, bhi, bC, rlo, rhi, rC, pts, has_points)


TRACKED_MESSAGE = ("the posture near the previous pose is proved unique in a box around it; the other "
                   "assembly modes were not searched")


def _tracked_results(robot, system, texts, proofs: Proofs, rows):
    """FKResults (tracked) for the proved rows: pose and platform points of every root box in one
    evaluation (as ``api._finish`` does for one result)."""
    if not len(rows):
        return []
    X = Interval.from_bounds(proofs.rlo[rows], proofs.rhi[rows])
    poses = system.pose(X)
    if proofs.has_points is not None and proofs.has_points[rows].all():   # computed with the proof
        pts = proofs.points[rows]
    else:
        pts = system.points(X)
    out = []
    for k, told in zip(rows, described(robot, poses, pts)):
        res = FKResult(robot, system, texts[k], (proofs.blo[k], proofs.bhi[k]), tracked=True, complete=False,
                       message=TRACKED_MESSAGE)
        res.solutions.append({"status": "unique", "box": Interval.from_bounds(proofs.rlo[k], proofs.rhi[k]),
                              "C": proofs.rC[k], **told})
        res.all_solutions = list(res.solutions)
        res.track_C = proofs.bC[k]
        out.append(res)
    return out


def _pose_guess(robot, previous):
    """The pose in the variables ``FKSystem.unknowns_of_pose`` reads (``_euler``)."""
    return _euler(robot, _pose_values(robot, previous))


def _euler(robot, pose):
    """Float pose values in the robot's own variables, as ``FKSystem.unknowns_of_pose`` reads them:
    tilt-and-torsion angles (phi1, phi2, sigma) become Euler angles (phi1, phi2, phi3 = sigma - phi1)."""
    if "sigma" in robot.pose_names:
        pose = np.array(pose, dtype=np.float64)
        pose[..., 2] = pose[..., 2] - pose[..., 0]
    return pose


def _pose_values(robot, previous):
    """The midpoint of ``robots.poses.parse_pose``'s enclosure of a pose (a start for Newton iterations
    only), directly for plain decimal texts and floats; anything else goes through ``parse_pose``
    (which also reports bad input)."""
    parts = [p.strip() for p in previous.split(",")] if isinstance(previous, str) else previous
    if isinstance(parts, (list, tuple)) and len(parts) == len(robot.pose_names):
        out = []
        for v in parts:
            if isinstance(v, float):
                lo = hi = float(v)
            elif isinstance(v, str) and (ab := enclose_plain(v)) is not None:
                lo, hi = ab
            else:
                break
            if not (-np.inf < lo and hi < np.inf):
                break
            out.append(min(max(0.5 * lo + 0.5 * hi, lo), hi))     # Interval.mid
        else:
            return np.array(out)
    return parse_pose(previous, robot, "track")[0].mid()


def track_one(robot, system, texts, L: Interval, previous):
    """The tracked result for one set of leg lengths (``L``: (1, legs) squared), or None when the
    posture near ``previous`` (a pose, text or sequence) is not proved."""
    t0 = time.perf_counter()
    system = StackedFKSystem.of(system)
    pose = _pose_guess(robot, previous)
    if system.kind == "planar-3rpr":    # (x, y, cos phi, sin phi), as unknowns_of_pose (a guess only)
        x0 = np.array([pose[0], pose[1], math.cos(pose[2]), math.sin(pose[2])])
    else:
        x0 = system.unknowns_of_pose(pose)
    L2 = L.mid()
    model = []
    x, converged = newton(system, x0, L2[0], _scale(system), model=model)
    if not converged:
        return None
    proofs = prove(system, x0[None], x[None], L, L2, [m[None] for m in model])
    if not proofs.ok[0]:
        return None
    res = _tracked_results(robot, system, [texts], proofs, [0])[0]
    res.seconds = time.perf_counter() - t0
    return res


def track_rows(robot, lengths_rows, start_pose):
    """Track the posture through a sequence of leg-length sets, starting near ``start_pose``.

    ``lengths_rows``: one row per step (2-D array or list of rows; exact decimals or floats, as
    ``forward_kinematics``); ``start_pose``: the pose before the first step (text or sequence).
    Step k starts its Newton iterations from step k−1's posture (extrapolated from the last two)
    and is proved unique in a box around both (``result.tracked``); all proofs of the sequence
    run in one batched evaluation.  A step that is not proved is not guessed.

    Returns ``(results, missing)``: one ``FKResult`` per row, and the rows that were not proved;
    their result has no solution, ``complete`` false and ``tracked`` false (its claim covers only
    the posture guess).  What to do with them (the full search, ``fk.api.track_sequence``) is the
    caller's choice.
    """
    parsed = float_length_rows(robot, lengths_rows)
    if parsed is None:
        rows, texts, _ = parse_lengths(robot, lengths_rows)
        rho = Interval.from_bounds(np.array([[float(v.lo) for v in r] for r in rows]),
                                   np.array([[float(v.hi) for v in r] for r in rows]))
    else:
        rho, texts = parsed
    pose, _ = parse_pose(start_pose, robot, "start_pose")
    system = StackedFKSystem.of(fk_system(robot))
    M, n = len(texts), system.n
    L = sqr(rho)
    L2 = L.mid()
    scale = _scale(system)
    starts, xs = np.empty((M, n)), np.empty((M, n))
    converged = np.zeros(M, dtype=bool)
    x_prev = system.unknowns_of_pose(_euler(robot, pose.mid()))
    velocity = None
    for k in range(M):
        ok = False
        if velocity is not None:   # predictor: the last step's motion repeated
            x, ok = newton(system, x_prev + velocity, L2[k], scale)
            # a root farther from the prediction than the step itself: start again from x_prev
            ok = ok and (np.abs(x - x_prev - velocity) / scale).max() <= (np.abs(velocity) / scale).max() + 1e-9
        if not ok:
            x, ok = newton(system, x_prev, L2[k], scale)
        starts[k], xs[k], converged[k] = x_prev, x, ok
        velocity = x - x_prev if ok else None
        if ok:
            x_prev = x
    conv = np.nonzero(converged)[0]
    results = [None] * M
    if len(conv):
        proofs = prove(system, starts[conv], xs[conv], Interval.from_bounds(L.lo[conv], L.hi[conv]), L2[conv])
        for k, r in zip(conv[proofs.ok], _tracked_results(robot, system, [texts[k] for k in conv], proofs,
                                                          np.nonzero(proofs.ok)[0])):
            results[k] = r
    missing = [k for k in range(M) if results[k] is None]
    for k in missing:
        # nothing proved: the claim covers only the posture guess x_prev, and is incomplete
        box = (starts[k].copy(), starts[k].copy())
        results[k] = FKResult(robot, system, texts[k], box, tracked=False, complete=False, user_domain=True)
    return results, missing
