"""Tests of intervals.elementary against mpmath at (at least) 100 digits.

Property tests draw batches of intervals over every magnitude (subnormal to
1e308, exact and negative zeros, near multiples of pi/2) and points inside
them; the exact image of each point must lie in the computed enclosure.
"""
import math

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from mpmath import mp, mpf

from intervals import elementary as el
from intervals.interval import Interval

MAX = float(np.finfo(np.float64).max)
SETTINGS = settings(max_examples=300, deadline=None)


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------
_TRIG = (mpmath.sin, mpmath.cos, mpmath.tan)


def exact(fn, *xs):
    """fn at the exact float arguments, >= 100 digits (more bits for huge trig arguments)."""
    e = 0
    if fn in _TRIG:
        e = max([0] + [math.frexp(x)[1] for x in xs if x != 0 and math.isfinite(x)])
    with mp.workprec(340 + e):
        return fn(*[mpf(x) for x in xs])


def inside(lo, hi, value):
    lo, hi = float(lo), float(hi)
    return mpf(lo) <= value <= mpf(hi)


def ulp(x):
    x = abs(float(x))
    return math.ulp(x) if x > 0 else 5e-324


def halfpi_float(k, nudge):
    with mp.workprec(200):
        f = float(mpf(k) * mp.pi / 2)
    for _ in range(abs(nudge)):
        f = math.nextafter(f, math.copysign(math.inf, nudge))
    return f


# ---------------------------------------------------------------------------
# strategies
# ---------------------------------------------------------------------------
binade = st.builds(lambda m, e, s: s * math.ldexp(m, e),
                   st.floats(1.0, 2.0, exclude_max=True), st.integers(-1074, 1023), st.sampled_from([1.0, -1.0]))
specials = st.sampled_from([0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1e-300, -1e-300,
                            1.0, -1.0, 1e300, -1e300, MAX, -MAX, 1e22, 2.0 ** 20, 3.0, -3.0])
_rng = np.random.default_rng(2024)
_HALFPI_K = ([int(k) for k in range(-8, 9)] + [int(k) for k in _rng.integers(-10 ** 6, 10 ** 6, 40)]
             + [int(k) for k in _rng.integers(-10 ** 15, 10 ** 15, 20)])
_HALFPI = sorted({halfpi_float(k, d) for k in _HALFPI_K for d in (-2, -1, 0, 1, 2)})
near_halfpi = st.sampled_from(_HALFPI)
anyfloat = st.one_of(binade, st.floats(-10, 10), specials, near_halfpi)
trigfloat = st.one_of(binade, st.floats(-10, 10), specials, near_halfpi, near_halfpi, st.floats(-1e7, 1e7))


def intervals(floats):
    wide = st.tuples(floats, floats).map(sorted)
    narrow = st.builds(lambda c, j: (c, c + abs(c) * j * 2.0 ** -45 if c + abs(c) * j * 2.0 ** -45 < math.inf else c),
                       floats, st.integers(0, 64))
    point = floats.map(lambda c: (c, c))
    return st.one_of(wide, narrow, point)


def pick(lo, hi, t):
    if t == 0.0:
        return lo
    if t == 1.0:
        return hi
    p = (1.0 - t) * lo + t * hi
    return min(max(p, lo), hi)


ts = st.one_of(st.sampled_from([0.0, 1.0]), st.floats(0.0, 1.0))


def batches(floats):
    return st.lists(st.tuples(intervals(floats), ts), min_size=1, max_size=6)


def batch_arrays(batch):
    lo = np.array([b[0][0] for b in batch])
    hi = np.array([b[0][1] for b in batch])
    pts = [pick(b[0][0], b[0][1], b[1]) for b in batch]
    return Interval(lo, hi), pts


