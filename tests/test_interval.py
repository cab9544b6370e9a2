"""Containment and tightness of the interval core (+ - * / sqr pown, decimals)."""
from decimal import Decimal
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from intervals import Interval, div, mul, pown, sqr, sqrt, to_fraction
from intervals.interval import as_interval
from intervals.rounding import EXACT_HIGH, EXACT_LOW, down, down_sum, enclose, enclose_decimal, enclose_fraction, up, up_sum

SETTINGS = settings(max_examples=300, deadline=None)


def floats_any():
    """Finite floats over the whole range, with many tiny, huge and exact values."""
    return st.one_of(
        st.floats(allow_nan=False, allow_infinity=False),
        st.floats(min_value=-1e3, max_value=1e3),
        st.floats(min_value=-1e-300, max_value=1e-300),
        st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 2.0 ** -1074, -(2.0 ** -1074), 1.7976931348623157e308]),
    )


@st.composite
def interval_and_point(draw):
    a, b = sorted([draw(floats_any()), draw(floats_any())])
    t = draw(st.floats(min_value=0, max_value=1))
    x = Fraction(a) + (Fraction(b) - Fraction(a)) * Fraction(t)
    return Interval(a, b), x


def inside(q: Fraction, iv: Interval) -> bool:
    lo, hi = float(iv.lo), float(iv.hi)
    return (lo == -np.inf or Fraction(lo) <= q) and (hi == np.inf or q <= Fraction(hi))


@SETTINGS
@given(interval_and_point(), interval_and_point())
def test_add_sub_mul_contain_exact(xp, yp):
    (x, p), (y, q) = xp, yp
    assert inside(p + q, x + y)
    assert inside(p - q, x - y)
    assert inside(p * q, x * y)


@SETTINGS
@given(interval_and_point(), interval_and_point())
def test_div_contains_exact(xp, yp):
    (x, p), (y, q) = xp, yp
    if q == 0:
        return
    assert inside(p / q, x / y)


@SETTINGS
@given(interval_and_point(), st.integers(min_value=-6, max_value=9))
def test_sqr_and_pown_contain_exact(xp, n):
    x, p = xp
    assert inside(p * p, sqr(x))
    if p == 0 and n < 0:
        return
    assert inside(p ** n, pown(x, n))


@SETTINGS
@given(floats_any())
def test_rounding_helpers_step_at_least_one_float(c):
    c = np.float64(c)
    assert up(c) >= np.nextafter(c, np.inf) or c == np.finfo(float).max and up(c) == np.inf
    assert down(c) <= np.nextafter(c, -np.inf) or c == -np.finfo(float).max and down(c) == -np.inf
    if abs(c) >= 2.0 ** -1022:  # sums in the subnormal range are exact: no step needed there
        assert up_sum(c) >= np.nextafter(c, np.inf)
        assert down_sum(c) <= np.nextafter(c, -np.inf)


@SETTINGS
@given(st.decimals(allow_nan=False, allow_infinity=False, places=None))
def test_decimal_enclosure_is_tight_and_exact(d):
    lo, hi = enclose(d)
    q = Fraction(d)
    assert Fraction(lo) <= q <= Fraction(hi) or (abs(q) > Fraction(np.finfo(float).max))
    if lo != hi and np.isfinite(lo) and np.isfinite(hi):
        assert np.nextafter(lo, np.inf) == hi


@pytest.mark.parametrize("exponent", [401, 500, 4000])
@pytest.mark.parametrize("sign", [1, -1])
def test_decimals_far_outside_the_float_range_are_enclosed_as_the_rationals_are(exponent, sign):
    """Above 10^400 or below 10^-400 the enclosure is found without building the rational (the same
    floats as ``enclose_fraction``), and an exponent of a billion is answered at once."""
    for d in (Decimal(sign) * Decimal(f"1.5e{exponent}"), Decimal(sign) * Decimal(f"1.5e-{exponent}")):
        assert enclose_decimal(d) == enclose_fraction(Fraction(d))
    assert enclose_decimal(Decimal("1e999999999")) == (np.finfo(float).max, np.inf)
    assert enclose_decimal(Decimal("-1e-999999999")) == (-5e-324, 0.0)


