"""The machine-code kernels (``intervals.native``) against the numpy operations they stand for.

- the rounding steps and the interval product/quotient give the numpy floats, bit for bit, on
  ordinary, tiny, huge and signed-zero operands;
- the extended Gauss-Seidel update gives ``linalg._gs_update``'s floats;
- the Hansen-Sengupta kernel keeps every zero (exact rational check), agrees with the numpy
  version to rounding (its sums may be taken in another order, which the error bound allows), and
  leaves boxes with non-finite input unchanged;
- the machine code holds no fused multiply-add.
"""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from intervals import Interval, native
from intervals.interval import div, mul
from intervals.linalg import _gs_update, _hansen_sengupta_numpy, hansen_sengupta
from intervals.rounding import down, down_square, down_sum, up, up_square, up_sum

from test_linalg import inside, zero_problem

SPECIAL = [0.0, -0.0, 1.0, -1.0, 2.0 ** -1074, -(2.0 ** -1074), 2.0 ** -1022, 1e-310, 1e308, -1e308,
           np.finfo(np.float64).max, -np.finfo(np.float64).max, np.inf, -np.inf, 0.1, -3.7e-200]


def _floats(rng, n):
    """Ordinary, tiny and huge floats of both signs, with the special values above."""
    x = rng.normal(size=n) * 10.0 ** rng.integers(-300, 300, n)
    return np.concatenate([x, SPECIAL])


@pytest.mark.parametrize("name, ref", [("up", up), ("down", down), ("up_sum", up_sum), ("down_sum", down_sum)])
def test_rounding_steps_give_the_numpy_floats(name, ref):
    x = _floats(np.random.default_rng(1), 2000)
    kernel = getattr(native, name)
    got = np.array([kernel(v) for v in x])
    with np.errstate(over="ignore"):
        assert np.array_equal(got, ref(x))


def test_product_and_quotient_give_the_numpy_floats():
    rng = np.random.default_rng(2)
    a, b = np.sort(rng.normal(size=(2, 3000)) * 10.0 ** rng.integers(-150, 150, (2, 3000)), axis=0)
    c, d = np.sort(rng.normal(size=(2, 3000)) * 10.0 ** rng.integers(-150, 150, (2, 3000)), axis=0)
    ref = mul(Interval(a, b), Interval(c, d))
    got = np.array([native.mul(*v) for v in zip(a, b, c, d)])
    assert np.array_equal(got[:, 0], ref.lo) and np.array_equal(got[:, 1], ref.hi)
    regular = (c > 0) | (d < 0)
    ref = div(Interval(a, b), Interval(c, d))
    got = np.array([native.div_regular(*v) for v in zip(a, b, c, d)])
    assert regular.sum() > 1000
    assert np.array_equal(got[regular, 0], ref.lo[regular]) and np.array_equal(got[regular, 1], ref.hi[regular])


def test_gauss_seidel_update_gives_the_numpy_floats():
    """Regular and extended division (0 in the divisor, one or two pieces), numerators with and
    without 0, and boxes the pieces miss (empty)."""
    rng = np.random.default_rng(3)
    n = 4000
    num = np.sort(rng.normal(size=(2, n)) * 3, axis=0)
    den = np.sort(rng.normal(size=(2, n)), axis=0)
    x = np.sort(rng.normal(size=(2, n)) * 5, axis=0)
    ref = _gs_update(Interval(*num), Interval(*den), Interval(*x))
    got = np.array([native.gs_update(*v) for v in zip(num[0], num[1], den[0], den[1], x[0], x[1])])
    extended = (den[0] <= 0) & (den[1] >= 0) & ((num[0] > 0) | (num[1] < 0))
    assert extended.sum() > 200 and (ref.lo > ref.hi).sum() > 50
    assert np.array_equal(got[:, 0], ref.lo) and np.array_equal(got[:, 1], ref.hi)


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 7), st.sampled_from([0.0, 1e-6, 0.01, 0.3, 2.0]),
       st.sampled_from([1e-3, 0.1, 1.0, 10.0]), st.sampled_from(["mid", "eye", "random"]))
