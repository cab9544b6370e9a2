"""Self-contained HTML reports for a certification file.

One page per run: the robot (exact data), the question, the verdict and its
evidence summary, and a picture when matplotlib is available (embedded as a
data URI, so the file stands alone).
"""
from __future__ import annotations

import base64
import html
import tempfile
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from . import __version__
from .certificates import write_text


def _robot_table(robot) -> str:
    rows = "".join(
        f"<tr><td>{i + 1}</td><td>{', '.join(b)}</td><td>{', '.join(p)}</td></tr>"
        for i, (b, p) in enumerate(zip(robot.base, robot.platform)))
    return (f"<p><b>{html.escape(robot.name)}</b> ({robot.kind}, {robot.n_legs} legs), "
            f"file <code>{html.escape(str(robot.source))}</code></p>"
            f"<table><tr><th>leg</th><th>base joint</th><th>platform joint</th></tr>{rows}</table>")


def _page(title: str, body: str) -> str:
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}}
table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:2px 8px;font-size:90%}}
.v{{font-size:130%;font-weight:bold}} code{{background:#f4f4f4}}</style></head>
<body><h1>{html.escape(title)}</h1>{body}
<hr><p style="font-size:80%">certkin {__version__}, {stamp}. Every verdict above is proved with
outward-rounded interval arithmetic; re-check the certificate with <code>certkin check</code>.</p>
</body></html>
"""


def _figure(draw) -> str:
    """Run ``draw(path)`` into a PNG and return an <img> tag, or a note if matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return "<p><i>(install matplotlib for pictures)</i></p>"
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "fig.png"
        draw(path)
        data = base64.b64encode(path.read_bytes()).decode()
    return f'<img alt="figure" style="max-width:100%" src="data:image/png;base64,{data}">'


def singularity_report(robot, results, path) -> None:
    from .plots import plot_cells
    counts = {}
    for r in results:
        counts[r.status] = counts.get(r.status, 0) + 1
    if len(results) == 1:
        r = results[0]
        box = ", ".join(f"{n} ∈ [{a:.10g}, {b:.10g}]" for n, a, b in zip(robot.pose_names, r.lo, r.hi))
        verdict = r.status + (f" (det(A) {'>' if r.sign > 0 else '<'} 0)" if r.status == "singularity-free" else "")
        body = f"<h2>Question</h2><p>Does det(A) vanish on the box {html.escape(box)}?</p>"
        body += f'<h2>Verdict</h2><p class="v">{html.escape(verdict)}</p>'
        if r.witnesses:
            body += "<p>Witnesses (certified signs): " + "; ".join(
                f"det(A) {'>' if k == 'positive' else '<'} 0 at ({', '.join(f'{x:.10g}' for x in v)})"
                for k, v in r.witnesses.items()) + "</p>"
        body += f"<p>{r.boxes} boxes, {r.seconds:.3f} s.</p>"
    else:
        body = f"<h2>Question</h2><p>Classify {len(results)} cells of poses.</p><h2>Verdict</h2><ul>"
        body += "".join(f"<li>{k}: {v}</li>" for k, v in sorted(counts.items())) + "</ul>"
        body += _figure(lambda p: plot_cells(robot, results, p))
    body = "<h2>Robot</h2>" + _robot_table(robot) + body
    write_text(path, _page(f"Singularity analysis: {robot.name}", body))


def _interval_text(v) -> str:
    lo, hi = float(v.lo), float(v.hi)
    return f"{0.5 * (lo + hi):.12g} ± {0.5 * (hi - lo):.1e}"


def fk_report(robot, result, path) -> None:
    """The assembly modes of one forward-kinematics result."""
    names = list(result.solutions[0]["pose"]) if result.solutions else list(robot.pose_names)
    rows = "".join("<tr><td>" + str(k + 1) + "</td>" + "".join(
        f"<td>{html.escape(_interval_text(s['pose'][n]))}</td>" for n in names) + "</tr>"
        for k, s in enumerate(result.solutions))
    verdict = (f"{len(result.solutions)} assembly modes, each proved unique in its box; "
               + ("the rest of the domain is proved to hold no posture (complete)." if result.complete else
                  f"incomplete: {len(result.unresolved)} unresolved regions."))
    if result.tracked:
        verdict = "tracked: exactly one posture in the box around the previous pose."
    body = "<h2>Robot</h2>" + _robot_table(robot)
    body += (f"<h2>Question</h2><p>Every real posture for the leg lengths "
             f"{html.escape(', '.join(result.lengths))}.</p>")
    body += f'<h2>Verdict</h2><p class="v">{html.escape(verdict)}</p>'
    body += "<table><tr><th>#</th>" + "".join(f"<th>{html.escape(n)}</th>" for n in names) + f"</tr>{rows}</table>"
    body += f"<p>{result.boxes} boxes, {result.seconds:.3f} s.</p>"
    write_text(path, _page(f"Forward kinematics: {robot.name}", body))


def trajectory_report(robot, result, path) -> None:
    """Verdict, certified margins and forbidden t-intervals of one trajectory, with a plot of the
    margin enclosures along the path."""
    j = result.to_json()
    pts = " &rarr; ".join(html.escape(",".join(p.values())) for p in j["path"])
    body = "<h2>Robot</h2>" + _robot_table(robot)
    body += f"<h2>Question</h2><p>Is the motion {pts} feasible (constraints: {', '.join(j['constraints'])})?</p>"
    for k, why in j["skipped"].items():
        body += f"<p>Not checked: {html.escape(k)} ({html.escape(why)}).</p>"
    body += f'<h2>Verdict</h2><p class="v">{html.escape(result.status)}</p>'
    rows = "".join(f"<tr><td>{html.escape(m['constraint'])}</td><td>{'-'.join(map(str, m['legs']))} "
                   f"{html.escape(m.get('detail', ''))}</td><td>[{m['margin'][0]:.9g}, {m['margin'][1]:.9g}]</td></tr>"
                   for m in j["margins"])
    body += "<h2>Certified minimum margins</h2><table><tr><th>constraint</th><th>legs</th><th>min margin</th></tr>"
    body += rows + "</table>"
    if j["violations"]:
        rows = "".join(f"<tr><td>{html.escape(v['constraint'])}</td><td>{'-'.join(map(str, v['legs']))}</td>"
                       f"<td>[{v['s'][0]:.12g}, {v['s'][1]:.12g}]</td><td>{'proved' if v['certain'] else 'possible'}</td></tr>"
                       for v in j["violations"])
        body += ("<h2>Forbidden instants (their union contains every violation)</h2><table><tr><th>constraint</th>"
                 "<th>legs</th><th>s interval</th><th>violation</th></tr>" + rows + "</table>")

    def draw(png):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        L = result.leaves
        s_lo, s_hi = L["segment"] + L["tlo"], L["segment"] + L["thi"]
        fig, ax = plt.subplots(figsize=(8, 4))
        for k, inst in enumerate(result.constraints.instances):
            if k == result.constraints.det_column:
                continue
            lo = np.clip(L["mlo"][:, k], -50, 200)
            ax.hlines(lo, s_lo, s_hi, lw=1, color=f"C{k % 10}")
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xlabel("s (segment index + t)")
        ax.set_ylabel("margin lower bound (clipped)")
        fig.tight_layout()
        fig.savefig(png, dpi=90)
        plt.close(fig)

    body += _figure(draw)
    write_text(path, _page(f"Trajectory: {robot.name}", body))
