"""Interval linear algebra: containment of exact results, Gauss-Seidel, Krawczyk, batching."""
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from intervals import Interval, stack
from intervals.linalg import _gs_update
from intervals.linalg import (
    det, gauss_seidel, hadamard_bound, hansen_sengupta, identity, krawczyk, matmul, matvec, mid_inverse, point,
)
from intervals.rounding import enclose_fraction

SETTINGS = settings(max_examples=150, deadline=None)


# ----------------------------------------------------------------- helpers
def inside(q: Fraction, lo: float, hi: float) -> bool:
    return (lo == -np.inf or Fraction(float(lo)) <= q) and (hi == np.inf or q <= Fraction(float(hi)))


def random_interval_matrix(rng, shape, scale, width, singular=False):
    """Midpoints ~ scale * N(0,1) (rank-deficient if ``singular``), radii ~ width * |mid| + tiny."""
    M = rng.normal(size=shape) * scale
    if singular and shape[-1] >= 2:
        M[..., -1, :] = M[..., 0, :] * 2.0  # exactly rank deficient midpoint
    R = width * np.abs(M) * rng.random(size=shape)
    if width > 0:
        R = R + width * scale * 1e-3 * (rng.random(size=shape) < 0.3)
    lo = M - R
    hi = M + R
    zero = rng.random(size=shape) < 0.1  # some exact zeros and degenerate entries
    lo[zero] = 0.0
    hi[zero] = np.where(rng.random(size=shape) < 0.5, 0.0, np.abs(hi))[zero]
    return Interval(np.minimum(lo, hi), np.maximum(lo, hi))


def sample_point(rng, iv: Interval):
    """A nested list of exact rationals inside ``iv`` (endpoints with some probability)."""
    lo = iv.lo.ravel()
    hi = iv.hi.ravel()
    pts = []
    for a, b in zip(lo, hi):
        u = rng.random()
        if u < 0.2:
            t = Fraction(0)
        elif u < 0.4:
            t = Fraction(1)
        else:
            t = Fraction(int(rng.integers(0, 2 ** 30)), 2 ** 30)
        pts.append(Fraction(float(a)) + t * (Fraction(float(b)) - Fraction(float(a))))
    return np.array(pts, dtype=object).reshape(iv.shape)


def exact_det(M) -> Fraction:
    M = [list(row) for row in M]
    n = len(M)
    d = Fraction(1)
    for k in range(n):
        p = next((i for i in range(k, n) if M[i][k] != 0), None)
        if p is None:
            return Fraction(0)
        if p != k:
            M[k], M[p] = M[p], M[k]
            d = -d
        d *= M[k][k]
        for i in range(k + 1, n):
            f = M[i][k] / M[k][k]
            if f:
                for j in range(k, n):
                    M[i][j] -= f * M[k][j]
    return d


def exact_matmul(A, B):
    n, k = A.shape
    m = B.shape[1]
    return [[sum((A[i, j] * B[j, l] for j in range(k)), Fraction(0)) for l in range(m)] for i in range(n)]


matrix_params = st.fixed_dictionaries({
    "seed": st.integers(0, 2 ** 32 - 1),
    "scale": st.sampled_from([1.0, 1e-3, 1e3, 1e-150, 1e150, 1e-310, 1e300]),
    "width": st.sampled_from([0.0, 1e-15, 1e-8, 1e-3, 0.1, 1.0, 5.0]),
    "singular": st.booleans(),
})


# ----------------------------------------------------------------- products
@SETTINGS
@given(matrix_params, st.integers(1, 4), st.integers(1, 4), st.integers(1, 4), st.sampled_from(["ii", "fi", "if", "ff"]))
def test_matmul_contains_exact(p, n, k, m, kinds):
    rng = np.random.default_rng(p["seed"])
    A = random_interval_matrix(rng, (n, k), p["scale"], p["width"])
    B = random_interval_matrix(rng, (k, m), 1.0, p["width"])
    if kinds[0] == "f":
        A = A.mid()
    if kinds[1] == "f":
        B = B.mid()
    P = matmul(A, B)
    assert P.shape == (n, m)
    for _ in range(3):
        a = sample_point(rng, point(A)) if kinds[0] == "i" else np.vectorize(Fraction, otypes=[object])(A)
        b = sample_point(rng, point(B)) if kinds[1] == "i" else np.vectorize(Fraction, otypes=[object])(B)
        exact = exact_matmul(a, b)
        for i in range(n):
            for l in range(m):
                assert inside(exact[i][l], P.lo[i, l], P.hi[i, l])


