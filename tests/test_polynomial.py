"""Interval polynomials: containment of exact coefficients and ranges (exact rationals, mpmath)."""
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from intervals import Interval
from intervals.polynomial import Poly, ratio_range

SETTINGS = settings(max_examples=150, deadline=None)
finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)
coefficients = st.lists(finite, min_size=1, max_size=7)
unit = st.floats(min_value=0.0, max_value=1.0, allow_nan=False)
anywhere = st.floats(min_value=-3.0, max_value=3.0, allow_nan=False)


def inside(q, lo, hi) -> bool:
    return Fraction(float(lo)) <= q <= Fraction(float(hi))


def exact_value(coeffs, t: Fraction) -> Fraction:
    return sum(Fraction(c) * t ** k for k, c in enumerate(coeffs))


def thin(coeffs) -> Poly:
    c = np.array(coeffs, dtype=np.float64)
    return Poly(c, c.copy())


@SETTINGS
@given(coefficients, coefficients, finite)
def test_sum_difference_product_contain_exact_coefficients(a, b, k):
    p, q = thin(a), thin(b)
    exact_a = [Fraction(x) for x in a]
    exact_b = [Fraction(x) for x in b]
    n = max(len(a), len(b))
    pad = lambda v: v + [Fraction(0)] * (n - len(v))  # noqa: E731
    prod = [Fraction(0)] * (len(a) + len(b) - 1)
    for i, x in enumerate(exact_a):
        for j, y in enumerate(exact_b):
            prod[i + j] += x * y
    cases = [(p + q, [x + y for x, y in zip(pad(exact_a), pad(exact_b))]),
             (p - q, [x - y for x, y in zip(pad(exact_a), pad(exact_b))]),
             (p * q, prod),
             (p * Interval(k), [x * Fraction(k) for x in exact_a]),
             (Interval(k) - p, [Fraction(k) - exact_a[0]] + [-x for x in exact_a[1:]])]
    for r, exact in cases:
        assert r.degree == len(exact) - 1
        for c, lo, hi in zip(exact, r.lo, r.hi):
            assert inside(c, lo, hi)


@SETTINGS
@given(coefficients, unit, unit, st.lists(unit, min_size=1, max_size=5))
def test_range_on_nonnegative_t_contains_every_value(coeffs, a, b, where):
    """The fast path (t ≥ 0, float products with a proved error bound)."""
    check_range(coeffs, a, b, where)


def check_range(coeffs, a, b, where):
    lo, hi = min(a, b), max(a, b)
    r = thin(coeffs).range(lo, hi)
    for s in where + [0.0, 1.0]:
        t = Fraction(lo) + Fraction(s) * (Fraction(hi) - Fraction(lo))
        assert inside(exact_value(coeffs, t), r.lo, r.hi)


@SETTINGS
@given(coefficients, anywhere, anywhere, st.lists(unit, min_size=1, max_size=5))
def test_range_on_any_interval_contains_every_value(coeffs, a, b, where):
    """Negative t uses the interval Taylor-shift path."""
    check_range(coeffs, a, b, where)


def test_range_is_tight_and_batched():
    """Monotone on the interval: the Bernstein bound is the two end values (up to rounding);
    a batch of polynomials and intervals gives the same as one at a time."""
    rng = np.random.default_rng(5)
    c = rng.normal(size=(40, 5))
    a = rng.uniform(0, 1, 40)
    b = a + 1e-4
    batch = Poly(c, c).range(a, b)
    mpmath.mp.prec = 200
    for i in range(40):
        one = Poly(c[i], c[i]).range(a[i], b[i])
        assert one.lo == batch.lo[i] and one.hi == batch.hi[i]
        values = [sum(mpmath.mpf(c[i, k]) * mpmath.mpf(t) ** k for k in range(5))
                  for t in np.linspace(a[i], b[i], 9)]
        true_lo, true_hi = min(values), max(values)
        assert batch.lo[i] <= true_lo and true_hi <= batch.hi[i]
        # the overestimation is second order in the width (1e-4): far below the range itself
        assert float(true_lo - batch.lo[i]) < 1e-6 and float(batch.hi[i] - true_hi) < 1e-6