def test_hansen_sengupta_kernel_and_numpy_keep_the_zero(seed, n, width, xwidth, precond):
    """f(x) = M (x − x*) with M in A (f(c) enclosed from exact rationals), up to 7 unknowns: the
    kernel's box and the numpy version's keep x*, lie in x, and are not called empty."""
    f, S, X, c, C, xstar = zero_problem(np.random.default_rng(seed), n, width, xwidth, precond)
    for H, empty in (hansen_sengupta(f, S, X, c, C), _hansen_sengupta_numpy(f, S, X, c, C)):
        assert not empty[0]
        assert np.all(H.lo >= X.lo) and np.all(H.hi <= X.hi)
        for i in range(n):
            assert inside(xstar[i], H.lo[0, i], H.hi[0, i])


@pytest.mark.parametrize("n", [2, 4, 7])
def test_hansen_sengupta_kernel_batches_and_non_finite_input(n):
    """Batches of random systems give the numpy version's empty flags and boxes (to 1e-12 of the
    box's magnitude: only sums bounded a priori are taken in another order); a box with an infinite
    or NaN input is returned unchanged, not empty."""
    rng = np.random.default_rng(4 + n)
    N = 500
    M = rng.normal(size=(N, n, n)) + 3 * np.eye(n)
    S = Interval(M - 0.05, M + 0.05)
    lo = rng.normal(size=(N, n)) - 0.5
    X = Interval(lo, lo + 1.0)
    c = X.mid()
    fm = rng.normal(size=(N, n)) * 0.5
    f = Interval(fm - 1e-9, fm + 1e-9)
    C = np.linalg.inv(M)
    H, empty = hansen_sengupta(f, S, X, c, C)
    ref, ref_empty = _hansen_sengupta_numpy(f, S, X, c, C)
    assert np.array_equal(empty, ref_empty) and 0 < empty.sum() < N
    keep = ~empty
    scale = 1e-12 * (1.0 + np.max(np.abs([X.lo, X.hi]), axis=(0, 2)))[keep, None]
    assert np.all(np.abs(H.lo[keep] - ref.lo[keep]) <= scale)
    assert np.all(np.abs(H.hi[keep] - ref.hi[keep]) <= scale)
    assert np.any(H.lo[keep] > X.lo[keep]) and np.any(H.hi[keep] < X.hi[keep])
    S.hi[0, 0, n - 1] = np.inf
    f.lo[1, 0] = np.nan
    C[2, 0, 0] = np.inf
    H, empty = hansen_sengupta(f, S, X, c, C)
    assert not empty[:3].any()
    assert np.array_equal(H.lo[:3], X.lo[:3]) and np.array_equal(H.hi[:3], X.hi[:3])


def test_kernels_are_compiled_without_fused_multiply_add():
    """The soundness argument (docs/soundness.md §1) has every operation rounded on its own: the
    machine code of the kernels holds no fused multiply-add (x86 vfmadd..., AArch64 fmadd/fmla...)."""
    import re

    import numba

    rng = np.random.default_rng(6)
    N, n = 3, 4
    M = rng.normal(size=(N, n, n)) + 3 * np.eye(n)
    x = rng.normal(size=(N, n))
    fresh = numba.njit(cache=False)(native.hansen_sengupta.py_func)          # cached code cannot be inspected
    fresh(x, x + 1e-9, M, M + 0.1, x - 1, x + 1, x, M)
    inverse = numba.njit(cache=False)(native.float_inverse.py_func)
    inverse(M, M + 0.1, True)
    fused = re.compile(r"\b(v?f(n)?m(add|sub)[a-z0-9]*|fml[as])\b", re.IGNORECASE)
    for kernel in (fresh, inverse):
        asm = "\n".join(kernel.inspect_asm().values())
        assert "mul" in asm and not fused.search(asm)


def test_exact_square_kernels_give_the_numpy_floats():
    """``native.up_square``/``down_square`` (no widening where the square is exact) give the floats
    of ``rounding.up_square``/``down_square``, on exact and inexact squares alike."""
    rng = np.random.default_rng(8)
    short = rng.integers(-2 ** 28, 2 ** 28, 400) * 2.0 ** rng.integers(-420, 420, 400)
    a = np.abs(np.concatenate([_floats(rng, 400), short]))
    with np.errstate(over="ignore", under="ignore"):
        p = a * a
    for kernel, ref in ((native.up_square, up_square), (native.down_square, down_square)):
        got = np.array([kernel(x, y) for x, y in zip(a, p)])
        assert np.array_equal(got, ref(a, p))
    exact = np.array([native.square_exact(x, y) for x, y in zip(a, p)])
    assert 100 < exact.sum() < len(a)