@SETTINGS
@given(matrix_params, st.integers(1, 5), st.integers(1, 5))
def test_matvec_contains_exact(p, n, k):
    rng = np.random.default_rng(p["seed"])
    A = random_interval_matrix(rng, (n, k), p["scale"], p["width"])
    x = random_interval_matrix(rng, (k,), 1.0, p["width"])
    y = matvec(A, x)
    for _ in range(3):
        a = sample_point(rng, A)
        v = sample_point(rng, x)
        for i in range(n):
            assert inside(sum((a[i, j] * v[j] for j in range(k)), Fraction(0)), y.lo[i], y.hi[i])


def test_matmul_infinite_and_zero_entries():
    A = Interval(np.array([[0.0, 1.0]]), np.array([[0.0, 2.0]]))
    B = Interval(np.array([[-np.inf], [1.0]]), np.array([[np.inf], [1.0]]))
    P = matmul(A, B)  # 0 * [-inf, inf] + [1, 2] * 1
    assert P.lo[0, 0] <= 1.0 and P.hi[0, 0] >= 2.0 and not np.isnan(P.hi[0, 0])
    # a point zero times an unbounded interval is 0, not NaN
    y = matvec(np.array([[0.0, 1.0]]), Interval(np.array([-np.inf, 3.0]), np.array([np.inf, 3.0])))
    assert y.lo[0] <= 3.0 <= y.hi[0] and np.isfinite(y.lo[0]) and np.isfinite(y.hi[0])
    with pytest.raises(ValueError):
        matmul(np.array([[np.nan]]), np.array([[1.0]]))
    with pytest.raises(ValueError):
        matmul(np.ones((2, 3)), np.ones((2, 3)))


def test_matmul_point_is_tight():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(7, 7))
    B = rng.normal(size=(7, 7))
    P = matmul(A, B)
    assert np.all(P.lo <= A @ B + 1e-12) and np.all(P.hi >= A @ B - 1e-12)
    assert np.max(P.hi - P.lo) < 1e-13


# ----------------------------------------------------------------- determinant
@settings(max_examples=200, deadline=None)
@given(matrix_params, st.integers(1, 6))
def test_det_contains_exact(p, n):
    rng = np.random.default_rng(p["seed"])
    A = random_interval_matrix(rng, (n, n), p["scale"], p["width"], p["singular"])
    D = det(A)
    assert D.shape == ()
    assert not np.isnan(D.lo) and not np.isnan(D.hi) and D.lo <= D.hi
    pts = [sample_point(rng, A) for _ in range(3)]
    pts.append(np.vectorize(Fraction, otypes=[object])(A.mid()))
    for M in pts:
        assert inside(exact_det(M), D.lo, D.hi)
    H = hadamard_bound(A)
    assert -H <= D.lo and D.hi <= H


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 7, 9])
def test_det_point_matrix_is_tight(n):
    rng = np.random.default_rng(n)
    M = rng.normal(size=(n, n)) + 3 * np.eye(n)
    D = det(M)
    exact = exact_det(np.vectorize(Fraction, otypes=[object])(M))
    assert inside(exact, D.lo, D.hi)
    assert (D.hi - D.lo) <= 1e-12 * abs(float(exact))


def test_det_narrow_interval_is_tight_and_signed():
    rng = np.random.default_rng(7)
    M = rng.normal(size=(50, 8, 8))
    A = Interval(M - 1e-10, M + 1e-10)
    D = det(A)
    ref = np.linalg.det(M)
    assert np.all(D.lo <= ref + 1e-6 * np.abs(ref)) and np.all(ref - 1e-6 * np.abs(ref) <= D.hi)
    well = np.abs(ref) > 1e-3
    assert np.all((D.lo > 0) | (D.hi < 0) | ~well)  # sign proved where |det| is not tiny