def test_interval_coefficients_cover_every_member():
    """A polynomial with wide coefficients encloses the values of every member."""
    p = Poly(np.array([-1.0, 2.0, -0.5]), np.array([1.0, 3.0, 0.5]))
    r = p.range(0.25, 0.75)
    rng = np.random.default_rng(1)
    for _ in range(200):
        c = rng.uniform(p.lo, p.hi)
        t = rng.uniform(0.25, 0.75)
        v = c[0] + c[1] * t + c[2] * t * t
        assert r.lo <= v <= r.hi


@SETTINGS
@given(coefficients, st.lists(st.floats(min_value=0.1, max_value=100.0), min_size=1, max_size=7), unit, unit)
def test_ratio_range_contains_every_quotient(num, den, a, b):
    lo, hi = min(a, b), max(a, b)
    n = max(len(num), len(den)) - 1
    P = thin(num + [0.0] * (n + 1 - len(num)))
    Q = thin(den + [0.0] * (n + 1 - len(den)))
    r = ratio_range(P.bernstein(lo, hi), Q.bernstein(lo, hi))
    for s in (0.0, 0.3, 0.5, 0.9, 1.0):
        t = Fraction(lo) + Fraction(s) * (Fraction(hi) - Fraction(lo))
        d = exact_value(den, t)
        if d > 0:
            assert inside(exact_value(num, t) / d, r.lo, r.hi)


def test_ratio_range_is_tighter_than_the_quotient_of_ranges():
    """E/Δ-like quotient of two correlated polynomials over a small interval."""
    P = thin([4.0, 2.0, 1.0])            # (t + 1)² + 3
    Q = thin([2.0, 1.0, 0.0])            # t + 2 (same degree as P)
    a, b = 0.4, 0.5
    r = ratio_range(P.bernstein(a, b), Q.bernstein(a, b))
    naive = P.range(a, b) / Q.range(a, b)
    assert (r.hi - r.lo) < 0.5 * float(naive.hi - naive.lo)


def test_indexing_keeps_coefficients_and_rejects_ellipsis():
    p = Poly(np.arange(12.0).reshape(2, 2, 3), np.arange(12.0).reshape(2, 2, 3))
    assert p[1].shape == (2,) and p[:, 0].shape == (2,) and p.degree == 2
    with pytest.raises(IndexError):
        p[..., 0]


@SETTINGS
@given(st.floats(min_value=-4.0, max_value=4.0), st.floats(min_value=-3.5, max_value=3.5), st.lists(unit, min_size=1, max_size=4))
def test_cos_sin_of_linear_polynomials_contain_the_exact_values(c0, c1, where):
    """Taylor expansion at t = 1/2 with the Lagrange remainder, for t ∈ [0, 1]."""
    from intervals.polynomial import cos, sin
    x = Poly.from_coefficients([Interval(c0), Interval(c1)])
    mpmath.mp.prec = 120
    from intervals.polynomial import degree_limit
    for fn, ref in ((cos, mpmath.cos), (sin, mpmath.sin)):
        p = fn(x)
        low = fn(x, order=3)                       # a short expansion: a wide remainder, still an enclosure
        with degree_limit(2):
            folded = fn(x)                         # terms above t² folded into c_0 (t ∈ [0, 1])
        assert folded.degree <= 2 and low.degree == 3
        for s in where + [0.0, 1.0]:
            v = ref(mpmath.mpf(c0) + mpmath.mpf(c1) * mpmath.mpf(s))
            for q in (p, low, folded):
                r = q.range(s, s)
                assert mpmath.mpf(float(r.lo)) <= v <= mpmath.mpf(float(r.hi))
            r = p.range(s, s)
            assert float(r.hi - r.lo) < 1e-6       # order ≤ 12: (|c1|/2)^13 / 13! for |c1| ≤ 3.5


@SETTINGS
@given(coefficients, coefficients, st.integers(min_value=0, max_value=4), st.lists(unit, min_size=1, max_size=4))
def test_truncated_products_contain_the_exact_values_on_0_1(a, b, d, where):
    """Inside ``degree_limit(d)`` the terms above d are folded into c_0: still an enclosure for t ∈ [0, 1]."""
    from intervals.polynomial import degree_limit
    with degree_limit(d):
        r = thin(a) * thin(b)
    assert r.degree <= max(d, len(a) - 1, len(b) - 1) if min(len(a), len(b)) == 1 else r.degree <= d
    for s in where:
        t = Fraction(s)
        rr = r.range(s, s)
        assert inside(exact_value(a, t) * exact_value(b, t), rr.lo, rr.hi)


