"""The batched interval type and its correctly rounded arithmetic.

One class, ``Interval``, holds two float64 arrays ``lo`` and ``hi`` of any
shape: a scalar interval is the 0-d case, a batch of boxes an (N, d) array.
Every operation encloses the exact set ``{x op y : x in X, y in Y}``:
correctly rounded results are widened with ``rounding.up``/``rounding.down``;
exact operations (negation, comparisons, hull) are not widened.

Conventions (see ``docs/soundness.md``):

* endpoints may be infinite (``[-inf, 1]`` is the half line); ``0 * inf``
  counts as 0 because an infinite endpoint is a bound, not a value;
* a NaN endpoint means *no information*; predicates answer conservatively;
* the empty set (from ``intersect``) has ``lo > hi``; ``is_empty`` detects it.
"""
from __future__ import annotations

from decimal import Decimal
from fractions import Fraction
import numbers

import numpy as np

from .rounding import (ABS, INF, MAX, REL, down, down_product, down_square, down_sum, enclose, float_bounds, up,
                       up_product, up_square, up_sum)

_EXACT_SCALARS = (str, Decimal, Fraction, numbers.Integral)


def _endpoints(value):
    """(lo, hi) float arrays enclosing ``value`` (exact for float64s, outward for decimals and long
    doubles)."""
    if isinstance(value, Interval):
        return value.lo, value.hi
    if isinstance(value, (float, np.floating)):
        if np.isnan(value):
            raise ValueError("NaN is not a number an interval can enclose")
        lo, hi = float_bounds(value)
        return np.float64(lo), np.float64(hi)
    if isinstance(value, _EXACT_SCALARS) and not isinstance(value, (bool, np.bool_)):
        lo, hi = enclose(value)
        return np.float64(lo), np.float64(hi)
    arr = np.asarray(value)
    if arr.dtype.kind == "f":
        if np.isnan(arr).any():
            raise ValueError("NaN is not a number an interval can enclose")
        return float_bounds(arr)
    if arr.dtype.kind in "iu" and not _beyond_exact_integers(arr):
        arr = arr.astype(np.float64)
        return arr, arr
    if arr.dtype.kind in "iuOU":             # (integers of more than 53 bits: each enclosed as a rational)
        flat = [enclose(v) for v in arr.ravel().tolist()]
        lo = np.array([p[0] for p in flat], dtype=np.float64).reshape(arr.shape)
        hi = np.array([p[1] for p in flat], dtype=np.float64).reshape(arr.shape)
        return lo, hi
    raise ValueError(f"cannot build an interval from {value!r}")


def _beyond_exact_integers(arr) -> bool:
    """True if the integer array holds a value of magnitude above 2**53 (its float64 may round)."""
    if arr.size == 0 or arr.dtype.itemsize < 8:
        return False
    return bool(arr.max() > 2 ** 53 or (arr.dtype.kind == "i" and arr.min() < -(2 ** 53)))


