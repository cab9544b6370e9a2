"""A certified bracket of the workspace volume between two heights (Gough-Stewart), over z slabs.

Each slab's (X, Y) domain is paved with z kept as the slab's interval: a box inside for every z of
the slab adds h·area to the inner volume, a box not proved outside adds it to the outer volume.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
import math
import time

import numpy as np

from intervals import Interval
from intervals.rounding import down, up, up_sum

from .. import display
from ..certificates import volume_certificate
from ..engine import Budget, budgets
from ..engine.budgets import make_budget, positive_integer, progress_callback
from ..errors import InputError
from ..quiet import quiet
from ..robots import as_robot
from ..robots.poses import parse_height_range, parse_orientation
from .annuli import ORIENTATION, check_robot, leg_data, section_domain
from .paving import Paving, pave
from .section import ignored_limits

DEFAULT_SLABS = 200
MAX_SLABS = 10_000          # each slab is a root of the search and a row of every array of the domains


@dataclass(repr=False)
class VolumeResult:
    """Certified volume bracket of the workspace part with z in the slabs [b_0, b_n]."""

    robot: object
    orientation: list
    z_range: tuple                      # exact texts
    bounds: np.ndarray                  # (n + 1,) floats b_0 < ... < b_n, b_0 <= z_lo, b_n >= z_hi
    domains: list                       # per slab (lo, hi) or None
    pavings: list                       # per slab Paving or None
    stats: dict
    status: str = "undecided"
    _areas: list | None = field(default=None, repr=False, compare=False)
    _volume: tuple | None = field(default=None, repr=False, compare=False)

    def areas(self):
        """Per slab, (inner, outer) area bounds of its section (computed once)."""
        if self._areas is None:
            self._areas = [(p.inner_area(), p.outer_area()) if p else (0.0, 0.0) for p in self.pavings]
        return self._areas

    def volume(self) -> tuple[float, float]:
        """(inner, outer) bounds of the volume for z in ``z_range``: the outer one over the whole slabs
        (they cover the range), the inner one over each slab's part inside the range (the first and
        last slabs start and end on the floats around the range's decimal ends; computed once)."""
        if self._volume is None:
            self._volume = self._bracket()
        return self._volume

    def _bracket(self) -> tuple[float, float]:
        h = np.diff(self.bounds)
        hhi = up_sum(h)
        ql, qh = (Fraction(t) for t in self.z_range)
        hlo = np.array([_below(max(Fraction(0), min(Fraction(float(b)), qh) - max(Fraction(float(a)), ql)))
                        for a, b in zip(self.bounds[:-1], self.bounds[1:])])
        ar = np.array(self.areas()).reshape(-1, 2)
        lo = np.maximum(down(hlo * ar[:, 0]), 0.0)
        hi = np.where(ar[:, 1] == 0, 0.0, up(hhi * ar[:, 1]))     # (0 times a height is exactly 0)
        inner, outer = math.fsum(lo), math.fsum(hi)     # (a volume is >= 0: a lower bound below 0 is 0)
        return (float(np.nextafter(inner, -np.inf)) if inner > 0 else 0.0), \
            (float(np.nextafter(outer, np.inf)) if np.any(hi > 0) else 0.0)

    def counts(self) -> dict:
        out = {"inner_boxes": 0, "boundary_boxes": 0, "outside_boxes": 0}
        for p in self.pavings:
            if p:
                for k, v in p.counts().items():
                    out[k] += v
        return out

    def __repr__(self):
        vin, vout = self.volume()
        return (f"<VolumeResult {self.status}: z in [{self.z_range[0]}, {self.z_range[1]}], "
                f"{display.counted(len(self.pavings), 'slab')}, "
                f"volume in [{display.lower(vin, 6)}, {display.upper(vout, 6)}]>")

    def to_json(self) -> dict:
        """The result as a JSON-ready dict: the document of ``certkin workspace --json``."""
        vin, vout = self.volume()
        return {"problem": "workspace-volume", "robot": self.robot.name, "kind": self.robot.kind,
                "status": self.status, "orientation": dict(zip(ORIENTATION[self.robot.kind], self.orientation)),
                "z_range": list(self.z_range), "slabs": len(self.pavings),
                "slab_bounds": [float(v) for v in self.bounds],
                "constraints": ["leg_length"], "ignored_limits": ignored_limits(self.robot),
                "volume": {"inner": vin, "outer": vout},
                "sections": [{"z": [float(self.bounds[k]), float(self.bounds[k + 1])], "inner": a, "outer": b}
                             for k, (a, b) in enumerate(self.areas())],
                "paving": self.counts(), "stats": dict(self.stats, bracket_width=vout - vin)}

    def certificate(self):
        """The certificate (``certificates.Document``: ``.write(path)``, or ``proofs.check`` it in memory)."""
        return volume_certificate(self)


