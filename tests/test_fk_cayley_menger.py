"""The Cayley-Menger rule of the FK search (``certkin.fk.cayley_menger``), against exact rationals.

The forms are checked by evaluation: at random rational quaternions, F(q) = CM·|q|^8 computed
exactly (the 6×6 determinant by Fraction elimination, not by the expansion the solver uses) lies
within the enclosure Σ (m_J ± r_J) q^J.  The test of a box is checked against exact values of F
inside excluded boxes, and never excludes a box around an exact rational posture.
"""
from __future__ import annotations

import itertools
import random
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from certfile import Doc
from certkin import load_robot
from certkin.fk import cayley_menger as cm
from certkin.fk import forward_kinematics
from intervals import Interval

ROBOT_A = [[Fraction(x) for x in row] for row in (
    ("1.5", "0.2", "0"), ("0.9", "1.3", "0.05"), ("-0.7", "1.1", "0"), ("-1.4", "-0.3", "0.1"),
    ("-0.4", "-1.2", "0"), ("0.8", "-0.9", "-0.05"))]
ROBOT_B = [[Fraction(x) for x in row] for row in (
    ("0.6", "0.1", "0"), ("0.2", "0.7", "0.02"), ("-0.5", "0.45", "0"), ("-0.55", "-0.2", "0"),
    ("-0.1", "-0.6", "0.03"), ("0.45", "-0.35", "0"))]


