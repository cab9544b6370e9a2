"""Rigorous elementary functions on batched intervals.

Every function takes an ``Interval`` (or anything ``Interval(...)`` accepts) of
any shape and returns an ``Interval`` of the (broadcast) shape enclosing the
exact image set.  NaN endpoints ("nothing known") give NaN or a sound
bounded answer (``sin``/``cos`` answer ``[-1, 1]``); an empty input (``lo >
hi``) gives an empty output.

Rounding
--------
* ``sqrt`` is correctly rounded by IEEE 754.  Its enclosure is the tightest
  possible: the sign of the residual ``r*r - x`` is computed exactly (Dekker's
  product), so ``sqrt([4, 9]) = [2, 3]`` exactly and an inexact root is
  enclosed by two adjacent floats.  Outside ``[2**-960, 2**960]`` the
  neighbours on both sides are taken.
* ``abs``, ``min``, ``max`` are exact.
* ``exp``, ``log``, ``sin``, ``cos``, ``tan``, ``atan``, ``atan2`` call numpy,
  whose libm is *not* correctly rounded.  A computed value ``c`` is widened by

      c +/- (K * 2**-52 * |c| + 2**-1022)      (computed to nearest)

  with ``K = ULPS[name]`` below.  ``2**-52 * |c|`` is one or two ulps of ``c``
  (at least one ulp of any real near ``c``) and the final rounding of the sum
  costs at most half of one, so the guaranteed widening is at least ``K - 1``
  ulps of the exact value (at most ``2K + 1`` ulps of ``c``), plus an absolute
  ``2**-1022`` that covers any error (even a flush to zero) of a result whose
  exact value is subnormal.
* Justification of ``K``: the error of numpy 2.4.6 (x86-64, AVX-512 machine)
  was measured against mpmath at 250 + exponent bits on about 1.5 million
  arguments per function: random over every binade 2**-1074 .. 2**1023, dense
  on [-10, 10], near multiples k*pi/2 (k up to 1e15) and their float
  neighbours, tiny and subnormal results, log near 1, exp up to overflow.
  Maxima in ulps of the exact value: exp 0.67, log 0.61, atan 0.53,
  atan2 0.75, sin 0.51, cos 0.56, tan 0.56 (trig for |x| <= 2**20; numpy's cos
  is off by 7.95 ulps at the classic hard argument 6381956970095103*2**797,
  which is why huge trig arguments take the mpmath path).  numpy documents
  its SVML (AVX-512) backends at <= 4 ulps; ``K = 8`` covers that bound as
  well, i.e. about ten times the measured error.  ``tests/test_elementary.py``
  re-measures on every run and fails if an error exceeds ``K / 2``.
* Functions keep exact values exact where cheap and certain: ``sin(0) =
  tan(0) = atan(0) = 0``, ``cos(0) = exp(0) = 1``, ``log(1) = 0``,
  ``atan2(0, x > 0) = 0``; and sign/monotonicity facts clamp the widened
  bounds (``0 <= sin x <= x`` on ``[0, 3]``, ``exp >= 0``, ``|atan x| <= |x|``,
  results of sin/cos within ``[-1, 1]``, of atan within ``pi/2``).

Trigonometry
------------
Extrema of sin (cos) are the points ``t * pi/2`` with integer ``t = 1, 3 mod
4`` (``t = 0, 2 mod 4``), poles of tan are the odd ``t``.  The quotient
``x / (pi/2)`` is enclosed with the outward-rounded enclosure of pi, and an
extremum counts as present whenever an integer of the right class lies in the
enclosure: any doubt gives the conservative ``+/-1`` (or the entire line for
tan).  For ``|x| > 2**20`` (a few elements at most in practice) endpoint
values and the extremum test are computed elementwise with mpmath interval
arithmetic (``mpmath.libmp.mpi_*``, directed rounding) at ``128 + exponent``
bits, then rounded outward to floats: ``sin(1e22)`` is enclosed by two
adjacent floats.  An interval of width ``>= 2 pi`` gives ``[-1, 1]``.
"""
from __future__ import annotations

