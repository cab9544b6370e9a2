"""Forward kinematics: every real assembly mode, each in a box proved to hold exactly one.

The equations are written with unknowns that keep them polynomial of
degree two (``robots`` give the systems: planar (x, y, c, s) with
c² + s² = 1, which covers every real posture since (c, s) ranges over the
whole unit circle).  The shared engine decides each box:

1. ``equation``: the enclosure of one equation over the box misses 0 — no
   solution in the box;
2. ``krawczyk-empty``: K(X) ∩ X = ∅ — no solution (Krawczyk 1969, Moore 1977);
3. ``krawczyk-unique``: K(X*) ⊂ int X* for a box X* ⊇ X — exactly one
   solution in X*, hence at most one in X (X* is X itself or X inflated
   around a Newton iterate when X is small);
4. otherwise X is contracted to K(X) ∩ X (slightly inflated, so that an
   independent re-computation still contains it) and bisected.

Solutions are then merged (two proofs whose solution enclosure lies inside
the other's X* concern the same root), and boxes left undecided (near a
double root, or at the resolution limit) are grouped into ``unresolved``
clusters: never reported as two roots, nor as none.  ``complete`` is true
only when every box of the domain was excluded or proved.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from intervals import Interval, linalg, sqr

from .engine import EXCLUDED, OPEN, PROVED, Budget, Decisions, search
from .errors import InputError

MARGIN = 2.0 ** -30      # relative safety margin of the proofs (room for an independent re-check)
INFLATE_BELOW = 1e-3     # scaled width under which a Newton-inflated box X* is tried


def _margin_box(lo, hi, rel=MARGIN):
    w = (hi - lo) * rel + 1e-300
    return lo + w, hi - w


class FKProblem:
    """Decides boxes of FK unknowns for a batch of instances (one root box per instance)."""

    def __init__(self, system, params_per_root: list[Interval], scale):
        self.system = system
        self.params = params_per_root     # list of Interval arrays (M,) per parameter, or 0-d
        self.scale = scale

    def _p(self, roots):
        return [p if p.ndim == 0 else p[roots] for p in self.params]

    def decide(self, lo, hi, roots) -> Decisions:
        n, d = lo.shape
        status = np.full(n, OPEN, dtype=np.int8)
        reason = [""] * n
        evidence = [None] * n
        X = Interval._raw(lo, hi)
        F = self.system.equations(X, self._p(roots))
        out = (F.lo > 0) | (F.hi < 0)
        excl = out.any(axis=1)
        for k in np.nonzero(excl)[0]:
            status[k] = EXCLUDED
            reason[k] = "equation"
            evidence[k] = {"equation": int(np.argmax(out[k]))}
        clo, chi = lo.copy(), hi.copy()
        rest = np.nonzero(~excl)[0]
        if len(rest):
            self._krawczyk(lo[rest], hi[rest], roots[rest], rest, status, reason, evidence, clo, chi)
        return Decisions(status, reason, evidence, contracted=(clo, chi))

    def _krawczyk(self, lo, hi, roots, rest, status, reason, evidence, clo, chi):
        P = self._p(roots)
        X = Interval._raw(lo, hi)
        _, J = self.system.equations.jacobian(X, P)
        c = X.mid()
        fc = self.system.equations(Interval._raw(c, c.copy()), P)
        K, unique, empty, C = linalg.krawczyk(fc, J, X, c)
        inner_lo, inner_hi = _margin_box(lo, hi)
        unique = np.all((K.lo > inner_lo) & (K.hi < inner_hi), axis=1)
        kx = K.intersect(X)
        empty = np.any(kx.lo > kx.hi, axis=1) & np.all(np.isfinite(K.lo) & np.isfinite(K.hi), axis=1)
        for j, k in enumerate(rest):
            if empty[j]:
                status[k] = EXCLUDED
                reason[k] = "krawczyk-empty"
                evidence[k] = {"c": c[j].tolist(), "C": C[j].tolist()}
            elif unique[j]:
                status[k] = PROVED
                reason[k] = "krawczyk-unique"
                evidence[k] = {"c": c[j].tolist(), "C": C[j].tolist(), "star": np.stack([lo[j], hi[j]], 1).tolist()}
        open_ = np.nonzero(~(empty | unique))[0]
        if not len(open_):
            return
        # contraction: K(X) ∩ X, widened by a relative margin and kept inside X
        w = (hi[open_] - lo[open_]) * 2.0 ** -20
        nlo = np.maximum(lo[open_], np.where(np.isfinite(K.lo[open_]), K.lo[open_] - w, lo[open_]))
        nhi = np.minimum(hi[open_], np.where(np.isfinite(K.hi[open_]), K.hi[open_] + w, hi[open_]))
        ok = np.all(nlo <= nhi, axis=1)
        idx = rest[open_[ok]]
        clo[idx], chi[idx] = nlo[ok], nhi[ok]
        # small boxes: try a Newton-inflated box X* around the root
        small = open_[np.max((hi[open_] - lo[open_]) / self.scale, axis=1) < INFLATE_BELOW]
        if len(small):
            self._inflate(lo[small], hi[small], roots[small], rest[small], C[small], status, reason, evidence)

    def _inflate(self, lo, hi, roots, idx, C, status, reason, evidence):
        P = self._p(roots)
        x = 0.5 * (lo + hi)
        for _ in range(4):  # float Newton steps with the preconditioner (not rigorous: only a guess)
            f = self.system.equations(Interval._raw(x, x.copy()), P)
            x = x - np.einsum("nij,nj->ni", C, 0.5 * (f.lo + f.hi))
        r = np.maximum(np.abs(x - 0.5 * (lo + hi)), hi - lo) + 1e-12 * self.scale
        slo, shi = np.minimum(lo, x - r), np.maximum(hi, x + r)
        S = Interval._raw(slo, shi)
        _, J = self.system.equations.jacobian(S, P)
        c = S.mid()
        fc = self.system.equations(Interval._raw(c, c.copy()), P)
        K, _, _, Cs = linalg.krawczyk(fc, J, S, c)
        inner_lo, inner_hi = _margin_box(slo, shi)
        unique = np.all((K.lo > inner_lo) & (K.hi < inner_hi), axis=1)
        for j, k in enumerate(idx):
            if unique[j]:
                status[k] = PROVED
                reason[k] = "krawczyk-unique"
                evidence[k] = {"c": c[j].tolist(), "C": Cs[j].tolist(), "star": np.stack([slo[j], shi[j]], 1).tolist()}


def tighten(system, params, star_lo, star_hi, steps=6):
    """Iterate X <- K(X) ∩ X from a box proved to hold one root: a tight enclosure of it."""
    X = Interval._raw(star_lo[None, :].copy(), star_hi[None, :].copy())
    for _ in range(steps):
        _, J = system.equations.jacobian(X, params)
        c = X.mid()
        fc = system.equations(Interval._raw(c, c.copy()), params)
        K, _, _, _ = linalg.krawczyk(fc, J, X, c)
        X = K.intersect(X)
        if np.any(X.lo > X.hi):
            return None
    return X[0]


@dataclass
class FKResult:
    """All real assembly modes for one set of leg lengths."""

    robot: object
    lengths: list                       # exact texts
    domain: tuple                       # (lo, hi) of the unknowns searched
    solutions: list = field(default_factory=list)    # dicts: status, unknowns box, pose, platform_points
    unresolved: list = field(default_factory=list)
    complete: bool = False
    tree: object = None
    boxes: int = 0
    seconds: float = 0.0

    def to_json(self) -> dict:
        def entry(s, with_status):
            e = {"pose": {k: [float(v.lo), float(v.hi)] for k, v in s["pose"].items()},
                 "platform_points": [[[float(c.lo), float(c.hi)] for c in p] for p in s["platform_points"]]}
            if with_status:
                e = {"status": "unique", **e}
            return e
        return {"problem": "forward-kinematics", "robot": self.robot.name, "kind": self.robot.kind,
                "lengths": self.lengths, "complete": self.complete,
                "solutions": [entry(s, True) for s in self.solutions],
                "unresolved": [entry(s, False) for s in self.unresolved],
                "stats": {"boxes": self.boxes, "seconds": round(self.seconds, 6)}}

    def certificate(self) -> dict:
        from .certificates import fk_certificate
        return fk_certificate(self)


def _clusters(boxes):
    """Group boxes that touch or overlap (union-find on pairwise contact)."""
    n = len(boxes)
    parent = list(range(n))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    for i in range(n):
        for j in range(i + 1, n):
            (a, b), (c, d) = boxes[i], boxes[j]
            if np.all(a <= d) and np.all(c <= b):
                parent[find(i)] = find(j)
    groups = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return [(np.min([boxes[i][0] for i in g], axis=0), np.max([boxes[i][1] for i in g], axis=0)) for g in groups.values()]


def forward_kinematics(robot, lengths, domain=None, budget: Budget | None = None, progress=None):
    """All real FK postures for the leg lengths ``lengths`` (one set, or a 2-D array: one row per instance).

    Returns an ``FKResult`` (or a list of them for a 2-D input) whose
    ``solutions`` are each proved unique in their box, and whose
    ``complete`` is true when the rest of the domain is proved empty.
    """
    from .robots.fk_systems import fk_system
    system = fk_system(robot)
    rows, texts = _parse_lengths(robot, lengths)
    M = len(rows)
    lo, hi = system.domain(robot, rows, domain)
    L2 = [Interval._raw(np.array([r[i].lo for r in rows]), np.array([r[i].hi for r in rows])) for i in range(robot.n_legs)]
    L2 = [sqr(l) for l in L2]
    params = list(robot.parameters) + L2
    scale = np.max(hi - lo, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    problem = FKProblem(system, params, scale)
    budget = budget or Budget(max_boxes=200_000 * max(1, M), max_seconds=60.0, min_width=1e-10)
    res = search(problem, lo, hi, scale=scale, budget=budget, batch=max(256, min(4096, 64 * M)), progress=progress)
    out = []
    for r, node in enumerate(res.roots):
        P = [p if p.ndim == 0 else p[r] for p in params]
        out.append(_collect(robot, system, texts[r], (lo[r], hi[r]), node, P))
        out[-1].boxes = sum(1 for _ in node.leaves())
        out[-1].seconds = res.seconds / M
    if np.ndim(lengths) == 2 or (isinstance(lengths, list) and lengths and isinstance(lengths[0], (list, tuple, np.ndarray))):
        return out
    out[0].boxes, out[0].seconds = res.boxes, res.seconds
    return out[0]


def _collect(robot, system, texts, dom, node, P) -> FKResult:
    result = FKResult(robot, texts, dom, tree=node)
    roots, pending = [], []
    for leaf in node.leaves():
        if leaf.status == "proved":
            star = np.array(leaf.evidence["star"])
            R = tighten(system, P, star[:, 0], star[:, 1])
            if R is None:  # cannot happen for a proved box; never drop a root silently
                pending.append((leaf.lo, leaf.hi))
                continue
            roots.append((R, star))
        elif leaf.status == "undecided":
            pending.append((leaf.lo, leaf.hi))
    distinct = []
    for R, star in roots:
        inside_dom = np.all(R.lo >= dom[0]) and np.all(R.hi <= dom[1])
        outside_dom = np.any(R.hi < dom[0]) or np.any(R.lo > dom[1])
        if outside_dom:
            continue
        if not inside_dom:
            pending.append((R.lo, R.hi))
            continue
        if not system.in_user_domain(R):
            continue
        same = ambiguous = False
        for R2, star2 in distinct:
            if (np.all(R.lo >= star2[:, 0]) and np.all(R.hi <= star2[:, 1])) or \
               (np.all(R2.lo >= star[:, 0]) and np.all(R2.hi <= star[:, 1])):
                same = True  # one root enclosure lies in the other's uniqueness box: the same root
                break
            if np.all(R.lo <= R2.hi) and np.all(R2.lo <= R.hi):
                ambiguous = True  # overlapping enclosures without a shared proof: cannot separate
        if ambiguous and not same:
            pending.append((R.lo, R.hi))
        elif not same:
            distinct.append((R, star))
    for R, star in distinct:
        result.solutions.append({"status": "unique", "box": R, "pose": system.pose(R), "platform_points": system.points(robot, R, P)})
    for lo, hi in _clusters(pending):
        B = Interval._raw(lo, hi)
        result.unresolved.append({"box": B, "pose": system.pose(B), "platform_points": system.points(robot, B, P)})
    result.complete = not pending
    result.solutions.sort(key=lambda s: [float(v.lo) for v in s["pose"].values()])
    return result


def _parse_lengths(robot, lengths):
    from .robots.base import parse_number
    if isinstance(lengths, str):
        lengths = [p.strip() for p in lengths.split(",")]
    arr = np.asarray(lengths, dtype=object)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != robot.n_legs:
        raise InputError("--lengths", "", f"expected {robot.n_legs} leg lengths per instance")
    rows, texts = [], []
    for i, row in enumerate(arr):
        ivs, ts = [], []
        for j, v in enumerate(row):
            if isinstance(v, (float, np.floating)):
                v = repr(float(v))  # a float is its exact binary value; keep that text
            try:
                iv, t = parse_number(v, "--lengths", f"[{i}][{j}]" if len(arr) > 1 else f"leg {j + 1}")
            except InputError as exc:
                raise InputError("--lengths", exc.field, exc.problem) from None
            if float(iv.hi) < 0:
                raise InputError("--lengths", f"leg {j + 1}", f"a leg length cannot be negative ({t})")
            ivs.append(iv)
            ts.append(str(t))
        rows.append(ivs)
        texts.append(ts)
    return rows, texts