@quiet
def _below(q: Fraction) -> float:
    """The largest float at most q."""
    f = float(q)
    return float(np.nextafter(f, -np.inf)) if Fraction(f) > q else f


def workspace_volume(robot, orientation=None, z_range=None, slabs=DEFAULT_SLABS, *, budget: Budget | None = None,
                     max_boxes=None, min_width=None, max_seconds=None, max_memory=None, progress=None) -> VolumeResult:
    """Certified bracket of the volume of {C in the workspace : z_lo <= z <= z_hi} (Gough-Stewart).

    ``z_range``: ``"lo:hi"`` or a pair of exact decimals, cut into ``slabs``
    equal slabs (float bounds; the outer ones round outward).  Each slab's
    (X, Y) domain is paved with z kept as the slab's interval: a box inside
    for every z of the slab adds h·area to the inner volume, a box not proved
    outside adds it to the outer volume.  ``min_width`` is relative to the
    largest section; boxes are not split below twice the distance a section
    boundary moves across a slab (finer boxes would mostly stay boundary
    boxes: more slabs is the better way to narrow the bracket).  ``progress``: None or a callable
    (else ``InputError``).
    """
    progress = progress_callback(progress)
    robot = as_robot(robot)
    check_robot(robot)
    if robot.kind != "gough-stewart":
        raise InputError("z_range", "z", "only spatial (gough-stewart) robots have a volume")
    angles, texts = parse_orientation(robot, orientation)
    if z_range is None:
        raise InputError("z_range", "", "missing: give lo:hi")
    (zl, tl), (zh, th) = parse_height_range(z_range)
    budget = make_budget(budgets.WORKSPACE, budget, max_boxes=max_boxes, max_seconds=max_seconds,
                         min_width=min_width, max_memory=max_memory)
    slabs = positive_integer(slabs, "slabs", min(MAX_SLABS, budget.max_boxes))
    t0 = time.perf_counter()
    ql, qh = Fraction(tl), Fraction(th)
    inner = [float(ql + (qh - ql) * k / slabs) for k in range(1, slabs)]
    bounds = np.array([float(zl.lo)] + inner + [float(zh.hi)])
    if np.any(np.diff(bounds) <= 0):
        raise InputError("slabs", "", "too many slabs for this z range (slab bounds collide in float64)")
    legs = leg_data(robot, angles)
    Z = Interval.from_bounds(bounds[:-1].copy(), bounds[1:].copy())
    _, r2out = legs.radii2(Z)
    lo, hi, empty = section_domain(legs.ux, legs.uy, r2out, t0 + budget.max_seconds / 2)
    live = np.nonzero(~empty)[0]
    domains = [None if empty[k] else (lo[k], hi[k]) for k in range(slabs)]
    pavings = [None] * slabs
    stats = {"boxes": 0, "seconds": 0.0, "exhausted": False, "min_width": budget.min_width}
    if len(live):
        # how far a section boundary can move across a slab, |dR/dz| h = h |z - u_z| / R (a float
        # estimate: it only sets the resolution, below which boundary boxes stay boundary anyway)
        zmid = 0.5 * (bounds[:-1] + bounds[1:])[live]
        r2mid = 0.5 * (r2out.lo + r2out.hi)[live]
        with np.errstate(divide="ignore", invalid="ignore"):
            speed = np.abs(zmid[:, None] - legs.uz.mid()) / np.sqrt(np.maximum(r2mid, 0.0))
        speed = np.where(np.isfinite(speed), speed, 0.0)
        # one resolution for all slabs: the median (a few slabs near a tangency move fast)
        floor = 2.0 * float(np.median(np.diff(bounds)[live] * np.max(speed, axis=1)))
        res = pave(legs, Z[live], lo[live], hi[live], budget.within(budget.max_seconds - (time.perf_counter() - t0)),
                   progress, floor)
        for root, k in enumerate(live):
            pavings[k] = Paving(res.tree, root)
        stats.update(boxes=res.boxes, exhausted=res.exhausted)
    stats["seconds"] = time.perf_counter() - t0
    result = VolumeResult(robot, texts, (tl, th), bounds, domains, pavings, stats)
    counts = result.counts()
    if counts["inner_boxes"]:
        result.status = "non-empty"
    elif not counts["boundary_boxes"]:
        result.status = "empty"
    return result
