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


# ---- any real input is rounded from its exact value (never through float first)
from fractions import Fraction

import mpmath
import numpy as np

fractions = st.fractions(max_denominator=10 ** 40).filter(lambda q: abs(q) < 10 ** 40)


def _exact_text(text: str) -> Fraction:
    return Fraction(Decimal(text))


@given(fractions, st.integers(1, 17))
def test_fractions_are_bounded_exactly(q, digits):
    a, b = _exact_text(display.lower(q, digits)), _exact_text(display.upper(q, digits))
    assert a <= q <= b
    assert b - a <= Fraction(10) ** (len(str(abs(q.numerator))) - len(str(q.denominator)) + 2 - digits)


@given(fractions, fractions, st.integers(1, 17))
def test_fraction_intervals_outward_and_inward(x, y, digits):
    lo, hi = min(x, y), max(x, y)
    a, b = (_exact_text(t) for t in display.outward(lo, hi, digits)[1:-1].split(", "))
    assert a <= lo and hi <= b
    text = display.inward(lo, hi, digits)[1:-1].split(", ")
    c, d = (Fraction(t) if "/" in t else _exact_text(t) for t in text)
    assert lo <= c <= d <= hi


@given(st.integers(-10 ** 30, 10 ** 30), st.integers(-2000, 2000), st.integers(1, 17))
def test_mpf_is_bounded_exactly(man, exp, digits):
    """An mpmath number (man * 2^exp, beyond float range too) is not rounded to a float first."""
    with mpmath.workprec(128):                       # 10^30 < 2^100: man is exact
        x = mpmath.ldexp(mpmath.mpf(man), exp)
    q = Fraction(man) * Fraction(2) ** exp
    assert _exact_text(display.lower(x, digits)) <= q <= _exact_text(display.upper(x, digits))


def test_issue_defect_an_mpf_or_fraction_just_above_a_float():
    """float(x) rounds to nearest: for x a hair below 1/10, float(x) is the float 0.1 (above 1/10),
    whose lower bound "0.1" is above x."""
    q = Fraction(1, 10) - Fraction(1, 10 ** 25)
    assert float(q) == 0.1 and display.lower(0.1, 17) == "0.1"
    assert display.lower(q, 17) == "0.099999999999999999" and _exact_text(display.upper(q, 17)) >= q
    with mpmath.workdps(50):
        m = mpmath.mpf(1) / 3                        # 1/3 to 166 bits: not the float 1/3
    assert display.lower(m, 17) == "0.33333333333333333" and display.upper(m, 17) == "0.33333333333333334"
    assert display.upper(Fraction(1, 3)) == "0.3333333334" and display.lower(Fraction(-1, 3)) == "-0.3333333334"


@given(st.floats(width=32, allow_nan=False, allow_infinity=False), st.integers(1, 17))
def test_numpy_floats_and_long_doubles(x, digits):
    for v in (np.float32(x), np.longdouble(x) / 3, np.float64(x)):
        q = Fraction(*v.as_integer_ratio())
        assert _exact_text(display.lower(v, digits)) <= q <= _exact_text(display.upper(v, digits))


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300), st.integers(1, 17))
def test_zero_dimensional_arrays_are_bounded_exactly(x, digits):
    """A 0-d numpy array (what indexing an ``Interval`` of one value can give) is the float it holds,
    never truncated to an integer: the demo once printed det(A) = -0.256 as ``[0, 0]``."""
    q = Fraction(*float(x).as_integer_ratio())
    v = np.array(x)
    assert _exact_text(display.lower(v, digits)) <= q <= _exact_text(display.upper(v, digits))
    assert display.outward(np.array(-0.25), np.array(-0.125), 8) == "[-0.25, -0.125]"
    with pytest.raises(TypeError):                   # an array of one float is not a number either
        display.exact(np.array([-0.25]))


