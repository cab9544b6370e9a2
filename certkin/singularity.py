"""Singularity-free regions: does det(A) keep one sign on a box of poses?

The rigorous version of the extremum method of seed 003 (Constantinescu
2004, after Merlet 1997): instead of solving the critical-point systems of
every face numerically, each box of the branch and bound is decided by

1. ``natural``: the interval extension of det(A) excludes 0;
2. ``centred``: the mean-value form det(m) + ∇det(X)·(X − m) excludes 0;
3. ``monotone``: where ∂det/∂x_i has one sign on X the extremum lies on a
   face (x_i at its bound), so det(X) ⊆ [min over F_min, max over F_max]
   with F_min, F_max the faces obtained by fixing every monotone coordinate
   at the bound that minimises (maximises) det; the faces are enclosed by
   rules 1–2;
4. otherwise the box is bisected.

For Gough-Stewart robots (no symbolic det of the 6x6 A) the natural
enclosure comes from ``linalg.det`` and the gradient from a Laplace
expansion of the compiled entries of A on dual numbers.

A box is ``singular`` as soon as two poses in it have certified det(A) of
opposite signs (the intermediate value theorem on the segment joining them,
which lies in the convex box); the witnesses come from box midpoints,
monotone extreme vertices and proved sub-boxes.  ``singularity-free``
requires every leaf proved with the same sign; a budget running out gives
``undecided`` with the boxes left.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from decimal import Decimal
import json
import time

import numpy as np

from intervals import Interval

from .engine import EXCLUDED, OPEN, PROVED, Budget, Decisions, search
from .poses import parse_box


class SingularityProblem:
    """Decides batches of boxes for the sign of det(A) (see the module docstring)."""

    def __init__(self, robot, n_roots: int):
        self.robot = robot
        self.positive = [None] * n_roots   # per root: a pose with certified det > 0
        self.negative = [None] * n_roots

    def _witness(self, roots, points, values: Interval):
        found = []
        for k in range(len(roots)):
            r = int(roots[k])
            if values.lo[k] > 0 and self.positive[r] is None:
                self.positive[r] = points[k].copy()
            elif values.hi[k] < 0 and self.negative[r] is None:
                self.negative[r] = points[k].copy()
            else:
                continue
            if self.positive[r] is not None and self.negative[r] is not None:
                found.append(r)
        return found

    def decide(self, lo, hi, roots) -> Decisions:
        n, d = lo.shape
        status = np.full(n, OPEN, dtype=np.int8)
        reason = [""] * n
        evidence = [None] * n
        box = Interval._raw(lo, hi)
        D = self.robot.det_enclosure(box)
        sign = np.where(D.lo > 0, 1, np.where(D.hi < 0, -1, 0))
        for k in np.nonzero(sign)[0]:
            status[k] = PROVED
            reason[k] = "natural"
            evidence[k] = {"sign": int(sign[k])}
        mids = box.mid()
        finished = []
        rest = np.nonzero(sign == 0)[0]
        if len(rest):
            sub = box[rest]
            m = mids[rest]
            Dm = self.robot.det_enclosure(Interval._raw(m, m.copy()))
            finished += self._witness(roots[rest], m, Dm)
            self._refine(sub, m, Dm, rest, status, reason, evidence, roots, finished)
        # proved boxes witness their sign at their midpoint
        proved = np.nonzero(status == PROVED)[0]
        if len(proved):
            signs = np.array([evidence[k]["sign"] for k in proved])
            fake = Interval._raw(signs.astype(float), signs.astype(float))
            finished += self._witness(roots[proved], mids[proved], fake)
        return Decisions(status, reason, evidence, finished=tuple(sorted(set(finished))))

    def _refine(self, sub, m, Dm, rest, status, reason, evidence, roots, finished):
        _, grad = self.robot.det_gradient(sub)
        dx = sub - Interval._raw(m, m.copy())
        centred = Dm + _dot(grad, dx)
        for j, k in enumerate(rest):
            if centred.lo[j] > 0 or centred.hi[j] < 0:
                status[k] = PROVED
                reason[k] = "centred"
                evidence[k] = {"sign": 1 if centred.lo[j] > 0 else -1}
        mono = np.where(grad.lo > 0, 1, np.where(grad.hi < 0, -1, 0)).astype(np.int8)
        todo = [j for j, k in enumerate(rest) if status[k] == OPEN and mono[j].any()]
        if not todo:
            return
        todo = np.array(todo)
        s = mono[todo]
        slo, shi = sub.lo[todo], sub.hi[todo]
        fmin_lo = np.where(s > 0, slo, np.where(s < 0, shi, slo))
        fmin_hi = np.where(s > 0, slo, np.where(s < 0, shi, shi))
        fmax_lo = np.where(s > 0, shi, np.where(s < 0, slo, slo))
        fmax_hi = np.where(s > 0, shi, np.where(s < 0, slo, shi))
        faces = Interval._raw(np.concatenate([fmin_lo, fmax_lo]), np.concatenate([fmin_hi, fmax_hi]))
        F = self._face_enclosure(faces)
        t = len(todo)
        lower, upper = F.lo[:t], F.hi[t:]
        for i, j in enumerate(todo):
            k = rest[j]
            if lower[i] > 0 or upper[i] < 0:
                status[k] = PROVED
                reason[k] = "monotone"
                evidence[k] = {"sign": 1 if lower[i] > 0 else -1, "monotone": [int(v) for v in s[i]]}
        # extreme faces that are single vertices give witnesses
        vertex = np.all(fmin_lo == fmin_hi, axis=1) & np.all(fmax_lo == fmax_hi, axis=1)
        if vertex.any():
            idx = np.nonzero(vertex)[0]
            r = roots[rest[todo[idx]]]
            pts = np.concatenate([fmin_lo[idx], fmax_lo[idx]])
            vals = Interval._raw(np.concatenate([F.lo[:t][idx], F.lo[t:][idx]]),
                                 np.concatenate([F.hi[:t][idx], F.hi[t:][idx]]))
            finished += self._witness(np.concatenate([r, r]), pts, vals)

    def _face_enclosure(self, faces: Interval) -> Interval:
        """Natural extension intersected with the centred form on the faces."""
        D = self.robot.det_enclosure(faces)
        m = faces.mid()
        Dm = self.robot.det_enclosure(Interval._raw(m, m.copy()))
        _, grad = self.robot.det_gradient(faces)
        centred = Dm + _dot(grad, faces - Interval._raw(m, m.copy()))
        return D.intersect(centred)


def _dot(grad: Interval, dx: Interval) -> Interval:
    out = grad[..., 0] * dx[..., 0]
    for i in range(1, grad.shape[-1]):
        out = out + grad[..., i] * dx[..., i]
    return out


@dataclass
class SingularityResult:
    """The verdict on one box: ``status`` in singularity-free | singular | undecided."""

    robot: object
    box: dict                       # exact texts {name: [lo, hi]}
    lo: np.ndarray                  # the float box searched (encloses ``box``)
    hi: np.ndarray
    status: str
    sign: int = 0                   # sign of det(A) when singularity-free
    witnesses: dict | None = None   # {"positive": pose, "negative": pose} when singular
    tree: object = None             # the search tree (engine.Node)
    undecided: list = field(default_factory=list)
    boxes: int = 0
    seconds: float = 0.0
    scale_factor: float | None = None  # for largest_free_box

    def to_json(self) -> dict:
        out = {"problem": "singularity", "robot": self.robot.name, "kind": self.robot.kind,
               "box": {n: [float(a), float(b)] for n, a, b in zip(self.robot.pose_names, self.lo, self.hi)},
               "status": self.status}
        if self.status == "singularity-free":
            out["sign"] = self.sign
        if self.witnesses:
            out["witnesses"] = {k: dict(zip(self.robot.pose_names, map(float, v))) for k, v in self.witnesses.items()}
        if self.status == "undecided":
            out["undecided_boxes"] = [{n: [float(a), float(b)] for n, a, b in zip(self.robot.pose_names, l, h)}
                                      for l, h in self.undecided[:100]]
            out["undecided_count"] = len(self.undecided)
        if self.scale_factor is not None:
            out["scale_factor"] = self.scale_factor
        out["stats"] = {"boxes": self.boxes, "seconds": round(self.seconds, 6)}
        return out

    def certificate(self) -> dict:
        from .certificates import singularity_certificate
        return singularity_certificate(self)


def _verdict(robot, problem, node, r):
    """Status, sign, witnesses and undecided boxes of one root of the search."""
    pos, neg = problem.positive[r], problem.negative[r]
    if pos is not None and neg is not None:
        return "singular", 0, {"positive": pos, "negative": neg}, []
    leaves = list(node.leaves())
    undecided = [(l.lo, l.hi) for l in leaves if l.status != "proved"]
    if undecided:
        return "undecided", 0, None, undecided
    signs = {l.evidence["sign"] for l in leaves}
    if len(signs) == 1:
        return "singularity-free", signs.pop(), None, []
    raise AssertionError("leaves of both signs without witnesses")  # witnesses are recorded for every proved leaf


def certify_singularity_free(robot, box, budget: Budget | None = None, progress=None) -> SingularityResult:
    """Prove that det(A) keeps one sign on ``box``, or exhibit a sign change.

    ``box`` is ``"x=a:b,y=c:d,phi=e:f"`` or ``{name: (lo, hi)}`` with exact
    decimals.  Returns a ``SingularityResult`` whose ``status`` is
    ``singularity-free`` (with ``sign``), ``singular`` (with two witness
    poses of opposite certified signs) or ``undecided``.
    """
    return classify_cells(robot, box, 1, budget, progress)[0]


def classify_cells(robot, box, n: int, budget: Budget | None = None, progress=None) -> list[SingularityResult]:
    """Split ``box`` into n^d cells (fixed coordinates stay fixed) and decide each one."""
    iv, texts = parse_box(box, robot) if not isinstance(box, tuple) else box
    lo0, hi0 = iv.lo, iv.hi
    free = hi0 > lo0
    counts = [n if f else 1 for f in free]
    grids = [np.linspace(lo0[i], hi0[i], c + 1) for i, c in enumerate(counts)]
    for i in range(len(grids)):
        grids[i][0], grids[i][-1] = lo0[i], hi0[i]
    idx = np.stack(np.meshgrid(*[np.arange(c) for c in counts], indexing="ij"), -1).reshape(-1, len(counts))
    clo = np.array([[grids[i][j[i]] for i in range(len(counts))] for j in idx])
    chi = np.array([[grids[i][j[i] + 1] for i in range(len(counts))] for j in idx])
    problem = SingularityProblem(robot, len(idx))
    scale = np.where(free, hi0 - lo0, 1.0)
    budget = budget or Budget(max_boxes=200_000, max_seconds=60.0, min_width=1e-7)
    res = search(problem, clo, chi, scale=scale, budget=budget, progress=progress)
    out = []
    per_cell_seconds = res.seconds / max(1, len(idx))
    for r, node in enumerate(res.roots):
        status, sign, wit, und = _verdict(robot, problem, node, r)
        nboxes = sum(1 for _ in node.leaves())
        out.append(SingularityResult(robot, texts if len(idx) == 1 else _cell_texts(robot, clo[r], chi[r]),
                                     clo[r], chi[r], status, sign, wit, node, und, nboxes, per_cell_seconds))
    if len(idx) == 1:
        out[0].boxes, out[0].seconds = res.boxes, res.seconds
    return out


def _cell_texts(robot, lo, hi):
    """The exact decimal values of a cell's float bounds (``Decimal(float)`` is exact)."""
    return {n: [str(Decimal(float(a))), str(Decimal(float(b)))] for n, a, b in zip(robot.pose_names, lo, hi)}