def test_degree_limit_holds_in_its_own_thread_only():
    """A ``degree_limit`` set by one thread (a trajectory with a moving orientation) does not truncate
    the products of another thread running at the same time (a path of constant orientation, whose
    polynomials are exact, the shapes its callers expect)."""
    import threading
    from intervals.polynomial import degree_limit
    p = thin([1.0, 1.0])                                # 1 + t
    seen = {}
    with degree_limit(1):
        other = threading.Thread(target=lambda: seen.setdefault("degree", (p * p * p).degree))
        other.start()
        other.join()
        assert (p * p).degree == 1                      # this thread's limit still holds
    assert seen["degree"] == 3                          # exact in the other thread


def test_compiled_model_on_polynomials_matches_mpmath():
    """The Gough-Stewart leg vectors compiled once run on polynomial variables (moving
    orientation): the values at sample instants enclose a 40-digit evaluation."""
    from pathlib import Path
    from certkin import load_robot
    robot = load_robot(Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed000-mel-tsukuba.toml")
    start = [-69.0, -50.0, 500.0, 85 * np.pi / 180, 10 * np.pi / 180, 0.0]
    step = [153.0, 142.0, 0.0, 10 * np.pi / 180, -5 * np.pi / 180, 0.3]
    var = [Poly.from_coefficients([Interval(a), Interval(b)]) for a, b in zip(start, step)]
    out = robot.compiled("leg_vectors").evaluate(var, robot.parameters)
    mpmath.mp.dps = 40
    for s in (0.0, 0.37, 1.0):
        x, y, z, psi, theta, phi = [mpmath.mpf(a) + mpmath.mpf(s) * mpmath.mpf(b) for a, b in zip(start, step)]
        rz = lambda g: mpmath.matrix([[mpmath.cos(g), -mpmath.sin(g), 0], [mpmath.sin(g), mpmath.cos(g), 0], [0, 0, 1]])  # noqa: E731
        rx = mpmath.matrix([[1, 0, 0], [0, mpmath.cos(theta), -mpmath.sin(theta)], [0, mpmath.sin(theta), mpmath.cos(theta)]])
        R = rz(psi) * rx * rz(phi)
        exact = lambda c: mpmath.mpf(Fraction(str(c)).numerator) / Fraction(str(c)).denominator  # noqa: E731
        for i, (A, b) in enumerate(zip(robot.base, robot.platform)):
            bm = mpmath.matrix([exact(c) for c in b])
            leg = mpmath.matrix([x, y, z]) + R * bm - mpmath.matrix([exact(c) for c in A])
            for k in range(3):
                r = out[3 * i + k].range(s, s) if isinstance(out[3 * i + k], Poly) else out[3 * i + k]
                assert mpmath.mpf(float(r.lo)) <= leg[k] <= mpmath.mpf(float(r.hi))


@SETTINGS
@given(st.lists(st.floats(min_value=-1e300, max_value=1e300, allow_nan=False), min_size=1, max_size=30),
       st.lists(st.floats(min_value=0.0, max_value=1e6, allow_nan=False), min_size=30, max_size=30))
def test_sum_bounds_contain_the_exact_sum(values, widths):
    """``rounding.sum_bounds`` (up to four terms: outward additions in turn; more: float sums
    widened by 4(n + 1)u Σ|x|) brackets the exact
    rational sums of the lower and of the upper ends, whatever numpy's summation order."""
    from intervals.rounding import sum_bounds
    lo = np.array(values)
    hi = lo + np.array(widths[:len(values)])
    hi = np.where(np.isfinite(hi), hi, lo)
    slo, shi = sum_bounds(lo[None, :], hi[None, :], axis=1)
    assert Fraction(float(slo[0])) <= sum(Fraction(float(v)) for v in lo)
    assert sum(Fraction(float(v)) for v in hi) <= Fraction(float(shi[0]))


def test_poly_sum_over_a_batch_axis_contains_the_exact_sums():
    rng = np.random.default_rng(3)
    c = rng.standard_normal((4, 9, 3)) * 1e8
    p = Poly(c, c.copy()).sum(axis=1)                  # (4,) polynomials of degree 2
    assert p.shape == (4,) and p.degree == 2
    for i in range(4):
        for k in range(3):
            assert inside(sum(Fraction(float(v)) for v in c[i, :, k]), p.lo[i, k], p.hi[i, k])
    q = Poly(c, c.copy()).sum(axis=-1)                 # the last batch axis, not the coefficients
    assert q.shape == (4,)