def rotation_tilde(q):
    """|q|² R(q), exact."""
    q0, q1, q2, q3 = q
    return [[q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
            [2 * (q1 * q2 + q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, 2 * (q2 * q3 - q0 * q1)],
            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3]]


def det(M):
    """Exact determinant by Fraction elimination."""
    M = [row[:] for row in M]
    n, out = len(M), Fraction(1)
    for c in range(n):
        r = next((r for r in range(c, n) if M[r][c] != 0), None)
        if r is None:
            return Fraction(0)
        if r != c:
            M[c], M[r], out = M[r], M[c], -out
        out *= M[c][c]
        for r in range(c + 1, n):
            f = M[r][c] / M[c][c]
            M[r] = [x - f * y for x, y in zip(M[r], M[c])]
    return out


def exact_form(a, b, L, quad, q):
    """F(q) = CM·|q|^8 for the legs ``quad``, exact: centres a − R b (R = R̃/|q|²)."""
    n2 = sum(x * x for x in q)
    Rt = rotation_tilde(q)
    centres = [[a[m][i] - sum(Rt[i][j] * b[m][j] for j in range(3)) / n2 for i in range(3)] for m in quad]
    d = lambda u, v: sum((x - y) ** 2 for x, y in zip(u, v))  # noqa: E731
    M = [[Fraction(0)] + [Fraction(1)] * 5]
    for m in range(4):
        M.append([Fraction(1)] + [d(centres[m], centres[n]) for n in range(4)] + [L[quad[m]]])
    M.append([Fraction(1)] + [L[m] for m in quad] + [Fraction(0)])
    return det(M) * n2 ** 4


def intervals_of(a, b, L):
    def iv(rows):
        lo = np.array([[float(x) for x in r] for r in rows], float)
        return Interval.from_bounds(np.nextafter(lo, -np.inf), np.nextafter(lo, np.inf))
    Ls = np.array([float(x) for x in L])
    return iv(a), iv(b), Interval.from_bounds(np.nextafter(Ls, -np.inf), np.nextafter(Ls, np.inf))


def posture_lengths(a, b, q, p):
    """Squared leg lengths (exact) of the posture (p, q/|q|)."""
    n2 = sum(x * x for x in q)
    Rt = rotation_tilde(q)
    return [sum((p[i] + sum(Rt[i][j] * b[m][j] for j in range(3)) / n2 - a[m][i]) ** 2 for i in range(3))
            for m in range(6)]


Q_POSE = (Fraction(1), Fraction(1, 3), Fraction(-1, 5), Fraction(2, 7))
P_POSE = (Fraction(1, 10), Fraction(-1, 20), Fraction(3, 2))
L_POSE = posture_lengths(ROBOT_A, ROBOT_B, Q_POSE, P_POSE)
ORDER = np.arange(15)
SINGLE = np.zeros((0, 15), np.float32)      # no weights: the single quads' test only


def test_determinant_terms_are_the_cayley_menger_expansion():
    """130 terms of degree 4; at random rational entries their sum equals the exact determinant."""
    rng = random.Random(3)
    assert len(cm.TERMS) == 130 and all(sum(e) == 4 for _, e in cm.TERMS)
    pairs = list(itertools.combinations(range(4), 2))
    for _ in range(5):
        v = [Fraction(rng.randint(-50, 50), rng.randint(1, 9)) for _ in range(10)]
        D = lambda m, n: v[pairs.index((min(m, n), max(m, n)))] if m != n else Fraction(0)  # noqa: E731
        M = [[Fraction(0)] + [Fraction(1)] * 5] + \
            [[Fraction(1)] + [D(m, n) for n in range(4)] + [v[6 + m]] for m in range(4)] + \
            [[Fraction(1)] + v[6:] + [Fraction(0)]]
        total = sum(c * np.prod([v[i] ** e[i] for i in range(10)]) for c, e in cm.TERMS)
        assert total == det(M)


def test_forms_enclose_the_exact_polynomials_at_rational_points():
    rng = random.Random(7)
    a, b, L = intervals_of(ROBOT_A, ROBOT_B, L_POSE)
    m, r = cm.forms(a, b, L)
    assert m.shape == r.shape == (15, 165) and np.all(r >= 0)
    monos = cm.MONO[8][0]
    for _ in range(12):
        q = [Fraction(rng.randint(-20, 20), rng.randint(1, 7)) for _ in range(4)]
        k = rng.randrange(15)
        exact = exact_form(ROBOT_A, ROBOT_B, L_POSE, cm.QUADS[k], q)
        powers = [np.prod([q[i] ** e[i] for i in range(4)]) for e in monos]
        centre = sum(Fraction(float(c)) * t for c, t in zip(m[k], powers))
        radius = sum(Fraction(float(c)) * abs(t) for c, t in zip(r[k], powers))
        scale = sum(abs(Fraction(float(c))) * abs(t) for c, t in zip(m[k], powers))
        assert abs(centre - exact) <= radius
        assert radius <= Fraction(1, 10 ** 10) * scale           # and tight


def test_the_posture_zeroes_every_form():
    """F(q) = 0 at the posture's rotation for all 15 quads (the rule's premise), exactly."""
    for quad in cm.QUADS:
        assert exact_form(ROBOT_A, ROBOT_B, L_POSE, quad, list(Q_POSE)) == 0


def test_chart_box_contains_every_quotient():
    rng = np.random.default_rng(5)
    lo, w = np.empty(3), np.empty(3)
    for _ in range(300):
        c = rng.uniform(-1, 1, 4)
        h = 10.0 ** rng.uniform(-9, -0.5, 4)
        qlo, qhi = c - h, c + h
        k = cm.chart_box(qlo, qhi, lo, w)
        if k < 0:
            assert all(qlo[i] <= 0 <= qhi[i] for i in range(4))
            continue
        assert qlo[k] > 0 or qhi[k] < 0
        others = [i for i in range(4) if i != k]
        for _ in range(20):
            q = [Fraction(float(x)) for x in rng.uniform(qlo, qhi)]
            for v, i in enumerate(others):
                assert Fraction(float(lo[v])) <= q[i] / q[k] <= Fraction(float(lo[v])) + Fraction(float(w[v]))


def posture_charts():
    """The chart polynomials of the test robot at the posture's lengths, and the posture's unit quaternion."""
    a, b, L = intervals_of(ROBOT_A, ROBOT_B, L_POSE)
    q = np.array([float(x) for x in Q_POSE])
    return cm.charts(*cm.forms(a, b, L)), q / np.linalg.norm(q)


def never_excluded_around(charts, q, combine: bool):
    """Boxes around the posture's rotation (and its negation), from wide to tight, are never excluded."""
    for h in (0.3, 0.05, 1e-3, 1e-6, 1e-9):
        for s in (1.0, -1.0):
            w = np.zeros((1, 15), np.float32) if combine else SINGLE
            assert cm.excluded(*charts, (s * q - h)[None], (s * q + h)[None], ORDER, w)[0] == -1


def test_excluded_boxes_hold_no_zero_and_a_posture_is_never_excluded():
    rng = np.random.default_rng(11)
    (Am, Ar, P, R), q = posture_charts()
    never_excluded_around((Am, Ar, P, R), q, combine=False)
    # random boxes: an excluded one names a quad whose form keeps one strict sign at exact samples
    c = rng.normal(size=(400, 4))
    c /= np.linalg.norm(c, axis=1, keepdims=True)
    h = 10.0 ** rng.uniform(-3, -0.7, (400, 1))
    got = cm.excluded(Am, Ar, P, R, c - h, c + h, ORDER, SINGLE)
    assert 0.2 < np.mean(got >= 0) < 1.0                 # the rule concludes often, not always
    for i in np.nonzero(got >= 0)[0][:25]:
        quad, chart = divmod(int(got[i]), 4)
        one_sign_in_box(rng, c[i] - h[i], c[i] + h[i], chart, 8,
                        lambda q: exact_form(ROBOT_A, ROBOT_B, L_POSE, cm.QUADS[quad], q))


def one_sign_in_box(rng, lo, hi, chart, samples, exact):
    """The chart's side of the box [lo, hi] misses 0, and ``exact`` keeps one strict sign at random
    rational points of the box."""
    assert lo[chart] * hi[chart] > 0
    values = [exact([Fraction(float(x)) for x in rng.uniform(lo, hi)]) for _ in range(samples)]
    assert all(v > 0 for v in values) or all(v < 0 for v in values)


def exact_combination(weights, q):
    """Σ_quad w_quad F_quad(q), exact (the weights: floats, exactly)."""
    return sum(Fraction(float(w)) * exact_form(ROBOT_A, ROBOT_B, L_POSE, quad, q) for w, quad in zip(weights, cm.QUADS)
               if w != 0)


def test_combinations_exclude_only_where_the_weighted_sum_keeps_one_sign():
    """Boxes the single quads leave are tried with a combination of the 15 forms: an excluded box
    (60 + chart) has weights whose exact combination keeps one strict sign at exact samples in it,
    and no box around the posture is excluded, however tight."""
    rng = np.random.default_rng(12)
    (Am, Ar, P, R), q = posture_charts()
    never_excluded_around((Am, Ar, P, R), q, combine=True)
    # boxes beside the posture's rotation, where every form has a zero surface close by
    d = rng.normal(size=(600, 4))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    h = 10.0 ** rng.uniform(-5, -2, (600, 1))
    c = q + d * h * rng.uniform(1.5, 4.0, (600, 1))
    weights = np.zeros((600, 15), np.float32)
    got = cm.excluded(Am, Ar, P, R, c - h, c + h, ORDER, weights)
    single = cm.excluded(Am, Ar, P, R, c - h, c + h, ORDER, SINGLE)
    combined = np.nonzero(got >= 60)[0]
    assert np.array_equal(got < 60, single == got)           # the single quads' verdicts are unchanged
    assert len(combined) >= 10 and np.all(single[combined] == -1)
    assert not np.any(weights[got < 60])                      # weights only where a combination proved
    for i in combined[:6]:
        one_sign_in_box(rng, c[i] - h[i], c[i] + h[i], int(got[i]) - 60, 3, lambda q: exact_combination(weights[i], q))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_sides_are_never_excluded(bad):
    a, b, L = intervals_of(ROBOT_A, ROBOT_B, L_POSE)
    Am, Ar, P, R = cm.charts(*cm.forms(a, b, L))
    lo = np.array([[0.5, 0.1, 0.1, 0.1]])
    hi = lo + 0.01
    lo[0, 1] = bad if bad != np.inf else -np.inf
    assert cm.excluded(Am, Ar, P, R, lo, hi, ORDER, SINGLE)[0] == -1


# ------------------------------------------------------------------ the rule in a certificate

SEED002 = Path(__file__).resolve().parent.parent / "examples" / "robots" / "seed002-general-6-6-24-solutions.toml"


@pytest.fixture(scope="module")
def seed002_certificate():
    result = forward_kinematics(load_robot(SEED002), "1.093,2.280,2.031,2.524,3.136,1.845")
    assert result.complete and len(result.solutions) == 24
    doc = Doc(result.certificate())
    assert doc.check().ok
    return doc


def test_the_rule_decides_most_leaves_and_the_checker_agrees(seed002_certificate):
    doc = seed002_certificate
    leaves = doc.nodes(3)
    cm_leaves = doc.nodes(3, 11)
    assert len(cm_leaves) > 0.5 * len(leaves)
    assert doc.claim()["figures"]["leaves"]["cm-bernstein-empty"] == len(cm_leaves)
    combined = doc.nodes(3, 12)
    assert len(combined) > 0.02 * len(leaves)
    assert doc.claim()["figures"]["leaves"]["cm-combination-empty"] == len(combined)


def test_tampered_weights_are_rejected(seed002_certificate):
    doc = seed002_certificate
    node = int(doc.nodes(3, 12)[0])
    row, index = doc.row("tree.weights", node), doc.row("tree.index", node)
    for name, at, value in (("tree.weights", row, 0.0), ("tree.weights", (row, 3), np.nan),
                            ("tree.weights", (row, 5), 1e30), ("tree.index", index, 4), ("tree.index", index, -1)):
        edited = doc.copy()
        edited.arrays[name][at] = value
        step = edited.check().step
        assert f"node {node}" in step and "Cayley-Menger" in step, (name, value, step)


def test_tampered_evidence_is_rejected(seed002_certificate):
    doc = seed002_certificate
    node = int(doc.nodes(3, 11)[0])
    row = doc.row("tree.index", node)
    e = int(doc.arrays["tree.index"][row])
    out_of_range = doc.copy()
    out_of_range.arrays["tree.index"][row] = 60
    assert f"node {node}" in out_of_range.check().step
    quad, chart = divmod(e, 4)
    for j in range(1, 15):                   # the other quads on the same chart, until one proves nothing
        edited = doc.copy()
        edited.arrays["tree.index"][row] = 4 * ((quad + j) % 15) + chart
        step = edited.check().step
        if step:
            break
    assert f"node {node}" in step and "Cayley-Menger" in step


def test_other_lengths_undo_the_rule(seed002_certificate):
    edited = seed002_certificate.copy()
    edited.claim()["lengths"][0] = "1.193"
    assert not edited.check().ok


def test_forms_dropped_and_computed_again_change_nothing(monkeypatch):
    """Past ``FORMS_KEPT`` instances the oldest forms are dropped: time, not the answer, depends on it."""
    from certkin.fk import search
    robot = load_robot(SEED002)
    rows = [["1.093", "2.280", "2.031", "2.524", "3.136", "1.845"], ["1.1", "2.28", "2.031", "2.524", "3.136", "1.845"]]

    def run():
        results = forward_kinematics(robot, rows, max_boxes=6000, independent=True)
        doc = Doc(results[0].certificate() if isinstance(results, list) else results.certificate())
        assert doc.check().ok
        return doc.arrays["tree.code"], doc.arrays["tree.index"]
    kept = run()
    monkeypatch.setattr(search, "FORMS_KEPT", 1)
    dropped = run()
    assert len(kept[0]) > 1000 and np.sum(kept[0] == 11) > 100
    assert all(np.array_equal(x, y) for x, y in zip(kept, dropped))


def test_a_certificate_in_segments_keeps_the_weights():
    """A search past its record limit writes its tree in segments: the weights of the combinations
    go with their leaves, and the checker accepts the whole."""
    result = forward_kinematics(load_robot(SEED002), "1.093,2.280,2.031,2.524,3.136,1.845", record=True, record_limit=2000)
    cert = result.certificate()
    assert cert.header["segments"] > 2
    assert cert.header["claims"][0]["figures"]["leaves"]["cm-combination-empty"] > 100
    assert Doc(cert).check().ok
