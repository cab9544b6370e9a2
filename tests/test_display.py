"""Printed numbers keep the proved claim true: outward for enclosures, inward for inner claims."""
from decimal import Decimal
import math

from hypothesis import given, strategies as st
import pytest

from certkin import display

finite = st.floats(allow_nan=False, allow_infinity=False)


def test_issue_example_free_box_printed_inward():
    # the box proved singularity-free by `certkin singular R2 --around=-20,25,0.1` (issue #18)
    lo, hi = -20.439551636576653, -19.560448363423347
    assert display.inward(lo, hi) == "[-20.43955163, -19.56044837]"
    assert display.outward(lo, hi) == "[-20.43955164, -19.56044836]"


@given(finite, st.integers(1, 17))
def test_lower_and_upper_bound_the_exact_float(x, digits):
    a, b = Decimal(display.lower(x, digits)), Decimal(display.upper(x, digits))
    assert a <= Decimal(x) <= b
    assert len(a.normalize().as_tuple().digits) <= digits and len(b.normalize().as_tuple().digits) <= digits


@given(finite, finite, st.integers(1, 17))
def test_outward_contains_and_inward_is_contained(x, y, digits):
    lo, hi = min(x, y), max(x, y)
    a, b = (Decimal(t) for t in display.outward(lo, hi, digits)[1:-1].split(", "))
    assert a <= Decimal(lo) and Decimal(hi) <= b
    c, d = (Decimal(t) for t in display.inward(lo, hi, digits)[1:-1].split(", "))
    assert Decimal(lo) <= c <= d <= Decimal(hi)


@given(finite)
def test_point_is_exact(x):
    assert float(display.point(x)) == x


def test_point_interval_inward_is_exact():
    x = 100000000000000.62                                # exactly 100000000000000.625
    assert display.inward(x, x) == "[100000000000000.625, 100000000000000.625]"


def test_thin_inner_interval_gets_more_digits():
    lo = 1.0
    hi = math.nextafter(1.0, 2.0)
    c, d = (Decimal(t) for t in display.inward(lo, hi)[1:-1].split(", "))
    assert Decimal(lo) <= c <= d <= Decimal(hi)


def test_special_values():
    assert display.outward(-math.inf, math.inf) == "[-inf, inf]"
    assert display.lower(0.0) == "0" and display.upper(-0.0) == "0"
    assert display.lower(1e300) == "1e300"                # 1e300 is 1.0000000000000000525...e300
    assert display.upper(1e300) == "1.000000001e300"
    assert display.upper(1.5e-9, 3) == "1.5e-9" and display.lower(1.5e-9, 3) == "1.49e-9"  # 1.4999...e-9
    assert display.upper(0.1) == "0.1000000001"   # 0.1 is 0.1000000000000000055...: up is above it
    assert display.lower(0.1) == "0.1"
    with pytest.raises(ValueError):
        display.lower(1.0, 0)
