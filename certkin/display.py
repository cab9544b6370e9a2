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

Rounding is done on the exact value of each number (``exact``: a float,
a numpy float of any width, an int, a ``Fraction``, a ``Decimal`` or an
mpmath ``mpf``, never converted to float first) toward -inf or +inf, so
the printed decimal bounds the number exactly, not up to another rounding.

    >>> outward(-20.439551636576653, -19.560448363423347)
    '[-20.43955164, -19.56044836]'
    >>> inward(-20.439551636576653, -19.560448363423347)
    '[-20.43955163, -19.56044837]'
    >>> point(0.1)
    '0.1'
"""
from __future__ import annotations

from decimal import ROUND_CEILING, ROUND_FLOOR, Context, Decimal
from fractions import Fraction
import json
import math
import operator

DIGITS = 10          # significant digits shown by default
MAX_DIGITS = 40      # most significant digits shown (a thin inner interval of a Fraction needs more than 17)


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


def exact(x) -> Decimal | Fraction | float:
    """The exact value of a real number: a ``Decimal`` when it has a finite decimal expansion
    (floats, numpy floats of any width or 0-d arrays of them, ints, ``Decimal``, mpmath ``mpf``,
    dyadic fractions), else a ``Fraction``; nan and infinities as floats.  Nothing is rounded on the
    way."""
    if getattr(x, "ndim", None) == 0 and hasattr(x, "item"):
        x = x[()]                                        # a 0-d numpy array: its scalar (never int(x))
    if isinstance(x, bool):
        return Decimal(int(x))
    if isinstance(x, Decimal):
        return x if x.is_finite() else float(x)
    if isinstance(x, Fraction):
        num, den = x.numerator, x.denominator
        k = den.bit_length() - 1
        return Decimal(f"{num * 5 ** k}E-{k}") if den == 1 << k else x     # dyadic: exact decimal
    if isinstance(x, int) or hasattr(x, "__index__") and not hasattr(x, "as_integer_ratio"):
        try:
            return Decimal(operator.index(x))            # an integer type; an array of floats is refused
        except TypeError:
            raise TypeError(f"not a real number: {x!r}") from None
    if getattr(x, "_mpf_", None) is not None:
        return _mpf_exact(x._mpf_)
    try:
        num, den = x.as_integer_ratio()                  # float, numpy floats (longdouble too)
    except (AttributeError, OverflowError, ValueError):
        f = float(x)
        if math.isnan(f) or math.isinf(f):
            return f
        raise TypeError(f"not a real number: {x!r}") from None
    return exact(Fraction(num, den))


def _mpf_exact(raw) -> Decimal | float:
    """The exact value of mpmath's raw number (sign, mantissa, exponent, bit count)."""
    sign, man, exp, bc = raw
    if not man:
        return Decimal(0) if bc == 0 else math.nan if bc == -1 else -math.inf if sign else math.inf
    return exact(Fraction((-1) ** sign * man * 2 ** exp) if exp >= 0 else Fraction((-1) ** sign * man, 2 ** -exp))


def _directed(q: Fraction, digits: int, up: bool) -> Decimal:
    """A decimal of ``digits`` significant digits, >= q (``up``) or <= q: exact rational rounding."""
    if q == 0:
        return Decimal(0)
    a = abs(q)
    e = len(str(a.numerator)) - len(str(a.denominator))        # 10^(e-1) <= |q| < 10^(e+1)
    if a >= Fraction(10) ** e:
        e += 1
    shift = e - digits                                          # q / 10^shift has ``digits`` integer digits
    scaled = q / Fraction(10) ** shift
    m = math.ceil(scaled) if up else math.floor(scaled)
    return Decimal(f"{m}E{shift}")          # exact (scaleb would round to the context's precision)


def _round(x, digits: int, mode: str) -> str:
    """``x`` (any real: float, numpy float, int, ``Fraction``, ``Decimal``, mpmath ``mpf``) rounded
    toward -inf (``ROUND_FLOOR``) or +inf (``ROUND_CEILING``) to ``digits`` significant digits, from
    its exact value."""
    if not 1 <= digits <= MAX_DIGITS:
        raise ValueError(f"digits must be between 1 and {MAX_DIGITS}")
    v = exact(x)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else "inf" if v > 0 else "-inf"
    if isinstance(v, Fraction):
        return _text(_directed(v, digits, mode == ROUND_CEILING))
    return _text(Context(prec=digits, rounding=mode, Emax=10 ** 9, Emin=-10 ** 9).plus(v))


def lower(x: float, digits: int = DIGITS) -> str:
    """A decimal <= x (x rounded toward -inf to ``digits`` significant digits)."""
    return _round(x, digits, ROUND_FLOOR)


