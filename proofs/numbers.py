"""Reading the numbers of a certificate.

Two kinds of numbers occur (docs/certificates.md):

- JSON numbers (box bounds, split points, witness poses) denote the exact
  binary64 value of Python's float ``repr``; ``real`` returns that float and
  ``iv.mpf(float)`` is then exact (at any ``iv.prec`` >= 53, else enclosed).
- Exact decimal strings (geometry, ``requested``): ``enclose`` returns an
  outward interval ``iv.mpf(text)`` and ``exact`` the rational ``Fraction``.
  A requested bound may carry ``deg`` (degrees, as certkin's command line
  accepts); its value d·π/180 is irrational and only enclosed.

Strings are limited in length and exponent so that a hostile file cannot
make the checker build gigantic integers.
"""
from __future__ import annotations

import math
import re
from fractions import Fraction

from mpmath import iv

from .report import Rejected

_DECIMAL = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)(?:[eE]([+-]?\d+))?")
MAX_TEXT = 200
MAX_EXPONENT = 1000


def real(value, where: str) -> float:
    """A JSON number as the exact float it denotes (ints only if exactly representable)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise Rejected(f"{where}: expected a number, got {value!r}")
    if isinstance(value, int):
        if abs(value) > 2 ** 53:
            raise Rejected(f"{where}: integer {value} is not an exact float")
        value = float(value)
    if not math.isfinite(value):
        raise Rejected(f"{where}: not a finite number")
    return value


def _decimal_text(value, where: str) -> str:
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise Rejected(f"{where}: expected an exact decimal string, got {value!r}")
    text = str(value).strip()
    m = _DECIMAL.fullmatch(text)
    if len(text) > MAX_TEXT or not m or (m.group(2) and abs(int(m.group(2))) > MAX_EXPONENT):
        raise Rejected(f"{where}: not an exact decimal: {value!r}")
    return text


def enclose(value, where: str):
    """Outward interval enclosing an exact decimal (string or JSON integer)."""
    return iv.mpf(_decimal_text(value, where))


def exact(value, where: str) -> Fraction:
    """The exact rational value of a decimal string."""
    return Fraction(_decimal_text(value, where))


def inside(value, lo: float, hi: float, where: str) -> bool:
    """Is the exact decimal (or ``<decimal>deg``) ``value`` in [lo, hi]?"""
    if isinstance(value, str) and value.strip().lower().endswith("deg"):
        x = enclose(value.strip()[:-3], where) * iv.pi / 180
        return (x >= iv.mpf(lo)) is True and (x <= iv.mpf(hi)) is True
    q = exact(value, where)
    return Fraction(lo) <= q <= Fraction(hi)


def sign(x) -> int:
    """1 or -1 when the interval ``x`` excludes 0, else 0."""
    if (x > 0) is True:
        return 1
    if (x < 0) is True:
        return -1
    return 0