def check_unary(fn, mpfn, batch, domain=lambda p: True):
    x, pts = batch_arrays(batch)
    r = fn(x)
    assert r.shape == x.shape
    assert not np.isnan(r.lo).any() and not np.isnan(r.hi).any()
    for i, p in enumerate(pts):
        if domain(p):
            v = exact(mpfn, p)
            assert inside(r.lo[i], r.hi[i], v), (fn.__name__, x[i], p, r[i], v)
    return x, r


# ---------------------------------------------------------------------------
# property tests: enclosure of the exact value
# ---------------------------------------------------------------------------
@SETTINGS
@given(batches(anyfloat))
def test_sqrt_exp_log_atan_abs_enclose(batch):
    x, r = check_unary(el.sqrt, mpmath.sqrt, batch, lambda p: p >= 0)
    assert np.all((r.lo > r.hi) == (x.hi < 0))
    assert np.all(r.lo[(x.lo <= 0) & (x.hi >= 0)] == 0.0)

    x, r = check_unary(el.exp, mpmath.exp, batch)
    assert np.all(r.lo >= 0)

    x, r = check_unary(el.log, mpmath.log, batch, lambda p: p > 0)
    assert np.all(r.lo[(x.lo <= 0) & (x.hi >= 0)] == -np.inf)
    assert np.all((r.lo > r.hi) == (x.hi < 0))

    x, r = check_unary(el.atan, mpmath.atan, batch)
    assert np.all(r.lo >= -el.pi.hi / 2) and np.all(r.hi <= el.pi.hi / 2)

    x, r = check_unary(el.abs, abs, batch)
    for i in range(len(batch)):
        lo, hi = x.lo[i], x.hi[i]
        assert r.hi[i] == max(abs(lo), abs(hi))
        assert r.lo[i] == (0.0 if lo <= 0 <= hi else min(abs(lo), abs(hi)))


@SETTINGS
@given(batches(trigfloat))
def test_sin_cos_tan_enclose(batch):
    x, r = check_unary(el.sin, mpmath.sin, batch)
    assert np.all(r.lo >= -1) and np.all(r.hi <= 1)
    x, r = check_unary(el.cos, mpmath.cos, batch)
    assert np.all(r.lo >= -1) and np.all(r.hi <= 1)
    check_unary(el.tan, mpmath.tan, batch)


small_or_any = st.one_of(anyfloat, st.floats(-3, 3), st.sampled_from([0.0, -0.0]))


@SETTINGS
@given(batches(small_or_any), batches(small_or_any))
def test_atan2_min_max_enclose(by, bx):
    n = min(len(by), len(bx))
    y, py = batch_arrays(by[:n])
    x, px = batch_arrays(bx[:n])
    lo_, hi_ = el.min(x, y), el.max(x, y)  # exact: [min(xlo, ylo), min(xhi, yhi)] etc.
    assert np.array_equal(lo_.lo, np.minimum(x.lo, y.lo)) and np.array_equal(lo_.hi, np.minimum(x.hi, y.hi))
    assert np.array_equal(hi_.lo, np.maximum(x.lo, y.lo)) and np.array_equal(hi_.hi, np.maximum(x.hi, y.hi))
    for i in range(n):
        assert lo_.lo[i] <= min(px[i], py[i]) <= lo_.hi[i]
        assert hi_.lo[i] <= max(px[i], py[i]) <= hi_.hi[i]
    r = el.atan2(y, x)
    assert r.shape == (n,)
    assert not np.isnan(r.lo).any() and not np.isnan(r.hi).any()
    assert np.all(r.lo >= -el.pi.hi) and np.all(r.hi <= el.pi.hi)
    for i in range(n):
        # the corners and the drawn point, with signed zeros read as 0 (atan2(0, -1) = pi)
        cands = [(py[i], px[i]), (y.lo[i], x.lo[i]), (y.lo[i], x.hi[i]), (y.hi[i], x.lo[i]), (y.hi[i], x.hi[i])]
        for a, b in cands:
            if a == 0 and b == 0:
                continue
            v = exact(mpmath.atan2, a, b)
            assert inside(r.lo[i], r.hi[i], v), (y[i], x[i], (a, b), r[i], v)


