"""Certified motion planning (seed 000 ch. 2, seed 001 ch. III): every emitted segment is feasible.

1. The end poses are verified first (a zero-length segment at each): an end
   pose that violates a constraint gives ``infeasible-endpoint``.
2. The straight segment is verified; if it is ``feasible`` it is the answer.
3. Otherwise A* on a grid of poses (seed 000 §2.2: cell decomposition and A*):
   the grid spans the coordinates in which the end poses differ (the others
   stay fixed), with ``divisions`` steps between start and goal, and extends
   ``margin`` steps beyond them.  Edges go to the 3^k − 1 neighbours and are
   verified lazily, a whole expansion in one batch of ``verify_trajectories``;
   an edge counts only when it is ``feasible`` (an uncertified edge is never
   used, unlike the seed's arbitrarily large weight).
4. Shortcuts (seed 000 §2.2, corrected per the digest, E23): from each anchor,
   the farthest later node joined by a ``feasible`` segment.

The method is not complete (a narrow passage between grid nodes is missed):
when no path is found within the budget the status is ``no-path-found``,
never a path with an unverified segment.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from decimal import Context, Decimal
from fractions import Fraction
import heapq
import itertools

import numpy as np

from .. import display
from ..certificates import trajectory_certificate
from ..engine import Budget, budgets, interrupt
from ..engine.budgets import Clock, make_budget, progress_callback
from ..errors import InputError, shown
from ..quiet import quiet
from ..robots import as_robot
from ..robots.poses import parse_pose
from .constraints import Constraints
from .path import parse_path
from .verify import verify_trajectories


@dataclass(repr=False)
class PlanResult:
    robot: object
    status: str                                   # found | infeasible-endpoint | no-path-found
    waypoints: list = field(default_factory=list)   # pose texts, start ... goal
    segments: list = field(default_factory=list)    # TrajectoryResult of each emitted segment
    endpoint: dict | None = None                    # the verdict on a failing end pose
    stats: dict = field(default_factory=dict)
    constraints: object = None                      # the Constraints checked on every segment

    @property
    def failing(self) -> str:
        """The constraints an end pose fails, in words ("leg-length 3; interference 1-2"), or ""."""
        return "; ".join(f"{v['constraint']} {'-'.join(map(str, v['legs']))}"
                         for v in (self.endpoint or {}).get("violations", ()))

    def __repr__(self):
        return (f"<PlanResult {self.status}: {display.counted(len(self.waypoints), 'waypoint')}, "
                f"{display.counted(len(self.segments), 'segment')} certified feasible>")

    def to_json(self) -> dict:
        """The result as a JSON-ready dict: the fields of ``certkin plan --json``."""
        out = {"problem": "plan", "status": self.status,
               "waypoints": [dict(zip(self.robot.pose_names, w)) for w in self.waypoints],
               "segments": [{"status": s.status, "margins": s.margins} for s in self.segments],
               "stats": self.stats}
        if self.constraints is not None:
            c = self.constraints
            out.update(constraints=sorted({i.constraint for i in c.instances}), skipped=dict(c.skipped),
                       not_asked=list(c.not_asked), partly_checked=dict(c.partial))
        if self.endpoint is not None:
            out["endpoint"] = self.endpoint
        return out

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory)."""
        if not self.segments:
            raise ValueError("no path: nothing to certify")
        found = self.status == "found"          # a route from start to goal, which the checker follows
        return trajectory_certificate(self.segments, (self.waypoints[0], self.waypoints[-1]) if found else None)


MAX_DIVISIONS = 1000


