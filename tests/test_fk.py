"""Forward kinematics against exact algebra (sympy), seed 002 Table VI.2, tampering, the CLI.

The reference answers are derived here, independently of certkin's solver:
planar instances by eliminating x, y and reducing to one polynomial in
T = tan(phi/2) whose real roots sympy isolates exactly; spherical instances
by a lex Groebner basis; Gough postures from the seed's own table.
"""
import json
import math
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import mpmath as mp

import numpy as np
import pytest
import sympy as sp

import proofs
from certfile import Doc, checked
from certkin import robot_from_dict
from certkin.fk import forward_kinematics

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data"
EXAMPLES = ROOT / "examples" / "robots"


def planar(base, plat):
    return robot_from_dict({"kind": "planar-3rpr", "base": [[str(c) for c in p] for p in base],
                            "platform": [[str(c) for c in p] for p in plat]})


# ----- exact planar reference ------------------------------------------------------
def exact_planar(base, plat, lengths):
    """All real postures, as world platform points at 30 digits, by exact elimination.

    With c = (1 - T^2)/(1 + T^2), s = 2T/(1 + T^2), legs 2 - 1 and 3 - 1 are linear in
    (x, y); Cramer's rule and leg 1 give one polynomial in T.  phi = pi (T infinite)
    is checked on its own.  Roots where the Cramer determinant vanishes are not used
    (the tests below pick instances where it does not vanish at a root).
    """
    R = lambda v: sp.Rational(str(v))  # noqa: E731
    A = [[R(c) for c in p] for p in base]
    Bp = [[R(c) for c in p] for p in plat]
    rho2 = [R(v) ** 2 for v in lengths]
    x, y, T = sp.symbols("x y T")

    def legs(c, s):
        out = []
        for (ax, ay), (px, py), r2 in zip(A, Bp, rho2):
            out.append(sp.expand((x + c * px - s * py - ax) ** 2 + (y + s * px + c * py - ay) ** 2 - r2))
        return out

    def solve_at(c, s, denom=1):
        eqs = [sp.expand(e * denom) for e in legs(c, s)]
        lin = [sp.expand(eqs[i] - eqs[0]) for i in (1, 2)]
        M = sp.Matrix([[sp.diff(l, v) for v in (x, y)] for l in lin])
        rhs = sp.Matrix([-l.subs({x: 0, y: 0}) for l in lin])
        return eqs, M, rhs

    c, s = (1 - T ** 2) / (1 + T ** 2), 2 * T / (1 + T ** 2)
    eqs, M, rhs = solve_at(c, s, (1 + T ** 2))
    M, rhs = M.applyfunc(sp.cancel), rhs.applyfunc(sp.cancel)
    det = sp.cancel(M.det())
    xs = sp.cancel((rhs[0] * M[1, 1] - rhs[1] * M[0, 1]) / det)
    ys = sp.cancel((M[0, 0] * rhs[1] - M[1, 0] * rhs[0]) / det)
    leg1 = sp.together(legs(c, s)[0].subs({x: xs, y: ys}))
    poly = sp.Poly(sp.numer(leg1), T)
    roots = []
    mp.mp.dps = 30
    for root in sp.Poly(poly, T).real_roots():
        if sp.simplify(det.subs(T, root)) == 0:
            raise AssertionError("degenerate instance: pick another")
        t = mp.mpf(str(sp.N(root, 40)))
        cc, ss = (1 - t ** 2) / (1 + t ** 2), 2 * t / (1 + t ** 2)
        xv = mp.mpf(str(sp.N(xs.subs(T, root), 40)))
        yv = mp.mpf(str(sp.N(ys.subs(T, root), 40)))
        roots.append((xv, yv, cc, ss))
    roots = list({tuple(mp.nstr(v, 20) for v in r): r for r in roots}.values())  # double roots once
    # phi = pi
    eqs, M, rhs = solve_at(-1, 0)
    if M.det() != 0:
        sol = M.solve(rhs)
        if sp.simplify(eqs[0].subs({x: sol[0], y: sol[1]})) == 0:
            roots.append((mp.mpf(str(sp.N(sol[0], 40))), mp.mpf(str(sp.N(sol[1], 40))), mp.mpf(-1), mp.mpf(0)))
    points = []
    for xv, yv, cc, ss in roots:
        points.append([(xv + cc * mp.mpf(str(px)) - ss * mp.mpf(str(py)), yv + ss * mp.mpf(str(px)) + cc * mp.mpf(str(py)))
                       for px, py in plat])
    return points


def _contains(box_points, exact_points):
    return all(float(iv[0]) <= float(v) <= float(iv[1]) or mp.mpf(iv[0]) <= v <= mp.mpf(iv[1])
               for bp, ep in zip(box_points, exact_points) for iv, v in zip(bp, ep))


def _points(solution):
    return [[(float(c.lo), float(c.hi)) for c in p] for p in solution["platform_points"]]


def assert_matches_exact(result, exact):
    """Same count; each exact posture in exactly one solution box (platform points)."""
    assert result.complete
    assert len(result.solutions) == len(exact)
    for e in exact:
        hits = [s for s in result.solutions if _contains(_points(s), e)]
        assert len(hits) == 1


SIX_MODES = [  # designs and lengths whose 6 real modes the elimination below confirms
    ([(0, 0), (15.91, 0), (0, 10)], [(0, 0), (17.04, 0), (13.236, 16.097)], ["14.98", "15.38", "12"]),
    ([("3.78", "4.34"), ("34.47", "-3.78"), ("16.233", "34.76")],
     [("-4.83", "-3.19"), ("12.04", "-3.19"), ("8.23", "12.09")], ["28.99", "13.66", "40.53"]),
]


@pytest.mark.parametrize("base,plat,lengths", SIX_MODES)
def test_planar_six_modes_match_exact_elimination(base, plat, lengths):
    exact = exact_planar(base, plat, lengths)
    assert len(exact) == 6
    result = forward_kinematics(planar(base, plat), lengths)
    assert_matches_exact(result, exact)
    assert all(s["status"] == "unique" for s in result.to_json()["solutions"])
    checked(result)


def test_planar_random_instances_match_exact_elimination():
    rng = np.random.default_rng(7)
    for _ in range(4):
        base = rng.uniform(-10, 10, (3, 2)).round(2)
        plat = rng.uniform(-4, 4, (3, 2)).round(2)
        robot = planar(base, plat)
        pose = np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-np.pi, np.pi)])
        lengths = [f"{v:.4f}" for v in robot.leg_lengths_float(pose)]
        exact = exact_planar(base, plat, lengths)
        result = forward_kinematics(robot, lengths)
        assert_matches_exact(result, exact)
        checked(result)


def test_batch_of_instances_equals_one_at_a_time():
    base, plat, _ = SIX_MODES[1]
    robot = planar(base, plat)
    rng = np.random.default_rng(3)
    poses = np.stack([rng.uniform(5, 30, 12), rng.uniform(-10, 20, 12), rng.uniform(-np.pi, np.pi, 12)], 1)
    L = robot.leg_lengths_float(poses)
    batch = forward_kinematics(robot, L)
    assert isinstance(batch, list) and len(batch) == 12
    for row, res in zip(L, batch):
        one = forward_kinematics(robot, [repr(float(v)) for v in row])
        assert res.complete and one.complete and len(res.solutions) == len(one.solutions) >= 1
        for a, b in zip(sorted(_points(s)[0][0] for s in res.solutions), sorted(_points(s)[0][0] for s in one.solutions)):
            assert a[0] <= b[1] and b[0] <= a[1]
    from certkin.certificates import fk_certificate
    report = proofs.check(fk_certificate(batch[:3]))
    assert report.ok and report.checked["claims"] == 3


