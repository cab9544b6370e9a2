"""The sympy-to-interval compiler and forward-mode AD, checked against mpmath."""
from fractions import Fraction

import mpmath
import numpy as np
import sympy as sp
from hypothesis import given, settings, strategies as st

from intervals import Interval
from intervals.autodiff import Dual
from intervals.compiler import compile_exprs
from intervals.evaluator import CHUNK

x, y, z, a, b = sp.symbols("x y z a b", real=True)
EXPRS = [
    x**2 * y - sp.Rational(1, 3) * z + a,
    sp.sin(x) * sp.cos(y) + b * z**3,
    (x - y) ** 2 / (1 + z**2),
    sp.sqrt(1 + x**2 + y**2) - sp.atan(z) + sp.pi * a,
    sp.exp(x / 4) * sp.log(2 + y**2),
    sp.Float("0.1") * x + sp.Rational(7, 10) * y,  # Float: its exact binary value; Rational: enclosed
]
COMPILED = compile_exprs(EXPRS, [x, y, z], [a, b])
PARAMS = [Interval("0.3"), Interval("-1.7")]


@st.composite
def box_and_point(draw):
    lo = [draw(st.floats(-4, 4)) for _ in range(3)]
    w = [draw(st.floats(0, 2)) for _ in range(3)]
    t = [draw(st.floats(0, 1)) for _ in range(3)]
    hi = [l + v for l, v in zip(lo, w)]
    pt = [l + s * (h - l) for l, h, s in zip(lo, hi, t)]
    pt = [min(max(p, l), h) for p, l, h in zip(pt, lo, hi)]
    return np.array(lo), np.array(hi), pt


def exact_values(pt):
    with mpmath.workdps(60):
        subs = {x: sp.Float(mpmath.mpf(pt[0]), 60), y: sp.Float(mpmath.mpf(pt[1]), 60), z: sp.Float(mpmath.mpf(pt[2]), 60),
                a: sp.Rational(3, 10), b: sp.Rational(-17, 10)}
        return [sp.N(e.subs(subs), 50) for e in EXPRS], \
               [[sp.N(sp.diff(e, v).subs(subs), 50) for v in (x, y, z)] for e in EXPRS]


@settings(max_examples=60, deadline=None)
@given(box_and_point())
def test_compiled_values_and_jacobian_contain_exact(bp):
    lo, hi, pt = bp
    box = Interval(lo[None, :], hi[None, :])
    vals = COMPILED(box, PARAMS)
    v2, jac = COMPILED.jacobian(box, PARAMS)
    exact, grads = exact_values(pt)
    for i, e in enumerate(exact):
        assert sp.Float(vals.lo[0, i], 50) <= e <= sp.Float(vals.hi[0, i], 50), (i, e)
        assert sp.Float(v2.lo[0, i], 50) <= e <= sp.Float(v2.hi[0, i], 50)
        for j in range(3):
            g = grads[i][j]
            assert sp.Float(jac.lo[0, i, j], 50) <= g <= sp.Float(jac.hi[0, i, j], 50), (i, j, g)


def test_constants_are_enclosed_from_exact_values():
    ev = compile_exprs([sp.Rational(1, 10) + 0 * x, sp.Float(0.1) + 0 * x, sp.pi + 0 * x], [x])
    out = ev(Interval(np.zeros((1, 1))))
    assert Fraction(float(out.lo[0, 0])) < Fraction(1, 10) < Fraction(float(out.hi[0, 0]))
    assert out.lo[0, 1] <= 0.1 <= out.hi[0, 1]
    with mpmath.workdps(40):  # pi at 40 digits: the floats are strictly around it
        assert mpmath.mpf(out.lo[0, 2]) < +mpmath.pi < mpmath.mpf(out.hi[0, 2])


def test_squares_compile_to_sqr_and_cse_shares_work():
    ev = compile_exprs([(x - y) ** 2 + sp.sin(x - y), sp.sin(x - y) * 3], [x, y])
    assert "sqr(" in ev.source
    assert ev.source.count("sin(") == 1
    out = ev(Interval(np.array([[-1.0, 0.0]]), np.array([[1.0, 0.0]])))
    assert out.lo[0, 0] >= -np.sin(1) - 1e-12  # (x-y)^2 >= 0 kept tight by sqr


def test_batches_larger_than_one_chunk_match_small_ones():
    rng = np.random.default_rng(0)
    n = CHUNK + 123
    lo = rng.uniform(-2, 2, size=(n, 3))
    hi = lo + rng.uniform(0, 0.1, size=(n, 3))
    big = COMPILED(Interval(lo, hi), PARAMS)
    small = COMPILED(Interval(lo[-5:], hi[-5:]), PARAMS)
    assert big.shape == (n, len(EXPRS))
    assert np.array_equal(big.lo[-5:], small.lo) and np.array_equal(big.hi[-5:], small.hi)
    v, j = COMPILED.jacobian(Interval(lo, hi), PARAMS)
    assert j.shape == (n, len(EXPRS), 3)


def test_dual_rules():
    box = Interval(np.array([[1.0, 2.0]]), np.array([[1.5, 2.5]]))
    u, v = Dual.variables(box)
    f = u * v / (u + v)
    # d/du (uv/(u+v)) = v^2/(u+v)^2, increasing in v, decreasing in u: range [4/12.25, 6.25/12.25]
    assert f.grad.lo[0, 0] <= 4 / 12.25 and f.grad.hi[0, 0] >= 6.25 / 12.25
    # d/dv = u^2/(u+v)^2: range [1/12.25, 2.25/12.25]
    assert f.grad.lo[0, 1] <= 1 / 12.25 and f.grad.hi[0, 1] >= 2.25 / 12.25
    assert f.grad.hi[0, 0] < 1 and f.grad.lo[0, 1] > -1  # and not absurdly loose
    assert f.grad.shape == (1, 2)