def _count(value, name: str, least: int, most: int) -> int:
    """An integer option in [least, most] (bools and floats refused), else an InputError naming it."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not least <= value <= most:
        raise InputError(name, "", f"expected an integer from {least} to {most}, got {shown(value)}")
    return int(value)


def _stopped(clock, otherwise: str) -> str:
    """What stopped a search without a path: Ctrl-C (noted as cutting the answer short, so that the
    command line marks it interrupted), the time budget, or ``otherwise``."""
    if interrupt.requested():
        interrupt.cut()
        return "interrupted"
    return "time" if clock.out() else otherwise


def _checked(result: PlanResult, start, goal) -> PlanResult:
    """A ``found`` path runs from the start pose to the goal pose with one verified segment per step."""
    w = result.waypoints
    if not (len(w) >= 2 and list(w[0]) == list(start) and list(w[-1]) == list(goal)
            and len(result.segments) == len(w) - 1 and all(r.status == "feasible" for r in result.segments)):
        raise AssertionError("plan: a found path must join start to goal through feasible segments")
    return result


@quiet
def plan(robot, start, goal, constraints=None, divisions: int = 6, margin: int = 3, max_edges: int = 4000,
         budget: Budget | None = None, progress=None, *, max_boxes=None, max_seconds=None, min_width=None,
         max_memory=None) -> PlanResult:
    """A path from ``start`` to ``goal`` whose every segment is certified ``feasible``.

    ``robot``: a robot or a robot file's path; ``start``, ``goal``: poses (texts such as
    ``"-90,140,520,0,0,0"`` or sequences of exact values).  ``divisions`` (1 to 1000): grid steps
    between start and goal; ``margin`` (0 to 1000): grid steps beyond them; ``max_edges``: grid
    segments verified at most (with the start-goal segment; the shortcuts of a path found come on
    top).  ``max_seconds`` bounds the whole plan, ``max_boxes`` and ``min_width`` each batch of
    segments verified; ``progress(edges, nodes)`` is called after each batch.  Waypoints
    are exact decimals (the grid's poses rounded to 12 digits: the poses verified are the ones
    printed).  A ``found`` result always starts at ``start``, ends at ``goal`` and has one
    ``feasible`` segment per step.  A ``progress`` neither None nor callable is an ``InputError``."""
    progress = progress_callback(progress)
    robot = as_robot(robot)
    divisions = _count(divisions, "divisions", 1, MAX_DIVISIONS)
    margin = _count(margin, "margin", 0, MAX_DIVISIONS)
    max_edges = _count(max_edges, "max_edges", 1, 10 ** 9)
    budget = make_budget(budgets.PLAN, budget, max_boxes=max_boxes, max_seconds=max_seconds, min_width=min_width,
                         max_memory=max_memory)
    clock = Clock(budget.max_seconds)
    s_iv, s_txt = parse_pose(start, robot, "start")
    g_iv, g_txt = parse_pose(goal, robot, "goal")
    verified = [0]
    constraints = constraints if isinstance(constraints, Constraints) else Constraints.of(robot, constraints)

    def verify(paths):
        out = verify_trajectories(robot, paths, constraints, budget.within(clock.left()), indices=False, rtol=None,
                                  refuse_slow=False)
        verified[0] += len(paths)
        if progress:
            progress(verified[0], len(paths))
        return out

    ends = verify([parse_path(robot, s_txt, s_txt), parse_path(robot, g_txt, g_txt)])
    for name, r in zip(("start", "goal"), ends):
        if r.status != "feasible":
            failing = [v for v in r.violations if v.get("certain")] or r.violations
            stats = {"seconds": clock.elapsed()}
            if r.status != "infeasible":
                stats["stopped"] = _stopped(clock, "undecided")
            return PlanResult(robot, "infeasible-endpoint" if r.status == "infeasible" else "no-path-found",
                              endpoint={"pose": name, "status": r.status, "violations": failing}, stats=stats,
                              constraints=constraints)
    straight = verify([parse_path(robot, s_txt, g_txt)])[0]
    if straight.status == "feasible":
        return _checked(PlanResult(robot, "found", [s_txt, g_txt], [straight],
                                   stats={"edges_verified": 1, "seconds": clock.elapsed()}, constraints=constraints),
                        s_txt, g_txt)

    grid = _Grid(robot, s_iv, s_txt, g_iv, g_txt, divisions, margin)
    nodes, edge_result, stats = _astar(robot, grid, verify, max_edges, clock)
    if nodes is None:
        stats["seconds"] = clock.elapsed()
        if grid.narrow:
            stats["narrow"] = grid.narrow
        return PlanResult(robot, "no-path-found", stats=stats, constraints=constraints)
    kept, segments = _shortcuts(robot, grid, nodes, edge_result, verify, stats)
    stats["seconds"] = clock.elapsed()
    return _checked(PlanResult(robot, "found", [grid.pose(n) for n in kept], segments, stats=stats,
                               constraints=constraints), s_txt, g_txt)


def _value(text: str, robot_angle: bool):
    """(exact value, unit) of a pose text: ``("85", "deg")`` -> (85, "deg"); None if not a plain decimal."""
    t = text.strip()
    unit = ""
    if robot_angle and t.lower().endswith("deg"):
        t, unit = t[:-3].strip(), "deg"
    try:
        return Fraction(Decimal(t)), unit
    except (ArithmeticError, ValueError):
        return None


def _differ(p: str, q: str, robot_angle: bool) -> bool:
    """Whether two pose texts name different values (0deg and 0 are the same angle)."""
    vp, vq = _value(p, robot_angle), _value(q, robot_angle)
    if vp is None or vq is None:
        return p != q
    return vp != vq and not vp[0] == vq[0] == 0


def _decimal(q: Fraction, unit: str = "") -> str:
    """The text of an exact value, rounded to 12 significant digits when it has more (a waypoint is
    then that decimal: the pose verified is the pose printed)."""
    d = Context(prec=12).divide(Decimal(q.numerator), Decimal(q.denominator))
    return display.decimal_text(d) + unit


class _Grid:
    """The grid of poses of step 3: it spans the coordinates in which the end poses differ (and the
    positions), ``divisions`` steps between start and goal, ``margin`` steps beyond; a node is a
    tuple of step counts from the start.  A node's pose is computed in exact decimals from the
    texts of the end poses (in degrees when both are), then rounded to 12 significant digits."""

    def __init__(self, robot, s_iv, s_txt, g_iv, g_txt, divisions, margin):
        a = 0.5 * (s_iv.lo + s_iv.hi)
        b = 0.5 * (g_iv.lo + g_iv.hi)
        angle = np.array([n in robot.angle_names for n in robot.pose_names])
        differs = np.array([_differ(p, q, ang) for p, q, ang in zip(s_txt, g_txt, angle)])
        moving = np.nonzero(differs | ~angle)[0]              # positions always, angles that change
        if len(moving) < 2:
            moving = np.arange(len(a))
        span = np.linalg.norm((b - a)[~angle]) if (~angle).any() else 0.0
        self.origin, self.steps = [], []                      # per coordinate: (start value, unit), exact step
        for k in range(len(a)):
            start_v, goal_v = _value(s_txt[k], angle[k]), _value(g_txt[k], angle[k])
            if start_v is None or goal_v is None or (differs[k] and start_v[1] != goal_v[1]):
                start_v = (Fraction(float(a[k])), "")         # mixed units: radians, from the enclosures
                goal_v = (Fraction(float(b[k])), "")
            if differs[k]:
                step = (goal_v[0] - start_v[0]) / divisions
            elif angle[k]:
                step = Fraction(5) if start_v[1] == "deg" else Fraction(Decimal("0.0872664626"))   # 5 degrees
            else:
                step = Fraction(Decimal(format(max(span, 1e-9) / divisions, ".6g")))
            self.origin.append(start_v)
            self.steps.append(step)
        step = np.array([float(st) * (np.pi / 180 if o[1] == "deg" else 1.0) for st, o in zip(self.steps, self.origin)])
        side = divisions // 2 + margin
        self.lo_idx = np.where(differs[moving], -margin, -side)
        self.hi_idx = np.where(differs[moving], divisions + margin, side)
        self.goal = tuple(int(v) for v in np.where(differs[moving], divisions, 0))
        self.start = tuple([0] * len(moving))
        self.scale = np.abs(step[moving])
        self.moves = [m for m in itertools.product((-1, 0, 1), repeat=len(moving)) if any(m)]
        self.moving = moving
        self.s_txt, self.g_txt = s_txt, g_txt
        # positions in which the end poses differ by less than one step of the others: the grid moves them
        # only between the two values (and ``margin`` such tiny steps beyond), which leaves no room there
        self.narrow = [robot.pose_names[k] for k in moving if differs[k] and not angle[k]
                       and abs(step[k]) * divisions < max(span, 1e-9) / divisions]

    def pose(self, node):
        """The exact texts of a node's pose (the end poses as the user wrote them)."""
        if node == self.start:
            return self.s_txt
        if node == self.goal:
            return self.g_txt
        texts = list(self.s_txt)
        for k, n in zip(self.moving, node):
            if n:
                value, unit = self.origin[k]
                texts[k] = _decimal(value + n * self.steps[k], unit)
        return texts

    def distance(self, node, other) -> float:
        return float(np.linalg.norm((np.asarray(other) - np.asarray(node)) * self.scale))

    def neighbours(self, node, closed):
        out = []
        for m in self.moves:
            nb = tuple(n + d for n, d in zip(node, m))
            if all(lo <= v <= hi for lo, v, hi in zip(self.lo_idx, nb, self.hi_idx)) and nb not in closed:
                out.append(nb)
        return out


