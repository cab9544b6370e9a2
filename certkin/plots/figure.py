"""matplotlib, an optional dependency (the ``plot`` extra), imported where a figure is drawn."""
from __future__ import annotations

from ..errors import InputError


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend; ``InputError`` (parameter
    ``plot``) when matplotlib is not installed."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise InputError("plot", "", "matplotlib is not installed: pip install 'certkin[plot]'") from None
    return plt