def test_one_tenth_strictly_enclosed():
    x = Interval("0.1")
    assert Fraction(float(x.lo)) < Fraction(1, 10) < Fraction(float(x.hi))
    assert np.nextafter(x.lo, 1) == x.hi
    assert Interval(Decimal("0.1")).lo == x.lo
    assert Interval(Fraction(1, 10)).hi == x.hi
    assert Interval(0.1).lo == Interval(0.1).hi == 0.1  # a float is its exact binary value


LONG_DOUBLE_IS_WIDER = np.finfo(np.longdouble).nmant > np.finfo(np.float64).nmant


@st.composite
def long_doubles(draw):
    """Long doubles with bits beyond float64's (a ratio of integers, scaled over the whole float64
    range and past it), and exact ones."""
    n = draw(st.integers(-(2 ** 64), 2 ** 64))
    d = draw(st.integers(1, 2 ** 64))
    e = draw(st.sampled_from([0, 0, 1, -1, 60, -60, 1000, -1000, 1023, -1070, 1100, -1100]))
    return np.ldexp(np.longdouble(n) / np.longdouble(d), e)


@pytest.mark.skipif(not LONG_DOUBLE_IS_WIDER, reason="numpy's long double is float64 on this platform")
@SETTINGS
@given(long_doubles())
def test_long_doubles_are_enclosed_outward(x):
    """A long double is enclosed by the float64s around its exact value (``as_integer_ratio``, checked
    with mpmath too), adjacent when it has no float64 equal, by Interval, enclose, as_interval,
    arrays of them and to_fraction alike."""
    q = Fraction(*x.as_integer_ratio())
    assert to_fraction(x) == q
    lo, hi = enclose(x)
    assert inside(q, Interval.from_bounds(np.float64(lo), np.float64(hi)))
    if np.isfinite(float(x)) and Fraction(float(x)) == q:
        assert lo == hi
    elif np.isfinite(lo) and np.isfinite(hi):
        assert np.nextafter(lo, np.inf) == hi
    with mpmath.workprec(200):
        m = mpmath.mpf(x.as_integer_ratio()[0]) / x.as_integer_ratio()[1]
        assert mpmath.mpf(lo) <= m <= mpmath.mpf(hi)
    for iv in (Interval(x), as_interval(x), Interval(np.array([x, -x]))[0], as_interval(np.array([x, -x]))[0],
               -Interval(np.array([x, -x]))[1], -as_interval(np.array([x, -x]))[1]):
        assert inside(q, iv)
        assert (float(iv.lo), float(iv.hi)) == (lo, hi)


@pytest.mark.skipif(not LONG_DOUBLE_IS_WIDER, reason="numpy's long double is float64 on this platform")
def test_one_third_as_a_long_double_is_strictly_enclosed():
    x = np.longdouble(1) / 3
    q = Fraction(*x.as_integer_ratio())
    iv = Interval(x)
    assert Fraction(float(iv.lo)) < q < Fraction(float(iv.hi))
    assert inside(q, Interval(1, 2) * x) and inside(q, Interval(x, 1))
    assert enclose(np.longdouble(0.5)) == (0.5, 0.5)       # exact in float64: not widened


@SETTINGS
@given(st.lists(st.integers(-(2 ** 63), 2 ** 63 - 1), min_size=1, max_size=4), st.sampled_from([np.int64, np.uint64]))
def test_integer_arrays_beyond_2_to_53_are_enclosed_outward(values, dtype):
    """An int64 or uint64 array holds integers float64 cannot all represent (2**53 + 1): each is
    enclosed as the integer it is, as a Python int is."""
    if dtype is np.uint64:
        values = [abs(v) for v in values]
    arr = np.array(values, dtype=dtype)
    for iv in (Interval(arr), as_interval(arr)):
        for k, v in enumerate(values):
            assert inside(Fraction(v), iv[k])
            assert (float(iv.lo[k]), float(iv.hi[k])) == enclose(v)


