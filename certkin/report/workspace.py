"""The report of a workspace section or volume: the area (or volume) bracket, the paving with its
inner and outer parts, the robot drawn at the centre of the section."""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..display import lower, outward, upper
from ..plots import plot_section, plot_volume
from ..workspace import VolumeResult
from ..workspace.section import ignored_limits
from .page import esc, evidence_section, figure, robot_section, table, write_report


def _pose(robot, result, z) -> list:
    """A pose at the centre of the searched domain with the result's orientation (for the drawing)."""
    dom = getattr(result, "domain", None) or next((d for d in getattr(result, "domains", []) if d), None)
    x, y = (0.5 * (np.asarray(dom[0], float) + np.asarray(dom[1], float))).tolist()[:2] if dom else (0.0, 0.0)
    angles = list(result.orientation)
    if robot.kind == "planar-3rpr":
        return [x, y] + angles
    return [x, y, z] + angles


def workspace_verdict(result) -> str:
    """The verdict in one line (the inner bound rounded down and never below 0, as on the terminal); for
    a robot with limits the workspace does not use, the bracket is of the leg-length workspace only."""
    stopped = "; a budget or Ctrl-C stopped the paving before its resolution" if result.stats.get("exhausted") else ""
    ignored = ignored_limits(result.robot)
    if ignored:
        stopped += (f"; of the leg-length workspace only: with {', '.join(ignored)} the robot's workspace is smaller, "
                    "so only the outer bound holds for it")
    if isinstance(result, VolumeResult):
        vin, vout = result.volume()
        return (f"Workspace volume {result.status}: between {lower(max(vin, 0.0))} and {upper(vout)} "
                f"(certified bracket{stopped}).")
    return (f"Workspace section {result.status}: area between {lower(max(result.inner, 0.0))} and "
            f"{upper(result.outer)} (certified bracket{stopped}).")


def workspace_report(robot, result, path, certificate=None, budget=None) -> None:
    volume = isinstance(result, VolumeResult)
    if volume:
        z = float((Fraction(result.z_range[0]) + Fraction(result.z_range[1])) / 2)
    else:
        z = result.z if result.z is not None else 0
    pose = _pose(robot, result, z)
    sections = [("Robot", robot_section(robot, [("centre of the section", pose)],
                                        "Drawn at the centre of the searched domain, with the section's orientation."))]
    ignored = ignored_limits(robot)
    where = f"between z = {result.z_range[0]} and {result.z_range[1]}" if volume else \
        ("" if result.z is None else f"at z = {result.z}")
    sections.append(("Question and assumptions", (
        f"<p>The positions reachable {esc(where)} with the orientation {esc(', '.join(result.orientation))} "
        "(constant-orientation workspace, seed 004), within the leg-length limits of the robot file. "
        + (f"Limits not used: {esc(', '.join(ignored))}: the answer describes a superset of the robot's "
           "workspace, so its outer bounds hold for the robot but its inner bounds and exact area do not."
           if ignored else "") + "</p>")))
    c = result.counts()
    used = {"boxes inside (proved)": c["inner_boxes"], "boxes outside (proved)": c["outside_boxes"],
            "boundary boxes (undecided)": c["boundary_boxes"], **{k: v for k, v in result.stats.items()}}
    sections.append(("Evidence", evidence_section(None, budget, used)))
    if volume:
        vin, vout = result.volume()
        rows = [("volume, inner bound (inside boxes)", lower(vin)), ("volume, outer bound", upper(vout))]
        draw, alt = (lambda p: plot_volume(result, p)), "inner and outer section areas per slab"
    else:
        rows = [("area, inner bound (inside boxes)", lower(result.inner)), ("area, outer bound", upper(result.outer))]
        b = result.boundary
        if b.decided and b.area is not None:
            rows.append(("exact area (enclosure)", outward(float(b.area.lo), float(b.area.hi))))
        draw, alt = (lambda p: plot_section(result, p)), "the paving: inside, boundary and outside boxes, exact arcs"
    sections.append(("Answer", table(("quantity", "value"), rows)))
    sections.append(("Paving", figure(draw, alt)))
    write_report(path, f"Workspace: {robot.name}", workspace_verdict(result), sections, certificate)
