"""The report of a trajectory: verdict, certified minimum margins, forbidden instants, and the
margins along the path."""
from __future__ import annotations

import html

from .. import display
from ..certificates import write_text
from ..plots import plot_margins
from .page import figure, page, robot_table


def trajectory_report(robot, result, path) -> None:
    """Verdict, certified margins and forbidden t-intervals of one trajectory, with a plot of the
    margin enclosures along the path."""
    j = result.to_json()
    pts = " &rarr; ".join(html.escape(",".join(p.values())) for p in j["path"])
    body = "<h2>Robot</h2>" + robot_table(robot)
    body += f"<h2>Question</h2><p>Is the motion {pts} feasible (constraints: {', '.join(j['constraints'])})?</p>"
    for k, why in j["skipped"].items():
        body += f"<p>Not checked: {html.escape(k)} ({html.escape(why)}).</p>"
    body += f'<h2>Verdict</h2><p class="v">{html.escape(result.status)}</p>'
    rows = "".join(f"<tr><td>{html.escape(m['constraint'])}</td><td>{'-'.join(map(str, m['legs']))} "
                   f"{html.escape(m.get('detail', ''))}</td><td>{display.pair(m['margin'])}</td></tr>"
                   for m in j["margins"])
    body += "<h2>Certified minimum margins</h2><table><tr><th>constraint</th><th>legs</th><th>min margin</th></tr>"
    body += rows + "</table>"
    if j["violations"]:
        rows = "".join(f"<tr><td>{html.escape(v['constraint'])}</td><td>{'-'.join(map(str, v['legs']))}</td>"
                       f"<td>{display.pair(v['s'], 12)}</td><td>{'proved' if v['certain'] else 'possible'}</td></tr>"
                       for v in j["violations"])
        body += ("<h2>Forbidden instants (their union contains every violation)</h2><table><tr><th>constraint</th>"
                 "<th>legs</th><th>s interval</th><th>violation</th></tr>" + rows + "</table>")
    body += figure(lambda png: plot_margins(result, png))
    write_text(path, page(f"Trajectory: {robot.name}", body))