def test_two_to_53_plus_one_in_an_integer_array_is_strictly_enclosed():
    iv = Interval(np.array([2 ** 53 + 1, 3], dtype=np.int64))
    assert float(iv.lo[0]) < 2 ** 53 + 1 < float(iv.hi[0])
    assert float(iv.lo[1]) == float(iv.hi[1]) == 3.0


def test_bad_inputs_rejected():
    for bad in ["abc", "nan", "inf", float("nan"), True]:
        with pytest.raises(ValueError):
            Interval(bad)
    with pytest.raises(ValueError):
        Interval(2, 1)


def test_tight_even_powers_and_sqr():
    x = Interval(-1, 2)
    assert float(sqr(x).lo) == 0.0 and 4 <= float(sqr(x).hi) <= 4 * (1 + 1e-15)
    assert float((x ** 2).lo) == 0.0
    assert float((x * x).lo) < -1.9  # the naive product is not tight: sqr must be used
    y = pown(Interval(-2, -1), 3)
    assert -8 * (1 + 1e-15) <= float(y.lo) <= -8 and -1 <= float(y.hi) <= -1 * (1 - 1e-15)


def test_exact_squares_and_powers_are_not_widened():
    """Where the float operation is exact (Dekker's error-free check proves it), the bound is that
    float: no one-step widening.  Inexact results are still widened."""
    def pair(x):
        return float(x.lo), float(x.hi)
    assert pair(sqr(Interval(-1, 2))) == (0.0, 4.0)
    assert pair(Interval(1, 2) ** 2) == (1.0, 4.0)
    assert pair(sqrt(Interval(4))) == (2.0, 2.0)
    assert pair(pown(Interval(-3, -2), 3)) == (-27.0, -8.0)
    assert pair(pown(Interval(0.5, 3), 4)) == (0.0625, 81.0)
    assert pair(sqr(Interval(0))) == (0.0, 0.0)
    a = 1.0 + 2.0 ** -30                          # 31 significant bits: a² needs 61
    lo, hi = pair(sqr(Interval(a)))
    assert lo < a * a < hi and Fraction(lo) < Fraction(a) ** 2 < Fraction(hi)
    tiny = 2.0 ** -450                             # exact, but outside the range where the check is error-free
    lo, hi = pair(sqr(Interval(tiny)))
    assert lo < tiny * tiny < hi


@st.composite
def short_floats(draw):
    """Floats with few significant bits (so that powers are often exact), over a wide range."""
    m = draw(st.integers(min_value=-2 ** 30, max_value=2 ** 30))
    k = draw(st.integers(min_value=-140, max_value=140))
    return float(m) * 2.0 ** k


def significant_bits(a: float) -> int:
    m = abs(Fraction(a).numerator)
    while m and m % 2 == 0:
        m //= 2
    return m.bit_length()


@SETTINGS
@given(short_floats(), short_floats(), st.integers(min_value=2, max_value=7))
def test_exact_powers_contain_the_mpmath_value_and_are_tight_when_proved_exact(a, b, n):
    """``pown`` and ``sqr`` hold x^n (mpmath at 600 bits: exact for these floats) at the ends of the
    interval and at 0 when inside; a point with few significant bits (the squares of binary
    powering checked exact by their fraction bits, the other products by Dekker's error) whose
    power is a float in the checked range gets that float as both bounds."""
    a, b = sorted([a, b])
    mpmath.mp.prec = 600
    x = Interval(a, b)
    for r, k in ((pown(x, n), n), (sqr(x), 2)):
        for v in [a, b] + ([0.0] if a <= 0 <= b else []):
            assert mpmath.mpf(float(r.lo)) <= mpmath.mpf(v) ** k <= mpmath.mpf(float(r.hi))
    bits = significant_bits(a)
    for r, k in ((pown(Interval(a), n), n), (sqr(Interval(a)), 2)):
        p = Fraction(a) ** k
        if not EXACT_LOW <= abs(p) <= EXACT_HIGH:
            continue
        if Fraction(float(p)) == p and bits <= (26 if k < 4 else 13):
            assert float(r.lo) == float(r.hi) == float(p)
        elif Fraction(float(p)) != p:
            assert float(r.lo) < float(r.hi)