def test_round_trip_generating_pose_is_in_a_solution_box():
    base, plat, _ = SIX_MODES[0]
    robot = planar(base, plat)
    rng = np.random.default_rng(11)
    for _ in range(5):
        pose = np.array([rng.uniform(-8, 8), rng.uniform(-8, 8), rng.uniform(-np.pi, np.pi)])
        lengths = robot.leg_lengths_float(pose)   # floats: their exact binary values are the data
        result = forward_kinematics(robot, [repr(float(v)) for v in lengths])
        # the generating pose solves the rounded lengths to within ~1e-14: one box lies within 1e-9 of it
        gen = [(pose[0] + np.cos(pose[2]) * p[0] - np.sin(pose[2]) * p[1],
                pose[1] + np.sin(pose[2]) * p[0] + np.cos(pose[2]) * p[1]) for p in plat]
        near = [s for s in result.solutions
                if all(b[0] - 1e-9 <= g <= b[1] + 1e-9 for bp, gp in zip(_points(s), gen) for b, g in zip(bp, gp))]
        assert len(near) == 1 and result.complete


def test_unreachable_lengths_are_a_complete_empty_answer():
    base, plat, _ = SIX_MODES[1]
    robot = planar(base, plat)
    result = forward_kinematics(robot, "1,1,1")
    assert result.complete and result.solutions == [] and result.unresolved == []
    checked(result)


def test_near_singular_lengths_never_give_a_false_unique():
    """Lengths of a pose on the singularity locus: the exact roots (a double root split by the
    rounding of the lengths, or none) are each covered, and never more unique boxes than roots."""
    base, plat, _ = SIX_MODES[1]
    robot = planar(base, plat)
    # a pose with det(A) = 0: bisect along x at y = 10, phi = pi/4 (det(A) changes sign in [20, 26])
    f = lambda xx: robot.det_float(np.array([xx, 10.0, np.pi / 4]))  # noqa: E731
    a, b = 20.0, 26.0
    assert f(a) * f(b) < 0
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if f(a) * f(m) > 0 else (a, m)
    lengths = [f"{v:.12f}" for v in robot.leg_lengths_float(np.array([a, 10.0, np.pi / 4]))]
    exact = exact_planar(base, plat, lengths)
    result = forward_kinematics(robot, lengths)
    assert len(result.solutions) <= len(exact)
    for e in exact:
        assert any(_contains(_points(s), e) for s in result.solutions + result.unresolved)
    checked(result)


# ----- spherical ------------------------------------------------------------------------
def exact_spherical(a, b, lengths):
    """Real solutions (world platform points) by a lex Groebner basis: with b_iz = 0 the legs
    are linear in the first two columns q1, q2 of the rotation (seed 003 eq. 4.2)."""
    R = lambda v: sp.Rational(str(v))  # noqa: E731
    A = [sp.Matrix([R(c) for c in p]) for p in a]
    Bp = [[R(c) for c in p] for p in b]
    q = sp.symbols("a1 a2 a3 b1 b2 b3")
    q1, q2 = sp.Matrix(q[:3]), sp.Matrix(q[3:])
    lin = [bi[0] * Ai.dot(q1) + bi[1] * Ai.dot(q2) - (Ai.dot(Ai) + bi[0] ** 2 + bi[1] ** 2 - R(r) ** 2) / 2
           for Ai, bi, r in zip(A, Bp, lengths)]
    sol = sp.solve(lin, q[:3], dict=True)[0]   # the a_i are independent here: solve for q1
    quad = [sp.expand(e.subs(sol)) for e in (q1.dot(q1) - 1, q2.dot(q2) - 1, q1.dot(q2))]
    G = sp.groebner(quad, *q[3:], order="lex")
    # shape position: G = [b1 - g1(b3), b2 - g2(b3), p(b3)] (checked, not assumed)
    assert len(G.exprs) == 3
    back = []
    for e, v in zip(G.exprs[:2], q[3:5]):
        coeff = sp.Poly(e, v)
        assert coeff.degree() == 1 and coeff.LC().is_number
        back.append(sp.solve(e, v)[0])
    assert all(set(g.free_symbols) <= {q[5]} for g in back)
    out = []
    for root in sp.Poly(G.exprs[-1], q[5]).real_roots():
        r = root.evalf(60)
        full = {q[5]: r, q[3]: back[0].subs(q[5], r).evalf(60), q[4]: back[1].subs(q[5], r).evalf(60)}
        v1 = [sol[k].subs(full).evalf(40) for k in q[:3]]
        v2 = [full[k] for k in q[3:]]
        out.append([[mp.mpf(str(bi[0] * v1[k] + bi[1] * v2[k])) for k in range(3)] for bi in Bp])
    return out


def test_spherical_eight_modes_match_groebner_basis():
    a = [("1.6", "0", "-1.2"), ("-1.1", "1.2", "-1.2"), ("-0.9", "-1", "-1.2")]   # seed 003 Table 4.13
    b = [("1", "0", "0"), ("-0.6", "1", "0"), ("-0.2", "-0.5", "0")]
    lengths = ["2.277", "2.473", "1.902"]
    exact = exact_spherical(a, b, lengths)
    assert len(exact) == 8
    robot = robot_from_dict({"kind": "spherical-3dof", "base": [list(p) for p in a], "platform": [list(p) for p in b]})
    result = forward_kinematics(robot, lengths)
    assert_matches_exact(result, exact)
    checked(result)


# ----- Gough-Stewart: seed 002 Table VI.2 --------------------------------------------------
def table_vi2():
    rows = []
    for line in (DATA / "seed002_table_vi2.txt").read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        v = [Fraction(t) for t in line.split()[1:]]
        rows.append(np.array([[float(v[3 * k + j]) for j in range(3)] for k in range(6)]))
    return rows


def _pose_from_points(robot, P):
    """(x, y, z, psi, theta, phi) of the rigid motion taking the platform points to P (least squares)."""
    b = np.array([[float(Fraction(c)) for c in p] for p in robot.platform])
    bc, pc = b.mean(0), P.mean(0)
    U, _, Vt = np.linalg.svd((P - pc).T @ (b - bc))
    Rm = U @ np.diag([1, 1, np.linalg.det(U @ Vt)]) @ Vt
    C = pc - Rm @ bc
    theta = np.arccos(np.clip(Rm[2, 2], -1, 1))
    return [*C, np.arctan2(Rm[0, 2], -Rm[1, 2]), theta, np.arctan2(Rm[2, 0], Rm[2, 1])]


def test_gough_table_vi2_postures_are_each_proved_unique():
    """Seed 002: every posture of Table VI.2 is a solution proved unique in a box (tracking proofs);
    the table's 12-decimal platform points lie within 1e-11 of the certified ones."""
    from certkin import load_robot
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    lengths = "1.093,2.280,2.031,2.524,3.136,1.845"   # the corrected lengths (digest seed 002)
    seen = []
    for P in table_vi2():
        pose = ",".join(repr(float(v)) for v in _pose_from_points(robot, P))
        r = forward_kinematics(robot, lengths, track=pose)
        assert r.tracked and len(r.solutions) == 1
        pts = _points(r.solutions[0])
        assert all(b[0] - 1e-11 <= v <= b[1] + 1e-11 for bp, vp in zip(pts, P) for b, v in zip(bp, vp))
        checked(r)
        seen.append(pts)
    for i in range(len(seen)):          # 24 distinct postures
        for j in range(i):
            assert any(a[1] < b[0] or b[1] < a[0] for pa, pb in zip(seen[i], seen[j]) for a, b in zip(pa, pb))


# ----- certificates ------------------------------------------------------------------------
@pytest.fixture(scope="module")
def planar_certificate():
    base, plat, lengths = SIX_MODES[0]
    result = forward_kinematics(planar(base, plat), lengths)
    cert = Doc(result.certificate())
    assert cert.check().ok
    return cert


