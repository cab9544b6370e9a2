"""The report of a plan: the waypoints of the path found and, per segment, its certified margins."""
from __future__ import annotations

import html

from .. import display
from ..certificates import write_text
from .page import page, robot_table


def plan_report(robot, result, path) -> None:
    """Verdict, waypoints (exact decimals) and the smallest certified margin of each segment."""
    body = "<h2>Robot</h2>" + robot_table(robot)
    body += f'<h2>Verdict</h2><p class="v">{html.escape(result.status)}</p>'
    if result.waypoints:
        names = list(robot.pose_names)
        rows = "".join("<tr><td>" + str(k) + "</td>" + "".join(f"<td>{html.escape(v)}</td>" for v in w) + "</tr>"
                       for k, w in enumerate(result.waypoints))
        body += ("<h2>Waypoints</h2><table><tr><th>#</th>" + "".join(f"<th>{html.escape(n)}</th>" for n in names)
                 + f"</tr>{rows}</table>")
        rows = ""
        for k, seg in enumerate(result.segments):
            worst = min((m for m in seg.margins if m["margin"][0] is not None), key=lambda m: m["margin"][0],
                        default=None)
            low = "" if worst is None else (f"{html.escape(worst['constraint'])} {'-'.join(map(str, worst['legs']))}: "
                                            f"&ge; {display.lower(worst['margin'][0])}")
            rows += f"<tr><td>{k}&rarr;{k + 1}</td><td>{html.escape(seg.status)}</td><td>{low}</td></tr>"
        body += ("<h2>Segments</h2><table><tr><th>segment</th><th>verdict</th><th>smallest margin (certified lower "
                 f"bound)</th></tr>{rows}</table>")
    if result.endpoint:
        e = result.endpoint
        body += (f"<p>The {html.escape(e['pose'])} pose is {html.escape(e['status'])}: " + html.escape("; ".join(
            f"{v['constraint']} {'-'.join(map(str, v['legs']))}" for v in e["violations"])) + ".</p>")
    body += f"<p>{result.stats.get('edges_verified', 0)} segments verified, {result.stats.get('seconds', 0):.2f} s.</p>"
    write_text(path, page(f"Plan: {robot.name}", body))
