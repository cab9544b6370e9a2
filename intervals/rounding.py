"""Outward rounding primitives and exact enclosure of decimal inputs.

numpy cannot switch the FPU rounding mode.  IEEE 754 makes +, -, *, / and
sqrt correctly rounded to nearest, so the exact result ``r`` of such an
operation lies within half a spacing of the computed float ``c``.  We widen
``c`` outward with

    up(c)   = c + (|c| * 2**-52 + 2**-1022)     (computed to nearest)
    down(c) = c - (|c| * 2**-52 + 2**-1022)

which is at least the next float above (below) ``c``: the proof is in
``docs/soundness.md`` (it follows Rump, Zimmermann, Boldo & Melquiond 2009,
"Computing predecessor and successor in rounding to nearest", with a normal
rather than subnormal additive constant so that no subnormal operand slows
the arithmetic).  It costs four array operations, about five times less than
``np.nextafter``.  An upper bound that overflowed to ``-inf`` is first clipped
to ``-MAX`` (the exact value is then above ``-inf``), likewise for lower bounds.

NaN endpoints mean "nothing is known" (they arise only from operations
undefined on extended reals, such as ``0 * inf``); every predicate of this
package answers conservatively on them.

Decimal inputs (strings, ``Decimal``, ``Fraction``, ``int``) are enclosed by
the two floats around their exact rational value; a float64 (or narrower) is
taken as its exact binary value, and a wider numpy float (a long double) by
the float64 below and above its value when it has no float64 equal
(``float_bounds``).
"""
from __future__ import annotations

from decimal import Decimal, InvalidOperation
from fractions import Fraction
import math

import numpy as np

INF = np.inf
MAX = float(np.finfo(np.float64).max)
REL = 2.0 ** -52         # the relative step of ``up``/``down``: one unit in the last place
ABS = 2.0 ** -1022       # and their absolute step: the smallest normal float


def up(c):
    """An upper bound of every real within half a spacing of ``c`` (elementwise, new array)."""
    c = np.maximum(c, -MAX)
    d = np.abs(c)
    d *= REL
    d += ABS
    d += c
    return d


def down(c):
    """A lower bound of every real within half a spacing of ``c`` (elementwise, new array)."""
    c = np.minimum(c, MAX)
    d = np.abs(c)
    d *= -REL
    d -= ABS
    d += c
    return d


def up_sum(c):
    """``up`` for a sum or difference: no additive slack is needed there.

    A sum whose exact value is zero or subnormal is computed exactly
    (gradual underflow), so only the relative term is required; exact zeros
    stay exact.
    """
    c = np.maximum(c, -MAX)
    d = np.abs(c)
    d *= REL
    d += c
    return d


def down_sum(c):
    """``down`` for a sum or difference (see ``up_sum``)."""
    c = np.minimum(c, MAX)
    d = np.abs(c)
    d *= -REL
    d += c
    return d


SPLIT = 134217729.0          # 2**27 + 1: Veltkamp's splitting constant (Dekker 1971)
EXACT_LOW = 2.0 ** -800     # products in [EXACT_LOW, EXACT_HIGH] of factors at most EXACT_HIGH are tested
EXACT_HIGH = 2.0 ** 800     # for exactness (no overflow, no underflow in Dekker's product)
_LOW_FRACTION_BITS = (1 << 27) - 1      # the 27 lowest of the 52 fraction bits of a float64


def product_error(a, b, p):
    """e with a·b = p + e exactly, for p = fl(a·b), by Dekker's product without fused multiply-add
    (Veltkamp's splitting, Dekker 1971; every operation exact where ``in_exact_range``)."""
    t = SPLIT * a
    ah = t - (t - a)
    al = a - ah
    t = SPLIT * b
    bh = t - (t - b)
    bl = b - bh
    return ((ah * bh - p) + ah * bl + al * bh) + al * bl


def in_exact_range(p, *factors):
    """Where Dekker's product of ``factors`` is error-free: |p| in [EXACT_LOW, EXACT_HIGH] and every
    |factor| at most EXACT_HIGH (the split cannot overflow; the exponents of the factors sum to at
    least −801, so no partial product underflows: Boldo 2006, the Veltkamp/Dekker conditions)."""
    m = np.abs(p)
    ok = (m >= EXACT_LOW) & (m <= EXACT_HIGH)
    for f in factors:
        ok &= np.abs(f) <= EXACT_HIGH
    return ok