def test_tampered_fk_certificates_are_rejected(planar_certificate):
    cert = planar_certificate

    dropped = cert.copy()                        # a solution left out of the list
    dropped.claim()["solutions"].pop()
    assert "solutions: must list" in dropped.check().step

    region = cert.copy()                         # a region moved away from its root
    region.arrays["fk.region.box"][0] += 1.0
    assert "claims[0].regions[0]" in region.check().step

    duplicated = cert.copy()
    duplicated.arrays["fk.region.box"][1] = duplicated.arrays["fk.region.box"][0]
    duplicated.arrays["fk.region.box_C"][1] = duplicated.arrays["fk.region.box_C"][0]
    assert "not proved distinct" in duplicated.check().step

    length = cert.copy()
    length.claim()["lengths"][0] = "14.99"
    assert not length.check().ok

    undecided = cert.copy()
    undecided.arrays["tree.code"][undecided.nodes(3, 1)[0]] = 10       # an hc4-empty leaf called undecided
    assert "undecided leaf in a claim that says complete" in undecided.check().step

    shrunk = cert.copy()
    shrunk.claim()["domain"][0][1] -= 5.0
    assert not shrunk.check().ok

    wrong_solution = cert.copy()
    leaf = wrong_solution.nodes(3, 6)[0]
    row = wrong_solution.row("tree.index", leaf)
    wrong_solution.arrays["tree.index"][row] = (wrong_solution.arrays["tree.index"][row] + 1) % 6
    assert "root box is not inside X*" in wrong_solution.check().step

    contraction = cert.copy()                    # a contracted box that claims more of its parent is empty
    node = contraction.nodes(2, [3 + 64, 0])[0]
    contraction.arrays["tree.box"][contraction.row("tree.box", node), :, 1] ^= np.uint64(1 << 51)
    assert not contraction.check().ok

    figures = cert.copy()
    figures.claim()["figures"]["solutions"] = 7
    assert "claims[0].figures: stated" in figures.check().step


# ----- slopes --------------------------------------------------------------------------------
SPHERICAL_8 = {"kind": "spherical-3dof", "base": [["1.6", "0", "-1.2"], ["-1.1", "1.2", "-1.2"], ["-0.9", "-1", "-1.2"]],
               "platform": [["1", "0", "0"], ["-0.6", "1", "0"], ["-0.2", "-0.5", "0"]]}