def test_division_by_intervals_containing_zero():
    inf = np.inf
    cases = [((1, 2), (0, 1), (1, inf)), ((1, 2), (-1, 0), (-inf, -1)), ((-2, -1), (0, 1), (-inf, -1)),
             ((1, 2), (-1, 1), (-inf, inf)), ((-1, 1), (0, 1), (-inf, inf)), ((0, 0), (-1, 1), (0, 0))]
    for (a, b), (c, d), (lo, hi) in cases:
        r = Interval(a, b) / Interval(c, d)
        assert r.lo <= lo and r.hi >= hi
        if np.isfinite(lo):
            assert abs(r.lo - lo) <= 1e-14 * max(1.0, abs(lo))
        if np.isfinite(hi):
            assert abs(r.hi - hi) <= 1e-14 * max(1.0, abs(hi))
    empty = Interval(1, 2) / Interval(0, 0)
    assert bool(empty.is_empty())


def test_infinite_endpoints():
    inf = np.inf
    r = Interval(0, 1) * Interval(1, inf)
    assert r.hi == inf and r.lo <= 0
    r = Interval(0, 0) * Interval(-inf, inf)
    assert bool(r.contains_zero())  # NaN ("unknown") or an enclosure of 0: never a wrong exclusion
    r = Interval(-inf, 1) + Interval(1, 2)
    assert r.lo == -inf and r.hi >= 3
    big = Interval(1e308, 1e308) * Interval(10, 10)
    assert big.hi == inf and big.lo >= 1e308  # overflow: lower bound stays finite and below the truth


def test_set_operations():
    a, b = Interval(0, 2), Interval(1, 3)
    assert float(a.hull(b).lo) == 0 and float(a.hull(b).hi) == 3
    c = a.intersect(b)
    assert float(c.lo) == 1 and float(c.hi) == 2
    assert bool(Interval(0, 1).intersect(Interval(2, 3)).is_empty())
    assert bool(Interval(1, 2).subset(a)) and bool(Interval(0.5, 1).interior(a)) and not bool(a.interior(a))
    assert bool(Interval(5, 6).disjoint(a)) and not bool(b.disjoint(a))
    assert bool(a.contains(1.5)) and not bool(a.contains(2.5))
    lo, hi = a.bisect()
    assert float(lo.hi) == float(hi.lo) == 1.0
    assert float(Interval(-3, 2).mag()) == 3 and float(Interval(-3, 2).mig()) == 0 and float(Interval(2, 3).mig()) == 2
    assert float(a.mid()) == 1.0 and float(a.width()) >= 2.0


def test_batched_shapes_match_scalar_results():
    rng = np.random.default_rng(1)
    lo = rng.normal(size=(50, 4))
    hi = lo + rng.uniform(0, 1, size=(50, 4))
    X = Interval(lo, hi)
    Y = Interval(lo + 1, hi + 2)
    Z = X * Y - X / Y + sqr(X)
    assert Z.shape == (50, 4)
    for i in (0, 17, 49):
        for j in range(4):
            x, y = Interval(lo[i, j], hi[i, j]), Interval(lo[i, j] + 1, hi[i, j] + 2)
            z = x * y - x / y + sqr(x)
            assert z.lo == Z.lo[i, j] and z.hi == Z.hi[i, j]


