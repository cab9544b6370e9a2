"""The page of every HTML report, self-contained (figures embedded as data URIs), in one order:

1. the verdict in one line; 2. the robot as a table and a drawing; 3. the question and its
assumptions; 4. the evidence (boxes proved, excluded, undecided, rules, budget used); 5. the
figures; 6. the certificate (file name, size, SHA-256 and the exact command that re-checks it), or
a line saying none was written; 7. the certkin version and the date.

Numbers shown go through ``certkin.display`` (enclosures outward, inner claims inward, points
exact), so a number copied from a report is as safe as the proved one.
"""
from __future__ import annotations

import base64
from datetime import datetime, timezone
import html
import os
import shlex
import tempfile
from pathlib import Path

import numpy as np

from .. import __version__
from ..batch.results import file_facts
from ..certificates import write_text
from ..display import pair, point
from ..engine import EXCLUDED, PROVED, UNDECIDED
from ..plots import plot_robot

STYLE = """body{font-family:sans-serif;max-width:62em;margin:2em auto;color:#222;padding:0 1em}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 8px;font-size:90%;text-align:left}
.verdict{font-size:135%;font-weight:bold;padding:.4em .6em;background:#f3f6fb;border-left:6px solid #1f5fbf}
code{background:#f4f4f4;word-break:break-all}img{max-width:100%;display:block;margin:.5em 0}
footer{font-size:80%;color:#555;margin-top:2em;border-top:1px solid #ccc;padding-top:.5em}"""


def esc(text) -> str:
    return html.escape(str(text))


