"""The exact FK oracle (msolve on the Study-parameter form) and certkin's FK checked against it.

The oracle's own correctness: its leg polynomial is the leg equation (sympy
identity), its conversion to certkin's unknowns round-trips exactly, it finds
the 24 postures of seed 002's Table VI.2 and Dietmaier's 40, the postures it
returns satisfy the leg equations to 1e-25 (mpmath), a posture on a chart's
plane is recovered by the second chart, a continuum is reported as such.

Then certkin against it (``msolve_fk.compare``: every posture in exactly one
``unique`` box, every box holding exactly one posture, ``complete``): one
random robot in the default suite, and the families of the FK issue as slow
tests (100 random general 6-6 robots, 20 symmetric hexapods at home and at a
random pose, every bundled Gough-Stewart robot at its home pose), each with
certkin's default budget and its certificate re-checked by ``proofs``.
"""
from __future__ import annotations

import itertools
import math
import os
import random
import time
from fractions import Fraction
from pathlib import Path

import mpmath as mp
import pytest
import sympy as sp

import proofs
from certkin import forward_kinematics, robot_from_dict
from oracle import msolve_fk as M
from oracle import robots as G

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "robots"
DATA = Path(__file__).parent / "data"
SEED002 = EXAMPLES / "seed002-general-6-6-24-solutions.toml"
SEED002_LENGTHS = "1.093,2.280,2.031,2.524,3.136,1.845"      # digest seed-002 erratum: rho1, rho5
DIETMAIER = EXAMPLES / "dietmaier-6-6-40.toml"
DIETMAIER_LENGTHS = "1,0.645275,1.086284,1.503439,1.281933,0.771071"

try:
    M.msolve_binary()
    HAVE_MSOLVE = True
except M.OracleUnavailable:
    HAVE_MSOLVE = False
needs_msolve = pytest.mark.skipif(not HAVE_MSOLVE, reason="msolve not installed (pip install 'certkin[test]')")


# ----- the formulation ----------------------------------------------------------------------------------
def test_leg_polynomial_is_the_leg_equation():
    """|q|² · leg_i(q, y) = |q b q̄ + |q|² (p − a)|² − ρ² |q|⁴ when y = p q / 2 (identity in every
    symbol), and y = p q / 2 lies on the Study quadric."""
    q = sp.symbols("q0:4")
    a, b, p = (sp.symbols(f"{c}1:4") for c in "abp")
    rho = sp.Symbol("rho")
    _, y = M.study_of_pose(p, q)
    n = M.dot(q, q)
    lhs = n * M.leg_polynomial(q, y, a, b, rho ** 2)
    rb = M.qmul(M.qmul(q, M.pure(b)), M.qconj(q))
    assert sp.expand(rb[0]) == 0
    rhs = sum((rb[k + 1] + n * (p[k] - a[k])) ** 2 for k in range(3)) - rho ** 2 * n ** 2
    assert sp.expand(lhs - rhs) == 0
    assert sp.expand(M.dot(q, y)) == 0