def test_det_singular_and_wide():
    # exactly singular point matrix: the enclosure contains 0
    M = np.array([[1.0, 2, 3, 4], [2, 4, 6, 8], [0, 1, 0, 1], [1, 0, 1, 0]])
    D = det(M)
    assert D.lo <= 0 <= D.hi and D.hi - D.lo < 1e-10
    # very wide: elimination fails, the Hadamard bound answers
    A = Interval(-np.ones((5, 5)), np.ones((5, 5)))
    D = det(A)
    assert -D.lo == D.hi and 5 ** 2.5 <= D.hi < 5 ** 2.5 * (1 + 1e-12)
    # unbounded entries
    A = Interval(np.full((4, 4), -np.inf), np.ones((4, 4)))
    D = det(A)
    assert D.lo == -np.inf and D.hi == np.inf
    # n = 0
    assert float(det(np.zeros((0, 0))).lo) == 1.0


def test_det_large_n_uses_sound_elimination():
    # a 6x6 with exact integer determinant, permutation needed (zero leading entry)
    M = np.array([[0, 1, 2, 0, 0, 1], [3, 0, 1, 1, 0, 0], [1, 1, 0, 2, 1, 0],
                  [0, 2, 1, 0, 3, 1], [1, 0, 0, 1, 1, 2], [2, 1, 1, 0, 0, 1]], dtype=float)
    exact = exact_det(np.vectorize(Fraction, otypes=[object])(M))
    D = det(M)
    assert inside(exact, D.lo, D.hi) and D.hi - D.lo < 1e-9
    D2 = det(M[[1, 0, 2, 3, 4, 5]])
    assert inside(-exact, D2.lo, D2.hi)


# ----------------------------------------------------------------- mid_inverse
def test_mid_inverse_regular_singular_and_batch():
    rng = np.random.default_rng(3)
    M = rng.normal(size=(4, 3, 3))
    M[1] = [[1, 2, 3], [2, 4, 6], [0, 0, 1]]  # singular
    M[2] = 0.0
    M[3] = np.eye(3)
    C, failed = mid_inverse(Interval(M - 1e-3, M + 1e-3))
    assert failed.tolist() == [False, True, True, False]
    assert np.all(np.isfinite(C))
    assert np.allclose(C[0] @ M[0], np.eye(3))
    assert np.array_equal(C[2], np.eye(3))
    assert np.allclose(C[3], np.eye(3))
    # ill conditioned (cond ~ 1e17) is reported
    _, f = mid_inverse(np.array([[1.0, 1.0], [1.0, 1.0 + 1e-16 * 4]]))
    assert f
    # batch equals one at a time
    for i in range(4):
        Ci, fi = mid_inverse(Interval(M[i] - 1e-3, M[i] + 1e-3))
        assert fi == failed[i] and np.allclose(Ci, C[i], rtol=1e-12, atol=0)


# ----------------------------------------------------------------- Gauss-Seidel
def _solution_problem(rng, n, width, xwidth):
    """Interval A, b and box x with a known exact solution x* (M x* = beta, M in A, beta in b)."""
    A = random_interval_matrix(rng, (n, n), 1.0, width)
    xs = rng.normal(size=n)
    x = Interval(xs - xwidth * rng.random(n), xs + xwidth * rng.random(n))
    M = sample_point(rng, A)
    xstar = sample_point(rng, x)
    beta = [sum((M[i, j] * xstar[j] for j in range(n)), Fraction(0)) for i in range(n)]
    enc = [enclose_fraction(v) for v in beta]
    b = Interval(np.array([e[0] for e in enc]), np.array([e[1] for e in enc]))
    return A, b, x, xstar


@SETTINGS
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 5), st.sampled_from([0.0, 1e-6, 0.01, 0.3, 2.0]),
       st.sampled_from([1e-3, 0.1, 1.0, 10.0]), st.sampled_from(["mid", "eye", "random"]))
def test_gauss_seidel_keeps_solution(seed, n, width, xwidth, precond):
    rng = np.random.default_rng(seed)
    A, b, x, xstar = _solution_problem(rng, n, width, xwidth)
    C = {"mid": None, "eye": np.eye(n), "random": rng.normal(size=(n, n))}[precond]
    y = x
    for _ in range(3):
        y, empty = gauss_seidel(A, b, y, C)
        assert not empty
        assert np.all(y.subset(x))
        for i in range(n):
            assert inside(xstar[i], y.lo[i], y.hi[i])


