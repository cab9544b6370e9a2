"""Numbers shown to people, rounded in the direction that keeps the claim true.

A reviewer copies printed numbers into a report, so a printed bound must
be at least as safe as the proved one:

- an *enclosure* (an FK box, the range of a margin, a forbidden
  t-interval, an outer area) is printed **outward**: the printed interval
  contains the proved one;
- an *inner claim* (a box proved singularity-free, a t-range proved
  feasible, an inner area) is printed **inward**: the printed interval lies
  inside the proved one;
- a *point* (a witness pose) is printed exactly (``repr``: the shortest
  decimal that reads back as the same float64).

Rounding is done on the exact decimal value of each float (``Decimal(x)``
is exact) with ``ROUND_FLOOR`` / ``ROUND_CEILING``, so the printed decimal
bounds the float exactly, not up to another rounding.

    >>> outward(-20.439551636576653, -19.560448363423347)
    '[-20.43955164, -19.56044836]'
    >>> inward(-20.439551636576653, -19.560448363423347)
    '[-20.43955163, -19.56044837]'
    >>> point(0.1)
    '0.1'
"""
from __future__ import annotations

from decimal import ROUND_CEILING, ROUND_FLOOR, Context, Decimal
import math

DIGITS = 10          # significant digits shown by default


def decimal_text(d: Decimal) -> str:
    """A decimal in plain notation for moderate magnitudes, scientific otherwise (exact either way)."""
    return _text(d)


def _text(d: Decimal) -> str:
    if d.is_zero():
        return "0"
    exponent = d.adjusted()
    if -6 <= exponent < 16:
        s = format(d, "f")
        if "." in s:
            s = s.rstrip("0").rstrip(".")
        return s
    mantissa, _, power = format(d, "e").partition("e")
    if "." in mantissa:
        mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(power)}"


def _round(x: float, digits: int, mode: str) -> str:
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    if not 1 <= digits <= 17:
        raise ValueError("digits must be between 1 and 17")
    return _text(Context(prec=digits, rounding=mode).plus(Decimal(x)))


def lower(x: float, digits: int = DIGITS) -> str:
    """A decimal <= x (x rounded toward -inf to ``digits`` significant digits)."""
    return _round(x, digits, ROUND_FLOOR)


def upper(x: float, digits: int = DIGITS) -> str:
    """A decimal >= x (x rounded toward +inf to ``digits`` significant digits)."""
    return _round(x, digits, ROUND_CEILING)


def point(x: float) -> str:
    """The exact float (shortest round-trip text): for witnesses and other points."""
    x = float(x)
    if math.isnan(x) or math.isinf(x):
        return _round(x, 1, ROUND_FLOOR)
    return repr(x)


def outward(lo: float, hi: float, digits: int = DIGITS) -> str:
    """``[a, b]`` with a <= lo and b >= hi: for enclosures."""
    return f"[{lower(lo, digits)}, {upper(hi, digits)}]"


def inward(lo: float, hi: float, digits: int = DIGITS) -> str:
    """``[a, b]`` with lo <= a <= b <= hi: for inner claims.

    When ``digits`` digits cannot show a non-empty inner interval (a very
    thin one), more digits are used, up to the exact decimal values of the floats."""
    lo, hi = float(lo), float(hi)
    for d in range(digits, 18):
        a, b = upper(lo, d), lower(hi, d)
        if Decimal(a) <= Decimal(b):
            return f"[{a}, {b}]"
    return f"[{_text(Decimal(lo))}, {_text(Decimal(hi))}]"      # the exact values


def pair(bounds, digits: int = DIGITS) -> str:
    """An enclosure given as a JSON pair ``[lo, hi]`` (``None``: that side is not bounded), outward."""
    lo, hi = bounds
    return outward(-math.inf if lo is None else lo, math.inf if hi is None else hi, digits)


def interval(iv, digits: int = DIGITS) -> str:
    """An enclosure given as an object with ``lo`` and ``hi`` (an ``Interval``), printed outward."""
    return outward(float(iv.lo), float(iv.hi), digits)
