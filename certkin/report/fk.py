"""The report of a forward-kinematics result: every assembly mode with its proved box."""
from __future__ import annotations

import html

from ..certificates import write_text
from .page import interval_text, page, robot_table


def fk_report(robot, result, path) -> None:
    """The assembly modes of one forward-kinematics result."""
    names = list(result.solutions[0]["pose"]) if result.solutions else list(robot.pose_names)
    rows = "".join("<tr><td>" + str(k + 1) + "</td>" + "".join(
        f"<td>{html.escape(interval_text(s['pose'][n]))}</td>" for n in names) + "</tr>"
        for k, s in enumerate(result.solutions))
    verdict = (f"{len(result.solutions)} assembly modes, each proved unique in its box; "
               + ("the rest of the domain is proved to hold no posture (complete)." if result.complete else
                  f"incomplete: {len(result.unresolved)} unresolved regions."))
    if result.tracked:
        verdict = "tracked: exactly one posture in the box around the previous pose."
    body = "<h2>Robot</h2>" + robot_table(robot)
    body += (f"<h2>Question</h2><p>Every real posture for the leg lengths "
             f"{html.escape(', '.join(result.lengths))}.</p>")
    body += f'<h2>Verdict</h2><p class="v">{html.escape(verdict)}</p>'
    body += "<table><tr><th>#</th>" + "".join(f"<th>{html.escape(n)}</th>" for n in names) + f"</tr>{rows}</table>"
    body += f"<p>{result.boxes} boxes, {result.seconds:.3f} s.</p>"
    write_text(path, page(f"Forward kinematics: {robot.name}", body))