def _certkin_matrix(q):
    """certkin's R(q) (certkin/robots/fk_systems.py docstring) for a unit quaternion, written out."""
    q0, q1, q2, q3 = q
    return [[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
            [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]]


def _mpf(f: Fraction):
    return mp.mpf(f.numerator) / f.denominator


def test_conversion_to_certkin_unknowns_round_trips():
    """Exact rationals: (p, q) -> (q, y) -> (p, q); R(q) v = q v q̄/|q|² is certkin's matrix R(q/|q|);
    the same through msolve-like boxes and mpmath intervals gives certkin's unknowns with q0 >= 0."""
    rng = random.Random(1)
    for _ in range(20):
        p = tuple(Fraction(rng.randint(-999, 999), 100) for _ in range(3))
        q = tuple(Fraction(rng.randint(-99, 99), 10) for _ in range(4))
        if not any(q):
            continue
        q_, y = M.study_of_pose(p, q)
        assert M.dot(q_, y) == 0
        back, q2 = M.pose_of_study(q_, y)
        assert back == p and q2 == q
        v = tuple(Fraction(rng.randint(-50, 50), 7) for _ in range(3))
        with mp.workdps(60):
            qm, vm = [_mpf(c) for c in q], [_mpf(c) for c in v]
            Rm = _certkin_matrix([c / mp.sqrt(sum(d * d for d in qm)) for c in qm])
            ref = [sum(Rm[i][j] * vm[j] for j in range(3)) for i in range(3)]
            assert all(abs(_mpf(a) - r) < mp.mpf(10) ** -50 for a, r in zip(M.rotate(q, v), ref))
        # the chart multiple of (q, y), as msolve returns it, in thin boxes -> certkin's unknowns
        s = Fraction(1, 1) / (sum(q) or 1) * rng.choice([-1, 1])
        box = [(c * s - Fraction(1, 10 ** 30), c * s + Fraction(1, 10 ** 30)) for c in tuple(q_) + tuple(y)]
        post = M.make_posture(box, (1, 1, 1, 1), [(Fraction(0),) * 3, v] + [(Fraction(1),) * 3] * 4)
        x = post.unknowns
        assert all(abs(float(x[k].mid) - float(p[k])) < 1e-12 for k in range(3))
        sign = 1 if q[0] > 0 else -1
        norm = math.sqrt(sum(float(c) ** 2 for c in q))
        assert all(abs(float(x[3 + k].mid) - sign * float(q[k]) / norm) < 1e-12 for k in range(4))
        assert post.quaternion[0].a >= 0


# ----- the oracle on published instances --------------------------------------------------------------
def _table_vi2():
    rows = []
    for line in (DATA / "seed002_table_vi2.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            v = [float(t) for t in line.split()[1:]]
            rows.append([v[3 * k:3 * k + 3] for k in range(6)])
    return rows


@needs_msolve
def test_seed002_robot_has_the_24_postures_of_table_vi2():
    """msolve finds 40 complex, 24 real postures, and they are the 24 rows of Table VI.2 (12 decimals)."""
    out = M.solve(SEED002, SEED002_LENGTHS)
    assert out.status == "finite" and out.complex_count == 40 and out.counts == [24, 24]
    table = _table_vi2()
    assert len(table) == 24
    used = set()
    for p in out.postures:
        pts = p.float_points()
        close = [k for k, row in enumerate(table)
                 if max(abs(a - b) for pa, pb in zip(pts, row) for a, b in zip(pa, pb)) < 2e-9]
        assert len(close) == 1
        used.add(close[0])
    assert len(used) == 24


@needs_msolve
def test_dietmaier_robot_has_40_real_postures():
    """Dietmaier (1998): all 40 complex postures real, for the published lengths and for its home pose's."""
    out = M.solve(DIETMAIER, DIETMAIER_LENGTHS)
    assert out.status == "finite" and out.complex_count == 40 and len(out) == 40
    robot = G.load_dict(DIETMAIER)
    lengths = G.leg_lengths(robot, G.home_pose(robot), 6)
    assert lengths == ["1", "0.645275", "1.086284", "1.503438", "1.281934", "0.771071"]
    again = M.solve(DIETMAIER, lengths)
    assert again.complex_count == 40 and len(again) == 40


@needs_msolve
def test_postures_satisfy_the_leg_equations_and_rigidity():
    """A random robot: each posture's platform points are at distance rho_i from A_i (to 1e-25) and
    congruent to the platform (pairwise distances); postures are distinct; the source pose is one."""
    inst = G.general_robot(7)
    out = M.solve(inst.robot, inst.lengths)
    assert out.status == "finite" and out.complex_count == 40 and len(out) >= 1 and len(out) % 2 == 0
    base, plat = M.robot_geometry(inst.robot)
    rho = M.parse_lengths(inst.lengths)
    with mp.workdps(60):
        for p in out.postures:
            pts = p.exact_points()
            for a, b, r in zip(base, pts, rho):
                d2 = sum((b[k] - _mpf(a[k])) ** 2 for k in range(3))
                assert abs(d2 - _mpf(r) ** 2) < mp.mpf(10) ** -25
            for i, j in itertools.combinations(range(6), 2):
                world = sum((pts[i][k] - pts[j][k]) ** 2 for k in range(3))
                body = sum((plat[i][k] - plat[j][k]) ** 2 for k in range(3))
                assert abs(world - _mpf(body)) < mp.mpf(10) ** -25
            assert all(c.delta < 1e-25 for c in p.unknowns)
    X = [p.floats() for p in out.postures]
    assert min(max(abs(a - b) for a, b in zip(u, v)) for u, v in itertools.combinations(X, 2)) > 1e-6
    R = G.rotation(*inst.pose[3:])
    src = [float(inst.pose[k]) + sum(float(R[k, j]) * float(plat[0][j]) for j in range(3)) for k in range(3)]
    assert min(max(abs(a - b) for a, b in zip(p.float_points()[0], src)) for p in out.postures) < 1e-4


def _rational_robot_with_posture(q, p, seed=3):
    """A robot whose leg lengths at the pose (p, q) are exact rationals: A_i = R b_i + p − ρ_i u_i with
    rational unit vectors u_i (Pythagorean quadruples)."""
    rng = random.Random(seed)
    units = [(Fraction(2, 3), Fraction(1, 3), Fraction(2, 3)), (Fraction(-2, 7), Fraction(3, 7), Fraction(6, 7)),
             (Fraction(1, 9), Fraction(-4, 9), Fraction(8, 9)), (Fraction(6, 11), Fraction(-6, 11), Fraction(7, 11)),
             (Fraction(-2, 3), Fraction(-2, 3), Fraction(1, 3)), (Fraction(4, 9), Fraction(4, 9), Fraction(7, 9))]
    plat = [tuple(Fraction(rng.randint(-150, 150), 100) for _ in range(3)) for _ in range(6)]
    rho = [Fraction(rng.randint(100, 300), 100) for _ in range(6)]
    base = []
    for b, r, u in zip(plat, rho, units):
        w = [c + pc for c, pc in zip(M.rotate(q, b), p)]
        base.append(tuple(wc - r * uc for wc, uc in zip(w, u)))
    robot = {"kind": "gough-stewart", "base": [[str(c) for c in a] for a in base],
             "platform": [[str(c) for c in b] for b in plat]}
    return robot, [str(r) for r in rho]


@needs_msolve
def test_a_posture_on_the_first_charts_plane_is_found_by_the_second():
    c1 = M.random_chart(random.Random(0))          # the first chart of solve(..., seed=0)
    q = (c1[1], -c1[0], c1[3], -c1[2])               # c1 · q = 0
    p = (Fraction(1, 5), Fraction(-3, 10), Fraction(3, 2))
    robot, lengths = _rational_robot_with_posture(q, p)
    one = M.solve(robot, lengths, charts=1)
    two = M.solve(robot, lengths, charts=2)
    assert two.counts[1] == one.counts[0] + 1 == len(two)
    target = [[float(c) for c in pt] for pt in M.platform_points(q, M.study_of_pose(p, q)[1], M.robot_geometry(robot)[1])]
    hits = [post for post in two.postures
            if max(abs(a - b) for pa, pb in zip(post.float_points(), target) for a, b in zip(pa, pb)) < 1e-12]
    assert len(hits) == 1
    assert not any(max(abs(a - b) for pa, pb in zip(post.float_points(), target) for a, b in zip(pa, pb)) < 1e-6
                   for post in one.postures)


@needs_msolve
def test_a_continuum_is_reported_not_dropped():
    """Collinear platform points: the platform turns freely about their line, a continuum of postures."""
    robot = {"kind": "gough-stewart",
             "base": [["0", "0", "0"], ["1", "0", "0"], ["0", "1", "0"], ["1", "1", "0.5"], ["-1", "0.5", "0.2"],
                      ["0.3", "-1", "0.1"]],
             "platform": [["0", "0", "0"], ["0.5", "0", "0"], ["1", "0", "0"], ["1.5", "0", "0"], ["-0.5", "0", "0"],
                          ["-1", "0", "0"]]}
    lengths = G.leg_lengths(robot, (0.2, 0.3, 1.1, 0.3, 0.4, 0.5), 6)
    out = M.solve(robot, lengths)
    assert out.status == "positive-dimensional" and out.postures is None and not out.finite
    with pytest.raises(M.OracleError, match="positive-dimensional"):
        M.compare({"complete": True, "solutions": [], "unresolved": []}, out)


# ----- certkin against the oracle ------------------------------------------------------------------------
# Every comparison re-checks certkin's certificate with ``proofs`` (a full-domain Gough-Stewart certificate
# of about 10^5 boxes: 6 CPU seconds for the checker, 2026-11-26); CERTKIN_ORACLE_CHECK_CERTIFICATES=0 skips it.
CHECK_CERTIFICATES = os.environ.get("CERTKIN_ORACLE_CHECK_CERTIFICATES", "1") != "0"
SMOKE = ("unit", 3)


def _source_points(robot: dict, pose):
    """World platform points of a pose (x, y, z, psi, theta, phi), mpmath (``robots.rotation``)."""
    R = G.rotation(*[mp.mpf(float(v)) for v in pose[3:]])
    return [[mp.mpf(float(pose[k])) + sum(R[k, j] * mp.mpf(str(b[j])) for j in range(3)) for k in range(3)]
            for b in robot["platform"]]


def _holds(entry, points, tol):
    return all(lo - tol <= float(v) <= hi + tol for box, pt in zip(entry["platform_points"], points)
               for (lo, hi), v in zip(box, pt))


def _certkin_vs_oracle(robot: dict, lengths, record=None, check_certificate=CHECK_CERTIFICATES, pose=None):
    """certkin FK with the default budget compared with msolve (and its certificate re-checked when
    ``check_certificate``).

    When msolve reports no finite list of postures (a positive-dimensional set over the complex
    numbers) the case is recorded (``oracle_status``) and certkin must not claim ``complete`` with a
    posture missing: if it does claim it, the posture the lengths come from (``pose``, lengths rounded,
    so within ``1e-4`` relative) lies in a ``unique`` box and the certificate is re-checked by ``proofs``."""
    oracle = M.solve(robot, lengths)
    record = record or (lambda *_: None)
    record("oracle_status", oracle.status)
    t = time.process_time()
    result = forward_kinematics(robot_from_dict(robot), lengths)
    seconds = time.process_time() - t
    doc = result.to_json()
    record("lengths", ",".join(str(v) for v in lengths) if not isinstance(lengths, str) else lengths)
    record("oracle_postures", len(oracle) if oracle.finite else None)
    record("certkin_solutions", len(result.solutions))
    record("certkin_unresolved", len(result.unresolved))
    record("certkin_complete", result.complete)
    record("certkin_boxes", doc["stats"]["boxes"])
    record("certkin_cpu_seconds", round(seconds, 2))
    record("msolve_seconds", round(oracle.seconds, 2))
    if not oracle.finite:
        if result.complete:
            assert pose is not None, f"msolve: {oracle.status}; certkin claims complete, no posture to test it"
            points = _source_points(robot, pose)
            size = max(1.0, max(abs(float(c)) for p in points for c in p))
            assert sum(_holds(s, points, 1e-4 * size) for s in doc["solutions"]) == 1
            report = proofs.check(result.certificate())
            assert report.ok, report.step
        return {"oracle": oracle.status, "solutions": len(result.solutions), "complete": result.complete}
    counts = M.compare(result, oracle)
    if check_certificate:
        t = time.process_time()
        report = proofs.check(result.certificate())
        record("check_cpu_seconds", round(time.process_time() - t, 2))
        assert report.ok, report.step
    return counts


@pytest.fixture(scope="module")
def smoke():
    """A random general robot that certkin solves with its default budget: (oracle, certkin result)."""
    inst = G.general_robot(SMOKE[1], SMOKE[0])
    return M.solve(inst.robot, inst.lengths), forward_kinematics(robot_from_dict(inst.robot), inst.lengths)


@needs_msolve
def test_certkin_agrees_with_msolve_on_a_random_robot(smoke):
    oracle, result = smoke
    counts = M.compare(result, oracle)
    assert counts["postures"] == counts["solutions"] == 6


@pytest.mark.slow
@needs_msolve
def test_certificate_of_the_compared_robot_rechecks(smoke):
    report = proofs.check(smoke[1].certificate())
    assert report.ok, report.step


@needs_msolve
def test_compare_rejects_a_missing_or_extra_posture(smoke):
    oracle, result = smoke
    doc = result.to_json()
    M.compare(doc, oracle)
    with pytest.raises(AssertionError, match="holds 0 oracle postures"):
        M.compare(doc, oracle.postures[1:])
    fewer = dict(doc, solutions=doc["solutions"][1:])
    with pytest.raises(AssertionError, match="inside 0"):
        M.compare(fewer, oracle)
    with pytest.raises(AssertionError, match="complete is false"):
        M.compare(dict(doc, complete=False), oracle)


GENERAL = [("seed002", s) for s in range(50)] + [("unit", s) for s in range(50)]


@pytest.mark.slow
@needs_msolve
@pytest.mark.parametrize("size,seed", GENERAL, ids=[f"{a}-{b}" for a, b in GENERAL])
def test_random_general_robot_against_msolve(size, seed, record_property):
    inst = G.general_robot(seed, size)
    _certkin_vs_oracle(inst.robot, inst.lengths, record_property, pose=inst.pose)


SYMMETRIC = [(s, "home") for s in range(20)] + [(s, "pose") for s in range(20)]


@pytest.mark.slow
@needs_msolve
@pytest.mark.parametrize("seed,where", SYMMETRIC, ids=[f"{a}-{b}" for a, b in SYMMETRIC])
def test_symmetric_hexapod_against_msolve(seed, where, record_property):
    inst = G.symmetric_at_home(seed) if where == "home" else G.symmetric_at_random_pose(seed)
    _certkin_vs_oracle(inst.robot, inst.lengths, record_property, pose=inst.pose)


BUNDLED = sorted(f.name for f in EXAMPLES.glob("*.toml") if 'kind = "gough-stewart"' in f.read_text())


@pytest.mark.slow
@needs_msolve
@pytest.mark.parametrize("name", BUNDLED)
def test_bundled_robot_at_home_against_msolve(name, record_property):
    """Every bundled Gough-Stewart robot with the leg lengths of its home pose (rounded to 9 decimals)."""
    robot = G.load_dict(EXAMPLES / name)
    home = G.home_pose(robot)
    _certkin_vs_oracle(robot, G.leg_lengths(robot, home, 9), record_property, pose=home)
