"""The checker's Cayley-Menger rule (``proofs.cayley_menger``, FK leaf code 11) against exact references.

The forms CM·|q|^8 are derived here independently (sympy: the 6×6 determinant in its 10 entries, then
exact products of quadratic forms over QQ) and must lie in the checker's enclosures; chart boxes must hold
q/q_k; the Bernstein enclosure must hold the exact Bernstein coefficients (Fractions), a proved sign must
hold on a grid (mpmath, 50 digits), and a box around an exact posture (rational unit quaternion, rational
position, exact squared lengths) must never be proved empty.  Nothing here uses certkin or intervals.
"""
import itertools
import tomllib
from fractions import Fraction
from math import comb
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from mpmath import mp, mpf
from sympy import QQ
from sympy.polys.rings import ring

from proofs import cayley_menger as cm
from proofs import fk
from proofs.arith import Iv
from proofs.fk_system import System
from proofs.report import Rejected

ROOT = Path(__file__).resolve().parent.parent
SEED002 = ROOT / "examples/robots/seed002-general-6-6-24-solutions.toml"
SMALL = {"base": [[3, 0, 0], [2, 2, 0], [-1, 3, 1], [-3, 0, 0], [-1, -3, 0], [2, -2, -1]],
         "platform": [[1, 0, 0], [1, 1, 1], [0, 2, 0], [-1, 0, -1], [0, -1, 0], [1, -1, 0]]}


def decimals(robot):
    return {k: [[repr(v) if isinstance(v, float) else str(v) for v in p] for p in robot[k]] for k in ("base", "platform")}


def rotation(q):
    """R̃(q) = |q|² R(q), written out (any ring)."""
    q0, q1, q2, q3 = q
    return [[q0 ** 2 + q1 ** 2 - q2 ** 2 - q3 ** 2, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
            [2 * (q1 * q2 + q0 * q3), q0 ** 2 - q1 ** 2 + q2 ** 2 - q3 ** 2, 2 * (q2 * q3 - q0 * q1)],
            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0 ** 2 - q1 ** 2 - q2 ** 2 + q3 ** 2]]


def cm_terms():
    """The Cayley-Menger determinant of 4 centres and p, expanded by sympy: [(coefficient, exponents)]."""
    D, Ls = sp.symbols("d01 d02 d03 d12 d13 d23"), sp.symbols("L0:4")
    M = sp.zeros(6, 6)
    for i in range(1, 6):
        M[0, i] = M[i, 0] = 1
    for (i, j), v in zip(itertools.combinations(range(4), 2), D):
        M[i + 1, j + 1] = M[j + 1, i + 1] = v
    for i in range(4):
        M[i + 1, 5] = M[5, i + 1] = Ls[i]
    return [(int(c), e) for e, c in sp.Poly(M.det(method="berkowitz"), *D, *Ls).terms()]


def exact_forms(robot, L, quads):
    """{quad index: {exponents: Fraction}} of CM·|q|^8, exact (L: the 6 squared lengths, Fractions)."""
    R, *q = ring("q0,q1,q2,q3", QQ)
    n2, Rt = sum(x ** 2 for x in q), rotation(q)
    a, b = ([[Fraction(v) for v in p] for p in decimals(robot)[k]] for k in ("base", "platform"))
    terms, out = cm_terms(), {}
    for iq in quads:
        quad = cm.QUADS[iq]
        entries = []
        for m, n in itertools.combinations(quad, 2):
            da, db = [a[m][i] - a[n][i] for i in range(3)], [b[m][i] - b[n][i] for i in range(3)]
            entries.append(QQ(sum(x * x for x in da + db)) * n2
                           - 2 * sum(QQ(da[i] * db[j]) * Rt[i][j] for i in range(3) for j in range(3)))
        entries += [QQ(L[m]) * n2 for m in quad]
        total = R(0)
        for c, e in terms:
            t = R(c)
            for v, k in enumerate(e):
                t *= entries[v] ** k
            total += t
        out[iq] = {mono: Fraction(int(c.numerator), int(c.denominator)) for mono, c in total.terms()}
    return out


def posture(robot, q, p):
    """Exact squared leg lengths (Fractions) of the posture (q rational with |q| = 1, p rational)."""
    a, b = ([[Fraction(v) for v in pt] for pt in decimals(robot)[k]] for k in ("base", "platform"))
    R = rotation([Fraction(x) for x in q])
    assert sum(Fraction(x) ** 2 for x in q) == 1
    return [sum((p[k] + sum(R[k][j] * b[i][j] for j in range(3)) - a[i][k]) ** 2 for k in range(3)) for i in range(6)]