def zero_problem(rng, n, width, xwidth, precond):
    """(f, S, X, c, C, x*), a batch of one: f(x) = M (x − x*) with M in the interval matrix S, f(c) at
    the midpoint c of the box X ∋ x* enclosed exactly (Fractions), C a preconditioner of the kind
    ``precond`` ("mid", "eye" or "random")."""
    A, _, x, xstar = _solution_problem(rng, n, width, xwidth)
    M = sample_point(rng, A)
    c = x.mid()
    fc = [sum((M[i, j] * (Fraction(float(c[j])) - xstar[j]) for j in range(n)), Fraction(0)) for i in range(n)]
    enc = [enclose_fraction(v) for v in fc]
    f = Interval(np.array([[e[0] for e in enc]]), np.array([[e[1] for e in enc]]))
    C = {"mid": mid_inverse(A)[0], "eye": np.eye(n), "random": rng.normal(size=(n, n))}[precond]
    return f, Interval(A.lo[None], A.hi[None]), Interval(x.lo[None], x.hi[None]), c[None], C[None], xstar


@SETTINGS
@given(st.integers(0, 2 ** 32 - 1), st.integers(1, 5), st.sampled_from([0.0, 1e-6, 0.01, 0.3, 2.0]),
       st.sampled_from([1e-3, 0.1, 1.0, 10.0]), st.sampled_from(["mid", "eye", "random"]))
def test_hansen_sengupta_keeps_zero(seed, n, width, xwidth, precond):
    """f(x) = M (x − x*) with M in A: f(c) enclosed exactly (Fractions), A as the slope enclosure; the
    operator's box keeps x*, lies in x, and is never called empty."""
    f, S, X, c, C, xstar = zero_problem(np.random.default_rng(seed), n, width, xwidth, precond)
    H, empty = hansen_sengupta(f, S, X, c, C)
    assert not empty[0]
    assert np.all(H.lo >= X.lo) and np.all(H.hi <= X.hi)
    for i in range(n):
        assert inside(xstar[i], H.lo[0, i], H.hi[0, i])


def test_hansen_sengupta_empty_far_and_tight_near():
    """x² − 2 = 0 and y − 1 = 0 with slopes at c: a box far from the root is proved empty, one around
    it is contracted onto it (one sweep, batched)."""
    lo = np.array([[3.0, 0.0], [1.3, 0.9]])
    hi = np.array([[4.0, 2.0], [1.5, 1.1]])
    X = Interval(lo, hi)
    c = X.mid()
    f = Interval(np.stack([c[:, 0] ** 2 - 2, c[:, 1] - 1], 1)) + Interval(-1e-15, 1e-15)
    S = Interval(np.zeros((2, 2, 2)), np.zeros((2, 2, 2)))
    S.lo[:, 0, 0], S.hi[:, 0, 0] = lo[:, 0] + c[:, 0], hi[:, 0] + c[:, 0]   # x² − c² = (x + c)(x − c)
    S.lo[:, 1, 1], S.hi[:, 1, 1] = 1.0, 1.0
    C = np.linalg.inv(S.mid())
    H, empty = hansen_sengupta(f, S, X, c, C)
    assert empty.tolist() == [True, False]
    assert H.lo[1, 0] <= 2 ** 0.5 <= H.hi[1, 0] and H.hi[1, 0] - H.lo[1, 0] < 0.05
    assert H.lo[1, 1] <= 1.0 <= H.hi[1, 1] and H.hi[1, 1] - H.lo[1, 1] < 1e-12

def test_gauss_seidel_contracts_and_detects_empty():
    rng = np.random.default_rng(5)
    M = rng.normal(size=(4, 4)) + 4 * np.eye(4)
    xs = rng.normal(size=4)
    b = matvec(M, xs)
    x = Interval(xs - 1.0, xs + 1.0)
    for _ in range(3):
        x, empty = gauss_seidel(M, b, x)
    assert not empty and np.all(x.width() < 1e-12)
    assert np.all(x.contains(xs))
    # no solution in the box
    far = Interval(xs + 5.0, xs + 6.0)
    _, empty = gauss_seidel(M, b, far)
    assert empty


