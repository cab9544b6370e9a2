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
from fractions import Fraction
import math

import numpy as np

from intervals import Interval

from . import display
from .certificates import singularity_certificate
from .certificates.singularity import least_header
from .certificates import writing
from .engine import OPEN, PROVED, Budget, Decisions, budgets, interrupt, search
from .engine.budgets import Clock, make_budget, positive_integer, progress_callback
from .errors import InputError, shown
from .quiet import quiet
from .robots import as_robot
from .robots.poses import MAX_MAGNITUDE, inner_box, parse_box, parse_pose

MAX_SCALE = 1e12        # half-widths of the unit box of ``largest_free_box``, at most


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


@dataclass(repr=False)
class SingularityResult:
    """The verdict on one box: ``status`` in singularity-free | singular | undecided."""

    robot: object
    texts: dict | None              # exact texts {name: [lo, hi]} of the box asked (None: ``lo``, ``hi`` exactly)
    lo: np.ndarray                  # the float box searched (encloses ``box``)
    hi: np.ndarray
    status: str
    sign: int = 0                   # sign of det(A) when singularity-free
    witnesses: dict | None = None   # {"positive": pose, "negative": pose} when singular
    tree: object = None             # the search tree (engine.Tree), shared by the cells of one run
    node: int = 0                   # the root node of this box in ``tree``
    undecided: list = field(default_factory=list)
    boxes: int = 0                  # the boxes of its search (a cell: the nodes of its part of the shared tree)
    seconds: float = 0.0
    search_boxes: int = 0           # the boxes the search decided for all the cells of its run together
    scale_factor: float | None = None  # for largest_free_box
    around: dict | None = None         # for largest_free_box: {"pose": texts, "scale": half-widths of the unit box}
    bisection: dict | None = None      # for largest_free_box: how the search for s went (see there)
    exact_values: dict = field(default_factory=dict)   # witness coordinates that are an exact text ({name: text})

    def witness(self, key: str, text: bool = False) -> list:
        """The witness pose ``key`` ("positive", "negative"): floats, except the coordinates given one
        exact value (a fixed ``phi=0.001``), which are their text (``text``) or the float nearest to it,
        never the bound of their enclosure (the sign is proved on the whole enclosure, which lies partly
        outside the box asked about)."""
        return [(t if text else _nearest(t)) if (t := self.exact_values.get(n)) is not None else float(v)
                for n, v in zip(self.robot.pose_names, self.witnesses[key])]

    @property
    def box(self) -> dict:
        """The exact texts {name: [lo, hi]} of the box (a cell's: the exact values of its floats)."""
        return self.texts if self.texts is not None else _cell_texts(self.robot, self.lo, self.hi)

    def __repr__(self):
        show = display.inward if self.status == "singularity-free" else display.outward    # a free box: inward
        box = ", ".join(f"{n}={show(a, b, 6)}" for n, a, b in zip(self.robot.pose_names, self.lo, self.hi))
        return f"<SingularityResult {self.status}: {box}>"

    def to_json(self) -> dict:
        """The result as a JSON-ready dict (``json.dumps(result.to_json())``): the fields of
        ``certkin singular --json``."""
        names = self.robot.pose_names
        out = {"problem": "singularity", "robot": self.robot.name, "kind": self.robot.kind,
               "box": {n: [float(a), float(b)] for n, a, b in zip(names, self.lo.tolist(), self.hi.tolist())},
               "status": self.status}
        if self.status == "singularity-free":
            out["sign"] = self.sign
        if self.witnesses:
            out["witnesses"] = {k: dict(zip(names, self.witness(k))) for k in self.witnesses}
        if self.status == "undecided":
            out["undecided_boxes"] = [{n: [float(a), float(b)] for n, a, b in zip(names, l, h)}
                                      for l, h in self.undecided[:100]]
            out["undecided_count"] = len(self.undecided)
        if self.scale_factor is not None:
            out["scale_factor"] = self.scale_factor
        if self.around is not None:
            out["around"] = self.around
        if self.bisection is not None:
            out["bisection"] = self.bisection
        out["stats"] = {"boxes": self.boxes, "seconds": round(self.seconds, 6)}
        return out

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory)."""
        return singularity_certificate(self)


SINGULAR, UNDECIDED_, FREE = 0, 1, 2
STATUS = {SINGULAR: "singular", UNDECIDED_: "undecided", FREE: "singularity-free"}
CELL_BYTES = 7000          # memory of one cell's result, its record, JSON and certificate (measured: 5 to 6.4 kB)
CELL_SECONDS = 20e-6       # per pose variable: time to build, print and write one cell's answer after the search
                           # (measured with a certificate and JSON: planar 47 µs, Gough-Stewart 77 to 175 µs;
                           # a plot or a report comes on top)


def _verdicts(problem, tree):
    """Per root of the search: (status codes, signs, open leaf ids sorted by root, their starts),
    computed on arrays."""
    n = tree.n_roots
    leaf = tree.leaf_mask()
    proved = tree.kind == PROVED
    sign = np.zeros(len(tree), dtype=np.int64)
    if proved.any():
        sign[proved] = tree.evidence_values("sign", np.nonzero(proved)[0])
    positive = np.bincount(tree.root[proved & (sign > 0)], minlength=n)
    negative = np.bincount(tree.root[proved & (sign < 0)], minlength=n)
    open_ids = np.nonzero(leaf & ~proved)[0]
    open_ids = open_ids[np.argsort(tree.root[open_ids], kind="stable")]
    starts = np.searchsorted(tree.root[open_ids], np.arange(n + 1))
    singular = problem.has_positive & problem.has_negative
    undecided = ~singular & (starts[1:] > starts[:-1])
    if np.any(~singular & ~undecided & (positive > 0) & (negative > 0)):
        raise AssertionError("leaves of both signs without witnesses")   # every proved leaf gives a witness
    status = np.where(singular, SINGULAR, np.where(undecided, UNDECIDED_, FREE))
    signs = np.where(status == FREE, np.where(positive > 0, 1, -1), 0)
    return status, signs, open_ids, starts


@quiet
def certify_singularity_free(robot, box, budget: Budget | None = None, progress=None, *, max_boxes=None,
                             max_seconds=None, min_width=None, max_memory=None) -> SingularityResult:
    """Prove that det(A) keeps one sign on ``box``, or exhibit a sign change.

    ``robot``: a robot or a robot file's path.  ``box`` is ``"x=a:b,y=c:d,phi=e:f"`` or
    ``{name: (lo, hi)}`` with exact decimals (a name given one value is fixed).  The budget
    (``budget``, or the keywords ``max_boxes``, ``max_seconds``, ``min_width``, ``max_memory``)
    bounds the search.  Returns a ``SingularityResult`` whose ``status`` is ``singularity-free``
    (with ``sign``), ``singular`` (with two witness poses of opposite certified signs) or
    ``undecided``.
    """
    return classify_cells(robot, box, 1, budget, progress, max_boxes=max_boxes, max_seconds=max_seconds,
                          min_width=min_width, max_memory=max_memory)[0]


@quiet
def classify_cells(robot, box, n: int, budget: Budget | None = None, progress=None, *, max_boxes=None,
                   max_seconds=None, min_width=None, max_memory=None, certificate=False) -> list[SingularityResult]:
    """Split ``box`` into n^k cells (k: the coordinates given as ranges; a coordinate given one
    value is fixed, never split) and decide each one.

    Each cell is a root of one search; cells the budget does not reach are ``undecided``.  More
    cells than ``max_boxes`` (each needs one box at least) or than ``max_memory`` holds
    (``CELL_BYTES`` each), or whose answers take longer than ``max_seconds`` (``CELL_SECONDS`` each,
    kept from the search's time), are refused (``InputError`` naming ``n``); with ``certificate``
    (the answers are to be written as one), so are more cells than the header a checker reads holds
    (``certificates.singularity.least_header``), before anything is searched.  ``progress``: None or
    a callable (else ``InputError``)."""
    progress = progress_callback(progress)
    robot = as_robot(robot)
    budget = make_budget(budgets.SINGULARITY, budget, max_boxes=max_boxes, max_seconds=max_seconds,
                         min_width=min_width, max_memory=max_memory)
    clock = Clock(budget.max_seconds)
    n = positive_integer(n, "n")
    if isinstance(box, tuple) and len(box) == 2 and isinstance(box[0], Interval) and isinstance(box[1], dict):
        iv, texts = box                     # (largest_free_box's cells: an enclosure and its exact texts)
        fixed = np.zeros(len(robot.pose_names), dtype=bool)
    else:
        iv, texts = parse_box(box, robot)
        fixed = np.array([_same(*texts[name]) for name in robot.pose_names])
    lo0, hi0 = iv.lo, iv.hi
    free = (hi0 > lo0) & ~fixed
    cells = n ** int(free.sum())
    if cells > budget.max_boxes:
        raise InputError("n" if n > 1 else "max_boxes", "", f"{n} cells per side make {cells} cells, more than "
                         f"the box budget ({budget.max_boxes} boxes): each cell needs one box at least")
    if cells * CELL_BYTES > budget.max_memory:                 # (one box: the budget is what is too small)
        what = f"{n} cells per side make {cells} cells, about" if n > 1 else "the box needs about"
        raise InputError("n" if n > 1 else "max_memory", "", f"{what} {display.size_bound(cells * CELL_BYTES)}, more "
                         f"than the memory budget ({display.size_bound(budget.max_memory, up=False)})")
    counts = [n if f else 1 for f in free]
    grids = [np.linspace(lo0[i], hi0[i], c + 1) for i, c in enumerate(counts)]
    for g, a, b in zip(grids, lo0, hi0):
        g[0], g[-1] = a, b  # the outer faces are exactly the box's
    if certificate and cells > 1 and least_header(robot.pose_names, grids) > writing.MAX_HEADER:
        raise InputError("n", "", f"{n} cells per side make {cells} cells, more claims than a certificate's "
                         f"header holds (a checker reads {writing.MAX_HEADER >> 20} MiB of it): ask for fewer cells, or "
                         "split the box")
    reserve = CELL_SECONDS * len(free) * cells if cells > 1 else 0.0     # the cells' answers, after the search
    if reserve and reserve > clock.left():           # (one box: a budget spent already gives undecided)
        raise InputError("n", "", f"{n} cells per side make {cells} cells, whose answers take about {reserve:.3g} s, "
                         f"more than the time budget ({budget.max_seconds:g} s)")
    idx = np.stack(np.meshgrid(*[np.arange(c) for c in counts], indexing="ij"), -1).reshape(-1, len(counts))
    clo = np.stack([grids[i][idx[:, i]] for i in range(len(counts))], axis=1)
    chi = np.stack([grids[i][idx[:, i] + 1] for i in range(len(counts))], axis=1)
    inner = inner_box(texts, robot) if len(idx) == 1 else None      # cells: their float bounds are exact
    problem = SingularityProblem(robot, len(idx), inner)
    scale = np.where(free, hi0 - lo0, np.inf)         # a fixed coordinate is never bisected
    res = search(problem, clo, chi, scale=scale, budget=budget.within(clock.left() - reserve), progress=progress)
    tree = res.tree
    status, signs, open_ids, starts = _verdicts(problem, tree)
    per_cell_seconds = res.seconds / len(idx)
    nodes = np.bincount(tree.root, minlength=len(idx)).tolist()
    out = []
    for r, (code, sign) in enumerate(zip(status.tolist(), signs.tolist())):
        wit = und = None
        if code == SINGULAR:
            wit = {"positive": problem.positive[r].copy(), "negative": problem.negative[r].copy()}
        elif code == UNDECIDED_:
            ids = open_ids[starts[r]:starts[r + 1]]
            und = list(zip(tree.lo[ids], tree.hi[ids]))
        out.append(SingularityResult(robot, texts if len(idx) == 1 else None, clo[r], chi[r], STATUS[code], sign,
                                     wit, tree, r, und or [], nodes[r], per_cell_seconds, res.boxes))
    if len(idx) == 1:
        out[0].boxes, out[0].seconds = res.boxes, res.seconds
        out[0].exact_values = {name: texts[name][0] for name, e in zip(robot.pose_names, inner[2]) if e}
    return out


def _nearest(text: str) -> float:
    """The float nearest to an exact decimal, or to q·π/180 for ``<q>deg``."""
    t = text.strip()
    if not t.lower().endswith("deg"):
        return float(Fraction(Decimal(t)))
    q = Fraction(Decimal(t[:-3]))
    import mpmath                              # (rarely needed: not imported with the package)
    with mpmath.workdps(40):
        return float(mpmath.mpf(q.numerator) / q.denominator * mpmath.pi / 180)


def _same(a, b) -> bool:
    """Whether two exact texts are the same number (a coordinate given one value)."""
    if a == b:
        return True
    fa, fb = _exact(a), _exact(b)
    return fa is not None and fa == fb


def _exact(text):
    try:
        return Fraction(str(text))
    except (ValueError, ZeroDivisionError):
        return None


def _cell_texts(robot, lo, hi):
    """The exact decimal values of a cell's float bounds (``Decimal(float)`` is exact)."""
    return {n: [writing.float_text(a), writing.float_text(b)] for n, a, b in zip(robot.pose_names, np.asarray(lo, float).tolist(),
                                                                    np.asarray(hi, float).tolist())}


@quiet
def largest_free_box(robot, pose, scale=None, budget: Budget | None = None, steps: int = 24, progress=None, *,
                     max_boxes=None, max_seconds=None, min_width=None, max_memory=None) -> SingularityResult:
    """The largest box ``pose ± s·scale`` proved singularity-free (bisection on s).

    ``scale`` gives the half-widths of the unit box (default 1 in every variable: length units
    and radians).  s is doubled from the value that makes the largest half-width 2⁻¹⁰ (as with
    the default scale) until a box is not proved (at most to half-width 2²⁰), then bisected: the
    same boxes for any multiple of the scale by a power of 2.  A box leaving the range of user
    values (``MAX_MAGNITUDE``) counts as not proved.  The returned result carries the certified box and its tree;
    ``result.scale_factor`` is s.  If the pose itself cannot be proved regular, the result is
    ``undecided`` with s = 0.  ``max_boxes`` bounds each box tried, ``max_seconds`` the whole
    bisection (when it runs out, or at a Ctrl-C, the largest box proved so far is returned); ``progress(k, s)`` is
    called after each box tried (k boxes tried so far, s the scale factor proved so far).
    ``result.boxes`` and ``result.seconds`` are those of the whole bisection (every box tried);
    ``result.bisection`` says how it went: ``tried`` (boxes tried), ``proved`` (s of the box returned),
    ``not_proved`` (the least s whose box was found singular, or left undecided by its box budget or the
    resolution; None if none: the largest s lies between the two), ``not_proved_status`` (that box's
    status, ``singular`` or ``undecided``: then a larger box budget may prove a larger box) and ``stopped``: None when the bisection ran
    to its end, else ``"time budget"`` or ``"interrupted"`` (it stopped there: more time may prove a larger box).
    """
    progress = progress_callback(progress)
    robot = as_robot(robot)
    budget = make_budget(budgets.LARGEST_FREE_BOX, budget, max_boxes=max_boxes, max_seconds=max_seconds,
                         min_width=min_width, max_memory=max_memory)
    steps = positive_integer(steps, "steps", 60)
    clock = Clock(budget.max_seconds)
    center, texts = parse_pose(pose, robot, "pose") if not isinstance(pose, Interval) else (pose, None)
    d = len(robot.pose_names)
    sc = _unit_box(scale, robot.pose_names)
    tried, proved, boxes, seen = 0, 0.0, 0, {}      # seen: each s tried, its box's status
    asked = {"pose": list(texts) if texts is not None else [float(v) for v in center.mid()], "scale": sc.tolist()}

    def attempt(s):
        nonlocal tried, proved, boxes
        w = Interval.from_bounds(np.full(d, s), np.full(d, s)) * Interval.from_bounds(sc, sc)
        lo, hi = ((center - w).lo, (center + w).hi) if s else (center.lo, center.hi)  # outward: ⊇ pose ± s·scale
        if not (np.all(np.abs(lo) <= MAX_MAGNITUDE) and np.all(np.abs(hi) <= MAX_MAGNITUDE)):
            return SingularityResult(robot, None, lo, hi, "undecided", scale_factor=s, around=asked)  # not tried
        iv = Interval.from_bounds(lo, hi)
        r = _corner_witness(robot, lo, hi, center, -best.sign) if s else None
        if r is None:
            r = classify_cells(robot, (iv, _cell_texts(robot, lo, hi)), 1, budget.within(clock.left()))[0]
        r.scale_factor, r.around = s, asked
        tried += 1
        seen[s] = r.status
        boxes += r.boxes
        if r.status == "singularity-free":
            proved = max(proved, s)
        if progress:
            progress(tried, proved)
        return r

    def stopped():
        """Why the bisection stops here (or why the box just tried was cut short): None, or the budget."""
        if interrupt.requested():
            interrupt.cut()
            return "interrupted"
        return "time budget" if clock.out() else None

    def answer(r, bad=None, why=None):
        r.boxes, r.seconds = boxes, clock.elapsed()
        r.bisection = {"tried": tried, "proved": proved, "not_proved": bad, "stopped": why,
                       "not_proved_status": seen.get(bad)}    # singular: no larger box is free; undecided: budget
        return r

    best = attempt(0.0)
    if best.status != "singularity-free":
        why = stopped()
        return answer(best, None if why else 0.0, why)
    good, bad = 0.0, None
    unit = 2.0 ** math.floor(math.log2(float(np.max(sc))))      # the scale's largest half-width, to a power of 2
    s, top = 2.0 ** -10 / unit, 2.0 ** 20 / unit
    while s <= top:
        if why := stopped():
            return answer(best, None, why)
        r = attempt(s)
        if r.status == "singularity-free":
            best, good = r, s
            s *= 2
        elif r.status == "undecided" and (why := stopped()):      # cut short: s not shown out of reach
            return answer(best, None, why)
        else:
            bad = s
            break
    if bad is None:
        return answer(best)
    for _ in range(steps):
        if why := stopped():
            return answer(best, bad, why)
        mid = 0.5 * (good + bad)
        r = attempt(mid)
        if r.status == "singularity-free":
            best, good = r, mid
        elif r.status == "undecided" and (why := stopped()):
            return answer(best, bad, why)
        else:
            bad = mid
    return answer(best, bad)


def _unit_box(scale, names) -> np.ndarray:
    """The half-widths of the unit box of ``largest_free_box`` (default 1 in every variable), one per
    pose variable of ``names``; a bad one is named."""
    d = len(names)
    if scale is None:
        return np.ones(d)
    parts = scale.split(",") if isinstance(scale, str) else list(np.atleast_1d(scale))
    if len(parts) != d:
        raise InputError("scale", "", f"expected {d} comma-separated positive numbers ({', '.join(names)}), "
                                      f"got {len(parts)}")
    sc = np.ones(d)
    for k, (name, part) in enumerate(zip(names, parts)):
        try:
            sc[k] = float(part.strip() if isinstance(part, str) else part)
        except (TypeError, ValueError, OverflowError):
            sc[k] = math.nan
        if not (math.isfinite(sc[k]) and 0 < sc[k] <= MAX_SCALE):
            raise InputError("scale", name, f"expected a positive number up to {MAX_SCALE:g}, got {shown(part)}")
    return sc


def _corner_witness(robot, lo, hi, center, sign):
    """A box ``[lo, hi]`` around ``center`` (where det(A) has the proved sign ``-sign``) with a corner where
    det(A) has the proved sign ``sign`` is singular (det vanishes on the segment between them): the result
    saying so, with the two poses as witnesses, else None.  A few ms for 2^d corners, where the search
    of a box near the singularity surface (depth first) may spend its whole budget without finding them."""
    d = len(lo)
    corners = np.where((np.arange(2 ** d)[:, None] >> np.arange(d)) & 1, hi, lo)
    found = np.nonzero(_sign(robot.det_enclosure(Interval.from_bounds(corners, corners.copy()))) == sign)[0]
    if not len(found):
        return None
    there, here = corners[found[0]].copy(), center.lo.copy()
    return SingularityResult(robot, None, lo, hi, "singular",
                             witnesses={"positive": there, "negative": here} if sign > 0 else
                             {"positive": here, "negative": there})