@SETTINGS
@given(st.one_of(st.floats(-1e6, 1e6), binade.filter(lambda v: abs(v) < 1e300), near_halfpi))
def test_point_intervals_are_tight(v):
    """A point interval gives an enclosure only a few ulps wide (K ulps each side at most)."""
    x = Interval(v)
    for fn, mpfn in [(el.sin, mpmath.sin), (el.cos, mpmath.cos), (el.atan, mpmath.atan), (el.exp, mpmath.exp)]:
        r = fn(x)
        y = float(exact(mpfn, v))
        if not (0 < abs(y) < MAX) or abs(y) < 1e-300:
            continue
        if fn is el.sin or fn is el.cos:
            if abs(v) > 2.0 ** 20:
                assert r.hi - r.lo <= 2 * ulp(y), (fn.__name__, v, r)
                continue
            if abs(y) < 1e-290 or (r.hi == 1.0 and y > 0.99) or (r.lo == -1.0 and y < -0.99):
                continue  # an extremum may be counted: [., 1] is the conservative answer
        k = el.ULPS[fn.__name__]  # K * 2**-52 * |c| is at most 2K ulps of c on each side
        assert r.hi - r.lo <= (4 * k + 4) * ulp(y) + 2.0 ** -1021, (fn.__name__, v, r)
    if v > 0:
        r = el.log(x)
        y = float(exact(mpmath.log, v))
        if y != 0:
            assert r.hi - r.lo <= (4 * el.ULPS["log"] + 4) * ulp(y)
        r = el.sqrt(x)
        if 2.0 ** -960 <= v <= 2.0 ** 960:  # adjacent floats (or exact)
            assert r.hi <= math.nextafter(r.lo, math.inf)
        else:
            assert r.hi <= math.nextafter(math.nextafter(r.lo, math.inf), math.inf)


# ---------------------------------------------------------------------------
# measured libm error: every ulp constant keeps a margin of 2 (error <= K/2)
# ---------------------------------------------------------------------------
def _ulp_error(c, y):
    if y == 0:
        return 0.0 if c == 0 else math.inf
    return float(abs(mpf(c) - y) / mpf(ulp(float(y))))


@pytest.mark.parametrize("name", ["exp", "log", "atan", "sin", "cos", "tan", "atan2"])
def test_numpy_libm_error_within_half_the_constant(name):
    rng = np.random.default_rng(12345)
    n = 1500
    m = rng.uniform(1, 2, n)
    if name == "exp":
        xs = rng.uniform(-745, 709.7, n)
    elif name == "log":
        xs = np.concatenate([np.ldexp(m, rng.integers(-1074, 1024, n)), 1 + rng.uniform(-0.01, 0.01, n)])
    elif name in ("sin", "cos", "tan"):
        xs = np.concatenate([np.ldexp(m, rng.integers(-60, 21, n)) * rng.choice([-1, 1], n),
                             [halfpi_float(int(k), int(d)) for k, d in zip(rng.integers(-10 ** 5, 10 ** 5, 300),
                                                                              rng.integers(-2, 3, 300))]])
    else:
        xs = np.ldexp(m, rng.integers(-1074, 1024, n)) * rng.choice([-1, 1], n)
    k = el.ULPS[name]
    worst = 0.0
    if name == "atan2":
        ys = np.ldexp(rng.uniform(1, 2, n), rng.integers(-60, 60, n)) * rng.choice([-1, 1], n)
        xs = np.ldexp(m, rng.integers(-60, 60, n)) * rng.choice([-1, 1], n)
        cs = np.arctan2(ys, xs)
        for a, b, c in zip(ys.tolist(), xs.tolist(), cs.tolist()):
            worst = max(worst, _ulp_error(c, exact(mpmath.atan2, a, b)))
    else:
        npf = {"atan": np.arctan}.get(name) or getattr(np, name)
        cs = npf(xs)
        mpfn = getattr(mpmath, name)
        for x, c in zip(xs.tolist(), cs.tolist()):
            worst = max(worst, _ulp_error(c, exact(mpfn, x)))
    assert worst <= k / 2, (name, worst)