import builtins

import numpy as np

from .interval import Interval, as_interval
from .rounding import INF, MAX


class _Libmp:
    """``mpmath.libmp``, imported at its first use (the huge-argument path only): 60 ms less start-up."""

    def __getattr__(self, name):
        from mpmath import libmp
        return getattr(libmp, name)


_mp = _Libmp()

__all__ = ["pi", "sqrt", "abs", "min", "max", "sin", "cos", "tan", "atan", "atan2", "exp", "log", "ULPS"]

# ---------------------------------------------------------------------------
# constants
# ---------------------------------------------------------------------------
_PI_LO = 3.141592653589793                     # fl(pi) = pi - 1.22e-16 (below pi)
_PI_HI = float(np.nextafter(_PI_LO, 4.0))      # next float: above pi
_HP_LO = 0.5 * _PI_LO                          # exact halving: pi/2 in [_HP_LO, _HP_HI]
_HP_HI = 0.5 * _PI_HI
_TWO_PI_LO = 2.0 * _PI_LO

pi = Interval.from_bounds(np.asarray(_PI_LO), np.asarray(_PI_HI))
"""The two adjacent floats around pi."""

#: widening, in ulps, applied to each numpy libm result (see module docstring)
ULPS = {"exp": 8.0, "log": 8.0, "atan": 8.0, "atan2": 8.0, "sin": 8.0, "cos": 8.0, "tan": 8.0}

_REL = 2.0 ** -52
_TINY = 2.0 ** -1022
_TRIG_FLOAT_MAX = 2.0 ** 20   # beyond: endpoint values and extremum tests with mpmath


def _arr(v):
    return np.asarray(v, dtype=np.float64)


def _wup(c, k):
    """Upper bound of any real within ``k - 1`` ulps (of itself) of the float ``c``."""
    c = np.maximum(c, -MAX)
    return c + (np.abs(c) * (k * _REL) + _TINY)


def _wdown(c, k):
    """Lower bound of any real within ``k - 1`` ulps of the float ``c``."""
    c = np.minimum(c, MAX)
    return c - (np.abs(c) * (k * _REL) + _TINY)


def _keep_empty(lo, hi, empty):
    """Force ``[inf, -inf]`` where the input was empty."""
    if np.any(empty):
        lo = np.where(empty, INF, lo)
        hi = np.where(empty, -INF, hi)
    return lo, hi


def _out(lo, hi):
    return Interval.from_bounds(_arr(lo), _arr(hi))


# ---------------------------------------------------------------------------
# exact functions
# ---------------------------------------------------------------------------
def abs(x):
    """``{|t| : t in X}`` (exact)."""
    x = as_interval(x)
    lo, hi = _keep_empty(x.mig(), x.mag(), x.lo > x.hi)
    return _out(lo, hi)


def min(x, y):
    """Elementwise ``{min(s, t)}`` hull: ``[min(xlo, ylo), min(xhi, yhi)]`` (exact)."""
    x, y = as_interval(x), as_interval(y)
    lo, hi = _keep_empty(np.minimum(x.lo, y.lo), np.minimum(x.hi, y.hi), (x.lo > x.hi) | (y.lo > y.hi))
    return _out(lo, hi)


def max(x, y):
    """Elementwise ``{max(s, t)}`` hull: ``[max(xlo, ylo), max(xhi, yhi)]`` (exact)."""
    x, y = as_interval(x), as_interval(y)
    lo, hi = _keep_empty(np.maximum(x.lo, y.lo), np.maximum(x.hi, y.hi), (x.lo > x.hi) | (y.lo > y.hi))
    return _out(lo, hi)


# ---------------------------------------------------------------------------
# sqrt (correctly rounded: tightest enclosure)
# ---------------------------------------------------------------------------
_SPLIT = 134217729.0  # 2**27 + 1