def test_gauss_seidel_zero_in_diagonal():
    C = np.array([[1.0]])
    # d t = 1, d in [-1, 2]: t in (-inf, -1] U [1/2, inf)
    A = Interval(np.array([[-1.0]]), np.array([[2.0]]))
    b = Interval(np.array([1.0]))
    y, e = gauss_seidel(A, b, Interval(np.array([-3.0]), np.array([3.0])), C)
    assert not e and y.lo[0] == -3.0 and y.hi[0] == 3.0
    y, e = gauss_seidel(A, b, Interval(np.array([-0.5]), np.array([3.0])), C)
    assert not e and 0.49 < y.lo[0] <= 0.5 and y.hi[0] == 3.0
    y, e = gauss_seidel(A, b, Interval(np.array([-3.0]), np.array([-0.5])), C)
    assert not e and y.lo[0] == -3.0 and -1.0 <= y.hi[0] < -0.99
    _, e = gauss_seidel(A, b, Interval(np.array([-0.9]), np.array([0.4])), C)
    assert e
    # numerator and denominator both contain 0: no information, x unchanged
    y, e = gauss_seidel(A, Interval(np.array([-1.0]), np.array([1.0])), Interval(np.array([-0.9]), np.array([0.4])), C)
    assert not e and y.lo[0] == -0.9 and y.hi[0] == 0.4
    # denominator exactly 0 and numerator not: no solution (the update itself; through C A the
    # product 1 * 0 is widened by the underflow slack of outward rounding, which is sound)
    new = _gs_update(Interval(1.0), Interval(0.0), Interval(-np.inf, np.inf))
    assert new.lo > new.hi


@SETTINGS
@given(st.integers(0, 2 ** 32 - 1))
def test_gauss_seidel_1d_extended_division(seed):
    """t in x with d t = v, d in D, v in N must survive, whatever signs D and N have."""
    rng = np.random.default_rng(seed)
    d_lo, d_hi = np.sort(rng.choice([-2.0, -1.0, 0.0, 0.5, 1.0, 3.0], size=2))
    x_lo, x_hi = np.sort(rng.normal(size=2) * 3)
    D = Interval(d_lo, d_hi)
    X = Interval(x_lo, x_hi)
    d = sample_point(rng, D.reshape(1))[0]
    t = sample_point(rng, X.reshape(1))[0]
    v = d * t
    lo, hi = enclose_fraction(v)
    N = Interval(lo - rng.random() * rng.choice([0, 1]), hi + rng.random() * rng.choice([0, 1]))
    y, e = gauss_seidel(D.reshape(1, 1), N.reshape(1), X.reshape(1), np.array([[1.0]]))
    assert not e[()] and inside(t, y.lo[0], y.hi[0])


# ----------------------------------------------------------------- Krawczyk
def circle_line(X):
    """f = (x^2 + y^2 - 1, x - y); roots +-(1/sqrt2, 1/sqrt2)."""
    x, y = X[..., 0], X[..., 1]
    return stack([x * x + y * y - 1.0, x - y], axis=-1)


def circle_line_J(X):
    x, y = X[..., 0], X[..., 1]
    one = Interval(np.ones(x.shape))
    return stack([stack([2.0 * x, 2.0 * y], axis=-1), stack([one, -one], axis=-1)], axis=-2)


def three(X):
    """f = (x^2+y^2+z^2-3, xy-1, yz-1); roots (1,1,1), -(1,1,1), +-(1/sqrt2, sqrt2, 1/sqrt2)."""
    x, y, z = X[..., 0], X[..., 1], X[..., 2]
    return stack([x * x + y * y + z * z - 3.0, x * y - 1.0, y * z - 1.0], axis=-1)


def three_J(X):
    x, y, z = X[..., 0], X[..., 1], X[..., 2]
    zero = Interval(np.zeros(x.shape))
    return stack([stack([2.0 * x, 2.0 * y, 2.0 * z], axis=-1),
                  stack([y, x, zero], axis=-1),
                  stack([zero, z, y], axis=-1)], axis=-2)


mpmath.mp.dps = 40
S2 = mpmath.sqrt(2)
ROOTS = {
    "circle": [(1 / S2, 1 / S2), (-1 / S2, -1 / S2)],
    "three": [(1, 1, 1), (-1, -1, -1), (1 / S2, S2, 1 / S2), (-1 / S2, -S2, -1 / S2)],
}
SYSTEMS = {"circle": (circle_line, circle_line_J), "three": (three, three_J)}


