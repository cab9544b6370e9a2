"""The page of an HTML report: self-contained (figures embedded as data URIs), the robot's exact
data, a footer stating how the verdicts were proved.  One module per capability fills it."""
from __future__ import annotations

import base64
import html
import tempfile
from datetime import datetime, timezone
from pathlib import Path

from .. import __version__, display

def robot_table(robot) -> str:
    rows = "".join(
        f"<tr><td>{i + 1}</td><td>{', '.join(b)}</td><td>{', '.join(p)}</td></tr>"
        for i, (b, p) in enumerate(zip(robot.base, robot.platform)))
    return (f"<p><b>{html.escape(robot.name)}</b> ({robot.kind}, {robot.n_legs} legs), "
            f"file <code>{html.escape(str(robot.source))}</code></p>"
            f"<table><tr><th>leg</th><th>base joint</th><th>platform joint</th></tr>{rows}</table>")


def page(title: str, body: str) -> str:
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


def figure(draw) -> str:
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


def interval_text(v) -> str:
    """An enclosure (an ``Interval``), printed outward."""
    return display.interval(v, 12)