def _sqrt_side(x, upper):
    """Tightest float bound (lower, or upper if ``upper``) of sqrt at the points ``x >= 0``.

    ``r = fl(sqrt(x))`` is correctly rounded, so the exact root lies between
    ``r`` and its neighbour on the side given by the sign of ``r*r - x``,
    which Dekker's exact product decides; ``r`` itself is returned when it is
    on the right side (exact squares give exact roots).
    """
    r = np.sqrt(x)
    ok = (x >= 2.0 ** -960) & (x <= 2.0 ** 960)
    rs = np.where(ok, r, 1.0)
    xs = np.where(ok, x, 1.0)
    # Dekker: rs*rs = p + e exactly (no overflow or underflow in this range)
    t = _SPLIT * rs
    h = t - (t - rs)
    l = rs - h
    p = rs * rs
    e = ((h * h - p) + 2.0 * h * l) + l * l
    d = (p - xs) + e  # p - xs is exact (Sterbenz); the rounded sum has the sign of rs*rs - xs
    if upper:
        keep = ok & (d >= 0)   # r >= sqrt(x)
        out = np.nextafter(r, np.where(keep, r, INF))
        return np.where(x == 0, 0.0, out)
    keep = ok & (d <= 0)       # r <= sqrt(x)
    out = np.nextafter(r, np.where(keep, r, -INF))
    return np.maximum(out, 0.0)


def sqrt(x):
    """Square root; the part below 0 is ignored, an interval entirely below 0 gives empty."""
    x = as_interval(x)
    with np.errstate(invalid="ignore"):
        lo = _sqrt_side(np.maximum(x.lo, 0.0), False)
        hi = _sqrt_side(np.maximum(x.hi, 0.0), True)
    lo, hi = _keep_empty(lo, hi, (x.lo > x.hi) | (x.hi < 0))
    return _out(lo, hi)


# ---------------------------------------------------------------------------
# exp, log, atan (monotone increasing)
# ---------------------------------------------------------------------------
def exp(x):
    """Exponential; overflow gives ``hi = inf``, the lower bound is never negative."""
    x = as_interval(x)
    k = ULPS["exp"]
    a, b = x.lo, x.hi
    with np.errstate(over="ignore", invalid="ignore"):
        lo = np.maximum(_wdown(np.exp(a), k), 0.0)
        hi = _wup(np.exp(b), k)
    lo = np.where(a >= 0, np.maximum(lo, 1.0), lo)   # exp(t) >= 1 for t >= 0
    hi = np.where(b <= 0, np.minimum(hi, 1.0), hi)   # exp(t) <= 1 for t <= 0
    lo, hi = _keep_empty(lo, hi, a > b)
    return _out(lo, hi)


def log(x):
    """Natural logarithm; ``lo = -inf`` when the interval reaches 0, empty if it lies below 0."""
    x = as_interval(x)
    k = ULPS["log"]
    a, b = x.lo, x.hi
    with np.errstate(divide="ignore", invalid="ignore"):
        lo = np.where(a > 0, _wdown(np.log(np.where(a > 0, a, 1.0)), k), -INF)
        hi = _wup(np.log(np.maximum(b, 0.0)), k)     # log(0) = -inf -> about -MAX (finite)
        lo = np.where(a >= 1, np.maximum(lo, 0.0), lo)
        hi = np.where(b <= 1, np.minimum(hi, 0.0), hi)
        near = (b >= 0.5) & (b <= 2.0)
        hi = np.where(near, np.minimum(hi, b - 1.0), hi)  # log t <= t - 1; b - 1 exact (Sterbenz)
    lo, hi = _keep_empty(lo, hi, (a > b) | (b < 0))
    return _out(lo, hi)