def krawczyk_on(system, box: Interval):
    f, J = SYSTEMS[system]
    c = box.mid()
    return krawczyk(f(Interval(c)), J(box), box)


def roots_in(system, box: Interval):
    """Boolean array (batch,) per root: does the root lie in the box (40-digit comparison)."""
    out = []
    for r in ROOTS[system]:
        ok = np.ones(box.shape[:-1], dtype=bool)
        for i, ri in enumerate(r):
            lo = np.vectorize(lambda v: mpmath.mpf(float(v)) <= ri, otypes=[bool])(box.lo[..., i])
            hi = np.vectorize(lambda v: ri <= mpmath.mpf(float(v)), otypes=[bool])(box.hi[..., i])
            ok &= lo & hi
        out.append(ok)
    return np.stack(out, axis=-1)


@pytest.mark.parametrize("system", ["circle", "three"])
def test_krawczyk_proves_unique_near_root_and_empty_far(system):
    for r in ROOTS[system]:
        c = np.array([float(v) for v in r])
        box = Interval(c - 1e-3, c + 1e-3)
        res = krawczyk_on(system, box)
        assert res.unique and not res.empty
        assert np.all(res.K.interior(box))
        assert res.C.shape == (len(c), len(c))
        far = Interval(c + 0.5, c + 0.6)
        res = krawczyk_on(system, far)
        assert res.empty and not res.unique


def test_krawczyk_iteration_converges():
    box = Interval(np.array([0.8, 0.8, 0.8]), np.array([1.2, 1.2, 1.2]))
    res = krawczyk_on("three", box)
    assert not res.unique and np.all(res.K.lo <= 0.8)  # too wide: K does not contract
    box = Interval(np.array([0.9, 0.9, 0.9]), np.array([1.1, 1.1, 1.1]))
    proved = []
    for _ in range(8):
        res = krawczyk_on("three", box)
        assert not res.empty
        proved.append(bool(res.unique))
        box = res.K.intersect(box)
    assert proved[0]  # unique already on the first box
    assert np.all(box.width() < 1e-13) and np.all(box.contains(1.0))  # quadratic convergence to the root


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.sampled_from(["circle", "three"]),
       st.sampled_from([1e-6, 1e-3, 0.05, 0.3, 1.0, 3.0]))
def test_krawczyk_claims_are_true(seed, system, radius):
    """Random batches of boxes: `unique` -> exactly one root inside; `empty` -> none."""
    rng = np.random.default_rng(seed)
    n = len(ROOTS[system][0])
    roots = np.array([[float(v) for v in r] for r in ROOTS[system]])
    centres = roots[rng.integers(0, len(roots), size=40)] + rng.normal(size=(40, n)) * radius
    rads = radius * (0.2 + rng.random(size=(40, n)))
    box = Interval(centres - rads, centres + rads)
    res = krawczyk_on(system, box)
    count = roots_in(system, box).sum(axis=-1)
    assert np.all(count[res.unique] == 1)
    assert np.all(count[res.empty] == 0)
    assert not np.any(res.unique & res.empty)


def square(X):
    return stack([X[..., 0] * X[..., 0] - 1e-6], axis=-1)


def square_J(X):
    return stack([stack([2.0 * X[..., 0]], axis=-1)], axis=-2)