def _exact_rotation(q0, q1, q2, q3):
    """R(q) of the FK formulation (robots/fk_systems.py), in the arithmetic of its arguments."""
    return [[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
            [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
            [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]]


def _exact_f(robot, n_pos, x, L):
    """The FK equations at the point x in exact rational arithmetic (Fractions), from the robot's texts."""
    geom = [Fraction(t) for t in robot.geometry_texts()]
    legs, dim = robot.n_legs, robot.dim
    a = [geom[i * dim:(i + 1) * dim] for i in range(legs)]
    b = [geom[legs * dim + i * dim: legs * dim + (i + 1) * dim] for i in range(legs)]
    if dim == 2:
        c, s = x[2], x[3]
        R = [[c, -s], [s, c]]
    else:
        R = _exact_rotation(*x[n_pos:])
    out = []
    for i in range(legs):
        ell = [(x[k] if k < n_pos else 0) + sum(R[k][j] * b[i][j] for j in range(dim)) - a[i][k] for k in range(dim)]
        out.append(sum(e * e for e in ell) - L[i])
    out.append(sum(v * v for v in x[n_pos:]) - 1)
    return out


def _frac(v):
    """The exact value of a float or an mpmath mpf."""
    if isinstance(v, mp.mpf):
        sign, man, exp, _ = v._mpf_
        return (-1) ** sign * Fraction(man) * Fraction(2) ** exp
    return Fraction(float(v))


def _in_product(S_lo, S_hi, d, value):
    """value in sum_j [S_lo_j, S_hi_j] d_j, in exact rational arithmetic."""
    lo = sum(min(_frac(l) * dj, _frac(h) * dj) for l, h, dj in zip(S_lo, S_hi, d))
    hi = sum(max(_frac(l) * dj, _frac(h) * dj) for l, h, dj in zip(S_lo, S_hi, d))
    return lo <= value <= hi


def test_slope_matrices_enclose_exact_differences():
    """f(x) − f(c) ∈ S(X, c)(x − c) for random boxes X, points x in X and c the midpoint, with f(x) − f(c)
    computed exactly (Fractions): the solver's FKSystem.slope and the checker's System.slope; the stacked
    twin gives the same enclosures; the slope is about half as wide as the Jacobian over X."""
    from certkin import load_robot
    from certkin.fk.stacked import StackedFKSystem
    from certkin.fk.system import FKSystem
    from intervals import Interval
    from proofs.arith import Iv
    from proofs.fk_system import System
    robots = [(planar(*SIX_MODES[0][:2]), ["14.98", "15.38", "12"]),
              (robot_from_dict(SPHERICAL_8), ["2.277", "2.473", "1.902"]),
              (load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml"), "1.093,2.280,2.031,2.524,3.136,1.845".split(","))]
    rng = np.random.default_rng(11)
    for robot, lengths in robots:
        s = FKSystem(robot)
        checker = System(f"{robot.kind}-fk/1", robot.to_dict())
        L = [Fraction(t) ** 2 for t in lengths]
        N = 12
        c = rng.uniform(-1, 1, (N, s.n))
        w = rng.uniform(0.01, 0.2, (N, s.n))
        X = Interval.from_bounds(c - w, c + w)
        m = X.mid()
        S = s.slope(X, m)
        T = StackedFKSystem.of(s).slope(X, m)
        assert np.array_equal(S.lo, T.lo) and np.array_equal(S.hi, T.hi)
        J = s.jacobian(X)
        rows = slice(0, s.legs)
        assert np.median((S.hi - S.lo)[:, rows] / (J.hi - J.lo)[:, rows]) < 0.6
        Sc = checker.slope([Iv(X.lo[:, j], X.hi[:, j]) for j in range(s.n)], m)
        for k in range(N):
            fc = _exact_f(robot, s.n_pos, [Fraction(float(v)) for v in m[k]], L)
            for _ in range(3):
                x = [Fraction(float(v)) for v in X.lo[k] + rng.random(s.n) * (X.hi[k] - X.lo[k])]
                fx = _exact_f(robot, s.n_pos, x, L)
                d = [xj - Fraction(float(mj)) for xj, mj in zip(x, m[k])]
                for i in range(s.n):
                    assert _in_product(S.lo[k, i], S.hi[k, i], d, fx[i] - fc[i])
                    assert _in_product(Sc.lo[k, i], Sc.hi[k, i], d, fx[i] - fc[i])


def test_rotated_derivatives_enclose_sympy_derivatives():
    """∂(R b_i)/∂q_r over random quaternion boxes (the midpoint-radius enclosure of FKSystem) holds the
    derivatives of R(q) b_i differentiated by sympy, evaluated exactly at random points of the boxes."""
    from certkin import load_robot
    from certkin.fk.system import FKSystem
    from intervals import Interval
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    s = FKSystem(robot)
    q = sp.symbols("q0:4")
    R = sp.Matrix([[1 - 2 * (q[2] ** 2 + q[3] ** 2), 2 * (q[1] * q[2] - q[0] * q[3]), 2 * (q[1] * q[3] + q[0] * q[2])],
                   [2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[1] ** 2 + q[3] ** 2), 2 * (q[2] * q[3] - q[0] * q[1])],
                   [2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2)]])
    b = [sp.Matrix([sp.Rational(t) for t in p]) for p in robot.to_dict()["platform"]]
    grads = [[[sp.diff((R * bi)[k], q[r]) for k in range(3)] for bi in b] for r in range(4)]
    rng = np.random.default_rng(3)
    N = 6
    c = rng.uniform(-1, 1, (N, 7))
    w = rng.uniform(0.001, 0.3, (N, 7))
    X = Interval.from_bounds(c - w, c + w)
    D = s._rotated_derivatives(X)
    for n in range(N):
        for _ in range(2):
            point = X.lo[n, 3:] + rng.random(4) * (X.hi[n, 3:] - X.lo[n, 3:])
            sub = {q[k]: sp.Rational(Fraction(float(point[k]))) for k in range(4)}
            for r in range(4):
                for i in range(6):
                    for k in range(3):
                        v = Fraction(str(grads[r][i][k].subs(sub)))
                        assert Fraction(D[r].lo[n, i, k]) <= v <= Fraction(D[r].hi[n, i, k])


def test_rotated_midrad_encloses_exact_products():
    """R b_i in midpoint-radius form (quaternion kinds, ``FKSystem.rotated_midrad``): for random interval
    matrices R it holds every exact Σ_j R_kj b_ij (Fractions, b_ij the exact decimals) at random points
    of R, is at most a few ulps wider than the interval products, and its per-column terms bound the
    sums that leave one column out (HC4 step 6)."""
    from certkin import load_robot
    from certkin.fk.rotation import from_midrad as _from_midrad
    from certkin.fk.system import FKSystem
    from intervals import Interval
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    s = FKSystem(robot)
    b = [[Fraction(t) for t in p] for p in robot.to_dict()["platform"]]
    rng = np.random.default_rng(11)
    N = 12
    c = rng.uniform(-1, 1, (N, 3, 3))
    w = rng.uniform(0, 0.1, (N, 3, 3)) * (rng.random((N, 1, 1)) < 0.8)
    R = Interval.from_bounds(c - w, c + w)
    U = s.rotated(R)
    m, r, P, Q = s.rotated_midrad(R, columns=True)
    natural = sum((R[:, None, :, j] * s.b[None, :, j, None] for j in range(1, 3)), R[:, None, :, 0] * s.b[None, :, 0, None])
    assert np.all(U.hi - U.lo <= (natural.hi - natural.lo) * (1 + 1e-12) + 1e-14)
    for n in range(N):
        for _ in range(3):
            t = rng.random((3, 3))
            Rx = [[Fraction(float(R.lo[n, k, j])) + Fraction(t[k, j]) * (Fraction(float(R.hi[n, k, j])) - Fraction(float(R.lo[n, k, j])))
                   for j in range(3)] for k in range(3)]
            for i in range(6):
                for k in range(3):
                    v = sum(Rx[k][j] * b[i][j] for j in range(3))
                    assert Fraction(U.lo[n, i, k]) <= v <= Fraction(U.hi[n, i, k])
                    for j in range(3):
                        rest = _from_midrad(P[n, i, k, j], Q[n, i, k, j])
                        v = sum(Rx[k][jj] * b[i][jj] for jj in range(3) if jj != j)
                        assert Fraction(float(rest.lo)) <= v <= Fraction(float(rest.hi))


def quaternion_cases():
    """The quaternion robots the machine-code kernels are compared on: the spherical 8-mode robot
    and seed 002's 24-solution Gough-Stewart robot, each with its leg lengths."""
    from certkin import load_robot
    return [(robot_from_dict(SPHERICAL_8), ["2.277", "2.473", "1.902"]),
            (load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml"), "1.093,2.280,2.031,2.524,3.136,1.845".split(","))]


def root_boxes(robot, lengths, count, rng):
    """(lo, hi), (count, n) each: boxes proved to hold one root each, drawn at random among the
    solutions of ``forward_kinematics(robot, lengths)``."""
    roots = [r["box"] for r in forward_kinematics(robot, lengths).solutions]
    pick = rng.integers(0, len(roots), count)
    return np.array([r.lo for r in roots])[pick], np.array([r.hi for r in roots])[pick]


def test_native_slope_step_gives_the_numpy_slope():
    """``slope_boxes`` for a quaternion (machine-code slope, equations at c and float inverse) gives the
    slope matrices and f(c) of ``FKSystem.slope`` / ``FKSystem.equations`` bit for bit, a C close to
    the inverse of mid S, and a Hansen-Sengupta box that keeps the root of every box around one."""
    from certkin.fk.step import slope_boxes
    from certkin.fk.centred import slope_quaternion
    from certkin.fk.system import FKSystem
    from intervals import Interval, sqr
    for robot, lengths in quaternion_cases():
        s = FKSystem(robot)
        rng = np.random.default_rng(17)
        N = 400
        rlo, rhi = root_boxes(robot, lengths, N, rng)
        w = rng.uniform(0, 1, (N, s.n)) * 10.0 ** rng.uniform(-6, -1.5, (N, 1))
        X = Interval.from_bounds(rlo - w * rng.uniform(0.1, 1, (N, s.n)), rhi + w * rng.uniform(0.1, 1, (N, s.n)))
        rho = [Interval(v) for v in lengths]
        L = sqr(Interval.from_bounds(np.tile([float(r.lo) for r in rho], (N, 1)), np.tile([float(r.hi) for r in rho], (N, 1))))
        c = X.mid()
        rb, rbc, drbs = s.rotated_centred(X, parts=True)
        H, C, S, empty = slope_boxes(s, X, L, rb=rb, rbc=rbc, drbs=drbs)
        ref = s.slope(X, c, rb=rb, rbc=rbc, drbs=drbs)
        assert np.array_equal(S.lo, ref.lo) and np.array_equal(S.hi, ref.hi)
        f = slope_quaternion(X.lo, X.hi, c, rb.lo, rb.hi, rbc.lo, rbc.hi, *drbs, s.a.lo, s.a.hi, L.lo, L.hi, s.n_pos)[2:]
        fref = s.equations(Interval.from_bounds(c, c.copy()), L, rb=rbc)
        assert np.array_equal(f[0], fref.lo) and np.array_equal(f[1], fref.hi)
        assert np.max(np.abs(C @ S.mid() - np.eye(s.n))) < 1e-6
        assert not empty.any()
        assert np.all((H.lo <= rhi) & (rlo <= H.hi))
        assert np.all((H.lo >= X.lo) & (H.hi <= X.hi)) and np.any((H.lo > X.lo) | (H.hi < X.hi))


def test_native_position_step_matches_numpy():
    """The spatial position step in machine code (``fk_native.position_gauss_seidel``) and the numpy
    sweep, on boxes around every Gough root with a tight rotation and a wide position, and on boxes
    all over the domain: the same empty boxes, P to one float32 ulp, positions equal to a few ulps of
    the box;
    every root is kept, and most of the boxes around roots are contracted."""
    from certkin import load_robot
    from certkin.fk import fk_system
    from certkin.fk.step import _position_gauss_seidel, contract_position
    from intervals import Interval, sqr
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    lengths = "1.093,2.280,2.031,2.524,3.136,1.845".split(",")
    s = fk_system(robot)
    rng = np.random.default_rng(19)
    N = 2000
    rlo, rhi = root_boxes(robot, lengths, N, rng)
    w = rng.uniform(0, 1, (N, 7)) * 10.0 ** rng.uniform(-7, -2, (N, 1))
    w[:, :3] = rng.uniform(0.01, 0.5, (N, 3))
    rho = [Interval(v) for v in lengths]
    Lrow = sqr(Interval.from_bounds(np.array([[float(r.lo) for r in rho]]), np.array([[float(r.hi) for r in rho]])))
    dlo, dhi = (np.atleast_2d(v)[0] for v in s.domain(Lrow))
    far_c = rng.uniform(dlo, dhi, (N, 7))
    far_w = rng.uniform(0, 1, (N, 7)) ** 2 * (dhi - dlo) * 0.1
    X = Interval.from_bounds(np.concatenate([rlo - w * rng.uniform(0.1, 1, (N, 7)), far_c - far_w]),
                      np.concatenate([rhi + w * rng.uniform(0.1, 1, (N, 7)), far_c + far_w]))
    L = Interval.from_bounds(np.repeat(Lrow.lo, 2 * N, 0), np.repeat(Lrow.hi, 2 * N, 0))
    rb = s.rotated_centred(X)
    lo, hi, empty, P = contract_position(s, X, L, rb=rb)
    new, ref_empty, ref_P = _position_gauss_seidel(s, X, L, rb)
    assert np.array_equal(empty, ref_empty) and 0 < empty.sum() and not empty[:N].any()
    assert np.all(np.abs(P - ref_P) <= 2.0 ** -22 * np.abs(ref_P))     # float32 values: at most one ulp apart
    live = ~empty
    width = X.hi[:, :3] - X.lo[:, :3]
    ref_lo = np.maximum(X.lo[:, :3], new.lo - width * 2.0 ** -20)
    ref_hi = np.minimum(X.hi[:, :3], new.hi + width * 2.0 ** -20)
    assert np.all(np.abs(lo[live, :3] - ref_lo[live]) <= 1e-9 * width[live])
    assert np.all(np.abs(hi[live, :3] - ref_hi[live]) <= 1e-9 * width[live])
    assert np.array_equal(lo[:, 3:], X.lo[:, 3:]) and np.array_equal(hi[:, 3:], X.hi[:, 3:])
    assert np.all((lo[:N] <= rhi) & (rlo <= hi[:N]))
    assert np.mean(np.any(lo[:N, :3] > X.lo[:N, :3], axis=1)) > 0.5


def test_rotation_at_points_encloses_exact_values():
    """R(q) at float quaternions, computed in floats with an error bound (``rotation_at_points``),
    holds the exact matrix (rational arithmetic), for ordinary, tiny (underflowing products) and
    non-unit points; the bound stays within a few ulps."""
    from certkin import load_robot
    from certkin.fk.system import FKSystem
    s = FKSystem(load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml"))
    rng = np.random.default_rng(5)
    c = rng.uniform(-1.2, 1.2, (60, 7))
    c[:6, 3:] *= 1e-160                      # squares and products underflow
    c[6:12, 3:] = rng.choice([0.0, 1.0, -1.0, 0.5], (6, 4))
    Rm, Rr = s.rotation_at_points(c)
    assert np.all(Rr <= 1e-15 * (1.0 + 2.0 * np.sum(c[:, 3:] ** 2, axis=1))[:, None, None] + 1e-300)
    for n in range(len(c)):
        R = _exact_rotation(*(Fraction(float(v)) for v in c[n, 3:]))
        for k in range(3):
            for j in range(3):
                assert abs(R[k][j] - Fraction(float(Rm[n, k, j]))) <= Fraction(float(Rr[n, k, j]))


def test_centred_rotated_points_enclose_exact_values():
    """R b_i over random quaternion boxes, natural ∩ centred (solver FKSystem.rotated_centred, checker
    System.rotated_box): holds the exact R(q) b_i (Fractions) at random points; it is narrower than the
    natural enclosure on small boxes."""
    from certkin import load_robot
    from certkin.fk.system import FKSystem
    from intervals import Interval
    from proofs.arith import Iv
    from proofs.fk_system import System
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    s = FKSystem(robot)
    checker = System("gough-stewart-fk/1", robot.to_dict())
    b = [[Fraction(t) for t in p] for p in robot.to_dict()["platform"]]
    rng = np.random.default_rng(7)
    N = 8
    c = rng.uniform(-1, 1, (N, 7))
    w = rng.uniform(0.001, 0.05, (N, 7))
    X = Interval.from_bounds(c - w, c + w)
    T = s.rotated_centred(X)
    natural = s.rotated_box(X)      # the natural enclosure T is met with (the machine-code one)
    assert np.all(T.lo >= natural.lo) and np.all(T.hi <= natural.hi)
    legs = slice(2, 5)   # the platform points with several nonzero coordinates (the others: exact anyway)
    assert np.median((T.hi - T.lo)[:, legs] / (natural.hi - natural.lo)[:, legs]) < 0.9
    U = checker.rotated([Iv(X.lo[:, j], X.hi[:, j]) for j in range(7)])     # [k]: (N, legs)
    for n in range(N):
        for _ in range(3):
            R = _exact_rotation(*(Fraction(float(v)) for v in X.lo[n, 3:] + rng.random(4) * (X.hi[n, 3:] - X.lo[n, 3:])))
            for i in range(6):
                for k in range(3):
                    v = sum(R[k][j] * b[i][j] for j in range(3))
                    assert Fraction(T.lo[n, i, k]) <= v <= Fraction(T.hi[n, i, k])
                    assert Fraction(U[k].lo[n, i]) <= v <= Fraction(U[k].hi[n, i])
    # the parts reused by the slope step: R b_i at the midpoints, derivatives over Y (as ``slope`` computes them,
    # bit for bit with the numpy centred form; the machine-code one, behind T, sums in another order)
    T2, rbc, drbs = s.rotated_centred(X, parts=True, form=s.centred_form(X, native=False))
    m = X.mid()
    S, S2 = s.slope(X, m, rb=T2), s.slope(X, m, rb=T2, rbc=rbc, drbs=drbs)
    assert np.array_equal(S.lo, S2.lo) and np.array_equal(S.hi, S2.hi)
    assert np.all(np.abs(T2.lo - T.lo) <= 2.0 ** -48 * (1 + np.abs(T.lo)))
    # an empty batch (every box of a batch emptied by HC4) has empty enclosures
    E = s.rotated_centred(Interval.from_bounds(np.zeros((0, 7)), np.zeros((0, 7))))
    assert E.shape == (0, 6, 3)


def test_native_rotated_points_enclose_exact_values_and_match_numpy():
    """R b_i over quaternion boxes by the machine-code kernel (``FKSystem.rotated_box``) and by numpy
    (``rotated(rotation(X))``): the same bounds to a few ulps (only the float sums of the midpoint-radius
    products are taken in another order), the same infinite entries; the kernel's holds the exact
    R(q) b_i (Fractions) at random points, ordinary and tiny; ∩ a form it is ``np.fmax``/``np.fmin``."""
    from certkin import load_robot
    from certkin.fk.system import FKSystem
    from intervals import Interval
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    s = FKSystem(robot)
    b = [[Fraction(t) for t in p] for p in robot.to_dict()["platform"]]
    rng = np.random.default_rng(23)
    N = 3000
    c = rng.uniform(-1.2, 1.2, (N, 7))
    w = rng.uniform(0, 1, (N, 7)) * 10.0 ** rng.uniform(-12, 0, (N, 1))
    c[:20, 3:] *= 1e-160                     # products underflow
    lo, hi = c - w, c + w
    lo[20:25, 4], hi[25:30, 6] = -np.inf, np.inf
    X = Interval.from_bounds(lo, hi)
    fast, ref = s.rotated_box(X), s.rotated(s.rotation(X))
    for a, r in ((fast.lo, ref.lo), (fast.hi, ref.hi)):
        assert np.array_equal(np.isfinite(a), np.isfinite(r))
        ok = np.isfinite(r)
        assert np.all(np.abs(a[ok] - r[ok]) <= 2.0 ** -48 * (1.0 + np.abs(r[ok])))
    for n in list(range(0, 20, 5)) + list(range(40, N, 150)):
        for _ in range(2):
            q = [Fraction(float(v)) for v in X.lo[n, 3:] + rng.random(4) * (X.hi[n, 3:] - X.lo[n, 3:])]
            R = _exact_rotation(*q)
            for i in range(6):
                for k in range(3):
                    v = sum(R[k][j] * b[i][j] for j in range(3))
                    assert Fraction(fast.lo[n, i, k]) <= v <= Fraction(fast.hi[n, i, k])
    flo, fhi = s.centred_form(X)[:2]
    met = s.rotated_box(X, form=(flo, fhi))
    with np.errstate(invalid="ignore"):
        assert np.array_equal(met.lo, np.fmax(fast.lo, flo)) and np.array_equal(met.hi, np.fmin(fast.hi, fhi))
    E = s.rotated_box(Interval.from_bounds(np.zeros((0, 7)), np.zeros((0, 7))))
    assert E.shape == (0, 6, 3)


def test_native_equations_give_the_numpy_floats():
    """The machine-code enclosure of the equations over boxes (``kernels.equations_quaternion``, the
    search's exclusion test) and ``FKSystem.equations`` / its stacked twin with the same R b_i: the same
    floats, bit for bit, on boxes around roots and all over the domain (Gough and spherical robots);
    a row with a non-finite input is the entire line."""
    from certkin.fk.centred import equations_quaternion
    from certkin.fk.stacked import StackedFKSystem
    from certkin.fk.system import FKSystem
    from intervals import Interval, sqr
    for robot, lengths in quaternion_cases():
        s = FKSystem(robot)
        rng = np.random.default_rng(31)
        N = 1500
        rlo, rhi = root_boxes(robot, lengths, N, rng)
        w = rng.uniform(0, 1, (N, s.n)) * 10.0 ** rng.uniform(-8, 0, (N, 1))
        lo, hi = rlo - w * rng.uniform(0, 1, (N, s.n)), rhi + w * rng.uniform(0, 1, (N, s.n))
        lo[-5:, 0] = -np.inf
        X = Interval.from_bounds(lo, hi)
        rho = [Interval(v) for v in lengths]
        L = sqr(Interval.from_bounds(np.tile([float(r.lo) for r in rho], (N, 1)), np.tile([float(r.hi) for r in rho], (N, 1))))
        rb = s.rotated_box(X)
        flo, fhi = equations_quaternion(lo, hi, rb.lo, rb.hi, s.a.lo, s.a.hi, L.lo, L.hi, s.n_pos)
        assert np.all(np.isneginf(flo[-5:])) and np.all(np.isposinf(fhi[-5:]))
        for sys_ in (s, StackedFKSystem.of(s)):
            F = sys_.equations(Interval.from_bounds(lo[:-5], hi[:-5]), L[:-5], rb=rb[:-5])
            assert np.array_equal(flo[:-5], F.lo) and np.array_equal(fhi[:-5], F.hi)
        assert not np.any((flo[:N // 2] > 0) | (fhi[:N // 2] < 0))      # the roots are kept


def test_tampered_slope_evidence_is_rejected():
    """The spherical 8-mode search excludes and contracts boxes by the Hansen-Sengupta step with slope
    matrices (``slope-gs-empty``, ``slope-gs``); the checker rebuilds their C (codes + 64) and accepts
    each step, and rejects it when a zero matrix is stored in its place or the contracted box is changed.
    The Krawczyk form of the slope step (``slope-empty``) is checked too."""
    lengths = ["2.277", "2.473", "1.902"]
    cert = Doc(forward_kinematics(robot_from_dict(SPHERICAL_8), lengths).certificate())
    assert cert.check().ok
    zero = np.zeros((1, 4, 4), np.float32)

    def stored(doc, node, code, C):                       # the rule with its C stored instead of rebuilt
        doc.arrays["tree.code"][node] = code
        doc.arrays["tree.C"] = np.insert(doc.arrays["tree.C"], doc.row("tree.C", node), C, axis=0)
        return doc

    leaf = cert.nodes(3, 5 + 64)[0]
    bad = stored(cert.copy(), leaf, 5, zero)
    assert "slope Gauss-Seidel sweep does not empty the box" in bad.check().step
    node = cert.nodes(2, 5 + 64)[0]
    bad = stored(cert.copy(), node, 5, zero)
    assert "slope-gs" in bad.check().step and "not inside the child box" in bad.check().step
    bad = cert.copy()                                     # a contracted box changed
    bad.arrays["tree.box"][bad.row("tree.box", node), :, 1] ^= np.uint64(1 << 50)
    assert not bad.check().ok
    assert "the image meets the box" in stored(cert.copy(), leaf, 4, zero).check().step      # the slope K form


@pytest.mark.slow
def test_gough_certificate_with_slope_steps_rechecks():
    """Seed 002 robot, position narrowed around one posture (the whole rotation range searched): the
    certificate, with its slope exclusions and contractions, re-checks (about 80 s in the checker)."""
    from certkin import load_robot
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    r = forward_kinematics(robot, "1.093,2.280,2.031,2.524,3.136,1.845",
                           domain="x=-0.9:-0.8,y=-0.4:-0.3,z=0.5:0.6,psi=-4:4,theta=-4:4,phi=-4:4")
    assert r.complete and len(r.solutions) == 1
    cert = r.certificate()
    assert len(Doc(cert).nodes(2, 5 + 64))
    checked(r)


# ----- the command line -----------------------------------------------------------------------
def _cli(*args):
    return subprocess.run([sys.executable, "-m", "certkin.cli", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def test_cli_fk_json_certificate_and_errors(tmp_path):
    robot = EXAMPLES / "seed003-planar-example-2.toml"
    cert = tmp_path / "fk.cert.json"
    r = _cli("fk", robot, "--lengths", "28.99,13.66,40.53", "--json", "--certificate", cert)
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)
    assert doc["problem"] == "forward-kinematics" and doc["complete"] is True and len(doc["solutions"]) == 6
    s = doc["solutions"][0]
    assert s["status"] == "unique" and set(s["pose"]) == {"x", "y", "phi"} and len(s["platform_points"]) == 3
    assert set(doc["stats"]) >= {"boxes", "seconds"} and doc["unresolved"] == []
    assert _cli("check", cert).returncode == 0
    for bad, field in (("28.99,abc,40.53", "--lengths: leg 2"), ("1,2", "--lengths"), ("1,-2,3", "--lengths: leg 2")):
        r = _cli("fk", robot, "--lengths", bad)
        assert r.returncode == 2 and r.stderr.count("\n") == 1 and field in r.stderr and "Traceback" not in r.stderr
    r = _cli("fk", tmp_path / "missing.toml", "--lengths", "1,2,3")
    assert r.returncode == 2 and "missing.toml" in r.stderr


# ----- tracking ----------------------------------------------------------------------------------
def _unknowns(robot, pose):
    from certkin.fk.system import FKSystem
    return FKSystem(robot).unknowns_of_pose(np.asarray(pose, dtype=float))


def _planar_motion(steps, amplitude=(0.5, 0.3, 0.05)):
    """The SIX_MODES[0] robot and poses along a smooth closed motion from one of its modes."""
    base, plat, lengths = SIX_MODES[0]
    robot = planar(base, plat)
    mode = forward_kinematics(robot, lengths).solutions[0]
    home = np.array([0.5 * (float(v.lo) + float(v.hi)) for v in mode["pose"].values()])
    t = np.linspace(0.0, 1.0, steps + 1)[:, None]
    poses = home + np.asarray(amplitude) * np.hstack([np.sin(2 * np.pi * t), 1 - np.cos(2 * np.pi * t),
                                                      np.sin(2 * np.pi * t)])
    return robot, plat, poses


def _pose_text(pose):
    return ",".join(repr(float(v)) for v in pose)


def _generating_pose_in_box(robot, plat, result, pose, tol=1e-9):
    """The pose that generated the lengths (IK) lies in the solution box: its unknowns (up to the
    rounding of the float lengths, tol) and, planar, its world platform points."""
    s = result.solutions[0]
    x = _unknowns(robot, pose)
    if robot.kind != "planar-3rpr" and np.dot(x[3:], 0.5 * (s["box"].lo + s["box"].hi)[3:]) < 0:
        x[3:] = -x[3:]   # q and -q: the same rotation
    assert np.all(s["box"].lo - tol <= x) and np.all(x <= s["box"].hi + tol)
    if robot.kind == "planar-3rpr":
        c, sn = np.cos(pose[2]), np.sin(pose[2])
        gen = [(pose[0] + c * p[0] - sn * p[1], pose[1] + sn * p[0] + c * p[1]) for p in plat]
        assert all(b[0] - tol <= g <= b[1] + tol for bp, gp in zip(_points(s), gen) for b, g in zip(bp, gp))


def test_stacked_fk_system_gives_the_same_enclosures():
    """StackedFKSystem performs FKSystem's interval operations stacked: bit-identical enclosures;
    the float evaluation (Newton guesses) agrees with the interval one at points."""
    from certkin import load_robot
    from certkin.fk.stacked import StackedFKSystem
    from certkin.fk.system import FKSystem
    from intervals import Interval
    robots = [planar(*SIX_MODES[0][:2]),
              robot_from_dict({"kind": "spherical-3dof", "base": [["1.6", "0", "-1.2"], ["-1.1", "1.2", "-1.2"],
                                                                   ["-0.9", "-1", "-1.2"]],
                               "platform": [["1", "0", "0"], ["-0.6", "1", "0"], ["-0.2", "-0.5", "0"]]}),
              load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")]
    rng = np.random.default_rng(5)
    for robot in robots:
        s = FKSystem(robot)
        t = StackedFKSystem.of(s)
        c = rng.uniform(-2, 2, (40, s.n))
        w = rng.uniform(0, 0.3, (40, s.n)) * (rng.random((40, 1)) < 0.8)
        X = Interval.from_bounds(c - w, c + w)
        Llo = rng.uniform(1, 20, (40, s.legs))
        L = Interval.from_bounds(Llo, Llo + 0.01)
        for name, a, b in (("rotation", s.rotation(X), t.rotation(X)),
                           ("equations", s.equations(X, L), t.equations(X, L)),
                           ("jacobian", s.jacobian(X), t.jacobian(X)), ("points", s.points(X), t.points(X))):
            assert np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi), \
                f"{robot.kind} {name}: StackedFKSystem (certkin/robots/fk_stacked.py) must mirror FKSystem's operations"
        if s.n_pos:
            for a, b in zip(s.position_system(X, L), t.position_system(X, L)):
                assert np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi), f"{robot.kind} position_system"
        f, J, mid = t.krawczyk_data(X, L)
        f0 = s.equations(Interval.from_bounds(X.mid(), X.mid()), L)
        assert np.array_equal(mid, X.mid()) and np.array_equal(f.lo, f0.lo) and np.array_equal(f.hi, f0.hi)
        assert np.array_equal(J.lo, s.jacobian(X).lo) and np.array_equal(J.hi, s.jacobian(X).hi)
        ff, Jf = s.float_system(c, Llo)
        point = Interval.from_bounds(c, c.copy())
        fi, Ji = s.equations(point, Interval.from_bounds(Llo, Llo.copy())), s.jacobian(point)
        assert np.all(fi.lo - 1e-9 <= ff) and np.all(ff <= fi.hi + 1e-9)
        assert np.all(Ji.lo - 1e-9 <= Jf) and np.all(Jf <= Ji.hi + 1e-9)


def test_track_sequence_planar_every_step_proved_and_certified():
    """A smooth motion in 60 steps: each step is tracked (proved unique in a box around the previous
    posture), its root box lies in that box, the generating pose lies in the root box, and the
    certificates of all steps re-check; forward_kinematics(2-D lengths, track=) is the same path."""
    from certkin.certificates import fk_certificate
    from certkin.fk import track_sequence
    robot, plat, poses = _planar_motion(60)
    L = robot.leg_lengths_float(poses[1:])
    out = track_sequence(robot, L, _pose_text(poses[0]))
    assert len(out) == 60 and all(r.tracked and not r.complete and len(r.solutions) == 1 for r in out)
    for k, r in enumerate(out):
        box, (dlo, dhi) = r.solutions[0]["box"], r.domain
        assert np.all(box.lo >= dlo) and np.all(box.hi <= dhi)          # root box inside the tracking box
        assert np.all(box.hi - box.lo < 1e-9)
        prev = _unknowns(robot, poses[k])                                # the previous posture is in it
        assert np.all(dlo - 1e-9 <= prev) and np.all(prev <= dhi + 1e-9)
        _generating_pose_in_box(robot, plat, r, poses[k + 1])
        assert r.to_json()["tracked"] is True
    report = proofs.check(fk_certificate(out))
    assert report.ok, report.step
    assert report.checked["claims"] == 60 and report.checked["solutions"] == 60
    again = forward_kinematics(robot, L, track=_pose_text(poses[0]))
    assert isinstance(again, list) and len(again) == 60 and all(r.tracked for r in again)
    for a, b in zip(out, again):
        assert np.array_equal(a.solutions[0]["box"].lo, b.solutions[0]["box"].lo)
    one = forward_kinematics(robot, [repr(float(v)) for v in L[0]], track=_pose_text(poses[0]))
    a, b = one.solutions[0]["box"], out[0].solutions[0]["box"]   # the same posture (lengths enclosed alike or
    assert one.tracked and np.all(a.lo <= b.hi) and np.all(b.lo <= a.hi)   # one ulp wider)


def test_track_sequence_gough_seed002():
    """Seed 002 robot: a small motion from posture 1 of Table VI.2, tracked step by step."""
    from certkin import load_robot
    from certkin.certificates import fk_certificate
    from certkin.fk import track_sequence
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    pose = np.array(_pose_from_points(robot, table_vi2()[0]))
    t = np.linspace(0.0, 1.0, 13)[:, None]
    poses = pose + np.sin(np.pi * t) * np.array([0.02, -0.01, 0.015, 0.01, 0.005, -0.01])
    L = robot.leg_lengths_float(poses[1:])
    out = track_sequence(robot, L, _pose_text(poses[0]), fallback=False)   # no 24-posture search here
    assert all(r.tracked and len(r.solutions) == 1 for r in out)
    for r, p in zip(out, poses[1:]):
        _generating_pose_in_box(robot, None, r, p)
    report = proofs.check(fk_certificate(out))
    assert report.ok and report.checked["claims"] == 12, report.step


def test_tracking_step_that_cannot_be_proved_is_not_reported_tracked():
    """Unreachable leg lengths in the middle of a sequence, and steps too large to prove: never a
    tracked guess.  With the fallback the full search answers those steps (tracked false); without,
    they are reported not proved (complete false, no solution).  Tracking resumes after them."""
    from certkin.certificates import fk_certificate
    from certkin.fk import track_sequence
    robot, plat, poses = _planar_motion(40)
    L = robot.leg_lengths_float(poses[1:6]).copy()
    L[2] = [1.0, 1.0, 1.0]                   # no posture at all
    start = _pose_text(poses[0])
    out = track_sequence(robot, L, start)
    assert [r.tracked for r in out] == [True, True, False, True, True]
    assert out[2].complete and out[2].solutions == [] and out[2].unresolved == []
    quiet = track_sequence(robot, L, start, fallback=False)
    assert [r.tracked for r in quiet] == [True, True, False, True, True]
    assert not quiet[2].complete and quiet[2].solutions == [] and quiet[2].to_json()["complete"] is False
    for results in (out, quiet):
        report = proofs.check(fk_certificate(results))
        assert report.ok, report.step
    # the single-call API: unreachable lengths fall back to the full search
    r = forward_kinematics(robot, "1,1,1", track=start)
    assert not r.tracked and r.complete and r.solutions == [] and r.to_json()["tracked"] is False
    # steps of several per cent of the robot's size: the proofs fail; the full search answers
    robot, plat, poses = _planar_motion(4)
    L = robot.leg_lengths_float(poses[1:3])
    out = track_sequence(robot, L, _pose_text(poses[0]))
    assert not any(r.tracked for r in out)
    for r, p in zip(out, poses[1:3]):
        assert r.complete and len(r.solutions) >= 1
        gen = [(p[0] + np.cos(p[2]) * q[0] - np.sin(p[2]) * q[1], p[1] + np.sin(p[2]) * q[0] + np.cos(p[2]) * q[1])
               for q in plat]
        near = [s for s in r.solutions
                if all(b[0] - 1e-9 <= g <= b[1] + 1e-9 for bp, gp in zip(_points(s), gen) for b, g in zip(bp, gp))]
        assert len(near) == 1                # the generating posture is one of the modes found
    report = proofs.check(fk_certificate(out))
    assert report.ok, report.step


def test_tracking_retries_keep_certificates_valid(monkeypatch):
    """The second-chance paths (a wider root box, other tracking boxes, the tracking box itself as
    the root box) give certificates that re-check."""
    import certkin.fk.tracking as tracking
    from certkin.certificates import fk_certificate
    from certkin.fk import track_sequence
    robot, plat, poses = _planar_motion(80)
    L = robot.leg_lengths_float(poses[1:9])
    start = _pose_text(poses[0])
    for slack, retry, grows in ((1e-9, 2.0 ** 10, tracking.GROWS), (1e-9, 1.0, tracking.GROWS),
                                (2.0, 2.0 ** 10, (1e-9, 1.0, 0.25))):
        monkeypatch.setattr(tracking, "ROOT_SLACK", slack)
        monkeypatch.setattr(tracking, "ROOT_RETRY", retry)
        monkeypatch.setattr(tracking, "GROWS", grows)
        out = track_sequence(robot, L, start, fallback=False)
        assert sum(r.tracked for r in out) >= 4
        for r, p in zip(out, poses[1:9]):
            if r.tracked:
                box, (dlo, dhi) = r.solutions[0]["box"], r.domain
                assert np.all(box.lo >= dlo) and np.all(box.hi <= dhi)
                _generating_pose_in_box(robot, plat, r, p)
        report = proofs.check(fk_certificate(out))
        assert report.ok, report.step


def test_tampered_tracking_certificates_are_rejected():
    robot, plat, poses = _planar_motion(60)
    L = robot.leg_lengths_float(poses[1:2])[0]
    r = forward_kinematics(robot, [repr(float(v)) for v in L], track=_pose_text(poses[0]))
    assert r.tracked
    cert = Doc(r.certificate())
    assert cert.check().ok

    moved = cert.copy()                          # the root box shifted out of the tracking box
    w = moved.claim()["domain"][0][1] - moved.claim()["domain"][0][0]
    moved.arrays["fk.region.box"][0, 0] += 2 * w
    assert not moved.check().ok

    widened = cert.copy()                        # a wider tracking box than the one proved
    widened.claim()["domain"][0][0] -= 5.0
    widened.arrays["tree.star"][0, 0, 0] -= 5.0
    assert not widened.check().ok

    length = cert.copy()
    length.claim()["lengths"][0] = str(float(length.claim()["lengths"][0]) + 0.01)
    assert not length.check().ok


def test_tracked_steps_agree_with_the_full_search():
    """Random robots and motions: every tracked step's tracking box meets exactly one of the full
    search's (complete) solutions, the one that meets its root box."""
    from certkin.fk import track_sequence
    rng = np.random.default_rng(42)
    tracked = 0
    for _ in range(3):
        base = rng.uniform(-10, 10, (3, 2)).round(2)
        plat = rng.uniform(-4, 4, (3, 2)).round(2)
        robot = planar(base, plat)
        p0 = np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-np.pi, np.pi)])
        t = np.linspace(0, 1, 16)[:, None]
        poses = p0 + np.hstack([np.sin(3 * t), np.cos(2 * t) - 1, 0.3 * np.sin(5 * t)]) * rng.uniform(0.1, 0.5, 3)
        L = robot.leg_lengths_float(poses[1:])
        out = track_sequence(robot, L, _pose_text(poses[0]), fallback=False)
        for r, full in zip(out, forward_kinematics(robot, L)):
            assert full.complete
            if not r.tracked:
                continue
            tracked += 1
            (blo, bhi), s = r.domain, r.solutions[0]["box"]
            near = [g["box"] for g in full.solutions if np.all(g["box"].hi >= blo) and np.all(g["box"].lo <= bhi)]
            assert len(near) == 1 and np.all(near[0].hi >= s.lo) and np.all(near[0].lo <= s.hi)
    assert tracked >= 30


def test_a_tracked_posture_is_not_called_complete():
    """Tracking proves the one posture near the previous pose: the answer (API, JSON) does not say
    complete, which means every assembly mode is listed; the certificate's claim is complete in its box."""
    from certkin import load_robot
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    r = forward_kinematics(robot, "28.99,13.66,40.53", track="13.3,-17,1.13")
    assert r.tracked and not r.complete and len(r.solutions) == 1 and r.status == "tracked"
    doc = r.to_json()
    assert doc["complete"] is False and doc["tracked"] is True and "not searched" in doc["message"]
    assert "1 solution, tracked" in repr(r)
    report = proofs.check(r.certificate())
    assert report.ok, report.step


def test_tracking_a_planar_posture_does_not_import_numba():
    """``fk --track`` on the planar robot took 0.6 s for a 2 ms proof: its Newton steps solved 4 x 4
    systems with a machine-code kernel, and importing numba (and loading the kernel) cost the rest."""
    code = ("import sys, certkin; r = certkin.forward_kinematics('examples/robots/seed003-planar-example-2.toml', "
            "'28.99,13.66,40.53', track='13.3,-17,1.13'); print(r.tracked, 'numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "True False"


def test_tracking_reads_the_pose_in_the_robots_own_angles():
    """With tilt and torsion (phi1, phi2, sigma) the previous pose is read as such (sigma was taken for
    phi3): the mode at (30deg, 60deg, sigma 60deg) is tracked from its own angles, and only from them."""
    from certkin import load_robot
    robot = load_robot(EXAMPLES / "seed003-spherical-example-1.toml").with_angles("tilt-torsion")
    lengths = "1.67332005307,2.32606878754,1.74216654891"
    every = forward_kinematics(robot, lengths)
    target = min(every.solutions, key=lambda s: abs(float(s["pose"]["sigma"].lo) - math.pi / 3)
                 + abs(float(s["pose"]["phi1"].lo) - math.pi / 6))
    from certkin.fk import track_sequence
    (step,) = track_sequence(robot, [lengths], "phi1=30deg,phi2=60deg,sigma=60deg", fallback=False)
    for pose in ("phi1=30deg,phi2=60deg,sigma=60deg", ",".join(repr(float(v.lo)) for v in target["pose"].values()),
                 None):
        r = forward_kinematics(robot, lengths, track=pose) if pose else step    # (a sequence reads it alike)
        assert r.tracked and len(r.solutions) == 1
        (s,) = r.solutions
        assert all(float(s["pose"][k].lo) <= float(target["pose"][k].hi) and float(target["pose"][k].lo)
                   <= float(s["pose"][k].hi) for k in ("phi1", "phi2", "sigma"))
        assert proofs.check(r.certificate()).ok


def test_the_memory_ceiling_bounds_a_spatial_fk_search_and_its_answer(tmp_path):
    """A Gough search's batch of 8 192 boxes holds about 12 KB a box while it is decided (100 MB),
    which the ceiling did not count: ``--max-memory 100MiB`` peaked 205 MiB beyond the start-up, and
    50MiB 128 MiB.  The batch is now shortened to what the ceiling leaves, and the search gets
    ``SEARCH_SHARE`` of it (the answer built from its leaves comes after).  In a fresh process (the
    kernels loaded and a first search made before the peak is measured from), the peak beyond that
    stays within the ceiling (and 10 %)."""
    from peak import beyond_start_up
    robot = str(Path(__file__).resolve().parent.parent / "examples" / "robots" / "dietmaier-6-6-40.toml")
    lengths = "1,0.645275,1.086284,1.503439,1.281933,0.771071"
    warm = (f"from certkin.cli import main; from certkin import forward_kinematics, keep_freed_memory; "
            f"keep_freed_memory(); forward_kinematics({robot!r}, {lengths!r}, max_boxes=2000)")
    rc, extra, done = beyond_start_up(
        f"result = main(['fk', {robot!r}, '--lengths', {lengths!r}, '--max-memory', '50MiB', '--json'])", warm)
    doc = json.loads(done.stdout)
    assert rc == 0 and not doc["complete"] and doc["unresolved"]
    assert extra <= 1.1 * 50 * 2 ** 20, extra / 2 ** 20      # (100 MiB: 118 MiB before, 43 MiB after; since the
    # Cayley-Menger combinations the search completes within 100 MiB, so 50 MiB)
