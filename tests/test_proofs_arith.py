"""The checker's own interval arithmetic (``proofs.arith``) against mpmath at 100 digits.

For random intervals (extreme magnitudes included: subnormals, huge values,
zeros, infinities) and random points inside them, the exact value of each
primitive lies in the interval result.  Nothing here uses certkin or intervals.
"""
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from mpmath import mp, mpf

from proofs import arith
from proofs.arith import Iv

mp.dps = 100
FINITE = st.floats(allow_nan=False, allow_infinity=False)
MODERATE = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)
EXTREME = st.sampled_from([0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1e-300, 1.0, -1.0,
                           1.7976931348623157e308, -1.7976931348623157e308, 1e300, 3.0, 0.1])
NUM = st.one_of(FINITE, EXTREME)


def interval(draw_a, draw_b):
    return (min(draw_a, draw_b), max(draw_a, draw_b))


@st.composite
def box_and_point(draw, elements=NUM):
    a, b = draw(elements), draw(elements)
    lo, hi = min(a, b), max(a, b)
    t = draw(st.floats(min_value=0, max_value=1))
    x = Fraction(lo) + (Fraction(hi) - Fraction(lo)) * Fraction(t)   # an exact point of [lo, hi]
    return lo, hi, x


def holds(r: Iv, value) -> bool:
    """The exact value (Fraction or mpf) lies in the interval (infinite bounds allowed; a NaN bound
    claims nothing: every predicate of the checker is false on it)."""
    lo, hi = float(np.asarray(r.lo).ravel()[0]), float(np.asarray(r.hi).ravel()[0])
    v = mpf(value.numerator) / value.denominator if isinstance(value, Fraction) else value
    return (np.isnan(lo) or lo == -np.inf or mpf(lo) <= v) and (np.isnan(hi) or hi == np.inf or v <= mpf(hi))


def iv(lo, hi):
    return Iv(np.array([lo]), np.array([hi]))


@settings(max_examples=400, deadline=None)
@given(box_and_point(), box_and_point())
def test_add_sub_mul_contain_the_exact_values(a, b):
    x, y = iv(a[0], a[1]), iv(b[0], b[1])
    with np.errstate(all="ignore"):
        assert holds(x + y, a[2] + b[2])
        assert holds(x - y, a[2] - b[2])
        assert holds(x * y, a[2] * b[2])
        if b[2] != 0:
            assert holds(x / y, a[2] / b[2])


@settings(max_examples=400, deadline=None)
@given(box_and_point())
def test_sqr_sqrt_scaling(a):
    x = iv(a[0], a[1])
    with np.errstate(all="ignore"):
        assert holds(x.sqr(), a[2] * a[2])
        assert not float(x.sqr().lo[0]) < 0
        if a[2] >= 0:
            assert holds(x.sqrt(), mp.sqrt(mpf(a[2].numerator) / a[2].denominator))
        assert holds(x * 0.1, a[2] * Fraction(0.1))


def test_rounding_is_one_float_wide_at_most_two():
    np.seterr(all="ignore")
    x = np.array([1.0, 3.0, 1e-310, 0.0, 1e308, -2.0])
    assert np.all(arith.up(x) > x) and np.all(arith.dn(x) < x)
    assert np.all(arith.up(x[:2]) == np.nextafter(x[:2], np.inf))     # succ(x) for ordinary x
    assert arith.up(np.array([1.7976931348623157e308]))[0] == np.inf
    assert np.isnan(arith.up(np.array([-np.inf]))[0])                 # "nothing known", never a wrong bound


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(NUM, NUM), min_size=1, max_size=12))
def test_sum_along_an_axis(pairs):
    lo = np.array([min(p) for p in pairs])
    hi = np.array([max(p) for p in pairs])
    with np.errstate(all="ignore"):
        s = Iv(lo[None], hi[None]).sum(-1)
    exact_lo, exact_hi = sum(Fraction(v) for v in lo), sum(Fraction(v) for v in hi)
    assert holds(Iv(s.lo, np.array([np.nan])), exact_lo) and holds(Iv(np.array([np.nan]), s.hi), exact_hi)


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 7), st.integers(1, 7), st.integers(0, 2 ** 32 - 1))
def test_point_matrix_times_interval_matrix(n, k, seed):
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.integers(-300, 300, size=(n, k))
    P = rng.standard_normal((n, k)) * scale
    blo = rng.standard_normal((k, 3)) * 10.0 ** rng.integers(-20, 20, size=(k, 3))
    bhi = blo + np.abs(rng.standard_normal((k, 3)))
    t = rng.random((k, 3))
    with np.errstate(all="ignore"):
        r = arith.pmatmul(P, Iv(blo, bhi))
    for i in range(n):
        for j in range(3):
            exact = sum(Fraction(P[i, m]) * (Fraction(blo[m, j]) + (Fraction(bhi[m, j]) - Fraction(blo[m, j]))
                                             * Fraction(t[m, j])) for m in range(k))
            assert holds(r[i:i + 1, j], exact)


