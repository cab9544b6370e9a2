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

import numpy as np

from intervals import Interval

from .certificates import singularity_certificate
from .engine import OPEN, PROVED, Budget, Decisions, budgets, search
from .errors import InputError
from .robots.poses import inner_box, parse_box, parse_pose


class SingularityProblem:
    """Decides batches of boxes for the sign of det(A) (see the module docstring)."""

    reasons = ("natural", "centred", "monotone")

    def __init__(self, robot, n_roots: int, inner=None):
        self.robot = robot
        self.inner = inner                       # per root: float bounds inside the exact requested box
        d = len(robot.pose_names)
        self.positive = np.zeros((n_roots, d))   # per root: a pose with certified det > 0
        self.negative = np.zeros((n_roots, d))
        self.has_positive = np.zeros(n_roots, dtype=bool)
        self.has_negative = np.zeros(n_roots, dtype=bool)

    def _witness(self, roots, points, signs):
        """Record the first pose of each certified sign per root; returns the roots with both.

        A witness must lie in the exact requested box (``inner``, ``poses.inner_box``): points outside it
        are moved onto its faces, and coordinates that take an exact irrational value are evaluated
        over its enclosure; their signs are computed again."""
        if self.inner is not None:
            wlo, whi, exact = (np.broadcast_to(a, points.shape) for a in self.inner)
            moved = np.any((points < wlo) | (points > whi) | exact, axis=1)
            if moved.any():
                at = np.clip(points[moved], wlo[moved], whi[moved])
                box = Interval.from_bounds(np.where(exact[moved], wlo[moved], at), np.where(exact[moved], whi[moved], at))
                points, signs = points.copy(), np.array(signs, copy=True)
                points[moved], signs[moved] = box.lo, _sign(self.robot.det_enclosure(box))
        for s, has, store in ((1, self.has_positive, self.positive), (-1, self.has_negative, self.negative)):
            sel = (signs == s) & ~has[roots]
            if sel.any():
                r, first = np.unique(roots[sel], return_index=True)
                store[r] = points[sel][first]
                has[r] = True
        return np.nonzero(self.has_positive & self.has_negative)[0]

    def decide(self, lo, hi, roots) -> Decisions:
        n, d = lo.shape
        box = Interval.from_bounds(lo, hi)
        D = self.robot.det_enclosure(box)
        sign = _sign(D)
        reason = np.zeros(n, dtype=np.int64)             # natural
        mono = np.zeros((n, d), dtype=np.int8)
        mids = box.mid()
        rest = np.nonzero(sign == 0)[0]
        if len(rest):
            m = mids[rest]
            Dm = self.robot.det_enclosure(Interval.from_bounds(m, m.copy()))
            self._witness(roots[rest], m, _sign(Dm))
            s, r, flags = self._refine(box[rest], m, Dm, roots[rest])
            sign[rest], reason[rest], mono[rest] = s, r, flags
        # proved boxes witness their sign at their midpoint
        self._witness(roots, mids, sign)
        finished = np.nonzero(self.has_positive & self.has_negative)[0]
        status = np.where(sign != 0, PROVED, OPEN).astype(np.int8)
        return Decisions(status, reason, {"sign": sign.astype(np.int8), "monotone": mono}, finished=finished)

    def _refine(self, sub, m, Dm, roots):
        """Centred form, then the monotonicity rule, on boxes the natural extension left open.

        Returns (sign, reason code, monotone flags) per box (sign 0: still open).
        """
        n, d = sub.shape
        _, grad = self.robot.det_gradient(sub)
        dx = sub - Interval.from_bounds(m, m.copy())
        sign = _sign(Dm + _dot(grad, dx))
        reason = np.where(sign != 0, 1, 0)
        flags = np.zeros((n, d), dtype=np.int8)
        mono = np.where(grad.lo > 0, 1, np.where(grad.hi < 0, -1, 0)).astype(np.int8)
        todo = np.nonzero((sign == 0) & mono.any(axis=1))[0]
        if not len(todo):
            return sign, reason, flags
        s = mono[todo]
        slo, shi = sub.lo[todo], sub.hi[todo]
        # F_min: each monotone coordinate at the bound minimising det; F_max: maximising
        fmin_lo = np.where(s > 0, slo, np.where(s < 0, shi, slo))
        fmin_hi = np.where(s > 0, slo, np.where(s < 0, shi, shi))
        fmax_lo = np.where(s > 0, shi, np.where(s < 0, slo, slo))
        fmax_hi = np.where(s > 0, shi, np.where(s < 0, slo, shi))
        faces = Interval.from_bounds(np.concatenate([fmin_lo, fmax_lo]), np.concatenate([fmin_hi, fmax_hi]))
        F = self._face_enclosure(faces)
        t = len(todo)
        lower, upper = F.lo[:t], F.hi[t:]
        got = np.where(lower > 0, 1, np.where(upper < 0, -1, 0))
        sign[todo] = got
        reason[todo] = np.where(got != 0, 2, 0)
        flags[todo] = np.where(got[:, None] != 0, s, 0)
        # extreme faces that are single vertices give witnesses
        vertex = np.all(fmin_lo == fmin_hi, axis=1) & np.all(fmax_lo == fmax_hi, axis=1)
        if vertex.any():
            idx = np.nonzero(vertex)[0]
            pts = np.concatenate([fmin_lo[idx], fmax_lo[idx]])
            vals = Interval.from_bounds(np.concatenate([F.lo[:t][idx], F.lo[t:][idx]]),
                                 np.concatenate([F.hi[:t][idx], F.hi[t:][idx]]))
            r = roots[todo[idx]]
            self._witness(np.concatenate([r, r]), pts, _sign(vals))
        return sign, reason, flags

    def _face_enclosure(self, faces: Interval) -> Interval:
        """Natural extension intersected with the centred form on the faces."""
        D = self.robot.det_enclosure(faces)
        m = faces.mid()
        Dm = self.robot.det_enclosure(Interval.from_bounds(m, m.copy()))
        _, grad = self.robot.det_gradient(faces)
        centred = Dm + _dot(grad, faces - Interval.from_bounds(m, m.copy()))
        return D.intersect(centred)


