"""Forward kinematics against exact algebra (sympy), seed 002 Table VI.2, tampering, the CLI.

The reference answers are derived here, independently of certkin's solver:
planar instances by eliminating x, y and reducing to one polynomial in
T = tan(phi/2) whose real roots sympy isolates exactly; spherical instances
by a lex Groebner basis; Gough postures from the seed's own table.
"""
import copy
import json
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

import proofs
from certkin import robot_from_dict
from certkin.fk import forward_kinematics

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data"
EXAMPLES = ROOT / "examples" / "robots"


def checked(result):
    report = proofs.check(result.certificate())
    assert report.ok, report.step
    return report


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
    cert = result.certificate()
    assert proofs.check(cert).ok
    return cert


def _first(node, want):
    stack = [node]
    while stack:
        n = stack.pop()
        if want(n):
            return n
        stack.extend(n.get("children", []) + ([n["child"]] if "child" in n else []))
    raise AssertionError("no such node")


def test_tampered_fk_certificates_are_rejected(planar_certificate):
    cert = planar_certificate
    claim = lambda c: c["claims"][0]  # noqa: E731

    dropped = copy.deepcopy(cert)
    claim(dropped)["solutions"].pop()
    assert not proofs.check(dropped).ok

    duplicated = copy.deepcopy(cert)
    claim(duplicated)["solutions"].append(copy.deepcopy(claim(duplicated)["solutions"][0]))
    assert "not proved distinct" in proofs.check(duplicated).step

    length = copy.deepcopy(cert)
    claim(length)["lengths"][0] = "14.99"
    assert not proofs.check(length).ok

    widened = copy.deepcopy(cert)
    leaf = _first(claim(widened)["tree"], lambda n: n.get("leaf") == "equation")
    leaf["box"][0][0] -= 1.0
    assert "box does not match" in proofs.check(widened).step

    undecided = copy.deepcopy(cert)
    leaf = _first(claim(undecided)["tree"], lambda n: n.get("leaf") == "krawczyk-empty")
    leaf["leaf"] = "undecided"
    assert "undecided leaf in a claim that says complete" in proofs.check(undecided).step

    shrunk = copy.deepcopy(cert)
    claim(shrunk)["domain"][0][1] -= 5.0
    assert not proofs.check(shrunk).ok

    wrong_solution = copy.deepcopy(cert)
    leaf = _first(claim(wrong_solution)["tree"], lambda n: n.get("leaf") == "krawczyk-unique")
    leaf["solution"] = (leaf["solution"] + 1) % len(claim(wrong_solution)["solutions"])
    assert "is not inside 'star'" in proofs.check(wrong_solution).step

    contraction = copy.deepcopy(cert)
    node = _first(claim(contraction)["tree"], lambda n: n.get("contract") == "krawczyk")
    mid = 0.5 * (node["box"][0][0] + node["box"][0][1])
    node["box"][0] = [mid, mid]   # claims more of the box is empty than K proves
    assert not proofs.check(contraction).ok


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
