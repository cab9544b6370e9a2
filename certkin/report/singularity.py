"""The report of a singularity run: the question, the verdict (with its witnesses) or the cell
counts with their picture."""
from __future__ import annotations

import html

from .. import display
from ..certificates import write_text
from ..plots import plot_cells
from .page import figure, page, robot_table


def singularity_report(robot, results, path) -> None:
    counts = {}
    for r in results:
        counts[r.status] = counts.get(r.status, 0) + 1
    if len(results) == 1:
        r = results[0]
        show = display.inward if r.status == "singularity-free" else display.outward   # a free box: inward
        box = ", ".join(f"{n} ∈ {show(a, b)}" for n, a, b in zip(robot.pose_names, r.lo, r.hi))
        verdict = r.status + (f" (det(A) {'>' if r.sign > 0 else '<'} 0)" if r.status == "singularity-free" else "")
        body = f"<h2>Question</h2><p>Does det(A) vanish on the box {html.escape(box)}?</p>"
        body += f'<h2>Verdict</h2><p class="v">{html.escape(verdict)}</p>'
        if r.witnesses:
            body += "<p>Witnesses (certified signs): " + "; ".join(
                f"det(A) {'>' if k == 'positive' else '<'} 0 at ({', '.join(display.point(x) for x in v)})"
                for k, v in r.witnesses.items()) + "</p>"
        body += f"<p>{r.boxes} boxes, {r.seconds:.3f} s.</p>"
    else:
        body = f"<h2>Question</h2><p>Classify {len(results)} cells of poses.</p><h2>Verdict</h2><ul>"
        body += "".join(f"<li>{k}: {v}</li>" for k, v in sorted(counts.items())) + "</ul>"
        body += figure(lambda p: plot_cells(robot, results, p))
    body = "<h2>Robot</h2>" + robot_table(robot) + body
    write_text(path, page(f"Singularity analysis: {robot.name}", body))
