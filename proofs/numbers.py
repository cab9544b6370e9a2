"""Reading the numbers of a certificate exactly (docs/soundness.md §12, "Decimals and π").

- Floats (JSON numbers, body arrays) denote their exact binary64 value.
- Decimal strings (geometry, leg lengths, requested boxes, paths) denote their exact rational value: ``exact``
  gives the ``Fraction``, ``enclose`` the tightest float interval; an angle ``<decimal>deg`` is q·π/180, enclosed.

Strings are limited in length and exponent, so that a hostile file cannot make the checker build gigantic integers."""
from __future__ import annotations

import math
import re
from fractions import Fraction

from .arith import PI_BELOW, PI_ABOVE, Iv
from .report import Rejected

_DECIMAL = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)(?:[eE]([+-]?\d+))?", re.ASCII)   # (\d alone: any script's digits)
MAX_TEXT, MAX_EXPONENT = 1100, 400     # (the exact decimal of a double: at most 767 significant digits)


def real(value, where: str) -> float:
    """A JSON number as the exact finite float it denotes (integers only if exactly representable)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise Rejected(f"{where}: expected a number, got {value!r:.60}")
    if isinstance(value, int):
        if abs(value) > 2 ** 53:
            raise Rejected(f"{where}: integer {value} is not an exact float")
        value = float(value)
    if not math.isfinite(value):
        raise Rejected(f"{where}: not a finite number")
    return value


def exact(value, where: str) -> Fraction:
    """The exact rational value of a decimal string (or JSON integer)."""
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise Rejected(f"{where}: expected an exact decimal string, got {value!r:.60}")
    text = str(value).strip()
    m = _DECIMAL.fullmatch(text)
    if len(text) > MAX_TEXT or not m or (m.group(2) and abs(int(m.group(2))) > MAX_EXPONENT):
        raise Rejected(f"{where}: not an exact decimal: {value!r:.60}")
    return Fraction(text)


def angle(value, where: str):
    """(exact rational, in degrees?) of ``<decimal>`` or ``<decimal>deg``."""
    if isinstance(value, str) and value.strip().lower().endswith("deg"):
        return exact(value.strip()[:-3], where), True
    return exact(value, where), False


def enclose(value, where: str, degrees_allowed: bool = False) -> Iv:
    """The tightest float interval holding a decimal (an angle in degrees: q·π/180, enclosed)."""
    q, deg = angle(value, where) if degrees_allowed else (exact(value, where), False)
    a, b = sorted((q * PI_BELOW / 180, q * PI_ABOVE / 180)) if deg else (q, q)
    return Iv(Iv.const(a).lo, Iv.const(b).hi)


def canonical(value) -> str:
    """The canonical text of an exact decimal (``3.780`` → ``3.78``, ``1e1`` → ``10``; ``deg`` kept)."""
    text = str(value).strip()
    suffix = "deg" if text.lower().endswith("deg") else ""
    q = exact(text[:-3] if suffix else text, "decimal")     # (its limits: no gigantic integer is built)
    sign, q = ("-" if q < 0 else ""), abs(q)
    whole, rest = divmod(q.numerator, q.denominator)
    digits = ""
    while rest and len(digits) < 2000:      # terminates: the denominator divides a power of ten
        rest *= 10
        d, rest = divmod(rest, q.denominator)
        digits += str(d)
    return sign + str(whole) + ("." + digits if digits else "") + suffix


def inside(value, lo: float, hi: float, where: str) -> bool:
    """Is the exact decimal (or ``<decimal>deg``, enclosed) ``value`` within [lo, hi]?"""
    q, deg = angle(value, where)
    if deg:
        x = enclose(value, where, True)
        return bool(x.lo >= lo and x.hi <= hi)
    return (lo == -math.inf or (math.isfinite(lo) and Fraction(lo) <= q)) and \
        (hi == math.inf or (math.isfinite(hi) and q <= Fraction(hi)))