def largest_free_box(robot, pose, scale=None, budget: Budget | None = None, steps: int = 24) -> SingularityResult:
    """The largest box ``pose ± s·scale`` proved singularity-free (bisection on s).

    ``scale`` gives the half-widths of the unit box (default 1 in every
    variable: length units and radians).  The returned result carries the
    certified box and its tree; ``result.scale_factor`` is s.  If the pose
    itself cannot be proved regular, the result is ``undecided`` with s = 0.
    """
    from .errors import InputError
    from .poses import parse_pose
    center, texts = parse_pose(pose, robot, "--around") if not isinstance(pose, Interval) else (pose, None)
    d = len(robot.pose_names)
    if scale is None:
        sc = np.ones(d)
    else:
        parts = scale.split(",") if isinstance(scale, str) else list(scale)
        try:
            sc = np.array([float(p) for p in parts], dtype=np.float64)
        except ValueError:
            raise InputError("--scale", "", f"expected {d} comma-separated positive numbers") from None
        if len(sc) != d or not np.all(np.isfinite(sc)) or np.any(sc <= 0):
            raise InputError("--scale", "", f"expected {d} comma-separated positive numbers")
    budget = budget or Budget(max_boxes=20_000, max_seconds=10.0, min_width=1e-7)

    def attempt(s):
        lo, hi = center.lo - s * sc, center.hi + s * sc
        iv = Interval._raw(lo, hi)
        texts_s = _cell_texts(robot, lo, hi)
        r = classify_cells(robot, (iv, texts_s), 1, budget)[0]
        r.scale_factor = s
        return r

    best = attempt(0.0)
    if best.status != "singularity-free":
        return best
    good, bad = 0.0, None
    s = 2.0 ** -10
    while s <= 2.0 ** 20:
        r = attempt(s)
        if r.status == "singularity-free":
            best, good = r, s
            s *= 2
        else:
            bad = s
            break
    if bad is None:
        return best
    for _ in range(steps):
        mid = 0.5 * (good + bad)
        r = attempt(mid)
        if r.status == "singularity-free":
            best, good = r, mid
        else:
            bad = mid
    return best
