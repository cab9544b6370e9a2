"""matplotlib (a core dependency: every report has its figures), imported where a figure is drawn."""
from __future__ import annotations


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