@settings(max_examples=400, deadline=None)
@given(box_and_point(st.one_of(st.floats(min_value=-50, max_value=50), EXTREME,
                               st.floats(min_value=-1e7, max_value=1e7))))
def test_sin_cos_contain_the_exact_values(a):
    x = iv(a[0], a[1])
    s, c = arith.sincos(x)
    v = mpf(a[2].numerator) / a[2].denominator
    assert holds(s, mp.sin(v)) and holds(c, mp.cos(v))
    assert -1 <= s.lo[0] <= s.hi[0] <= 1 and -1 <= c.lo[0] <= c.hi[0] <= 1


def test_sin_cos_are_tight_and_find_the_extrema():
    x = np.array([0.0, 1.0, -2.5, 1e6, 0.3])
    s, c = arith.sincos(Iv(x))
    assert np.all(s.hi - s.lo < 2e-15) and np.all(c.hi - c.lo < 2e-15)
    s, c = arith.sincos(Iv(np.array([1.0, 4.0, -0.1]), np.array([2.0, 5.0, 0.1])))
    assert s.hi[0] == 1.0 and s.lo[1] == -1.0 and c.hi[2] == 1.0          # π/2, 3π/2, 0 inside
    assert s.lo[0] > 0.84 and c.hi[1] < 0.29
    big = arith.sincos(Iv(np.array([1e300, np.nan])))
    assert np.all(big[0].lo == -1) and np.all(big[0].hi == 1)


def test_pi_and_decimals_are_enclosed():
    assert arith.PI.lo < mp.pi < arith.PI.hi and arith.PI.hi - arith.PI.lo < 1e-15
    for text in ("0.1", "3.78", "-1e-310", "123456789.123456789"):
        e = Iv.const(Fraction(text))
        assert Fraction(float(e.lo)) <= Fraction(text) <= Fraction(float(e.hi))
        assert e.hi == e.lo or np.nextafter(e.lo, np.inf) == e.hi


def test_degrees_are_enclosed_in_one_float_step():
    """q·π/180 for q = -360.0, -359.9, ..., 360.0 (and 0, 1e-300, 1e300): inside the checker's enclosure
    (mpmath, 60 digits), which is at most one float wide.  A wider one (π as an interval, two roundings)
    did not fit inside the box certkin proved (its own tightest enclosure) for a third of these values."""
    from proofs.numbers import enclose
    mp.dps = 60
    for text in [f"{k / 10}" for k in range(-3600, 3601)] + ["0", "1e-300", "1e300", "-45"]:
        e = enclose(text + "deg", "phi", True)
        exact = mpf(Fraction(text).numerator) / Fraction(text).denominator * mp.pi / 180
        assert mpf(float(e.lo)) <= exact <= mpf(float(e.hi)), text
        assert e.hi == e.lo or np.nextafter(e.lo, np.inf) == e.hi, text


@pytest.mark.parametrize("x", [np.array([np.nan]), np.array([np.inf])])
def test_nan_proves_nothing(x):
    v = Iv(x, x) + 1.0
    assert not v.pos().any() and not v.neg().any() and not v.empty().any()