def test_nan_means_unknown_in_predicates():
    u = Interval.from_bounds(np.array(np.nan), np.array(np.nan))
    assert bool(u.contains_zero())          # cannot exclude
    assert not bool(u.subset(Interval(-1, 1)))
    assert not bool(u.disjoint(Interval(5, 6)))
    assert not bool(u.is_empty())


def test_mpmath_agreement_on_products_of_decimals():
    x = Interval("1.1") * Interval("2.3") - Interval("0.7")
    with mpmath.workdps(50):
        exact = mpmath.mpf("1.1") * mpmath.mpf("2.3") - mpmath.mpf("0.7")
        assert mpmath.mpf(float(x.lo)) <= exact <= mpmath.mpf(float(x.hi))


@SETTINGS
@given(st.decimals(allow_nan=False, allow_infinity=False, places=None))
def test_decimal_fast_enclosure_equals_the_rational_one(d):
    """``enclose`` of a decimal (no rational arithmetic) gives the floats of ``enclose_fraction``."""
    from intervals.rounding import enclose_fraction
    assert enclose(d) == enclose_fraction(Fraction(d))
    assert enclose(str(d)) == enclose_fraction(Fraction(d))


def test_decimal_fast_enclosure_at_the_edges():
    from intervals.rounding import enclose_fraction
    for text in ["0", "-0", "0.1", "-0.1", "1e-400", "-1e-400", "5e-324", "2.4703282292062327e-324",
                 "2.4703282292062328e-324", "1.7976931348623157e308", "1.7976931348623158e308",
                 "1.7976931348623159e308", "2e308", "-2e308", " 3.78 ", "14.98", "16.097"]:
        assert enclose(text) == enclose_fraction(Fraction(Decimal(text.strip()))), text


def test_mul_in_place_is_bit_identical_to_reference():
    """The in-place ``mul`` returns exactly the floats of the reference formula (signed zeros, NaN,
    infinities, broadcasting, 0-d operands included)."""
    import numpy as np
    from intervals.interval import Interval as I, _mul_reference, mul
    rng = np.random.default_rng(4)
    special = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e-310, -1e-310, 1.7e308, -1.7e308, 1.0, -1.0, 5e-324])

    def sample(shape):
        v = np.atleast_1d(rng.standard_normal(shape) * 10.0 ** rng.integers(-300, 300, shape))
        pick = rng.random(shape) < 0.3
        v[np.atleast_1d(pick)] = rng.choice(special, size=int(np.sum(pick)))
        return v.reshape(shape)

    for shape_x, shape_y in [((5000,), (5000,)), ((40, 7, 3), (7, 3)), ((200, 1), (1, 30)), ((), ()), ((9,), ())]:
        a, b, c, d = sample(shape_x), sample(shape_x), sample(shape_y), sample(shape_y)
        x = I.from_bounds(np.asarray(np.minimum(a, b)), np.asarray(np.maximum(a, b)))
        y = I.from_bounds(np.asarray(np.minimum(c, d)), np.asarray(np.maximum(c, d)))
        # also unordered and NaN endpoints, as the arithmetic may meet them
        for xx, yy in [(x, y), (I.from_bounds(np.asarray(a), np.asarray(b)), I.from_bounds(np.asarray(c), np.asarray(d)))]:
            got, ref = mul(xx, yy), _mul_reference(xx, yy)
            for g, r in [(got.lo, ref.lo), (got.hi, ref.hi)]:
                g, r = np.asarray(g), np.asarray(r)
                assert g.shape == r.shape and g.dtype == r.dtype
                assert np.array_equal(np.isnan(g), np.isnan(r))     # NaN payloads may differ, not NaN-ness
                same = np.where(np.isnan(g), 0, g.reshape(-1).view(np.int64).reshape(g.shape)) == \
                    np.where(np.isnan(r), 0, r.reshape(-1).view(np.int64).reshape(r.shape))
                assert np.all(same)
