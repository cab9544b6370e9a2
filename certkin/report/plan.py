"""The report of a plan: the path found (every segment certified feasible) or why none was."""
from __future__ import annotations

from .page import evidence_section, robot_section, table, write_report
from .trajectory import trajectory_sections


def plan_verdict(result) -> str:
    if result.status == "found":
        return f"Path found: {len(result.segments)} segments, each certified feasible."
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
    sections.append(("Question and assumptions", (
        "<p>A path from the start to the goal whose every straight segment is certified feasible for all "
        "the constraints the robot file allows to check; waypoints are searched on a grid between the two "
        f"poses.</p>{table(('waypoint', 'pose'), rows) if rows else ''}")))
    stats = {{"edges_verified": "segments verified", "nodes_expanded": "grid nodes expanded"}.get(k, k): v
             for k, v in result.stats.items()}
    sections.append(("Evidence", evidence_section(None, budget, stats)))
    for k, seg in enumerate(result.segments):
        for heading, html in trajectory_sections(robot, seg, budget):
            sections.append((f"Segment {k + 1}: {heading.lower()}", html))
    write_report(path, f"Plan: {robot.name}", plan_verdict(result), sections, certificate)
