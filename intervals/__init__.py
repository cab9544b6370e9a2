"""Rigorous, batched interval arithmetic on float64 (knows nothing of robots).

Every function returns an enclosure of the exact real result; see
``docs/soundness.md`` for the rounding argument of each primitive.
"""
from .rounding import enclose, to_fraction
from .interval import Interval, concatenate, div, mul, pown, sqr, stack
from .elementary import abs, atan, atan2, cos, exp, log, max, min, sin, sqrt, tan, pi

__all__ = [
    "Interval", "enclose", "to_fraction", "stack", "concatenate", "mul", "div", "pown", "sqr",
    "sqrt", "abs", "min", "max", "sin", "cos", "tan", "atan", "atan2", "exp", "log", "pi",
]
