"""A certified section z = const of the constant-orientation workspace (seed 004; leg-length limits).

Only the leg-length limits are constraints here: passive-joint limits and leg interference are
*not* taken into account (the results describe a superset of the workspace of a robot that has
such limits, and say so in ``ignored_limits``).  Two answers, each rigorous: the paving's area
bracket (``workspace.paving``) and the exact boundary (``workspace.boundary``); they must meet.
"""
from __future__ import annotations

from dataclasses import dataclass
import time

import numpy as np

from intervals import Interval

from .. import display
from ..certificates import section_certificate
from ..engine import Budget, budgets
from ..engine.budgets import make_budget, progress_callback
from ..errors import InputError, shown
from ..quiet import quiet
from ..robots import as_robot
from ..robots.poses import parse_height, parse_orientation
from .annuli import ORIENTATION, Legs, check_robot, leg_data, section_domain
from .boundary import Boundary, exact_boundary
from .paving import Paving, pave


def ignored_limits(robot):
    return sorted(k for k in robot.limits if k != "leg_length")


def _pair(iv):
    return None if iv is None else [float(iv.lo), float(iv.hi)]


@dataclass(repr=False)
class SectionResult:
    """One certified section.  ``status``: ``non-empty`` (a box or the exact area proves it), ``empty``
    (every box of the domain is outside, or the domain is empty), ``undecided``."""

    robot: object
    orientation: list
    z: str | None
    legs: Legs
    domain: tuple | None                    # (lo (2,), hi (2,)) or None when proved empty
    paving: Paving | None
    boundary: Boundary
    stats: dict
    status: str = "undecided"

    @property
    def inner(self) -> float:
        return self.paving.inner_area() if self.paving else 0.0

    @property
    def outer(self) -> float:
        return self.paving.outer_area() if self.paving else 0.0

    @property
    def area(self) -> Interval | None:
        return self.boundary.area

    @property
    def perimeter(self) -> Interval | None:
        return self.boundary.perimeter

    def counts(self) -> dict:
        return self.paving.counts() if self.paving else {"inner_boxes": 0, "boundary_boxes": 0, "outside_boxes": 0}

    def __repr__(self):
        where = "" if self.z is None else f" z={self.z}"
        return (f"<SectionResult {self.status}:{where} area in [{display.lower(self.inner, 6)}, "
                f"{display.upper(self.outer, 6)}]>")

    def to_json(self) -> dict:
        """The result as a JSON-ready dict: the document of ``certkin workspace --json``."""
        b = self.boundary
        doc = {"problem": "workspace-section", "robot": self.robot.name, "kind": self.robot.kind,
               "status": self.status, "orientation": dict(zip(ORIENTATION[self.robot.kind], self.orientation)),
               "z": self.z,
               "constraints": ["leg_length"], "ignored_limits": ignored_limits(self.robot),
               "area": {"exact": _pair(b.area), "inner": self.inner, "outer": self.outer},
               "perimeter": _pair(b.perimeter),
               "arcs": b.arcs if b.decided else [],
               "loops": b.loops,
               "paving": self.counts(),
               "domain": None if self.domain is None else [[float(self.domain[0][k]), float(self.domain[1][k])]
                                                           for k in range(2)],
               "stats": dict(self.stats, bracket_width=self.outer - self.inner)}
        if not b.decided or b.reason:
            doc["exact_undecided"] = b.reason
        return doc

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory)."""
        return section_certificate(self)


def _z_interval(robot, z):
    if robot.kind == "planar-3rpr":
        if z is not None:
            raise InputError("z", "z", "a planar robot has no z: leave it out")
        return Interval(0), None
    if z is None:
        raise InputError("z", "", "missing: give the height of the section")
    return parse_height(z)


@quiet
def workspace_section(robot, orientation=None, z=None, *, budget: Budget | None = None, max_boxes=None,
                      min_width=None, max_seconds=None, max_memory=None, progress=None, exact=True) -> SectionResult:
    """Certified section ``z = const`` of the constant-orientation workspace (leg-length limits).

    ``orientation``: ``"psi,theta,phi"`` (Gough) or ``"phi"`` (planar), a
    sequence or a mapping of exact decimals (``deg`` allowed); ``z``: an exact
    decimal (Gough only).  ``robot``: a robot or a robot file's path.  ``min_width`` is relative to
    the domain.  ``progress``: None or a callable.  Raises ``InputError`` for bad input.
    """
    progress = progress_callback(progress)
    if not isinstance(exact, (bool, np.bool_)):
        raise InputError("exact", "", f"expected True or False, got {shown(exact)}")
    robot = as_robot(robot)
    check_robot(robot)
    angles, texts = parse_orientation(robot, orientation)
    Z, ztext = _z_interval(robot, z)
    budget = make_budget(budgets.WORKSPACE, budget, max_boxes=max_boxes, max_seconds=max_seconds,
                         min_width=min_width, max_memory=max_memory)
    t0 = time.perf_counter()
    legs = leg_data(robot, angles)
    Z1 = Z.reshape(1)
    r2in, r2out = legs.radii2(Z1)
    lo, hi, empty = section_domain(legs.ux, legs.uy, r2out)
    stats = {"boxes": 0, "seconds": 0.0, "exhausted": False, "min_width": budget.min_width}
    if empty[0]:
        domain, paving = None, None
    else:
        domain = (lo[0], hi[0])
        res = pave(legs, Z1, lo, hi, budget.within(budget.max_seconds - (time.perf_counter() - t0)), progress)
        paving = Paving(res.tree, 0)
        stats.update(boxes=res.boxes, exhausted=res.exhausted)
    stats["paving_seconds"] = time.perf_counter() - t0
    if exact:
        origin = (0.0, 0.0) if domain is None else tuple(0.5 * domain[0] + 0.5 * domain[1])
        boundary = exact_boundary(legs, Z1, origin)
    else:
        boundary = Boundary(reason="not computed (exact=False)")
    stats["seconds"] = time.perf_counter() - t0
    result = SectionResult(robot, texts, ztext, legs, domain, paving, boundary, stats)
    _consistent(result)
    counts = result.counts()
    if domain is None or (counts["inner_boxes"] == 0 and counts["boundary_boxes"] == 0):
        result.status = "empty"
    elif counts["inner_boxes"] > 0 or (boundary.decided and boundary.area.lo > 0):
        result.status = "non-empty"
    return result


def _consistent(r):
    """The exact area and the paving bracket are two proofs about one number: they must meet."""
    a = r.boundary.area
    if a is not None and (a.hi < r.inner or a.lo > r.outer):
        raise RuntimeError(f"internal error: exact area [{a.lo}, {a.hi}] outside the paving bracket "
                           f"[{r.inner}, {r.outer}]; please report this robot and section")