def _sign(D: Interval) -> np.ndarray:
    """1 where the enclosure is > 0, -1 where < 0, else 0."""
    return np.where(D.lo > 0, 1, np.where(D.hi < 0, -1, 0))


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
    tree: object = None             # the search tree (engine.Tree), shared by the cells of one run
    node: int = 0                   # the root node of this box in ``tree``
    undecided: list = field(default_factory=list)
    boxes: int = 0
    seconds: float = 0.0
    scale_factor: float | None = None  # for largest_free_box
    exact_values: dict = field(default_factory=dict)   # witness coordinates that are an exact text ({name: text})

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

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory)."""
        return singularity_certificate(self)


def _verdicts(problem, tree):
    """Per root of the search: (status, sign, witnesses, undecided boxes), computed on arrays."""
    n = tree.n_roots
    leaf = tree.leaf_mask()
    proved = tree.kind == PROVED
    sign = np.zeros(len(tree), dtype=np.int64)
    if proved.any():
        sign[proved] = tree.evidence_values("sign", np.nonzero(proved)[0])
    positive = np.bincount(tree.root[proved & (sign > 0)], minlength=n)
    negative = np.bincount(tree.root[proved & (sign < 0)], minlength=n)
    open_ = leaf & ~proved
    open_ids = np.nonzero(open_)[0]
    open_ids = open_ids[np.argsort(tree.root[open_ids], kind="stable")]
    starts = np.searchsorted(tree.root[open_ids], np.arange(n + 1))
    out = []
    for r in range(n):
        if problem.has_positive[r] and problem.has_negative[r]:
            out.append(("singular", 0, {"positive": problem.positive[r].copy(),
                                        "negative": problem.negative[r].copy()}, []))
        elif starts[r + 1] > starts[r]:
            ids = open_ids[starts[r]:starts[r + 1]]
            out.append(("undecided", 0, None, list(zip(tree.lo[ids], tree.hi[ids]))))
        elif positive[r] and negative[r]:  # every proved leaf gives a witness, so this cannot happen
            raise AssertionError("leaves of both signs without witnesses")
        else:
            out.append(("singularity-free", 1 if positive[r] else -1, None, []))
    return out


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
    for g, a, b in zip(grids, lo0, hi0):
        g[0], g[-1] = a, b  # the outer faces are exactly the box's
    idx = np.stack(np.meshgrid(*[np.arange(c) for c in counts], indexing="ij"), -1).reshape(-1, len(counts))
    clo = np.stack([grids[i][idx[:, i]] for i in range(len(counts))], axis=1)
    chi = np.stack([grids[i][idx[:, i] + 1] for i in range(len(counts))], axis=1)
    inner = inner_box(texts, robot) if len(idx) == 1 else None      # cells: their float bounds are exact
    problem = SingularityProblem(robot, len(idx), inner)
    scale = np.where(free, hi0 - lo0, 1.0)
    budget = budget or Budget(**budgets.SINGULARITY)
    res = search(problem, clo, chi, scale=scale, budget=budget, progress=progress)
    tree = res.tree
    out = []
    per_cell_seconds = res.seconds / max(1, len(idx))
    nodes = np.bincount(tree.root, minlength=len(idx))
    for r, (status, sign, wit, und) in enumerate(_verdicts(problem, tree)):
        nboxes = int(nodes[r])
        out.append(SingularityResult(robot, texts if len(idx) == 1 else _cell_texts(robot, clo[r], chi[r]),
                                     clo[r], chi[r], status, sign, wit, tree, r, und, nboxes, per_cell_seconds))
    if len(idx) == 1:
        out[0].boxes, out[0].seconds = res.boxes, res.seconds
        out[0].exact_values = {name: texts[name][0] for name, e in zip(robot.pose_names, inner[2]) if e}
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
    center, texts = parse_pose(pose, robot, "pose") if not isinstance(pose, Interval) else (pose, None)
    d = len(robot.pose_names)
    if scale is None:
        sc = np.ones(d)
    else:
        parts = scale.split(",") if isinstance(scale, str) else list(scale)
        try:
            sc = np.array([float(p) for p in parts], dtype=np.float64)
        except ValueError:
            raise InputError("scale", "", f"expected {d} comma-separated positive numbers") from None
        if len(sc) != d or not np.all(np.isfinite(sc)) or np.any(sc <= 0):
            raise InputError("scale", "", f"expected {d} comma-separated positive numbers")
    budget = budget or Budget(**budgets.LARGEST_FREE_BOX)

    def attempt(s):
        lo, hi = center.lo - s * sc, center.hi + s * sc
        iv = Interval.from_bounds(lo, hi)
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