def square_exact(a, p):
    """Where p = fl(a·a) is proved to be a² exactly: a = 0, or a has at most 26 significant bits (its
    27 lowest fraction bits are 0, so a² has at most 52) and EXACT_LOW ≤ p ≤ MAX (no underflow, no
    overflow).  A sufficient test (a 27-bit odd significand also squares exactly), in two integer
    operations and two comparisons."""
    bits = np.asarray(a, dtype=np.float64).view(np.int64)
    return (((bits & _LOW_FRACTION_BITS) == 0) & (p >= EXACT_LOW) & (p <= MAX)) | (a == 0)


def up_square(a, p):
    """An upper bound of a² from p = fl(a·a): p itself where ``square_exact``, ``up(p)`` elsewhere."""
    return np.where(square_exact(a, p), p, up(p))


def down_square(a, p):
    """A lower bound of a² from p = fl(a·a) (see ``up_square``)."""
    return np.where(square_exact(a, p), p, down(p))


def _product_exact(a, b, p):
    with np.errstate(invalid="ignore", over="ignore"):
        return ((product_error(a, b, p) == 0) & in_exact_range(p, a, b)) | \
            ((a == 0) & np.isfinite(b)) | ((b == 0) & np.isfinite(a))


def up_product(a, b, p):
    """An upper bound of a·b from p = fl(a·b): p itself where the product is proved exact (Dekker's
    error is 0 in the range where it is error-free, or a factor is 0 and the other finite),
    ``up(p)`` elsewhere."""
    return np.where(_product_exact(a, b, p), p, up(p))


def down_product(a, b, p):
    """A lower bound of a·b from p = fl(a·b) (see ``up_product``)."""
    return np.where(_product_exact(a, b, p), p, down(p))


def next_up(c):
    """The next float above ``c`` (exact, slower; for scalars and tests)."""
    return np.nextafter(c, INF)


def next_down(c):
    """The next float below ``c``."""
    return np.nextafter(c, -INF)


def to_fraction(value) -> Fraction:
    """Exact rational value of an int, float, Decimal, Fraction or decimal string.

    Raises ``ValueError`` for NaN, infinities, booleans and non-numeric strings.
    """
    if isinstance(value, Fraction):
        return value
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"not a number: {value!r}")
    if isinstance(value, (int, np.integer)):
        return Fraction(int(value))
    if isinstance(value, (float, np.floating)):
        if not np.isfinite(value):          # (math.isfinite rounds a long double to float64 first)
            raise ValueError(f"not a finite number: {value!r}")
        return Fraction(*value.as_integer_ratio())      # exact for a long double too (float() would round it)
    if isinstance(value, (str, Decimal)):
        return Fraction(_finite_decimal(value))
    raise ValueError(f"not a number: {value!r}")


def _finite_decimal(value) -> Decimal:
    """The exact finite ``Decimal`` of a decimal string or ``Decimal`` (ValueError otherwise)."""
    if isinstance(value, str):
        try:
            value = Decimal(value.strip())
        except InvalidOperation as exc:
            raise ValueError(f"not a decimal number: {value!r}") from exc
    if not value.is_finite():
        raise ValueError(f"not a finite number: {value}")
    return value


def enclose_fraction(q: Fraction) -> tuple[float, float]:
    """The floats ``lo <= q <= hi`` adjacent to the rational ``q`` (equal if ``q`` is a float).

    ``float(Fraction)`` rounds correctly to nearest, so the exact value lies
    between the rounded float and its neighbour on the side of the error.
    Magnitudes beyond the float range give an infinite endpoint.
    """
    try:
        f = float(q)
    except OverflowError:
        return (MAX, math.inf) if q > 0 else (-math.inf, -MAX)
    exact = Fraction(f)
    if exact == q:
        return f, f
    if exact < q:
        return f, math.nextafter(f, math.inf)
    return math.nextafter(f, -math.inf), f