def _astar(robot, grid: _Grid, verify, max_edges, clock):
    """A* from the start node to the goal node; an edge counts only when its segment is proved
    ``feasible`` (a whole expansion verified in one batch).  Returns (the nodes of the path, or
    None; the verified edges' results; stats)."""
    best = {grid.start: 0.0}
    parent = {grid.start: None}
    edge_result = {}
    frontier = [(grid.distance(grid.start, grid.goal), 0.0, grid.start)]
    closed = set()
    edges = 1
    found = False
    while frontier and edges < max_edges and not clock.out() and not interrupt.requested():   # Ctrl-C: stop
        _, cost, node = heapq.heappop(frontier)
        if node in closed:
            continue
        closed.add(node)
        if node == grid.goal:
            found = True
            break
        nbrs = grid.neighbours(node, closed)[:max_edges - edges]     # never past max_edges
        results = verify([parse_path(robot, grid.pose(node), grid.pose(nb)) for nb in nbrs])
        edges += len(nbrs)
        for nb, r in zip(nbrs, results):
            if r.status != "feasible":
                continue
            c = cost + grid.distance(node, nb)
            if c < best.get(nb, np.inf):
                best[nb], parent[nb] = c, node
                edge_result[(node, nb)] = r
                heapq.heappush(frontier, (c + grid.distance(nb, grid.goal), c, nb))
    stats = {"edges_verified": edges, "nodes_expanded": len(closed)}
    if not found:       # what ended the search: a budget, or every reachable node of the grid expanded
        stats["stopped"] = _stopped(clock, "max-edges" if edges >= max_edges else "grid")
        return None, edge_result, stats
    nodes = [grid.goal]
    while parent[nodes[-1]] is not None:
        nodes.append(parent[nodes[-1]])
    nodes.reverse()
    return nodes, edge_result, stats


def _shortcuts(robot, grid: _Grid, nodes, edge_result, verify, stats):
    """Step 4: from each anchor, the farthest later node joined by a ``feasible`` segment (else
    the next node, by the edge A* verified).  Returns (the nodes kept, their segments' results)."""
    kept, segments = [nodes[0]], []
    i = 0
    while i < len(nodes) - 1:
        later = list(range(len(nodes) - 1, i + 1, -1))
        results = verify([parse_path(robot, grid.pose(nodes[i]), grid.pose(nodes[j])) for j in later]) if later else []
        stats["edges_verified"] += len(later)
        j, r = next(((j, r) for j, r in zip(later, results) if r.status == "feasible"),
                    (i + 1, edge_result[(nodes[i], nodes[i + 1])]))
        kept.append(nodes[j])
        segments.append(r)
        i = j
    return kept, segments