def test_krawczyk_never_unique_with_two_roots():
    r = float(mpmath.sqrt(mpmath.mpf(1e-6)))
    rng = np.random.default_rng(11)
    # boxes containing both roots +-1e-3: centred, shifted, tiny margin, huge
    lo = -np.concatenate([np.full(5, r * 1.0001), r * (1 + rng.random(500) * 10), [r * 1.000000001, 1.0, 1e3]])
    hi = np.concatenate([np.full(5, r * 1.0001), r * (1 + rng.random(500) * 10), [r * 1.000000001, 1.0, 1e3]])
    box = Interval(lo[:, None], hi[:, None])
    res = krawczyk(square(Interval(box.mid())), square_J(box), box)
    assert not np.any(res.unique)
    assert not np.any(res.empty)
    # and it does prove each simple root alone
    for s in (1.0, -1.0):
        c = np.array([s * r])
        b1 = Interval(c - 1e-5, c + 1e-5)
        assert krawczyk(square(Interval(c)), square_J(b1), b1).unique


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.sampled_from([1e-5, 1e-4, 1e-3, 1e-2]))
def test_krawczyk_square_claims_are_true(seed, radius):
    rng = np.random.default_rng(seed)
    root = mpmath.sqrt(mpmath.mpf(1e-6))
    c = rng.normal(size=200) * 2e-3
    w = radius * (0.1 + rng.random(200))
    box = Interval((c - w)[:, None], (c + w)[:, None])
    res = krawczyk(square(Interval(box.mid())), square_J(box), box)
    lo = np.array([mpmath.mpf(float(v)) for v in box.lo[:, 0]])
    hi = np.array([mpmath.mpf(float(v)) for v in box.hi[:, 0]])
    count = np.array([(l <= root <= h) + (l <= -root <= h) for l, h in zip(lo, hi)])
    assert np.all(count[res.unique] == 1)
    assert np.all(count[res.empty] == 0)


def test_krawczyk_conservative_cases():
    box = Interval(np.array([0.6, 0.6]), np.array([0.8, 0.8]))
    f, J = SYSTEMS["circle"]
    # c outside the box: neither claim
    c = np.array([2.0, 2.0])
    res = krawczyk(f(Interval(c)), J(box), box, c=c)
    assert not res.unique and not res.empty
    # unbounded box: never unique
    ub = Interval(np.array([0.6, -np.inf]), np.array([0.8, np.inf]))
    res = krawczyk(f(Interval(ub.mid())), J(ub), ub)
    assert not res.unique


# ----------------------------------------------------------------- batching
def test_batch_matches_one_at_a_time():
    rng = np.random.default_rng(2)
    for n in (2, 3, 4, 6, 9):
        A = random_interval_matrix(rng, (12, n, n), 1.0, 1e-4)
        A2 = random_interval_matrix(rng, (12, n, n), 1.0, 1e-2, singular=True)
        x = random_interval_matrix(rng, (12, n), 1.0, 0.1)
        B = random_interval_matrix(rng, (12, n), 1.0, 1e-3)
        D = det(A)
        D2 = det(A2)
        P = matmul(A, A2)
        v = matvec(A, x)
        G, e = gauss_seidel(A, B, x)
        assert D.shape == (12,) and P.shape == (12, n, n) and v.shape == (12, n) and G.shape == (12, n)
        for i in range(12):
            for whole, single in ((D, det(A[i])), (D2, det(A2[i])), (P, matmul(A[i], A2[i])),
                                  (v, matvec(A[i], x[i])), (G, gauss_seidel(A[i], B[i], x[i])[0])):
                assert np.array_equal(whole.lo[i], single.lo, equal_nan=True)
                assert np.array_equal(whole.hi[i], single.hi, equal_nan=True)
            assert e[i] == gauss_seidel(A[i], B[i], x[i])[1]
    # several batch dimensions and broadcasting a single matrix against a batch of vectors
    A = random_interval_matrix(rng, (3, 4, 5, 5), 1.0, 1e-3)
    assert det(A).shape == (3, 4)
    M = rng.normal(size=(5, 5))
    xs = random_interval_matrix(rng, (7, 5), 1.0, 0.1)
    y = matvec(M, xs)
    assert y.shape == (7, 5)
    assert np.array_equal(y.lo[3], matvec(M, xs[3]).lo)
    assert identity(3, (2,)).shape == (2, 3, 3)


def test_krawczyk_batch_matches_one_at_a_time():
    rng = np.random.default_rng(4)
    c = np.array([1.0, 1.0, 1.0]) + rng.normal(size=(30, 3)) * 0.05
    box = Interval(c - 0.02, c + 0.02)
    res = krawczyk_on("three", box)
    assert res.K.shape == (30, 3) and res.unique.shape == (30,) and res.C.shape == (30, 3, 3)
    for i in range(30):
        r = krawczyk_on("three", box[i])
        assert np.array_equal(r.K.lo, res.K.lo[i]) and np.array_equal(r.K.hi, res.K.hi[i])
        assert r.unique == res.unique[i] and r.empty == res.empty[i]
        assert np.array_equal(r.C, res.C[i])
    assert res.unique.any()
