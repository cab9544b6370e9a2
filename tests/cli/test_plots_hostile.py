"""Pictures (``--plot``, and the figures of ``--report``) of robots whose name is hostile text."""
from pathlib import Path
import re

import numpy as np
import pytest

from conftest import MEL, MICRO, R2, answered

NAME = r"cost $\frac{1}{$ and <b>bold</b> & 5"      # matplotlib once read '$...$' as TeX and failed


def renamed(path: str, tmp_path) -> str:
    """A copy of the robot file ``path`` in ``tmp_path``, named ``NAME``."""
    text = re.sub(r"^name = .*$", lambda m: "name = " + '"' + NAME.replace("\\", "\\\\") + '"', Path(path).read_text(),
                  count=1, flags=re.M)
    out = tmp_path / "robot" / Path(path).name
    out.parent.mkdir(exist_ok=True)
    out.write_text(text)
    return str(out)


@pytest.mark.parametrize("robot, argv", [
    (MICRO, ["workspace", "--z", "20005", "--min-width", "0.05", "--plot", "{tmp}/p.png"]),
    (MICRO, ["workspace", "--z-range", "20000:20010", "--slabs", "4", "--min-width", "0.05", "--plot", "{tmp}/p.svg"]),
    (R2, ["singular", "--box", "x=-20:-10,y=20:30,phi=0:0.3", "--cells", "2", "--plot", "{tmp}/p.png"]),
    (MEL, ["trajectory", "--from", "-69,-50,500,85deg,10deg,0", "--to", "84,92,500,85deg,10deg,0",
           "--report", "{tmp}/p.html"]),
], ids=["section", "volume", "cells", "trajectory-report"])
def test_a_name_with_dollar_signs_is_drawn_as_text(cli, tmp_path, robot, argv):
    pytest.importorskip("matplotlib")
    run = cli(argv[0], renamed(robot, tmp_path), *argv[1:])
    answered(run, NAME)
    assert run.left == ["p" + Path(argv[-1]).suffix]
    if argv[-1].endswith(".html"):
        page = Path(tmp_path, "p.html").read_text()
        assert "<b>bold</b>" not in page and "&lt;b&gt;bold&lt;/b&gt;" in page


def test_thousands_of_ranges_are_shaded_as_their_union(monkeypatch, tmp_path):
    """A search down to the floats' resolution (min_width=1e-300) leaves thousands of 'may fail'
    ranges: each was one span (13 s to draw 6000, after the time budget).  Now each kind is shaded as
    the union of its ranges, joined across gaps below a pixel, and still covers every range."""
    pytest.importorskip("matplotlib")
    from matplotlib.axes import Axes
    import certkin
    from certkin.plots import plot_margins
    from certkin.plots.trajectory import SHADES
    r = certkin.verify_trajectory(MEL, "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0", min_width=1e-300,
                                  max_boxes=5000)
    first = r.violations[0]                        # (how many ranges a cut search leaves depends on when its
    edges = np.linspace(0.2, 0.9, 6001)           # clock stops it: the ranges are made here, 6000 of them)
    r.violations = [dict(first, s=[a, b], t=[a, b], certain=bool(k % 3)) for k, (a, b) in enumerate(zip(edges[:-1], edges[1:] - 1e-12))]
    spans, axvspan = [], Axes.axvspan

    def counted(self, a, b, **kw):
        spans.append((a, b, kw["color"]))
        return axvspan(self, a, b, **kw)
    monkeypatch.setattr(Axes, "axvspan", counted)
    plot_margins(r, tmp_path / "m.png")
    assert len(spans) < 200
    for v in r.violations:
        colour = SHADES[0 if v["certain"] else 1][1]
        assert any(a <= v["s"][0] and v["s"][1] <= b for a, b, c in spans if c == colour), v


@pytest.mark.parametrize("suffix", ["eps", "ps"])
def test_a_postscript_picture_adds_nothing_to_stderr(tmp_path, suffix):
    """matplotlib's PostScript backend logged 'does not support transparency' on stderr (in a process of
    its own: pytest's log capture hides it in this one)."""
    pytest.importorskip("matplotlib")
    from conftest import limited
    run = limited(["workspace", MICRO, "--z", "20005", "--min-width", "0.05", "--plot", f"{{tmp}}/p.{suffix}"],
                  tmp_path)
    answered(run, "section z = 20005")
    assert run.err == "" and run.left == [f"p.{suffix}"]