# ---------------------------------------------------------------------------
# tightness and special values
# ---------------------------------------------------------------------------
def test_pi_encloses_pi_with_adjacent_floats():
    with mp.workdps(100):
        assert mpf(float(el.pi.lo)) < mp.pi < mpf(float(el.pi.hi))
    assert el.pi.hi == math.nextafter(float(el.pi.lo), math.inf)


def test_sqrt_tight():
    r = el.sqrt(Interval(4, 9))
    assert r.lo == 2.0 and r.hi == 3.0
    r = el.sqrt(Interval(2))
    assert r.hi == math.nextafter(float(r.lo), math.inf)
    assert inside(r.lo, r.hi, exact(mpmath.sqrt, 2.0))
    r = el.sqrt(Interval(-1, 4))
    assert r.lo == 0.0 and r.hi == 2.0
    r = el.sqrt(Interval(-3, -1))
    assert r.lo > r.hi
    r = el.sqrt(Interval(0, 1e-300))
    assert r.lo == 0.0
    assert el.sqrt(Interval(0.0)).hi == 0.0


def test_sin_cos_tightness():
    half_pi = Interval(0.5 * el.pi.lo, 0.5 * el.pi.hi)
    r = el.sin(Interval(0.0, float(half_pi.hi)))
    assert r.lo == 0.0 and r.hi == 1.0
    r = el.sin(Interval(1.0, 2.0))  # contains pi/2
    assert r.hi == 1.0 and inside(r.lo, r.hi, exact(mpmath.sin, 1.0))
    assert r.lo <= math.sin(1.0) and r.lo > math.sin(1.0) - 4e-15
    r = el.cos(Interval(1.0))
    assert r.hi - r.lo <= (4 * el.ULPS["cos"] + 2) * ulp(math.cos(1.0))
    assert inside(r.lo, r.hi, exact(mpmath.cos, 1.0))
    r = el.cos(Interval(-0.5, 0.5))
    assert r.hi == 1.0
    r = el.cos(Interval(3.0, 3.5))  # contains pi
    assert r.lo == -1.0
    r = el.sin(Interval(4.0, 5.0))  # contains 3 pi / 2
    assert r.lo == -1.0 and r.hi < -0.75
    assert el.sin(Interval(0.0)).lo == 0.0 and el.sin(Interval(0.0)).hi == 0.0
    assert el.cos(Interval(0.0)).lo == 1.0 and el.cos(Interval(-0.0)).hi == 1.0
    r = el.sin(Interval(-1e-300, 1e-300))
    assert r.lo == -1e-300 and r.hi == 1e-300
    r = el.sin(Interval(0, 7))
    assert r.lo == -1 and r.hi == 1
    r = el.sin(Interval(-np.inf, np.inf))
    assert r.lo == -1 and r.hi == 1