def upper(x: float, digits: int = DIGITS) -> str:
    """A decimal >= x (x rounded toward +inf to ``digits`` significant digits)."""
    return _round(x, digits, ROUND_CEILING)


def point(x) -> str:
    """A point printed exactly: a float as its shortest round-trip text (``repr``), any other real as
    its exact decimal (or ``p/q`` when it has none): for witnesses and other points."""
    v = exact(x)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else "inf" if v > 0 else "-inf"
    if isinstance(x, float) or type(x).__module__ == "numpy" and hasattr(x, "as_integer_ratio") \
            and float(x) == x:
        return repr(float(x))
    return _text(v) if isinstance(v, Decimal) else str(v)


def outward(lo, hi, digits: int = DIGITS) -> str:
    """``[a, b]`` with a <= lo and b >= hi: for enclosures (bounds of any real type, exactly)."""
    return f"[{lower(lo, digits)}, {upper(hi, digits)}]"


def inward(lo, hi, digits: int = DIGITS) -> str:
    """``[a, b]`` with lo <= a <= b <= hi: for inner claims (bounds of any real type, exactly).

    When ``digits`` digits cannot show a non-empty inner interval (a very
    thin one), more digits are used, up to the exact values of the bounds."""
    elo, ehi = exact(lo), exact(hi)
    if isinstance(elo, float) or isinstance(ehi, float):        # nan or an infinite side
        return f"[{upper(lo, digits)}, {lower(hi, digits)}]"
    for d in range(digits, MAX_DIGITS + 1):
        a, b = _round(elo, d, ROUND_CEILING), _round(ehi, d, ROUND_FLOOR)
        if Decimal(a) <= Decimal(b):
            return f"[{a}, {b}]"
    show = [_text(v) if isinstance(v, Decimal) else str(v) for v in (elo, ehi)]
    return f"[{show[0]}, {show[1]}]"      # the exact values


def pair(bounds, digits: int = DIGITS) -> str:
    """An enclosure given as a JSON pair ``[lo, hi]`` (``None``: that side is not bounded), outward."""
    lo, hi = bounds
    return outward(-math.inf if lo is None else lo, math.inf if hi is None else hi, digits)


def interval(iv, digits: int = DIGITS) -> str:
    """An enclosure given as an object with ``lo`` and ``hi`` (an ``Interval``), printed outward."""
    if hasattr(iv, "_mpi_"):                     # an mpmath interval: its endpoints exactly
        lo, hi = (_mpf_exact(e) for e in iv._mpi_)
    else:
        lo, hi = iv.lo, iv.hi
    return outward(lo, hi, digits)


SIZE_UNITS = (("GiB", 2 ** 30), ("MiB", 2 ** 20), ("KiB", 2 ** 10))


def size(n_bytes: float) -> str:
    """A memory size for a person: '1 MiB', '0.5 GiB' (3 significant digits; a measure, not a claim)."""
    for unit, scale in SIZE_UNITS:
        if n_bytes >= scale:
            return f"{n_bytes / scale:.3g} {unit}"
    return f"{n_bytes:.0f} bytes"


def size_bound(n_bytes, up: bool = True) -> str:
    """A memory size in a claim, in ``size``'s units with 3 significant digits, rounded on the exact
    value: up (``up``: a stated need is never understated, 54 700 bytes is '53.5 KiB') or down (an
    amount given or available is never overstated).  Under 1 KiB a whole number of bytes, rounded
    likewise ('1 byte', '1000 bytes'); never '0' for a positive size shown up.

    >>> size_bound(54_700), size_bound(54_700, up=False), size_bound(0.4), size_bound(2 ** 20 + 1)
    ('53.5 KiB', '53.4 KiB', '1 byte', '1.01 MiB')
    """
    q = Fraction(exact(n_bytes))
    for unit, scale in SIZE_UNITS:
        if q >= scale:
            return f"{_text(_directed(q / scale, 3, up))} {unit}"
    n = math.ceil(q) if up else math.floor(q)
    return f"{n} byte{'' if n == 1 else 's'}"


def counted(n: int, noun: str) -> str:
    """``n`` and the noun, plural unless n is 1: '1 cluster', '0 clusters', '2 clusters'."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def printable(text: str) -> str:
    """``text`` with every character that is not printable (a newline, a terminal escape, a bidi control)
    escaped, so that text from a file (a path, an id in a jobs file) prints as one honest line."""
    return "".join(c if c.isprintable() else ascii(c)[1:-1] for c in text)


def json_text(document) -> str:
    """A document as strict JSON: a non-finite number in it (an unbounded side, which the documents
    already write as null, as a margin's) is written null, never as a bare NaN or Infinity, which no
    JSON parser need accept."""
    try:
        return json.dumps(document, allow_nan=False)
    except ValueError:
        return json.dumps(_finite(document), allow_nan=False)


def _finite(value):
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value
