"""The report of a workspace section (exact area, paving bracket, picture) or volume bracket."""
from __future__ import annotations

import html

from .. import display
from ..certificates import write_text
from ..plots import plot_section, plot_volume
from .page import figure, page, robot_table


def workspace_report(robot, result, path) -> None:
    """Verdict and certified brackets of one section or volume (inner bounds rounded down, outer up)."""
    doc = result.to_json()
    orientation = ", ".join(f"{k} = {v}" for k, v in doc["orientation"].items())
    body = "<h2>Robot</h2>" + robot_table(robot)
    if doc["problem"] == "workspace-volume":
        lo, hi = doc["z_range"]
        body += (f"<h2>Question</h2><p>Volume of the constant-orientation workspace ({html.escape(orientation)}) "
                 f"for z in [{html.escape(lo)}, {html.escape(hi)}], {doc['slabs']} slabs.</p>")
        body += f'<h2>Verdict</h2><p class="v">{html.escape(result.status)}</p>'
        v = doc["volume"]
        body += f"<p>{display.lower(v['inner'])} &le; volume &le; {display.upper(v['outer'])}</p>"
        body += figure(lambda png: plot_volume(result, png))
    else:
        where = "" if doc["z"] is None else f" at z = {html.escape(doc['z'])}"
        body += (f"<h2>Question</h2><p>Section{where} of the constant-orientation workspace "
                 f"({html.escape(orientation)}).</p>")
        body += f'<h2>Verdict</h2><p class="v">{html.escape(result.status)}</p>'
        a = doc["area"]
        if a["exact"] is not None:
            body += f"<p>Exact area in {display.outward(*a['exact'])}.</p>"
        else:
            body += f"<p>Exact boundary undecided: {html.escape(str(doc.get('exact_undecided')))}.</p>"
        body += f"<p>Paving: {display.lower(a['inner'])} &le; area &le; {display.upper(a['outer'])}.</p>"
        body += figure(lambda png: plot_section(result, png))
    if doc["ignored_limits"]:
        body += f"<p>Leg-length limits only; ignored: {html.escape(', '.join(doc['ignored_limits']))}.</p>"
    body += f"<p>{doc['stats']['boxes']} boxes, {doc['stats']['seconds']:.3f} s.</p>"
    write_text(path, page(f"Workspace: {robot.name}", body))