def test_sin_huge_arguments():
    y = exact(mpmath.sin, 1e22)
    assert abs(float(y) - (-0.8522008497671888)) < 1e-15
    r = el.sin(Interval(1e22))
    assert inside(r.lo, r.hi, y)
    assert r.hi - r.lo <= 2 * ulp(float(y))
    for v in [1e300, -1e300, MAX, 6381956970095103 * 2.0 ** 797, 2.0 ** 20 + 1, float.fromhex("0x1.6ac5b262ca1ffp+849")]:
        for fn, mpfn in [(el.sin, mpmath.sin), (el.cos, mpmath.cos), (el.tan, mpmath.tan)]:
            r = fn(Interval(v))
            y = exact(mpfn, v)
            assert inside(r.lo, r.hi, y), (fn.__name__, v)
            assert r.hi - r.lo <= 2 * ulp(float(y)), (fn.__name__, v, r)
    # large intervals of width < 2 pi (mpmath path) with and without an extremum of sin
    a = 2.0 ** 40 + 0.3  # ulp 2**-12
    with mp.workprec(400):
        k = mpmath.floor((mpf(a) - mp.pi / 2) / (2 * mp.pi)) + 1
        peak = float(mp.pi / 2 + 2 * k * mp.pi)
        trough = float(-mp.pi / 2 + 2 * k * mp.pi)
    r = el.sin(Interval(peak - 0.25, peak + 0.25))
    assert r.hi == 1.0 and inside(r.lo, r.hi, exact(mpmath.sin, peak - 0.25)) and r.lo > 0.95
    r = el.cos(Interval(peak - 0.25, peak + 0.25))  # cos is monotone there
    assert inside(r.lo, r.hi, exact(mpmath.cos, peak + 0.25)) and inside(r.lo, r.hi, exact(mpmath.cos, peak - 0.25))
    assert r.hi - r.lo < 0.5
    r = el.sin(Interval(trough - 0.25, trough + 0.25))
    assert r.lo == -1.0 and r.hi < -0.95
    r = el.sin(Interval(peak + 0.25, peak + 3.0))  # monotone piece, no extremum
    assert r.hi < 0.97 and -0.995 < r.lo < -0.98
    r = el.tan(Interval(peak - 0.25, peak + 0.25))  # a pole of tan
    assert r.lo == -np.inf and r.hi == np.inf
    r = el.tan(Interval(peak + 0.25, peak + 3.0))
    assert np.isfinite(r.lo) and np.isfinite(r.hi)
    r = el.sin(Interval(-1e300, 1e300))
    assert r.lo == -1.0 and r.hi == 1.0
    # a batch mixing huge and small elements
    x = Interval(np.array([[1e22, 0.5], [3.0, -1e300]]))
    r = el.sin(x)
    for idx in [(0, 0), (0, 1), (1, 0), (1, 1)]:
        assert inside(r.lo[idx], r.hi[idx], exact(mpmath.sin, float(x.lo[idx])))


def test_tan_poles():
    r = el.tan(Interval(1.0, 2.0))
    assert r.lo == -np.inf and r.hi == np.inf
    r = el.tan(Interval(-1.0, 1.0))
    assert inside(r.lo, r.hi, exact(mpmath.tan, 1.0)) and inside(r.lo, r.hi, exact(mpmath.tan, -1.0))
    assert r.hi < 1.5575
    r = el.tan(Interval(2.0, 4.0))  # pole-free (pi/2 < 2, 4 < 3 pi / 2)
    assert np.isfinite(r.lo) and np.isfinite(r.hi)
    assert el.tan(Interval(0.0)).lo == 0.0 and el.tan(Interval(0.0)).hi == 0.0
    r = el.tan(Interval(0.0, 4.0))
    assert r.lo == -np.inf
    big = el.tan(Interval(1e22, 1e22 + 2.0 ** 24))  # width 8 > pi
    assert big.lo == -np.inf and big.hi == np.inf


def test_exp_log_special_values():
    r = el.exp(Interval(710.0))
    assert r.hi == np.inf and r.lo > 1e308
    r = el.exp(Interval(-1000.0, 0.0))
    assert r.lo == 0.0 and r.hi == 1.0
    r = el.exp(Interval(0.0))
    assert r.lo == 1.0 and r.hi == 1.0
    r = el.exp(Interval(-np.inf, np.inf))
    assert r.lo == 0.0 and r.hi == np.inf
    r = el.exp(Interval(-745.5))  # exact value below the smallest subnormal
    assert r.lo == 0.0 and r.hi > 0
    r = el.log(Interval(0.0))
    assert r.lo == -np.inf and r.hi <= -1e308
    r = el.log(Interval(-1.0, np.e))
    assert r.lo == -np.inf and inside(r.lo, r.hi, mpf(1))
    r = el.log(Interval(-2.0, -1.0))
    assert r.lo > r.hi
    r = el.log(Interval(1.0))
    assert r.lo == 0.0 and r.hi == 0.0
    r = el.log(Interval(1.0, np.inf))
    assert r.lo == 0.0 and r.hi == np.inf