class Interval:
    """A closed interval ``[lo, hi]``, or an array of them (elementwise).

    >>> x = Interval("0.1")
    >>> bool(x.lo < x.hi) and bool(x.contains(0.1))
    True
    >>> y = Interval(-1, 2) ** 2
    >>> float(y.lo), bool(4 <= y.hi < 4.0000001)
    (0.0, True)
    """

    __slots__ = ("lo", "hi")
    __array_ufunc__ = None  # ndarray op Interval defers to Interval's reflected ops

    def __init__(self, lo, hi=None):
        if isinstance(lo, Interval) and hi is None:
            self.lo, self.hi = lo.lo, lo.hi
            return
        lo_lo, lo_hi = _endpoints(lo)
        if hi is None:
            a, b = lo_lo, lo_hi
        else:
            hi_lo, hi_hi = _endpoints(hi)
            a, b = lo_lo, hi_hi
        a, b = np.broadcast_arrays(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
        if np.any(a > b):
            raise ValueError("interval lower bound exceeds upper bound")
        if np.any(a == INF) or np.any(b == -INF):
            raise ValueError("an interval endpoint cannot be +inf below or -inf above")
        self.lo = np.array(a, dtype=np.float64)
        self.hi = np.array(b, dtype=np.float64)

    @classmethod
    def from_bounds(cls, lo, hi):
        """The interval (or array of intervals) with endpoint arrays ``lo`` and ``hi``, trusted as
        they are: no check, no copy, no rounding.

        For code that has computed its bounds itself, already outward rounded (``rounding.down``,
        ``up``, ...) or exact floats, and wants them held without cost.  The caller vouches that
        ``[lo, hi]`` encloses what it stands for; ``lo > hi`` marks an empty set and a NaN bound
        means "nothing known", as everywhere in this package.  ``Interval(lo, hi)`` is the checked
        constructor (it encloses decimals, rejects NaN and ``lo > hi``).
        """
        obj = object.__new__(cls)
        obj.lo = lo
        obj.hi = hi
        return obj

    @classmethod
    def entire(cls, shape=()):
        return cls.from_bounds(np.full(shape, -INF), np.full(shape, INF))

    @classmethod
    def empty(cls, shape=()):
        return cls.from_bounds(np.full(shape, INF), np.full(shape, -INF))

    # ----- array protocol ------------------------------------------------
    @property
    def shape(self):
        return self.lo.shape

    @property
    def ndim(self):
        return self.lo.ndim

    @property
    def size(self):
        return self.lo.size

    def __len__(self):
        return len(self.lo)

    def __getitem__(self, index):
        return Interval.from_bounds(self.lo[index], self.hi[index])

    def __setitem__(self, index, value):
        lo, hi = _endpoints(value)
        self.lo[index] = lo
        self.hi[index] = hi

    def reshape(self, *shape):
        return Interval.from_bounds(self.lo.reshape(*shape), self.hi.reshape(*shape))

    def copy(self):
        return Interval.from_bounds(self.lo.copy(), self.hi.copy())

    def __iter__(self):
        for i in range(len(self)):
            yield self[i]

    def __repr__(self):
        if self.ndim == 0:
            return f"Interval([{float(self.lo)!r}, {float(self.hi)!r}])"
        return f"Interval(lo={self.lo!r}, hi={self.hi!r})"

    # ----- set operations (exact) ----------------------------------------
    def mid(self):
        """A float inside the interval (0 for the entire line, a finite bound's neighbour for half-lines)."""
        lo = np.maximum(self.lo, -MAX)
        hi = np.minimum(self.hi, MAX)
        m = 0.5 * lo + 0.5 * hi  # no overflow; rounding keeps it inside [lo, hi]
        return np.minimum(np.maximum(m, self.lo), self.hi)

    def width(self):
        """An upper bound of ``hi - lo``."""
        return up_sum(self.hi - self.lo)

    def rad(self):
        """An upper bound of the radius around ``mid()``."""
        m = self.mid()
        return np.maximum(up_sum(m - self.lo), up_sum(self.hi - m))

    def mag(self):
        """max |x| over the interval (exact)."""
        return np.maximum(np.abs(self.lo), np.abs(self.hi))

    def mig(self):
        """min |x| over the interval (exact)."""
        return np.where((self.lo <= 0) & (self.hi >= 0), 0.0, np.minimum(np.abs(self.lo), np.abs(self.hi)))

    def hull(self, other):
        o = as_interval(other)
        return Interval.from_bounds(np.minimum(self.lo, o.lo), np.maximum(self.hi, o.hi))

    def intersect(self, other):
        """Intersection; empty where ``lo > hi``. A NaN (unknown) side is ignored."""
        o = as_interval(other)
        return Interval.from_bounds(np.fmax(self.lo, o.lo), np.fmin(self.hi, o.hi))

    def is_empty(self):
        return self.lo > self.hi

    def contains(self, x):
        """True where the number or interval ``x`` lies in ``self`` (NaN -> True: cannot exclude)."""
        o = as_interval(x)
        return ~((o.lo < self.lo) | (o.hi > self.hi))

    def subset(self, other):
        """True where ``self`` is proved inside ``other`` (NaN -> False)."""
        o = as_interval(other)
        return (self.lo >= o.lo) & (self.hi <= o.hi)

    def interior(self, other):
        """True where ``self`` is proved inside the interior of ``other`` (NaN -> False)."""
        o = as_interval(other)
        return (self.lo > o.lo) & (self.hi < o.hi)

    def disjoint(self, other):
        """True where ``self`` and ``other`` are proved to share no point (NaN -> False)."""
        o = as_interval(other)
        return (self.hi < o.lo) | (o.hi < self.lo)

    def contains_zero(self):
        """True where 0 may lie in the interval (NaN -> True)."""
        return ~((self.lo > 0) | (self.hi < 0))

    def bisect(self, ratio=0.5):
        """Two intervals ``[lo, m]``, ``[m, hi]`` split at ``lo + ratio*(hi-lo)`` (elementwise)."""
        m = self.lo + ratio * (self.hi - self.lo)
        m = np.where(np.isfinite(m), m, self.mid())
        m = np.minimum(np.maximum(m, self.lo), self.hi)
        return Interval.from_bounds(self.lo.copy(), m), Interval.from_bounds(m.copy(), self.hi.copy())

    # ----- arithmetic ------------------------------------------------------
    def __neg__(self):
        return Interval.from_bounds(-self.hi, -self.lo)

    def __pos__(self):
        return self

    def __add__(self, other):
        if _defers(other):
            return NotImplemented
        o = as_interval(other)
        return Interval.from_bounds(down_sum(self.lo + o.lo), up_sum(self.hi + o.hi))

    __radd__ = __add__

    def __sub__(self, other):
        if _defers(other):
            return NotImplemented
        o = as_interval(other)
        return Interval.from_bounds(down_sum(self.lo - o.hi), up_sum(self.hi - o.lo))

    def __rsub__(self, other):
        return as_interval(other) - self

    def __mul__(self, other):
        if _defers(other):
            return NotImplemented
        return mul(self, as_interval(other))

    __rmul__ = __mul__

    def __truediv__(self, other):
        if _defers(other):
            return NotImplemented
        return div(self, as_interval(other))

    def __rtruediv__(self, other):
        return div(as_interval(other), self)

    def __pow__(self, n):
        return pown(self, n)


def _defers(other) -> bool:
    """True for the types that implement mixed operations with intervals themselves
    (``autodiff.Dual``, ``polynomial.Poly``): Interval's operators return NotImplemented."""
    return getattr(other, "takes_interval_operands", False)


def as_interval(x) -> Interval:
    if isinstance(x, Interval):
        return x
    if isinstance(x, (float, np.floating)) or (isinstance(x, np.ndarray) and x.dtype.kind == "f"):
        lo, hi = float_bounds(x)             # a float64 is its own exact binary value, a long double is
        return Interval.from_bounds(lo, hi)  # enclosed by the float64s around it
    return Interval(x)


def mul(x: Interval, y: Interval) -> Interval:
    """Product enclosure: hull of the four endpoint products, rounded outward.

    ``fmin``/``fmax`` skip the NaN of ``0 * inf``, which is right because an
    infinite endpoint bounds the set and is not one of its values.  (Only
    ``[0, 0] * [-inf, inf]`` has all four corners NaN; its NaN result means
    "unknown", which every predicate treats conservatively.)

    The same operations on the same operands, in the same order, as
    ``_mul_reference`` (``fmin(fmin(p1, p2), fmin(p3, p4))``, then ``down``;
    likewise for the upper bound), with the intermediate arrays reused
    (``out=``): the same floats, bit for bit (``tests/test_interval.py``).
    """
    with np.errstate(invalid="ignore"):
        p1 = x.lo * y.lo
        p2 = x.lo * y.hi
        p3 = x.hi * y.lo
        p4 = x.hi * y.hi
    if not (type(p1) is np.ndarray and p1.dtype == np.float64 and p1.ndim
            and p1.shape == p2.shape == p3.shape == p4.shape):
        return _mul_corners(p1, p2, p3, p4)
    lo = np.fmin(p1, p2)
    hi = np.fmax(p1, p2, out=p1)
    b = np.fmin(p3, p4, out=p2)
    d = np.fmax(p3, p4, out=p3)
    np.fmin(lo, b, out=lo)
    np.fmax(hi, d, out=hi)
    # down(lo) and up(hi) (intervals.rounding), in place: the same operations
    np.minimum(lo, MAX, out=lo)
    t = np.abs(lo, out=b)
    t *= -REL
    t -= ABS
    t += lo
    np.maximum(hi, -MAX, out=hi)
    u = np.abs(hi, out=d)
    u *= REL
    u += ABS
    u += hi
    return Interval.from_bounds(t, u)


def _mul_corners(p1, p2, p3, p4) -> Interval:
    lo = np.fmin(np.fmin(p1, p2), np.fmin(p3, p4))
    hi = np.fmax(np.fmax(p1, p2), np.fmax(p3, p4))
    # only [0,0] * [-inf, inf] leaves NaN here: it then means "unknown", which is sound
    return Interval.from_bounds(down(lo), up(hi))


def _mul_reference(x: Interval, y: Interval) -> Interval:
    """``mul`` as first written (four corner products, ``fmin``/``fmax``, ``down``/``up``): the
    reference the in-place ``mul`` is compared with bit for bit in the tests."""
    with np.errstate(invalid="ignore"):
        p1 = x.lo * y.lo
        p2 = x.lo * y.hi
        p3 = x.hi * y.lo
        p4 = x.hi * y.hi
    return _mul_corners(p1, p2, p3, p4)


def div(x: Interval, y: Interval) -> Interval:
    """Quotient enclosure.

    When 0 lies in ``y`` the result is the hull of the extended-real quotient
    set: ``[1,2]/[0,1] = [1, inf]``, ``[1,2]/[-1,1] = [-inf, inf]``,
    ``[0,0]/y = [0,0]`` for ``y != [0,0]``, and ``x/[0,0]`` is empty
    (``lo > hi``) unless ``x`` contains 0, where it is entire.  Never a
    finite interval that misses a quotient.
    """
    x, y = np.broadcast_arrays(x.lo, y.lo), np.broadcast_arrays(x.hi, y.hi)
    xlo, ylo = x
    xhi, yhi = y
    with np.errstate(divide="ignore", invalid="ignore"):
        q1 = xlo / ylo
        q2 = xlo / yhi
        q3 = xhi / ylo
        q4 = xhi / yhi
        lo = np.fmin(np.fmin(q1, q2), np.fmin(q3, q4))
        hi = np.fmax(np.fmax(q1, q2), np.fmax(q3, q4))
    lo = down(lo)
    hi = up(hi)
    y_has_zero = (ylo <= 0) & (yhi >= 0)
    if np.any(y_has_zero):
        lo, hi = _div_zero(xlo, xhi, ylo, yhi, lo, hi, y_has_zero)
    return Interval.from_bounds(lo, hi)


def _div_zero(xlo, xhi, ylo, yhi, lo, hi, mask):
    lo = np.array(lo, copy=True)
    hi = np.array(hi, copy=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        xpos = xlo > 0
        xneg = xhi < 0
        xzero = (xlo == 0) & (xhi == 0)
        yzero = (ylo == 0) & (yhi == 0)
        # default: entire line
        lo[mask] = -INF
        hi[mask] = INF
        # y = [0, d], d > 0
        right = mask & (ylo == 0) & (yhi > 0)
        sel = right & xpos
        lo[sel] = down(xlo[sel] / yhi[sel])
        hi[sel] = INF
        sel = right & xneg
        lo[sel] = -INF
        hi[sel] = up(xhi[sel] / yhi[sel])
        # y = [c, 0], c < 0
        left = mask & (yhi == 0) & (ylo < 0)
        sel = left & xpos
        lo[sel] = -INF
        hi[sel] = up(xlo[sel] / ylo[sel])
        sel = left & xneg
        lo[sel] = down(xhi[sel] / ylo[sel])
        hi[sel] = INF
        # x = [0, 0] and y != [0, 0]: quotient 0
        sel = mask & xzero & ~yzero
        lo[sel] = 0.0
        hi[sel] = 0.0
        # y = [0, 0] and 0 not in x: no quotient at all
        sel = mask & yzero & (xpos | xneg)
        lo[sel] = INF
        hi[sel] = -INF
    return lo, hi


def sqr(x: Interval) -> Interval:
    """Tight square: ``sqr([-1, 2]) = [0, 4]`` (not ``x*x = [-2, 4]``), exactly: a bound whose float
    square is exact (Dekker's error-free check, ``rounding.up_square``) is not widened."""
    a = x.mig()
    b = x.mag()
    with np.errstate(invalid="ignore", over="ignore"):
        lo, hi = a * a, b * b
        return Interval.from_bounds(np.maximum(down_square(a, lo), 0.0), up_square(b, hi))


def _pow_nonneg(base, n, direction):
    """base**n for base >= 0 by binary powering, each product rounded ``direction`` (``up`` or
    ``down``) unless Dekker's error-free check proves it exact (``rounding.up_product``)."""
    product, square = (up_product, up_square) if direction is up else (down_product, down_square)
    result = np.ones_like(base)
    b = np.array(base, dtype=np.float64, copy=True)
    with np.errstate(invalid="ignore", over="ignore"):
        while n:
            if n & 1:
                result = product(result, b, result * b)
            n >>= 1
            if n:
                b = square(b, b * b)
    if direction is down:
        result = np.maximum(result, 0.0)
    return result


def pown(x: Interval, n: int) -> Interval:
    """Integer power, tight: even powers use (mig, mag); odd powers are monotone."""
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool):
        raise TypeError("interval powers take integer exponents; use exp/log otherwise")
    n = int(n)
    if n == 0:
        return Interval.from_bounds(np.ones(x.shape), np.ones(x.shape))
    if n < 0:
        return div(Interval.from_bounds(np.ones(x.shape), np.ones(x.shape)), pown(x, -n))
    if n == 1:
        return x
    if n % 2 == 0:
        return Interval.from_bounds(_pow_nonneg(x.mig(), n, down), _pow_nonneg(x.mag(), n, up))
    lo_abs = np.abs(x.lo)
    hi_abs = np.abs(x.hi)
    lo = np.where(x.lo >= 0, _pow_nonneg(lo_abs, n, down), -_pow_nonneg(lo_abs, n, up))
    hi = np.where(x.hi >= 0, _pow_nonneg(hi_abs, n, up), -_pow_nonneg(hi_abs, n, down))
    return Interval.from_bounds(lo, hi)


def stack(items, axis=-1) -> Interval:
    """Stack intervals (or numbers) along a new axis."""
    ivs = [as_interval(i) for i in items]
    return Interval.from_bounds(np.stack([np.broadcast_to(i.lo, np.broadcast_shapes(*[j.shape for j in ivs])) for i in ivs], axis=axis),
                         np.stack([np.broadcast_to(i.hi, np.broadcast_shapes(*[j.shape for j in ivs])) for i in ivs], axis=axis))


def concatenate(items, axis=0) -> Interval:
    ivs = [as_interval(i) for i in items]
    return Interval.from_bounds(np.concatenate([i.lo for i in ivs], axis=axis), np.concatenate([i.hi for i in ivs], axis=axis))
