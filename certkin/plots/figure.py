"""matplotlib (a core dependency: every report has its figures), imported where a figure is drawn."""
from __future__ import annotations

import logging


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # (EPS and PS draw transparent shades opaque: matplotlib said so on stderr, a stray line after the answer)
    logging.getLogger("matplotlib.backends.backend_ps").setLevel(logging.ERROR)
    return plt


def plain(text: str) -> str:
    """``text`` drawn as written: matplotlib reads what lies between two '$' as mathematics (and
    fails on bad TeX, ``$\\frac{$``), so every '$' is escaped (a robot's name is the user's text)."""
    return str(text).replace("$", r"\$")