def atan(x):
    """Arctangent, within ``[-pi/2, pi/2]`` (enclosed outward)."""
    x = as_interval(x)
    k = ULPS["atan"]
    a, b = x.lo, x.hi
    lo = np.maximum(_wdown(np.arctan(a), k), -_HP_HI)
    hi = np.minimum(_wup(np.arctan(b), k), _HP_HI)
    # sign and |atan t| <= |t|
    lo = np.where(a >= 0, np.maximum(lo, 0.0), np.maximum(lo, a))
    hi = np.where(b <= 0, np.minimum(hi, 0.0), np.minimum(hi, b))
    lo, hi = _keep_empty(lo, hi, a > b)
    return _out(lo, hi)


# ---------------------------------------------------------------------------
# trigonometric functions
# ---------------------------------------------------------------------------
def _quarter_lo(x):
    """Lower bound of x / (pi/2) (x finite, |x| <= 2**20)."""
    q = np.minimum(x / _HP_HI, x / _HP_LO)
    return q - (np.abs(q) * _REL + _TINY)


def _quarter_hi(x):
    q = np.maximum(x / _HP_HI, x / _HP_LO)
    return q + (np.abs(q) * _REL + _TINY)


def _has_class(qlo, qhi, r, m):
    """True where some integer n = r (mod m) may lie in [qlo, qhi] (|q| < 2**50, m = 2 or 4).

    Tests ``floor((qhi - r)/m) >= ceil((qlo - r)/m)``.  The subtraction rounds,
    but rounding is monotone and the integers are floats, so
    ``floor(fl(v)) >= floor(v)`` and ``ceil(fl(v)) <= ceil(v)``: an error can
    only answer "present" (conservative).  Division by m is exact.
    """
    inv = 1.0 / m
    return np.floor((qhi - r) * inv) >= np.ceil((qlo - r) * inv)


def _widen_bounded(c, k):
    """``(_wdown(c, k), _wup(c, k))`` for finite ``c`` (no clipping needed), clamped to [-1, 1]."""
    d = np.abs(c)
    d *= k * _REL
    d += _TINY
    lo = c - d
    hi = np.add(c, d, out=d)
    np.maximum(lo, -1.0, out=lo)
    np.minimum(hi, 1.0, out=hi)
    return lo, hi


def _sin_point(x, k):
    """Bounds of sin at the points x (|x| <= 2**20)."""
    lo, hi = _widen_bounded(np.sin(x), k)
    # 0 <= sin t <= t on [0, 3] and t <= sin t <= 0 on [-3, 0] (3 < pi); exact at 0
    near = np.abs(x) <= 3.0
    pos = near & (x >= 0)
    neg = near & (x <= 0)
    np.maximum(lo, np.where(pos, 0.0, x), out=lo, where=near)
    np.minimum(hi, np.where(neg, 0.0, x), out=hi, where=near)
    return lo, hi


def _cos_point(x, k):
    lo, hi = _widen_bounded(np.cos(x), k)
    lo[...] = np.where(x == 0, 1.0, lo)
    return lo, hi


# --- mpmath path for huge arguments -----------------------------------------
def _mpi_point(v):
    f = _mp.from_float(float(v))
    return (f, f)


def _floor_float(m):
    return _mp.to_float(m, rnd=_mp.round_floor)


def _ceil_float(m):
    return _mp.to_float(m, rnd=_mp.round_ceiling)


def _prec_for(*vals):
    e = builtins.max(int(np.frexp(v)[1]) for v in vals)
    return 128 + builtins.max(e, 0)


def _half_pi_mpi(prec):
    return (_mp.mpf_shift(_mp.mpf_pi(prec, _mp.round_floor), -1),
            _mp.mpf_shift(_mp.mpf_pi(prec, _mp.round_ceiling), -1))


def _has_class_mp(a, b, r, m, prec):
    """mpmath version of ``_has_class`` for the true quotients a/(pi/2) .. b/(pi/2)."""
    hp = _half_pi_mpi(prec)
    qa = _mp.mpi_div(_mpi_point(a), hp, prec)
    qb = _mp.mpi_div(_mpi_point(b), hp, prec)
    c = _mp.to_int(_mp.mpf_ceil(qa[0]))
    first = c + (r - c) % m
    return _mp.mpf_le(_mp.from_int(first), qb[1])