def test_points_and_integers():
    assert display.point(0.1) == "0.1" and display.point(np.float64(0.1)) == "0.1"
    assert display.point(Fraction(1, 4)) == "0.25" and display.point(Fraction(1, 3)) == "1/3"
    assert display.lower(10 ** 400) == "1e400" and display.upper(10 ** 400 + 1) == "1.000000001e400"
    assert display.interval(mpmath.mpi(1, 2) / 3) == "[0.3333333333, 0.6666666667]"


def test_a_plotted_slice_of_cells_is_named_by_its_exact_range():
    """A slice of the cell plot once read "phi in [0.1963, 0.3927]" (outward, 4 digits): wider than the
    cells proved singularity-free beneath it.  Its bounds are now printed exactly."""
    from certkin.plots.singularity import slab_title
    lo, hi = 0.7853981634 / 4, 0.7853981634 / 2
    title = slab_title("phi", (lo, hi))
    a, b = title.split("[")[1].rstrip("]").split(", ")
    assert float(a) == lo and float(b) == hi and title.startswith("phi in [")


def test_counted_is_plural_unless_one():
    from certkin.display import counted
    assert [counted(n, "cluster") for n in (0, 1, 2)] == ["0 clusters", "1 cluster", "2 clusters"]


def test_sizes_are_shown_in_the_largest_binary_unit():
    from certkin.display import size
    assert size(2 ** 20) == "1 MiB" and size(1.5 * 2 ** 30) == "1.5 GiB" and size(512) == "512 bytes"
    assert size(77.2 * 2 ** 20) == "77.2 MiB" and size(3 * 2 ** 10) == "3 KiB"


@given(st.one_of(st.integers(1, 2 ** 45), st.floats(min_value=1e-3, max_value=2.0 ** 45)))
def test_a_size_in_a_claim_is_rounded_on_its_side(n):
    """A stated need shown "about 0 MiB" (a size under 1 MiB, rounded to whole MiB): ``size_bound`` shows
    3 significant digits in the largest binary unit, whole bytes below 1 KiB, never below the size
    rounded up and never above it rounded down."""
    from certkin.display import size_bound
    units = {"byte": 1, "bytes": 1, "KiB": 2 ** 10, "MiB": 2 ** 20, "GiB": 2 ** 30}
    q = Fraction(n)
    for up in (True, False):
        number, unit = size_bound(n, up).split()
        shown = Fraction(Decimal(number)) * units[unit]
        assert (shown >= q if up else shown <= q), (n, up, number, unit)
        assert shown == 0 or abs(shown - q) <= q / 99 + 1
        assert unit in ("byte", "bytes") or Fraction(Decimal(number)) >= 1
    assert size_bound(1) == "1 byte" and size_bound(0.4) == "1 byte" and size_bound(0.4, up=False) == "0 bytes"
    assert size_bound(2 ** 20 + 1) == "1.01 MiB" and size_bound(2 ** 20 + 1, up=False) == "1 MiB"


def test_a_report_shows_a_one_sided_margin_as_proved_not_as_missing():
    """A margin with a proved lower bound and no upper bound was shown "not computed" in reports."""
    from certkin.report.page import enclosure
    assert enclosure((184.0023, None)) == "[184.0022999, inf]" and enclosure((None, None)) == "not computed"
    assert enclosure((None, 3.0)) == "[-inf, 3]"


def test_documents_are_strict_json_with_unbounded_sides_as_null():
    """``json_text``: a non-finite number in a document is written null (as a margin's unbounded side),
    never a bare NaN or Infinity, which a strict parser refuses."""
    import json
    from certkin.display import json_text

    text = json_text({"margin": [float("-inf"), 1.5], "nested": [{"v": float("nan")}], "name": "x"})
    assert json.loads(text, parse_constant=lambda c: 1 / 0) == {"margin": [None, 1.5], "nested": [{"v": None}],
                                                                "name": "x"}
    assert json_text({"a": 1.0}) == '{"a": 1.0}'