def test_atan_bounds():
    r = el.atan(Interval(-np.inf, np.inf))
    with mp.workdps(100):
        assert inside(r.lo, r.hi, -mp.pi / 2) and inside(r.lo, r.hi, mp.pi / 2)
    assert r.hi <= el.pi.hi / 2 and r.lo >= -el.pi.hi / 2
    assert el.atan(Interval(0.0)).lo == 0.0 and el.atan(Interval(0.0)).hi == 0.0
    r = el.atan(Interval(1e-300))
    assert r.hi == 1e-300 and r.lo > 0.9e-300


def test_atan2_boxes():
    pi_lo, pi_hi = float(el.pi.lo), float(el.pi.hi)
    # touching the negative x axis from above: contiguous, contains pi
    r = el.atan2(Interval(0.0, 1.0), Interval(-2.0, -1.0))
    assert r.hi == pi_hi and r.lo > 2.0 and r.lo <= math.atan2(1, -1)
    r = el.atan2(Interval(-0.0, 1.0), Interval(-2.0, -1.0))  # signed zero read as 0
    assert r.hi == pi_hi and r.lo > 2.0
    r = el.atan2(Interval(0.0), Interval(-2.0, -1.0))
    assert r.lo <= pi_lo and r.hi >= pi_hi and r.lo > 3.14
    # touching it from below: angles near -pi and the angle pi itself
    r = el.atan2(Interval(-1.0, 0.0), Interval(-2.0, -1.0))
    assert r.lo == -pi_hi and r.hi == pi_hi
    r = el.atan2(Interval(-1.0, -0.0), Interval(-2.0, -1.0))
    assert r.lo == -pi_hi and r.hi == pi_hi
    # crossing it
    r = el.atan2(Interval(-1.0, 1.0), Interval(-2.0, -1.0))
    assert r.lo == -pi_hi and r.hi == pi_hi
    # strictly below: contiguous near -pi
    r = el.atan2(Interval(-1.0, -0.5), Interval(-2.0, -1.0))
    assert r.lo >= -pi_hi and r.hi < -2.0
    # containing the origin
    r = el.atan2(Interval(-1.0, 1.0), Interval(0.0, 1.0))
    assert r.lo == -pi_hi and r.hi == pi_hi
    # crossing the positive x axis: tight
    r = el.atan2(Interval(-1.0, 1.0), Interval(1.0, 2.0))
    assert inside(r.lo, r.hi, exact(mpmath.atan2, -1.0, 1.0)) and r.hi < 0.7854
    r = el.atan2(Interval(0.0), Interval(1.0, 2.0))
    assert r.lo == 0.0 and r.hi == 0.0
    # a point
    r = el.atan2(Interval(1.0), Interval(1.0))
    with mp.workdps(100):
        assert inside(r.lo, r.hi, mp.pi / 4)
    assert r.hi - r.lo <= (4 * el.ULPS["atan2"] + 2) * ulp(math.pi / 4)
    # unbounded boxes
    r = el.atan2(Interval(1.0, np.inf), Interval(-np.inf, -1.0))
    assert r.lo <= math.pi / 2 and r.hi >= math.pi and r.lo > 1.5