def system_of(robot):
    return System("gough-stewart-fk/1", decimals(robot))


def point_L(L):
    encl = [Iv.const(x) for x in L]
    return Iv(np.array([e.lo for e in encl]), np.array([e.hi for e in encl]))


Q_POSE = [Fraction(1, 5), Fraction(2, 5), Fraction(2, 5), Fraction(4, 5)]        # |q|² = 25/25
P_POSE = [Fraction(1, 3), Fraction(-1, 7), Fraction(5, 2)]


@pytest.fixture(scope="module")
def seed002():
    robot = tomllib.loads(SEED002.read_text())
    L = [Fraction(x) ** 2 for x in ("1.093", "2.280", "2.031", "2.524", "3.136", "1.845")]
    return robot, system_of(robot), L


@pytest.fixture(scope="module")
def small():
    L = posture(SMALL, Q_POSE, P_POSE)
    return SMALL, system_of(SMALL), L, exact_forms(SMALL, L, range(15))


def enclosed(F, exact, iq):
    lo, hi = F.lo[iq], F.hi[iq]
    for t, mono in enumerate(cm.MONO[8]):
        c = exact.get(mono, Fraction(0))
        assert Fraction(lo[t]) <= c <= Fraction(hi[t]), (iq, mono, lo[t], c, hi[t])
    scale = max(abs(v) for v in exact.values())
    assert np.max(hi - lo) < 1e-9 * float(scale)          # and tightly


def test_forms_enclose_exact_coefficients_seed002(seed002):
    robot, system, L = seed002
    F = cm.forms(system, point_L(L))
    assert F.lo.shape == (15, 165)
    quads = (0, 6, 14)                                    # sympy takes about a second per quad here
    exact = exact_forms(robot, L, quads)
    for iq in quads:
        enclosed(F, exact[iq], iq)


def test_forms_enclose_exact_coefficients_small_and_vanish_at_its_posture(small):
    robot, system, L, exact = small
    F = cm.forms(system, point_L(L))
    for iq in range(15):
        enclosed(F, exact[iq], iq)
        value = sum(c * np.prod([x ** e for x, e in zip(Q_POSE, mono)]) for mono, c in exact[iq].items())
        assert value == 0                                 # the reference itself: F(q) = 0 at a posture


def test_forms_with_length_ranges_enclose_every_length(small):
    robot, system, L, exact = small
    wide = Iv(np.array([float(x) for x in L]) * 0.99, np.array([float(x) for x in L]) * 1.01)
    F = cm.forms(system, wide)
    for iq in (0, 9):
        for mono, c in exact[iq].items():
            t = cm.MONO[8].index(mono)
            assert Fraction(F.lo[iq, t]) <= c <= Fraction(F.hi[iq, t])


def test_chart_box_holds_every_quotient():
    rng = np.random.default_rng(7)
    N = 400
    lo = rng.uniform(-1, 1, (N, 4))
    hi = lo + rng.uniform(0, 0.5, (N, 4)) * rng.choice([1e-9, 1e-3, 1.0], (N, 1))
    chart = rng.integers(0, 4, N)
    Y, away = cm.chart_box(lo, hi, chart)
    assert away.any() and not away.all()
    for i in np.nonzero(away)[0]:
        for _ in range(5):
            q = lo[i] + rng.uniform(0, 1, 4) * (hi[i] - lo[i])
            q = np.clip(q, lo[i], hi[i])
            k = chart[i]
            for slot, j in enumerate(cm.OTHERS[k]):
                y = Fraction(q[j]) / Fraction(q[k])
                assert Fraction(Y.lo[i, slot]) <= y <= Fraction(Y.hi[i, slot])
    assert np.all(Y.lo[~away] == -np.inf) and np.all(Y.hi[~away] == np.inf)


