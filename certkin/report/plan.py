"""The report of a plan: the path found (every segment certified feasible) or why none was."""
from __future__ import annotations

from ..display import counted
from .page import esc, evidence_section, robot_section, table, write_report
from .trajectory import trajectory_sections


def plan_verdict(result) -> str:
    if result.status == "found":
        only = " for the constraints checked (not all the robot file allows)" if result.constraints is not None \
            and result.constraints.unchecked() else ""
        return f"Path found: {counted(len(result.segments), 'segment')}, each certified feasible{only}."
    if result.status == "infeasible-endpoint" and result.endpoint:
        return f"No path: the {result.endpoint['pose']} pose is {result.endpoint['status']}" + \
            (f" ({result.failing})." if result.failing else ".")
    return "No path found within the grid and the budget (this proves nothing about other paths)."


def plan_report(robot, result, path, certificate=None, budget=None) -> None:
    w = result.waypoints
    poses = [("start", w[0]), ("goal", w[-1])] if w else []
    sections = [("Robot", robot_section(robot, poses, "Drawn at the start and the goal." if poses else
                                        "No path to draw."))]
    rows = [(k, ",".join(p)) for k, p in enumerate(w)]
    c = result.constraints
    checked = ", ".join(sorted({i.constraint for i in c.instances})) if c is not None else "?"
    unchecked = "".join(f"<li>not checked: {esc(k)} ({esc(why)})</li>" for k, why in c.unchecked()) if c else ""
    sections.append(("Question and assumptions", (
        "<p>A path from the start to the goal whose every straight segment is certified feasible for the "
        f"constraints checked: {esc(checked)}; waypoints are searched on a grid between the two poses.</p>"
        f"<ul>{unchecked or '<li>every constraint family was checked</li>'}</ul>"
        f"{table(('waypoint', 'pose'), rows) if rows else ''}")))
    stats = {{"edges_verified": "segments verified", "nodes_expanded": "grid nodes expanded"}.get(k, k): v
             for k, v in result.stats.items()}
    sections.append(("Evidence", evidence_section(None, budget, stats)))
    for k, seg in enumerate(result.segments):
        for heading, html in trajectory_sections(robot, seg, budget):
            sections.append((f"Segment {k + 1}: {heading.lower()}", html))
    write_report(path, f"Plan: {robot.name}", plan_verdict(result), sections, certificate)