def table(header, rows) -> str:
    """An HTML table (cells are escaped)."""
    head = "".join(f"<th>{esc(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def enclosure(lo_hi) -> str:
    """An enclosure [lo, hi] printed outward (``display.outward``); a ``None`` bound is a side not
    bounded (``display.pair``: -inf or inf), both ``None``: not computed."""
    lo, hi = lo_hi
    if lo is None and hi is None:
        return "not computed"
    return pair((lo, hi))


def figure(draw, alt: str) -> str:
    """Run ``draw(path)`` into a PNG and return an <img> tag with the picture embedded."""
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "figure.png"
        draw(path)
        data = base64.b64encode(path.read_bytes()).decode()
    return f'<img alt="{esc(alt)}" src="data:image/png;base64,{data}">'


def robot_section(robot, poses, caption: str) -> str:
    """The robot's exact data as a table and a drawing at ``poses`` (``[(label, pose)]``)."""
    rows = [(i + 1, ", ".join(b), ", ".join(p)) for i, (b, p) in enumerate(zip(robot.base, robot.platform))]
    out = (f"<p><b>{esc(robot.name)}</b> ({esc(robot.kind)}, {robot.n_legs} legs), file "
           f"<code>{esc(robot.source)}</code>; pose variables {esc(', '.join(robot.pose_names))} "
           f"(angles in radians).</p>")
    out += table(("leg", "base joint A_i (base frame)", "platform joint B_i (platform frame)"), rows)
    if robot.limits:
        out += table(("limit", "values (exact, from the robot file)"),
                     [(k, _limit_text(v)) for k, v in robot.limits.items()])
    else:
        out += "<p>The robot file states no limits.</p>"
    out += figure(lambda p: plot_robot(robot, poses, p), f"the robot drawn at: {', '.join(l for l, _ in poses)}")
    return out + f"<p>{esc(caption)}</p>"


def _limit_text(value) -> str:
    """A limit of the robot file as written: numbers, [lo, hi] pairs, or tables."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_limit_text(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_limit_text(v)}" for k, v in value.items()) + "}"
    return str(value)


def tree_evidence(tree, roots=None) -> dict:
    """Leaves proved, excluded and undecided of a search tree (of some roots), and the rule of each."""
    leaves = tree.leaves()
    if roots is not None:
        leaves = leaves[np.isin(tree.root[leaves], np.asarray(roots))]
    rules: dict = {}
    for kind, name in ((PROVED, "proved"), (EXCLUDED, "excluded"), (UNDECIDED, "undecided")):
        ids = leaves[tree.kind[leaves] == kind]
        for reason in np.unique(tree.reason[ids]):
            n = int(np.sum(tree.reason[ids] == reason))
            rule = f"{name}: {tree.reason_name(int(ids[tree.reason[ids] == reason][0]))}".removesuffix(", C kept")
            rules[rule] = rules.get(rule, 0) + n    # (one rule, whether the certificate keeps its C or not)
    counts = {name: int(np.sum(tree.kind[leaves] == kind))
              for kind, name in ((PROVED, "proved"), (EXCLUDED, "excluded"), (UNDECIDED, "undecided"))}
    return {"counts": counts, "rules": rules}


def evidence_section(evidence: dict | None, budget=None, used: dict | None = None) -> str:
    """Boxes by outcome, the rule that decided them, and the budget used against the budget given."""
    out = ""
    if evidence is not None:
        c = evidence["counts"]
        out += (f"<p>Boxes of the search: {c['proved']} proved, {c['excluded']} excluded, "
                f"{c['undecided']} undecided.</p>")
        out += table(("outcome: rule", "boxes"), sorted(evidence["rules"].items()))
    if used:
        rows = list(used.items())
        if budget is not None:
            rows += [("budget: boxes", budget.max_boxes), ("budget: seconds", budget.max_seconds),
                     ("budget: smallest width split", budget.min_width)]
        out += table(("work", "amount"), [(k.replace("_", " "), _amount(k, v)) for k, v in rows])
    return out


def _amount(name: str, value):
    """A work figure as shown: times to the millisecond (a measurement, not a claim), other floats
    exactly (``display.point``), yes or no."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.3f}" if "seconds" in name else point(value)
    return value


def certificate_section(path, report=None) -> str:
    """The certificate's name, size, SHA-256 and re-check command (its path from the report's directory,
    ``report`` being the report's own path), or that none was written."""
    if not path or not Path(path).exists():
        return ("<p>No certificate was written for this report: the command writes one when given "
                "<code>--certificate FILE</code> and its answer proves something (a plan that found no path "
                "proves nothing).</p>")
    facts = file_facts(path)
    where = ""
    if report is not None:
        path = from_report(path, report)
        where = " from the directory of this report"
    return table(("file", "size (bytes)", "SHA-256"), [(facts["file"], facts["bytes"], facts["sha256"])]) + \
        f"<p>Re-check it with the independent checker{where}: <code>certkin check {esc(shell_path(path))}</code> " \
        f"(or <code>python -m proofs {esc(shell_path(path))}</code>); exit code 0 only when every step " \
        "re-verifies.</p>"


def from_report(path, report) -> str:
    """``path`` relative to the directory of the report ``report`` (what a reader of the report types there)."""
    return os.path.relpath(os.path.abspath(path), os.path.dirname(os.path.abspath(report)))


def shell_path(path) -> str:
    """``path`` as one word of a shell command that no command reads as an option: quoted
    (``shlex.quote``), and a relative path starting with '-' given as ``./-...``."""
    text = str(path)
    return shlex.quote("./" + text if text.startswith("-") else text)


def write_report(path, title: str, verdict: str, sections, certificate=None, certificates_html=None) -> None:
    """Write a report: the verdict line, the sections ``[(heading, html)]``, the certificate (or the
    given ``certificates_html``: a campaign's), the footer."""
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    body = "".join(f"<h2>{esc(h)}</h2>{content}" for h, content in sections)
    body += f"<h2>Certificate</h2>{certificates_html or certificate_section(certificate, path)}"
    write_text(path, f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{esc(title)}</title><style>{STYLE}</style></head>
<body><h1>{esc(title)}</h1><p class="verdict" id="verdict">{esc(verdict)}</p>{body}
<footer>certkin {esc(__version__)}, report written {stamp}. Every verdict above is proved with
outward-rounded interval arithmetic; numbers are printed so that the claim stays true (enclosures
rounded outward, inner claims inward, points exactly).</footer>
</body></html>
""")