def test_bernstein_encloses_exact_coefficients():
    """Exact Bernstein coefficients (Fractions) of the chart polynomial on the box [a, a + w] the checker
    uses lie in its enclosures (times 280³), for a random form on a random chart box."""
    rng = np.random.default_rng(3)
    F = Iv(rng.normal(size=(1, 165)) * 10.0 ** rng.integers(-3, 4, (1, 165)))
    Y = Iv(np.array([[-0.7, 0.1, 1.3]]), np.array([[-0.3, 0.45, 2.0]]))
    for k in range(4):
        got = cm.bernstein(F, np.array([k]), Y)
        p = np.full((9, 9, 9), Fraction(0), dtype=object)
        for t, mono in enumerate(cm.MONO[8]):
            p[tuple(np.array(mono)[cm.OTHERS[k]])] = Fraction(F.lo[0, t])
        for v in range(3):
            a = Fraction(Y.lo[0, v])
            w = Fraction(Y.hi[0, v]) - a
            M = np.array([[sum((Fraction(comb(j, m) * comb(i, m), comb(8, m)) * a ** (j - m) * w ** m
                                for m in range(min(i, j) + 1)), Fraction(0)) for j in range(9)] for i in range(9)], dtype=object)
            p = np.moveaxis(np.tensordot(M, p, axes=([1], [v])), 0, v)
        exact = (p * 280 ** 3).ravel()
        # after its three cycles the checker's order is (x, y, z) again
        lo, hi = got.lo[0].reshape(9, 9, 9), got.hi[0].reshape(9, 9, 9)
        for idx in np.ndindex(9, 9, 9):
            e = exact[np.ravel_multi_index(idx, (9, 9, 9))]
            assert Fraction(lo[idx]) <= e <= Fraction(hi[idx]), (k, idx)
        assert np.max(hi - lo) < 1e-9 * float(max(abs(x) for x in exact))


def test_imatmul_encloses_exact_products():
    rng = np.random.default_rng(11)
    for scale in (1e-300, 1e-5, 1.0, 1e100):
        A = rng.normal(size=(3, 5, 9)) * scale
        X = rng.normal(size=(3, 9, 4))
        Ai, Xi = Iv(A, A + np.abs(A) * 1e-3), Iv(X - 1e-12, X)
        R = cm.imatmul(Ai, Xi)
        for n, i, j in itertools.product(range(3), range(5), range(4)):
            for pick in (lambda z: z.lo, lambda z: z.hi):
                v = sum(Fraction(pick(Ai)[n, i, m]) * Fraction(pick(Xi)[n, m, j]) for m in range(9))
                assert Fraction(R.lo[n, i, j]) <= v <= Fraction(R.hi[n, i, j])


def chart_poly(exact, k):
    """{(x, y, z) exponents: coefficient} of the form with q_k = 1."""
    return {tuple(np.array(mono)[cm.OTHERS[k]]): c for mono, c in exact.items()}


def test_proved_sign_holds_on_a_grid(small):
    robot, system, L, exact = small
    F = cm.forms(system, point_L(L))
    rng = np.random.default_rng(5)
    found = 0
    mp.dps = 50
    for _ in range(200):
        if found == 6:
            break
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        iq, k = rng.integers(0, 15), int(np.argmax(np.abs(q)))
        lo, hi = (q - 0.02)[None], (q + 0.02)[None]
        proved, away = cm.proved_empty(F[np.array([iq])], np.array([k]), lo, hi)
        assert away[0]
        if not proved[0]:
            continue
        found += 1
        Y, _ = cm.chart_box(lo, hi, np.array([k]))
        poly = chart_poly(exact[iq], k)
        coefs = [(e, mpf(c.numerator) / c.denominator) for e, c in poly.items()]
        signs = set()
        for t in itertools.product((0, 0.5, 1), repeat=3):
            x = [[(mpf(Y.lo[0, v]) + mpf(t[v]) * (mpf(Y.hi[0, v]) - mpf(Y.lo[0, v]))) ** j for j in range(9)] for v in range(3)]
            signs.add(sum(c * x[0][e[0]] * x[1][e[1]] * x[2][e[2]] for e, c in coefs) > 0)
        assert len(signs) == 1
    assert found == 6


def test_box_around_a_posture_is_never_proved(small, seed002):
    for robot, system, L in (small[:3], seed002):
        if robot is not SMALL:
            L = posture(robot, Q_POSE, P_POSE)
        F = cm.forms(system, point_L(L))
        q = np.array([float(x) for x in Q_POSE])
        rows, charts, los, his = [], [], [], []
        for iq, k, w in itertools.product(range(15), range(4), (1e-1, 1e-4, 1e-8)):
            rows.append(iq), charts.append(k), los.append(q - w * np.array([0.3, 0.9, 0.5, 0.1])), his.append(q + w)
        proved, away = cm.proved_empty(F[np.array(rows)], np.array(charts), np.array(los), np.array(his))
        assert away.all() and not proved.any()
        # the same boxes moved away from the posture: then the rule does prove (the test is not vacuous)
        far = np.array([1.0, -0.3, 0.2, 0.5]) - q
        proved, _ = cm.proved_empty(F[np.array(rows)], np.array(charts), np.array(los) + far, np.array(his) + far)
        assert proved.sum() > len(rows) // 2