def test_batched_shapes_and_broadcasting():
    rng = np.random.default_rng(7)
    lo = rng.uniform(-5, 5, (50, 3))
    x = Interval(lo, lo + rng.uniform(0, 1, (50, 3)))
    pos = Interval(np.abs(lo) + 0.1, np.abs(lo) + 1)
    for fn in (el.sin, el.cos, el.tan, el.atan, el.exp, el.abs, el.sqrt):
        r = fn(x)
        assert r.shape == (50, 3)
        assert r.lo.dtype == np.float64 and r.hi.dtype == np.float64
    assert el.log(pos).shape == (50, 3)
    assert el.sqrt(pos).shape == (50, 3)
    col = Interval(np.array([[1.0], [2.0]]), np.array([[1.5], [2.5]]))
    row = Interval(np.array([[0.0, -1.0, 3.0]]), np.array([[1.0, 2.0, 4.0]]))
    assert el.atan2(col, row).shape == (2, 3)
    assert el.min(col, row).shape == (2, 3) and el.max(col, row).shape == (2, 3)
    assert el.atan2(1.0, row).shape == (1, 3)
    # each element agrees with the scalar call
    r = el.sin(x)
    for i in (0, 17, 49):
        s = el.sin(Interval(float(x.lo[i, 1]), float(x.hi[i, 1])))
        assert r.lo[i, 1] == s.lo and r.hi[i, 1] == s.hi
    # scalars and plain numbers are accepted
    assert el.exp(0).lo == 1.0 and el.sqrt(4.0).hi == 2.0
    assert el.sin(Interval(0.5)).shape == ()


def test_min_max_semantics():
    r = el.min(Interval(1, 3), Interval(0, 5))
    assert (r.lo, r.hi) == (0.0, 3.0)
    r = el.max(Interval(1, 3), Interval(0, 5))
    assert (r.lo, r.hi) == (1.0, 5.0)
    r = el.abs(Interval(-3, 2))
    assert (r.lo, r.hi) == (0.0, 3.0)
    r = el.abs(Interval(-3, -2))
    assert (r.lo, r.hi) == (2.0, 3.0)


def test_empty_and_nan():
    e = Interval.empty((2,))
    for fn in (el.sqrt, el.abs, el.exp, el.log, el.atan, el.sin, el.cos, el.tan):
        r = fn(e)
        assert np.all(r.lo > r.hi), fn.__name__
    assert np.all(el.atan2(e, Interval(1.0)).is_empty())
    assert np.all(el.min(e, Interval(1.0)).is_empty())
    nan = Interval.from_bounds(np.array([np.nan, 0.0]), np.array([1.0, np.nan]))
    for fn in (el.sqrt, el.abs, el.exp, el.log, el.atan, el.sin, el.cos, el.tan):
        r = fn(nan)  # must not raise; NaN means "unknown", and any bound given must be sound
        assert r.shape == (2,)
    r = el.sin(nan)
    assert np.all(r.lo == -1.0) and np.all(r.hi == 1.0)


def test_atan2_of_a_box_around_the_origin_in_the_upper_half_plane_is_0_to_pi():
    """s >= 0 on the whole box (as sin theta = sqrt(...) in FKSystem.pose): [0, pi], not [-pi, pi] (a
    cluster's theta was printed [-3.1416, 3.1416]); every angle of the box is inside."""
    r = el.atan2(Interval.from_bounds(np.array([0.0, -0.0]), np.array([1.0, 2.0])),
                 Interval.from_bounds(np.array([-1.0, -3.0]), np.array([1.0, 0.0])))
    assert np.all(r.lo == 0.0) and np.all(r.hi == el.pi.hi)
    for s, c in ((1e-300, -1.0), (1.0, -1e-300), (0.5, 0.5), (0.0, -1.0)):
        assert inside(r.lo[0], r.hi[0], exact(mpmath.atan2, s, c))
    below = el.atan2(Interval.from_bounds(np.array([-1e-9]), np.array([1.0])), Interval.from_bounds(np.array([-1.0]), np.array([1.0])))
    assert below.lo[0] == -el.pi.hi                                   # a point below: the whole circle