def _trig_big(kind, a, b):
    """(lo, hi) of sin/cos/tan over [a, b] (finite, b - a < 2 pi) with mpmath intervals."""
    prec = _prec_for(a, b)
    if kind == "tan":
        if _has_class_mp(a, b, 1, 2, prec):
            return -INF, INF
        return _floor_float(_mp.mpi_tan(_mpi_point(a), prec)[0]), _ceil_float(_mp.mpi_tan(_mpi_point(b), prec)[1])
    f = _mp.mpi_sin if kind == "sin" else _mp.mpi_cos
    fa = f(_mpi_point(a), prec)
    fb = f(_mpi_point(b), prec)
    lo = builtins.min(_floor_float(fa[0]), _floor_float(fb[0]))
    hi = builtins.max(_ceil_float(fa[1]), _ceil_float(fb[1]))
    rmax, rmin = (1, 3) if kind == "sin" else (0, 2)
    if _has_class_mp(a, b, rmax, 4, prec):
        hi = 1.0
    if _has_class_mp(a, b, rmin, 4, prec):
        lo = -1.0
    return builtins.max(lo, -1.0), builtins.min(hi, 1.0)


def _sincos(x, kind):
    x = as_interval(x)
    k = ULPS[kind]
    a, b = np.broadcast_arrays(_arr(x.lo), _arr(x.hi))
    shape = a.shape
    a, b = np.atleast_1d(a), np.atleast_1d(b)  # in-place steps below need arrays, not scalars
    with np.errstate(invalid="ignore", over="ignore"):
        wide = ~(b - a < _TWO_PI_LO)             # includes NaN and infinite endpoints
        big = ~wide & ~(a > b) & ((np.abs(a) > _TRIG_FLOAT_MAX) | (np.abs(b) > _TRIG_FLOAT_MAX))
        small = ~(wide | big)
        if small.all():
            az, bz = a, b
        else:
            az = np.where(small, a, 0.0)
            bz = np.where(small, b, 0.0)
        point = _sin_point if kind == "sin" else _cos_point
        la, ha = point(az, k)
        lb, hb = point(bz, k)
        lo = np.minimum(la, lb)
        hi = np.maximum(ha, hb)
        qlo, qhi = _quarter_lo(az), _quarter_hi(bz)
        rmax, rmin = (1.0, 3.0) if kind == "sin" else (0.0, 2.0)
        hi = np.where(_has_class(qlo, qhi, rmax, 4.0), 1.0, hi)
        lo = np.where(_has_class(qlo, qhi, rmin, 4.0), -1.0, lo)
        lo = np.where(wide, -1.0, lo)
        hi = np.where(wide, 1.0, hi)
    if np.any(big):
        lo = np.array(lo, copy=True)
        hi = np.array(hi, copy=True)
        for idx in map(tuple, np.argwhere(big)):  # the rare huge elements only
            lo[idx], hi[idx] = _trig_big(kind, a[idx], b[idx])
    lo, hi = _keep_empty(lo, hi, a > b)
    return _out(lo.reshape(shape), hi.reshape(shape))


def sin(x):
    """Sine over each interval (monotone pieces; conservative extremum test)."""
    return _sincos(x, "sin")


def cos(x):
    """Cosine over each interval (monotone pieces; conservative extremum test)."""
    return _sincos(x, "cos")


