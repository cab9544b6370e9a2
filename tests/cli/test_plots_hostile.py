"""Pictures (``--plot``, and the figures of ``--report``) of robots whose name is hostile text."""
from pathlib import Path
import re

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