def test_nan_and_inf_are_not_proved(small):
    F = cm.forms(small[1], point_L(small[2]))[np.array([0, 0, 0])]
    lo = np.array([[0.5, 0.1, 0.1, np.nan], [0.5, 0.1, -np.inf, 0.1], [0.5, 0.1, 0.1, 0.1]])
    hi = np.array([[0.6, 0.2, 0.2, 0.2], [0.6, 0.2, 0.2, 0.2], [0.6, 0.2, 0.2, np.inf]])
    proved, away = cm.proved_empty(F, np.array([0, 0, 0]), lo, hi)
    assert away.all() and not proved.any()
    bad = Iv(np.full((1, 165), np.nan), np.full((1, 165), np.nan))
    assert not cm.proved_empty(bad, np.array([0]), lo[2:] * 0 + 0.5, lo[2:] * 0 + 0.6)[0].any()


class _Forest:
    def __init__(self, e):
        self.e = np.array(e, dtype=np.int32)

    def rows(self, name, ids, k=0):
        assert name == "tree.index"
        return self.e[ids]


class _ClaimStub:
    def __init__(self, L):
        self.L, self.complete = L, True


def leaf11(system, L, e, qlo, qhi):
    """fk._leaf on code-11 leaves (unit level: no certificate)."""
    N = len(e)
    lo = np.concatenate([np.full((N, 3), -1.0), np.array(qlo, float)], 1)
    hi = np.concatenate([np.full((N, 3), 1.0), np.array(qhi, float)], 1)
    claim = _ClaimStub(point_L(L))
    fk._leaf(system, _Forest(e), 11, np.arange(N), lo, hi, None, [claim] * N, lambda i, what: f"leaf {i}: {what}")
    return claim


def test_leaf_rule_accepts_and_rejects(small):
    robot, system, L, _ = small
    good_lo, good_hi = [[0.95, -0.3, 0.2, 0.5]], [[0.97, -0.29, 0.21, 0.51]]
    e = np.arange(60)
    proved, _ = cm.proved_empty(cm.forms(system, point_L(L))[e // 4], e % 4, np.repeat(good_lo, 60, 0), np.repeat(good_hi, 60, 0))
    ok = np.nonzero(proved)[0].tolist()
    assert ok
    claim = leaf11(system, L, [ok[0]] * 2, good_lo * 2, good_hi * 2)     # accepted: no exception
    assert claim.cm.lo.shape == (15, 165)
    for e, fragment in (([ok[0], 60], "leaf 1: the Cayley-Menger evidence"), ([-1], "leaf 0: the Cayley-Menger evidence")):
        with pytest.raises(Rejected, match=fragment):
            leaf11(system, L, e, good_lo * len(e), good_hi * len(e))
    zero_side = [[0.95, -0.3, 0.2, 0.5], [-0.01, -0.3, 0.2, 0.5]]
    with pytest.raises(Rejected, match="leaf 1: the chart's quaternion side contains 0"):
        leaf11(system, L, [ok[0], 4 * (ok[0] // 4)], zero_side, [[0.97, -0.29, 0.21, 0.51], [0.01, -0.29, 0.21, 0.51]])
    q = [float(x) for x in Q_POSE]                         # the posture's own box: never proved
    with pytest.raises(Rejected, match="leaf 0: no Cayley-Menger polynomial of the quad is proved sign-definite"):
        leaf11(system, L, [0], [[x - 1e-6 for x in q]], [[x + 1e-6 for x in q]])
    spherical = System("spherical-3dof-fk/1", {"base": [["1", "0", "0"]] * 3, "platform": [["1", "0", "0"]] * 3})
    with pytest.raises(Rejected, match="needs a 6-6 Gough-Stewart robot"):
        fk._leaf(spherical, _Forest([0]), 11, np.arange(1), np.zeros((1, 4)), np.ones((1, 4)), None,
                 [_ClaimStub(point_L(L[:3]))], lambda i, what: what)
    assert fk.LEAVES[11] == ("cm-bernstein-empty", {"tree.index": 1}) and "cm-bernstein-empty" in fk._Claim.EXCLUDED
    assert 11 + fk.REBUILT not in fk.LEAVES