def tan(x):
    """Tangent; an interval that may contain a pole gives the entire line."""
    x = as_interval(x)
    k = ULPS["tan"]
    a, b = np.broadcast_arrays(_arr(x.lo), _arr(x.hi))
    with np.errstate(invalid="ignore", over="ignore"):
        wide = ~(b - a < _PI_LO)
        big = ~wide & ~(a > b) & ((np.abs(a) > _TRIG_FLOAT_MAX) | (np.abs(b) > _TRIG_FLOAT_MAX))
        small = ~(wide | big)
        az = np.where(small, a, 0.0)
        bz = np.where(small, b, 0.0)
        pole = wide | (small & _has_class(_quarter_lo(az), _quarter_hi(bz), 1.0, 2.0))
        lo = _wdown(np.tan(az), k)
        hi = _wup(np.tan(bz), k)
        # tan t >= t >= 0 on [0, 1.5], tan t <= t <= 0 on [-1.5, 0]
        lo = np.where((az >= 0) & (az <= 1.5), np.maximum(lo, az), lo)
        hi = np.where((bz <= 0) & (bz >= -1.5), np.minimum(hi, bz), hi)
        lo = np.where(pole, -INF, lo)
        hi = np.where(pole, INF, hi)
    if np.any(big):
        lo = np.array(lo, copy=True)
        hi = np.array(hi, copy=True)
        for idx in map(tuple, np.argwhere(big)):  # the rare huge elements only
            lo[idx], hi[idx] = _trig_big("tan", a[idx], b[idx])
    lo, hi = _keep_empty(lo, hi, a > b)
    return _out(lo, hi)


# ---------------------------------------------------------------------------
# atan2
# ---------------------------------------------------------------------------
def atan2(y, x):
    """The angles ``atan2(s, t)`` (in ``(-pi, pi]``) of the points of the box ``Y x X``.

    A box containing the origin, or containing points ``(t < 0, s = 0)`` together
    with points ``s < 0`` (the angle set then wraps around +/-pi), gives
    ``[-pi, pi]``, or ``[0, pi]`` when ``s >= 0`` on the whole box (atan2(0, 0) taken as 0).  Otherwise the angle is continuous on the convex box and its
    extremes are at corners.  Signed zeros are read as 0: ``atan2([0, 1], -1)``
    contains pi, never -pi.
    """
    y, x = as_interval(y), as_interval(x)
    k = ULPS["atan2"]
    ylo, yhi, xlo, xhi = np.broadcast_arrays(_arr(y.lo) + 0.0, _arr(y.hi) + 0.0, _arr(x.lo) + 0.0, _arr(x.hi) + 0.0)
    with np.errstate(invalid="ignore"):
        origin = (xlo <= 0) & (xhi >= 0) & (ylo <= 0) & (yhi >= 0)
        cut = (xlo < 0) & (ylo < 0) & (yhi >= 0)
        full = origin | cut
        c1 = np.arctan2(ylo, xlo)
        c2 = np.arctan2(ylo, xhi)
        c3 = np.arctan2(yhi, xlo)
        c4 = np.arctan2(yhi, xhi)
        lo = np.minimum(np.minimum(c1, c2), np.minimum(c3, c4))
        hi = np.maximum(np.maximum(c1, c2), np.maximum(c3, c4))
        lo = np.maximum(_wdown(lo, k), -_PI_HI)
        hi = np.minimum(_wup(hi, k), _PI_HI)
        # angles in [0, pi] when y >= 0; in [-pi/2, pi/2] when x >= 0
        lo = np.where(ylo >= 0, np.maximum(lo, 0.0), lo)
        right = xlo >= 0
        lo = np.where(right, np.maximum(lo, -_HP_HI), lo)
        hi = np.where(right, np.minimum(hi, _HP_HI), hi)
        hi = np.where(right & (yhi <= 0), np.minimum(hi, 0.0), hi)
        # atan2(0, t > 0) = 0 exactly
        axis = (ylo == 0) & (yhi == 0) & (xlo > 0)
        lo = np.where(axis, 0.0, lo)
        hi = np.where(axis, 0.0, hi)
        lo = np.where(full, np.where(ylo >= 0, 0.0, -_PI_HI), lo)    # (y >= 0: the upper half-plane, [0, pi])
        hi = np.where(full, _PI_HI, hi)
    lo, hi = _keep_empty(lo, hi, (ylo > yhi) | (xlo > xhi))
    return _out(lo, hi)