def enclose_decimal(d: Decimal) -> tuple[float, float]:
    """``enclose_fraction(Fraction(d))`` for a finite decimal, without rational arithmetic.

    ``f = float(d)`` is the float nearest to ``d``; ``Decimal(f)`` is the exact value of ``f`` and
    decimal comparisons are exact, so the comparisons below place ``d`` at ``f`` or strictly
    between ``f`` and its neighbour, and the neighbour's side is checked too (the enclosure
    rests on these exact comparisons, not on how ``float`` rounds).  Anything else (overflow, a
    failed check) takes the rational path.  The result equals ``enclose_fraction``'s.  Exponents far
    outside the float range (|d| ≥ 10⁴⁰⁰ or 0 < |d| < 10⁻⁴⁰⁰) are answered without it: the rational
    path would build an integer of that many digits (``1e999999999``: gigabytes).
    """
    if d and d.is_finite() and abs(d.adjusted()) > 400:
        if d.adjusted() > 0:                # beyond MAX: what float() overflowing gives below
            return (MAX, math.inf) if d > 0 else (-math.inf, -MAX)
        return (0.0, math.nextafter(0.0, math.inf)) if d > 0 else (math.nextafter(0.0, -math.inf), 0.0)
    f = float(d) + 0.0                      # + 0.0: no negative zero (as float(Fraction(0)))
    if math.isfinite(f):
        exact = Decimal(f)
        if exact == d:
            return f, f
        if exact < d:
            g = math.nextafter(f, math.inf)
            if math.isfinite(g) and d < Decimal(g):
                return f, g
        else:
            g = math.nextafter(f, -math.inf)
            if math.isfinite(g) and Decimal(g) < d:
                return g, f
    return enclose_fraction(Fraction(d))


def enclose_plain(text: str) -> tuple[float, float] | None:
    """``enclose`` of a plain finite decimal text, or None for anything else (no exception)."""
    try:
        d = Decimal(text)
    except InvalidOperation:
        return None
    return enclose_decimal(d) if d.is_finite() else None


def float_bounds(values) -> tuple[np.ndarray, np.ndarray]:
    """Float64 arrays ``lo <= values <= hi`` (elementwise) for a float array or scalar of any precision.

    A float64, or a narrower float, is its own exact binary value: ``lo = hi = values``.  A wider
    float (a long double: 64 or 112 significand bits) has a float64 equal only if it is short
    enough; otherwise it lies strictly between two adjacent float64s, which are returned.  The
    cast to float64 rounds (to nearest); comparing the cast back with the original is exact
    (every float64 is a long double), so it tells on which side the value lies, and the
    neighbour on that side (``np.nextafter``) is the other bound.  A value beyond the float64
    range gets an infinite bound on its side (``[MAX, inf]``), one below the smallest subnormal
    a bound 0.  NaN stays NaN (the caller decides what it means).
    """
    a = np.asarray(values)
    if a.dtype.kind != "f" or a.dtype.itemsize <= 8:
        f = np.asarray(a, dtype=np.float64)  # no copy of a float64 array
        return f, f
    with np.errstate(over="ignore", under="ignore"):
        f = a.astype(np.float64)
    below = f.astype(a.dtype) < a          # the value is above its rounding: f is the lower bound
    above = f.astype(a.dtype) > a
    lo = np.where(above, np.nextafter(f, -INF), f) + 0.0     # + 0.0: no negative zero
    hi = np.where(below, np.nextafter(f, INF), f) + 0.0
    return lo, hi


def enclose(value) -> tuple[float, float]:
    """Outward float enclosure ``(lo, hi)`` of an exact number (see ``to_fraction``): a float64 is
    its own value, a long double is enclosed by the float64s around it (``float_bounds``)."""
    if isinstance(value, (float, np.floating)):
        if math.isnan(value):
            raise ValueError("NaN is not a number an interval can enclose")
        lo, hi = float_bounds(value)
        return float(lo), float(hi)
    if isinstance(value, (str, Decimal)):
        return enclose_decimal(_finite_decimal(value))
    return enclose_fraction(to_fraction(value))


def sum_bounds(lo, hi, axis):
    """Lower and upper bounds of the exact sums along ``axis`` of the reals between ``lo`` and
    ``hi``: float sums widened by 4(n + 1)u Σ|x| (n terms; any order of summation loses at most
    γ_{n−1} Σ|x_i|, Higham 2002 §4.2, and the float Σ|x_i| is within γ_{n−1} of the exact one;
    4(n + 1)u covers both), each step rounded outward.  Up to four terms: one outward-rounded
    addition after another (tighter, and as cheap)."""
    n = np.shape(lo)[axis]
    if 1 <= n <= 4:
        lo, hi = np.moveaxis(np.asarray(lo), axis, 0), np.moveaxis(np.asarray(hi), axis, 0)
        slo, shi = lo[0].copy(), hi[0].copy()
        for k in range(1, n):
            slo, shi = down_sum(slo + lo[k]), up_sum(shi + hi[k])
        return slo, shi
    d = 4.0 * (n + 1) * 2.0 ** -53
    slack_lo = up(np.sum(np.abs(lo), axis=axis) * d)
    slack_hi = up(np.sum(np.abs(hi), axis=axis) * d)
    return down_sum(np.sum(lo, axis=axis) - slack_lo), up_sum(np.sum(hi, axis=axis) + slack_hi)
