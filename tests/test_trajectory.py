"""Trajectory verification and planning against independent derivations.

Reference values are computed here with mpmath (exact decimals, 40 digits) or
from exact algebra, never copied from certkin's output: seed 000 Fig. 1.8
(MEL robot), seed 001's planar 3-RPR path that crosses the singularity locus
twice ((pi - 3)/3 exactly, and a second instant bracketed by sign changes),
synthetic joint limits with a rational crossing instant, and a sampling
property test.  Every certificate is re-checked by ``proofs``.
"""
import copy
import json
import math
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import proofs
from certfile import Doc, checked
from certkin import InputError, load_robot, plan, robot_from_dict, verify_trajectory, verify_trajectories
from certkin.trajectory import parse_path

ROOT = Path(__file__).resolve().parents[1]
MEL = ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml"
START, GOAL = "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"
mp.mp.dps = 40


@pytest.fixture(scope="module")
def mel():
    return load_robot(MEL)


# ----- independent model (mpmath) -------------------------------------------------------------
def _rot(psi, theta, phi):
    def rz(a):
        return mp.matrix([[mp.cos(a), -mp.sin(a), 0], [mp.sin(a), mp.cos(a), 0], [0, 0, 1]])

    def rx(a):
        return mp.matrix([[1, 0, 0], [0, mp.cos(a), -mp.sin(a)], [0, mp.sin(a), mp.cos(a)]])
    return rz(psi) * rx(theta) * rz(phi)


def _pose(text):
    out = []
    for v in text.split(","):
        out.append(mp.mpf(Fraction(v[:-3]).numerator) / Fraction(v[:-3]).denominator * mp.pi / 180
                   if v.endswith("deg") else mp.mpf(Fraction(v).numerator) / Fraction(v).denominator)
    return out


def _legs_mp(robot, pose):
    A = [mp.matrix([mp.mpf(Fraction(c).numerator) / Fraction(c).denominator for c in p]) for p in robot.base]
    b = [mp.matrix([mp.mpf(Fraction(c).numerator) / Fraction(c).denominator for c in p]) for p in robot.platform]
    R = _rot(*pose[3:])
    C = mp.matrix(pose[:3])
    return A, [C + R * bi for bi in b]


def _seg_dist(p1, q1, p2, q2):
    """Exact distance between segments [p1, q1] and [p2, q2] (minimum over the square, by cases)."""
    u, v, w0 = q1 - p1, q2 - p2, p1 - p2
    a, b, c, d, e = (mp.fdot(u, u), mp.fdot(u, v), mp.fdot(v, v), mp.fdot(u, w0), mp.fdot(v, w0))
    cands = []
    den = a * c - b * b
    if den > 0:
        s, t = (b * e - c * d) / den, (a * e - b * d) / den
        if 0 <= s <= 1 and 0 <= t <= 1:
            cands.append(mp.norm(w0 + s * u - t * v))

    def pseg(P, X, Y):
        e_ = Y - X
        tau = min(max(mp.fdot(P - X, e_) / mp.fdot(e_, e_), 0), 1)
        return mp.norm(P - X - tau * e_)
    cands += [pseg(p1, p2, q2), pseg(q1, p2, q2), pseg(p2, p1, q1), pseg(q2, p1, q1)]
    return min(cands)


def _dist_at(robot, s0, s1, i, j, t):
    P0, P1 = _pose(s0), _pose(s1)
    pose = [a + t * (b - a) for a, b in zip(P0, P1)]
    A, B = _legs_mp(robot, pose)
    return _seg_dist(A[i], B[i], A[j], B[j])


def _first_crossing(robot, i, j, lo, hi, r=4):
    """Bisection at 40 digits for d_ij(t) = r between lo (d > r) and hi (d < r)."""
    lo, hi = mp.mpf(lo), mp.mpf(hi)
    assert _dist_at(robot, START, GOAL, i, j, lo) > r > _dist_at(robot, START, GOAL, i, j, hi)
    for _ in range(120):
        m = (lo + hi) / 2
        lo, hi = (m, hi) if _dist_at(robot, START, GOAL, i, j, m) > r else (lo, m)
    return lo


# ----- seed 000 Fig. 1.8 -------------------------------------------------------------------------
def test_mel_fig_1_8_interference_instants_are_enclosed(mel):
    result = verify_trajectory(mel, START, GOAL)
    assert result.status == "infeasible"
    certain = {tuple(v["legs"]): v for v in result.violations if v["certain"]}
    assert set(certain) == {(1, 2), (2, 5)}
    for (i, j), guess in (((0, 1), (0.5, 0.6)), ((1, 4), (0.7, 0.72))):
        t_star = _first_crossing(mel, i, j, *guess)          # digest: 0.548853053564660741..., 0.707437620702...
        v = certain[(i + 1, j + 1)]
        assert v["t"][0] <= t_star and v["t"][1] == 1.0
        assert t_star - v["t"][0] < 1e-6                   # tight
        assert _dist_at(mel, START, GOAL, i, j, v["t"][0] - mp.mpf("1e-6")) > 4
    checked(result)


def test_mel_fig_1_8_leg_margins_contain_the_exact_minima(mel):
    result = verify_trajectory(mel, START, GOAL, constraints=["leg-length"])
    margins = {m["legs"][0]: m["margin"] for m in result.to_json()["margins"]}
    P0, P1 = _pose(START), _pose(GOAL)
    A0, B0 = _legs_mp(mel, P0)
    w = mp.matrix(P1[:3]) - mp.matrix(P0[:3])
    for i, (rmin, rmax) in enumerate(mel.limits["leg_length"]):
        V = B0[i] - A0[i]
        a, b = mp.fdot(w, w), 2 * mp.fdot(V, w)
        ts = [mp.mpf(0), mp.mpf(1)] + ([-b / (2 * a)] if 0 < -b / (2 * a) < 1 else [])
        rho = [mp.norm(V + t * w) for t in ts]
        exact = min(min(r - mp.mpf(rmin) for r in rho), min(mp.mpf(rmax) - r for r in rho))
        lo, hi = margins[i + 1]
        assert lo <= exact <= hi and hi - lo < 1e-3 * abs(exact)
    assert abs(float(margins[6][0]) - 7.451160709) < 1e-3     # digest: leg 6, at t = 0.661682
    assert result.status == "feasible"
    checked(result)


def test_mel_half_path_is_feasible_with_the_exact_pair_margin(mel):
    goal = "7.5,21,500,85deg,10deg,0"                           # C(0.5) of the Fig. 1.8 path
    result = verify_trajectory(mel, START, goal)
    assert result.status == "feasible" and result.det_sign == -1
    margins = {tuple(m["legs"]): m["margin"] for m in result.to_json()["margins"]}
    ts = [mp.mpf(k) / 200 for k in range(201)]
    for (i, j) in ((0, 1), (1, 4), (0, 3)):
        d = min(_dist_at(mel, START, goal, i, j, t) for t in ts) - 4   # sampled: an upper bound of the min
        lo, hi = margins[(i + 1, j + 1)]
        assert lo <= d and hi - lo < 1e-3
        assert d - hi < 1e-2
    checked(result)


def test_sampled_violations_always_lie_in_reported_intervals(mel):
    """Random constant-orientation paths: every dense-sampling violation is inside an interval
    reported for its instance, and a sampled violation never coexists with 'feasible'."""
    rng = np.random.default_rng(7)
    paths, texts = [], []
    for _ in range(6):
        a = rng.uniform(-90, 90, 2)
        b = rng.uniform(-90, 90, 2)
        z = rng.uniform(480, 560)
        s = f"{a[0]:.3f},{a[1]:.3f},{z:.3f},85deg,10deg,0"
        g = f"{b[0]:.3f},{b[1]:.3f},{z:.3f},85deg,10deg,0"
        texts.append((s, g))
        paths.append(parse_path(mel, s, g))
    results = verify_trajectories(mel, paths, ["leg-length", "interference"])
    ts = np.linspace(0, 1, 401)
    lim = [(float(a), float(b)) for a, b in mel.limits["leg_length"]]
    for (s, g), r in zip(texts, results):
        P0 = np.array([float(v) for v in s.replace("deg", "").split(",")])
        P1 = np.array([float(v) for v in g.replace("deg", "").split(",")])
        P0[3:], P1[3:] = np.deg2rad(P0[3:]), np.deg2rad(P1[3:])
        poses = P0 + ts[:, None] * (P1 - P0)
        rho = mel.leg_lengths_float(poses)
        sampled = []
        for k, (lo, hi) in enumerate(lim):
            bad = (rho[:, k] < lo - 1e-6) | (rho[:, k] > hi + 1e-6)
            sampled += [(("leg-length", (k + 1,)), t) for t in ts[bad]]
        for t in ts[::8]:
            A, B = _legs_mp(mel, [mp.mpf(float(v)) for v in P0 + t * (P1 - P0)])
            for i in range(6):
                for j in range(i + 1, 6):
                    if _seg_dist(A[i], B[i], A[j], B[j]) < 4 - 1e-6:
                        sampled.append((("interference", (i + 1, j + 1)), t))
        if sampled:
            assert r.status != "feasible"
        for (name, legs), t in sampled:
            assert any(v["constraint"] == name and tuple(v["legs"]) == legs and v["t"][0] <= t <= v["t"][1]
                       for v in r.violations), (name, legs, t)
        checked(r)



def test_moving_orientation_sampled_violations_lie_in_reported_intervals(mel):
    """Random paths whose three angles move (up to 25 deg): every violation found by sampling at 40
    digits (leg lengths, segment distances, a sign change of det A) lies in an interval reported for
    its instance, and 'feasible' never coexists with one."""
    rng = np.random.default_rng(12)
    paths, texts = [], []
    for _ in range(4):
        a, b = rng.uniform(-60, 60, 2), rng.uniform(-60, 60, 2)
        z = rng.uniform(480, 540)
        ang0 = rng.uniform(-20, 20, 3) + np.array([85, 10, 0])
        ang1 = ang0 + rng.uniform(-25, 25, 3)
        s = f"{a[0]:.2f},{a[1]:.2f},{z:.2f}," + ",".join(f"{v:.2f}deg" for v in ang0)
        g = f"{b[0]:.2f},{b[1]:.2f},{z:.2f}," + ",".join(f"{v:.2f}deg" for v in ang1)
        texts.append((s, g))
        paths.append(parse_path(mel, s, g))
    results = verify_trajectories(mel, paths, ["leg-length", "interference", "singularity"], indices=False)
    lim = [(mp.mpf(a), mp.mpf(b)) for a, b in mel.limits["leg_length"]]
    ts = [mp.mpf(k) / 60 for k in range(61)]
    for (s, g), r in zip(texts, results):
        P0, P1 = _pose(s), _pose(g)
        sampled, dets = [], []
        for t in ts:
            pose = [p + t * (q - p) for p, q in zip(P0, P1)]
            A, B = _legs_mp(mel, pose)
            for k, (lo, hi) in enumerate(lim):
                rho = mp.norm(B[k] - A[k])
                if rho < lo or rho > hi:
                    sampled.append((("leg-length", (k + 1,)), t))
            for i in range(6):
                for j in range(i + 1, 6):
                    if _seg_dist(A[i], B[i], A[j], B[j]) < 4:
                        sampled.append((("interference", (i + 1, j + 1)), t))
            dets.append(_det_mp(mel, pose))
        for k in range(len(ts) - 1):      # det A changes sign in [t_k, t_k+1]: a singular instant there
            if dets[k] * dets[k + 1] < 0:
                assert any(v["constraint"] == "singularity" and v["t"][0] <= ts[k + 1] and ts[k] <= v["t"][1]
                           for v in r.violations), (s, g, ts[k])
                sampled.append(None)
        if sampled:
            assert r.status != "feasible", (s, g)
        for item in sampled:
            if item is not None:
                (name, legs), t = item
                assert any(v["constraint"] == name and tuple(v["legs"]) == legs and v["t"][0] <= t <= v["t"][1]
                           for v in r.violations), (s, g, name, legs, t)
        checked(r)

# ----- seed 001: planar 3-RPR, det(A) vanishes twice between equal end signs ----------------------
SEED001 = {"kind": "planar-3rpr", "base": [["0", "0"], ["75", "0"], ["37.5", "64.952"]],
           "platform": [["0", "0"], ["15", "0"], ["7.5", "12.990381"]],   # assumed geometry (digest 001)
           "limits": {"leg_length": [["10", "200"]] * 3}}


def test_seed001_singularity_crossings_are_found():
    robot = robot_from_dict(SEED001)
    result = verify_trajectory(robot, "20,0,3.0", "60,-50,6.0")
    assert result.status == "infeasible"
    sing = [v for v in result.violations if v["constraint"] == "singularity"]
    assert all(v["certain"] for v in sing) and len(sing) == 2
    # digest 001: with the ideal equilateral design det(A) = 0 where the platform angle is pi, at
    # s = (pi - 3)/3; the file's 4-7 digit decimals move it slightly.  Each reported interval must
    # hold a sign change of det(A), evaluated here at 40 digits from the exact decimals.
    def det_mp(t):
        t = mp.mpf(t)
        x, y, phi = 20 + 40 * t, -50 * t, 3 + 3 * t
        c, s_ = mp.cos(phi), mp.sin(phi)
        rows = []
        for (bx, by), (px, py) in zip(SEED001["base"], SEED001["platform"]):
            bx, by, px, py = (mp.mpf(v) for v in (bx, by, px, py))
            qx, qy = c * px - s_ * py, s_ * px + c * py
            rows.append([(y - by) * qx - (x - bx) * qy, x + qx - bx, y + qy - by])
        return mp.det(mp.matrix(rows))
    for v, near in zip(sing, (float((mp.pi - 3) / 3), 0.367473112867)):
        assert det_mp(v["t"][0] - 1e-12) * det_mp(v["t"][1] + 1e-12) < 0
        assert v["t"][1] - v["t"][0] < 1e-8 and abs(v["t"][0] - near) < 1e-6
    checked(result)


# ----- joint limits: a rational crossing instant ---------------------------------------------------
def test_base_joint_facet_violation_has_the_exact_instant(mel):
    data = {"kind": "gough-stewart", "base": [list(p) for p in mel.base], "platform": [list(p) for p in mel.platform],
            "limits": {"base_joints": [{"normals": [["1", "0", "0"], ["0", "0", "1"]]}] +
                       [{"normals": [["0", "0", "1"]]}] * 5}}
    robot = robot_from_dict(data)
    # leg 1: (B1 - A1)_x = x + 95.263 - 112.5 at R = I, so n = (1,0,0) fails while x < 17.237
    result = verify_trajectory(robot, "0,0,500,0,0,0", "40,0,500,0,0,0", constraints=["joints"])
    t_star = Fraction("17.237") / 40
    assert result.status == "infeasible"
    (v,) = [v for v in result.violations if v.get("detail") == "base facet 1"]
    assert v["t"][0] == 0.0 and v["t"][1] >= t_star and v["t"][1] - t_star < 1e-6 and v["certain"]
    checked(result)
    ok = verify_trajectory(robot, "20,0,500,0,0,0", "40,0,500,0,0,0", constraints=["joints"])
    assert ok.status == "feasible"
    checked(ok)


def test_a_feasible_margin_is_never_printed_below_zero(mel):
    """Leg 6's base cone is 2e-8 rad wider than the largest angle the leg makes with its axis on this motion
    (half-angle taken from a 30-digit minimisation): the verdict proves the margin >= 0, and the margin's
    enclosure, which reached -4.9e-6, now says so too."""
    cone = {"axis": ["0", "0", "1"], "half_angle": "0.217052100307354236241115246132"}
    data = {"kind": "gough-stewart", "base": [list(p) for p in mel.base], "platform": [list(p) for p in mel.platform],
            "limits": {"base_joints": [{"axis": ["0", "0", "1"], "half_angle": "80deg"}] * 5 + [cone]}}
    r = verify_trajectory(robot_from_dict(data), "-10,-9,533,10deg,-10deg,28deg", "30,54,542,-26deg,-6deg,17deg",
                          constraints=["joints"])
    assert r.status == "feasible"
    checked(r)
    (lo, hi), = [m["margin"] for m in r.margins if m["legs"] == [6]]
    assert 0.0 <= lo <= hi < 1e-7


def test_polyline_reports_global_parameter(mel):
    result = verify_trajectory(mel, START, GOAL, waypoints=["7.5,21,500,85deg,10deg,0"],
                               constraints=["interference"])
    assert result.status == "infeasible"
    v = [v for v in result.violations if tuple(v["legs"]) == (1, 2) and v["certain"]][0]
    assert v["segment"] == 1 and 1.0 < v["s"][0] < 2.0
    assert Fraction(v["s"][0]) <= 1 + Fraction(v["t"][0]) and 1.0 + v["t"][0] - v["s"][0] <= 4.5e-16   # outward
    checked(result)


def test_a_search_down_to_the_floats_resolution_ends_within_its_time_budget(mel):
    """min_width=1e-300 splits t down to one ulp where a margin crosses zero: thousands of leaves and
    'may fail' ranges, each concluded after the search (once with Fractions, 80 us each: 2.4 s for a
    2 s budget)."""
    import time
    from certkin.trajectory.result import TrajectoryResult, conclude
    verify_trajectory(mel, START, GOAL, max_boxes=100)                  # (models built: not timed)
    r = verify_trajectory(mel, START, GOAL, min_width=1e-300, max_seconds=2)
    assert r.status == "infeasible" and len(r.violations) > 50           # (100 to 10 000, as the search goes)
    assert r.stats["seconds"] < 2 * 1.25, r.stats
    assert all(v["s"] == v["t"] for v in r.violations + r.undecided)      # (one segment: s = t; polylines above)
    again = TrajectoryResult(r.robot, r.path, r.constraints)
    again.leaves = r.leaves
    c0 = time.process_time()                 # (CPU time: the search is bounded by the clock, the rest is not)
    conclude(again)
    assert time.process_time() - c0 < 40e-6 * len(r.violations)            # (was 80 to 110 us a range; now 10)
    assert again.violations == r.violations and again.undecided == r.undecided


# ----- parallel legs (seed 000 digest E11) ------------------------------------------------------------
PARALLEL = {"name": "parallel legs", "kind": "gough-stewart",
            "base": [["0", "0", "0"], ["100", "0", "0"], ["200", "50", "0"], ["150", "150", "0"], ["0", "150", "0"],
                     ["-50", "80", "0"]],
            "platform": [["0", "0", "0"], ["100", "0", "0"], ["60", "60", "0"], ["40", "90", "0"], ["0", "70", "0"],
                         ["-20", "40", "0"]],
            "limits": {"leg_radius": "1"}}


def test_parallel_legs_have_a_proved_interference_margin():
    """At the pose (0, 0, 500, 0, 0, 0) legs 1 and 2 are vertical segments 100 apart (exact
    geometry: A_1 = B_1 - (0, 0, 500), A_2 = A_1 + (100, 0, 0)), so their distance is 100 and the
    margin 100 - (1 + 1) = 98.  The line distance is 0/0 there; the margin was [-2, 98], undecided."""
    robot = robot_from_dict(PARALLEL)
    pose = "0,0,500,0,0,0"
    r = verify_trajectory(robot, pose, pose, constraints="interference")
    m = next(m for m in r.margins if m["legs"] == [1, 2])
    assert m["margin"][0] <= 98 <= m["margin"][1] and m["margin"][1] - m["margin"][0] < 1e-9
    assert r.status == "feasible"
    checked(r)
    # translating by t (10, 0, 10): both legs stay parallel to (10t, 0, 500 + 10t), 100 apart along x,
    # so their distance is 100 (500 + 10t) / |(10t, 0, 500 + 10t)|, least at t = 1
    moving = verify_trajectory(robot, pose, "10,0,510,0,0,0", constraints=["interference"])
    m = next(m for m in moving.margins if m["legs"] == [1, 2])
    exact = 100 * mp.mpf(510) / mp.sqrt(mp.mpf(10) ** 2 + 510 ** 2) - 2
    assert m["margin"][0] <= exact <= m["margin"][1] and m["margin"][1] - m["margin"][0] < 1e-2
    assert moving.status == "feasible"
    checked(moving)


def test_plain_paths_and_constraint_names():
    """verify_trajectories takes (start, goal) pairs, polylines and mappings; constraints as one name."""
    robot = robot_from_dict(PARALLEL)
    a, b, c = "0,0,500,0,0,0", [10, 0, 510, 0, 0, 0], np.array([5.0, 5.0, 505.0, 0.0, 0.0, 0.0])
    rs = verify_trajectories(robot, [(a, b), [a, c, b], {"start": a, "goal": b}], constraints="interference")
    assert [r.path.segments for r in rs] == [1, 2, 1] and all(len(r.margins) == 15 for r in rs)
    assert len(repr(rs[0])) < 200
    assert "1 segment, 15 margins, 0 violations, 0 undecided ranges" in repr(rs[0])
    with pytest.raises(InputError) as exc:
        verify_trajectories(robot, [(a,)], constraints="interference")
    assert exc.value.source == "paths[0]"
    for bad in ("", "leg-length,,joints", "leg-length,leg-length", "legs"):
        with pytest.raises(InputError) as exc:
            verify_trajectory(robot, a, b, constraints=bad)
        assert exc.value.source == "constraints"


# ----- planning --------------------------------------------------------------------------------------
def test_planner_finds_a_certified_detour(mel):
    """The straight line dips under rho_min of leg 3 (rho^2 is convex in t, so only an interior
    minimum fails); the planner goes around, and every emitted segment is feasible."""
    s, g = "-90,140,520,0,0,0", "55,140,520,0,0,0"
    assert verify_trajectory(mel, s, g, indices=False).status == "infeasible"
    result = plan(mel, s, g)
    assert result.status == "found" and len(result.waypoints) >= 3
    assert result.waypoints[0] == s.split(",") and result.waypoints[-1] == g.split(",")
    assert all(seg.status == "feasible" for seg in result.segments)
    n = len(result.segments)
    assert f"{len(result.waypoints)} waypoints, {n} segment{'' if n == 1 else 's'} certified feasible" in repr(result)
    report = proofs.check(result.certificate())
    assert report.ok, report.step
    assert f"a route from {s} to {g}: the {len(result.segments)} paths, end to end, for interference, leg-length, " \
           "singularity" in report.proved
    for w in result.waypoints[1:-1]:               # the grid's poses as exact decimals of 12 digits at most
        assert all(len(v.replace("-", "").replace(".", "").lstrip("0")) <= 12 and "e" not in v for v in w)


def test_the_planner_reads_0deg_and_0_as_one_angle(mel):
    """A start written 0deg and a goal written 0 made the angle a coordinate that changes, by a step of
    0: the grid's scale was 0 and the search gave up after 4000 segments."""
    result = plan(mel, "-90,140,520,0deg,0,0", "55,140,520,0,0,0")
    assert result.status == "found" and result.waypoints[-1] == "55,140,520,0,0,0".split(",")
    assert proofs.check(result.certificate()).ok


@pytest.mark.parametrize("divisions", [0, -3, True, 2.5, "6", 10 ** 6])
def test_planner_refuses_bad_divisions(mel, divisions):
    """divisions=0 once returned `found` with the start pose alone (issue #18): now an input error."""
    with pytest.raises(InputError, match="divisions"):
        plan(mel, "-90,140,520,0,0,0", "55,140,520,0,0,0", divisions=divisions)


@pytest.mark.parametrize("value", ["0", "-3"])
def test_cli_plan_refuses_bad_divisions(value):
    out = subprocess.run([sys.executable, "-m", "certkin", "plan", str(MEL), "--from", "-90,140,520,0,0,0",
                          "--to", "55,140,520,0,0,0", f"--divisions={value}"], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 2 and "divisions" in out.stderr and "Traceback" not in out.stderr
    assert "found" not in out.stdout


def test_planner_rejects_a_colliding_goal(mel):
    result = plan(mel, START, GOAL)
    assert result.status == "infeasible-endpoint" and result.endpoint["pose"] == "goal"
    assert {tuple(v["legs"]) for v in result.endpoint["violations"]} >= {(1, 2), (2, 5)}


def test_a_plan_certificate_proves_its_route_joined(mel):
    """A plan's certificate listed its paths, each re-proved alone: without its last path, or with a gap
    between two, it still checked (the route from start to goal was not a claim).  It now states the
    route, and the checker follows it from start to goal."""
    cert = Doc(plan(mel, "-90,140,520,0,0,0", "55,140,520,0,0,0").certificate())
    assert cert.header["route"] == {"from": "-90,140,520,0,0,0".split(","), "to": "55,140,520,0,0,0".split(",")}
    dropped = cert.copy()
    dropped.header["claims"].pop()
    gap = cert.copy()
    gap.header["claims"][1]["path"][0][0] = "-89.9999999"
    more = cert.copy()
    more.header["route"]["via"] = ["0", "0", "0", "0", "0", "0"]
    for bad in (dropped, gap, more):
        report = bad.check()
        assert not report.ok and report.step.startswith("route: the paths must be feasible for the same constraints"), report.step
    assert cert.check().ok


# ----- certificates and CLI ----------------------------------------------------------------------
def test_tampered_trajectory_certificate_is_rejected(mel):
    cert = Doc(verify_trajectory(mel, START, GOAL).certificate())
    bad = cert.copy()
    bad.claim()["status"] = "feasible"
    assert not bad.check().ok
    bad = cert.copy()
    states = bad.arrays["traj.state"]
    k = int(np.nonzero(np.any(states == 2, axis=1))[0][0])     # a leaf with a '-' (2)
    states[k] = np.where(states[k] == 2, 1, states[k])
    assert not bad.check().ok


def test_cli_trajectory_json_certificate_and_errors(tmp_path):
    cert = tmp_path / "t.json"
    out = subprocess.run([sys.executable, "-m", "certkin", "trajectory", str(MEL), "--from", START, "--to",
                          "7.5,21,500,85deg,10deg,0", "--json", "--certificate", str(cert)],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["status"] == "feasible" and "violations" in doc and "margins" in doc
    assert subprocess.run([sys.executable, "-m", "certkin", "check", str(cert)], cwd=ROOT).returncode == 0
    bad = subprocess.run([sys.executable, "-m", "certkin", "trajectory", str(MEL), "--from", "1,2,3", "--to", GOAL],
                         capture_output=True, text=True, cwd=ROOT)
    assert bad.returncode == 2 and "--from" in bad.stderr and "Traceback" not in bad.stderr


@pytest.mark.parametrize("angle", ["-70deg", "350deg", "90deg"])
def test_cone_half_angle_outside_0_90_is_rejected(mel, angle):
    from certkin import RobotFileError
    data = {"kind": "gough-stewart", "base": [list(p) for p in mel.base], "platform": [list(p) for p in mel.platform],
            "limits": {"base_joints": [{"axis": ["0", "0", "1"], "half_angle": angle}] * 6}}
    with pytest.raises(RobotFileError, match="half_angle"):
        robot_from_dict(data)


# ----- constant orientation: polynomials in t ---------------------------------------------------
def _det_mp(robot, pose):
    """det of the rows [l_i, (A_i − C) × l_i] at 40 digits (independent of certkin)."""
    A, B = _legs_mp(robot, pose)
    C = mp.matrix(pose[:3])
    rows = []
    for a, b in zip(A, B):
        l, arm = b - a, a - C
        m = [arm[1] * l[2] - arm[2] * l[1], arm[2] * l[0] - arm[0] * l[2], arm[0] * l[1] - arm[1] * l[0]]
        rows.append([l[0], l[1], l[2]] + m)
    return mp.det(mp.matrix(rows))


def test_constant_orientation_uses_exact_zero_steps_and_polynomials(mel):
    """Equal angle texts give a step of exactly 0 (constant orientation), hence the polynomial
    path; the det(A) polynomial encloses the exact determinant along the path."""
    from certkin.trajectory import TrajectoryProblem
    from certkin.trajectory.constraints import Constraints
    path = parse_path(mel, START, GOAL)
    P0, D = path.start_and_step()
    assert D.lo[0, 3] == D.hi[0, 3] == 0.0 and D.lo[0, 4] == D.hi[0, 4] == 0.0
    cons = Constraints(mel, ["singularity", "leg-length"])
    problem = TrajectoryProblem(cons, P0, D, np.zeros(1, dtype=int), np.zeros(1, dtype=int), 1)
    assert problem.polys is not None and problem.polys["det"][0].degree <= 6
    det_poly = problem.polys["det"][0]
    sq = problem.polys["legs_sq"][0]
    P0m, P1m = _pose(START), _pose(GOAL)
    for t in ("0", "0.25", "0.548853", "0.9", "1"):
        tq = Fraction(t)
        pose = [a + mp.mpf(tq.numerator) / tq.denominator * (b - a) for a, b in zip(P0m, P1m)]
        exact = _det_mp(mel, pose)
        r = det_poly.range(float(tq), float(tq))
        assert r.lo[0] <= exact <= r.hi[0]
        assert float(r.hi[0] - r.lo[0]) < 1e-9 * abs(float(exact))
        A, B = _legs_mp(mel, pose)
        rho2 = sq.range(float(tq), float(tq))
        for i in range(6):
            exact_sq = mp.fdot(B[i] - A[i], B[i] - A[i])
            assert rho2.lo[0, i] <= exact_sq <= rho2.hi[0, i]


def test_batch_agrees_with_one_path_at_a_time(mel):
    """Many segments in one search (per-segment polynomials gathered by row) give the same
    verdicts and overlapping margin enclosures as each path alone, det(A) included."""
    rng = np.random.default_rng(11)
    paths = [parse_path(mel, START, GOAL)]
    for _ in range(6):
        a, b = rng.uniform(-60, 60, 2), rng.uniform(-60, 60, 2)
        paths.append(parse_path(mel, f"{a[0]:.2f},{a[1]:.2f},520,85deg,10deg,0",
                                f"{b[0]:.2f},{b[1]:.2f},520,85deg,10deg,0"))
    batch = verify_trajectories(mel, paths, indices=False)
    for path, rb in zip(paths, batch):
        rs = verify_trajectories(mel, [path], indices=False)[0]
        assert rb.status == rs.status
        for mb, ms in zip(rb.margins, rs.margins):
            assert mb["margin"][0] <= ms["margin"][1] and ms["margin"][0] <= mb["margin"][1], (mb, ms)
        det = [m for m in rb.margins if m["constraint"] == "singularity"][0]
        pose = _pose(",".join(path.texts[0]))
        assert det["margin"][0] <= abs(_det_mp(mel, pose))      # min |det| along the path ≤ |det| at t = 0
        checked(rb)


def test_engine_cuts_where_the_problem_asks():
    """``Decisions.split_at``: the box is cut there once, not at the default ratio."""
    from certkin.engine.search import OPEN, PROVED, Decisions, search

    class Cut:
        reasons = ("narrow",)

        def decide(self, lo, hi, roots):
            wide = (hi - lo)[:, 0] > 0.3
            status = np.where(wide, OPEN, PROVED).astype(np.int8)
            return Decisions(status=status, reason=np.zeros(len(lo), dtype=np.int64),
                             split_at=np.where(wide, lo[:, 0] + 0.125, np.nan))

    tree = search(Cut(), np.array([[0.0]]), np.array([[1.0]]), min_batch=1).tree
    cuts = sorted(tree.split_at[tree.kind == 4].tolist())
    assert cuts == [0.125, 0.25, 0.375, 0.5, 0.625, 0.75]


def test_constraints_are_reused_per_robot_and_rebuilt_when_the_limits_change(mel):
    from certkin.trajectory.constraints import Constraints
    robot = copy.deepcopy(mel)
    first = Constraints.of(robot)
    assert Constraints.of(robot) is first
    robot.limits["leg_radius"] = ["50"] * 6                # fat legs: the Fig. 1.8 start interferes
    second = Constraints.of(robot)
    assert second is not first and float(second.family("interference").r.lo[0]) == 100.0
    assert verify_trajectory(robot, START, GOAL, indices=False).status == "infeasible"


def test_rigid_platform_leg_vectors_enclose_the_exact_ones(mel):
    """The leg vectors of a rigid platform (l_i = C + R b_i − a_i, checked on the symbolic model)
    at the path's start hold the mpmath values from the exact decimals."""
    from certkin.trajectory.constraints import Constraints
    assert type(mel).rigid_legs()
    assert not type(load_robot(ROOT / "examples" / "robots" / "seed003-planar-example-1.toml")).rigid_legs()
    cons = Constraints.of(mel)
    P0, D = parse_path(mel, START, GOAL).start_and_step()
    V = cons.linear_data(P0, D)["V"]
    A, B = _legs_mp(mel, _pose(START))
    for i, (a, b) in enumerate(zip(A, B)):
        for k in range(3):
            assert V[k].lo[0, i] <= b[k] - a[k] <= V[k].hi[0, i]


def test_piece_plan_keeps_truncated_terms_negligible():
    from math import factorial
    from certkin.trajectory.constraints import PIECE_TRUNCATION, piece_plan
    for step in (0.0, 0.17, 1.0, 3.0, 6.0):
        pieces, d = piece_plan(step)
        assert pieces & (pieces - 1) == 0 and 4 <= pieces <= 64
        assert (step / pieces) ** (d + 1) / factorial(d + 1) <= PIECE_TRUNCATION


def test_crossing_estimates_converge_near_an_end():
    """A root 1e-9 inside a wide bracket: Newton with regula falsi fallback lands on it."""
    from certkin.trajectory.crossings import crossing_points
    root = 0.25 + 1e-9
    c = np.zeros((1, 16))
    c[0, :3] = [root * 3.0, -(root + 3.0), 1.0]           # (t − root)(t − 3)
    t, err = crossing_points(c, np.array([0.25]), np.array([0.9]), radii=np.zeros((1, 16)))
    assert abs(t[0] - root) < 1e-15 and err[0] < 1e-14
    assert np.isnan(crossing_points(c, np.array([0.3]), np.array([0.9]))[0])


SINGULAR_EVERYWHERE = {"kind": "planar-3rpr", "base": [[0, 0], [20, 0], [0, 20]], "platform": [[0, 0], [1, 0], [0, 1]],
                       "limits": {"leg_length": [[1, 100], [1, 100], [1, 100]]}}


def test_the_memory_ceiling_bounds_the_whole_call_not_only_the_search():
    """A path on which det(A) is 0 everywhere, with boxes and width unbounded: the search's records
    reach the ceiling; the leaves' states and the answer built after it came on top (2.3 times the
    ceiling at the peak).  In a fresh process, the peak stays within the ceiling and the start-up."""
    from peak import beyond_start_up
    (status, exhausted), extra, _ = beyond_start_up(
        f"r = verify_trajectory(robot_from_dict({SINGULAR_EVERYWHERE!r}), '19.1,21.1,0', '22.9,16.9,0', "
        "max_boxes=10**18, min_width=1e-300, max_seconds=120, max_memory=96 * 2**20); "
        "result = [r.status, r.stats['budget_exhausted']]",
        "from certkin import robot_from_dict, verify_trajectory")
    assert status == "undecided" and exhausted
    assert extra <= 96 * 2 ** 20 * 1.1, extra


def test_a_path_that_stays_at_one_pose_is_decided_without_bisecting_t():
    """Start = goal at a singular pose bisected t until the box budget ran out (200 000 boxes, 6 to 10 s)
    for the ``undecided`` that the first evaluation already gave: every sub-interval has that pose."""
    robot = robot_from_dict(SINGULAR_EVERYWHERE)
    r = verify_trajectory(robot, "19.1,21.1,0", "19.1,21.1,0")
    assert r.status == "undecided" and not r.stats["budget_exhausted"] and r.stats["boxes"] <= 64
    assert r.to_json()["undecided"] == [{"s": [0.0, 1.0], "segment": 0, "t": [0.0, 1.0]}]
    assert checked(r).ok
    away = verify_trajectory(robot, "19.1,21.1,0.5", "19.1,21.1,0.5")    # (not singular: phi is not 0)
    assert away.status == "feasible" and away.stats["boxes"] <= 64 and checked(away).ok
    both = verify_trajectory(robot, "19.1,21.1,0.5", "19.1,21.1,0.5", waypoints=["19.1,21.1,0", "19.1,21.1,0"])
    assert both.status == "undecided" and both.stats["boxes"] < 1000
    [(lo, hi)] = [u["s"] for u in both.to_json()["undecided"]]     # (the still segment, s in [1, 2], and
    assert 1 - 1e-8 < lo <= 1 and 2 <= hi < 2 + 1e-8                  # the ends of its neighbours, down to min_width)


def test_a_polyline_too_long_for_the_memory_ceiling_is_refused_before_it_starts():
    """Each segment with a moving orientation holds its polynomials: 300 segments took 2.8 GB under a
    256 MiB ceiling; now the call is refused at once, naming max_memory and what it would need."""
    robot = load_robot(MEL)
    with pytest.raises(InputError) as exc:
        verify_trajectory(robot, "0,0,500,0,0,0", "84,92,500,85deg,10deg,0",
                          waypoints=["-69,-50,500,85deg,10deg,0"] * 300, max_memory=256 * 2 ** 20)
    assert exc.value.source == "max_memory" and "301 segments" in exc.value.problem
    r = verify_trajectory(robot, "0,0,500,0,0,0", "84,92,500,85deg,10deg,0",
                          waypoints=["-69,-50,500,85deg,10deg,0"] * 5, max_memory=256 * 2 ** 20, max_seconds=30)
    assert r.path.segments == 6


def test_the_memory_a_moving_orientation_needs_is_shown_rounded_up_and_suffices():
    """max_memory=1 said the segment "need about 0 MiB" (and max_memory=2**20 "about 1 MiB", more than
    1 MiB): the least max_memory is now shown rounded up with 3 significant digits (KiB under 1 MiB),
    with the amount given rounded down, and that least amount is taken."""
    import re
    from decimal import Decimal
    robot = load_robot(MEL)
    for given, shown_given in ((1, "1 byte given"), (2 ** 20, "1 MiB given")):
        with pytest.raises(InputError) as exc:
            verify_trajectory(robot, "-69,-50,500,0,0,0", "0,0,500,10deg,0,0", max_memory=given)
        assert exc.value.source == "max_memory" and "0 MiB" not in exc.value.problem
        assert shown_given in exc.value.problem and "1 segment with" in exc.value.problem
        number, unit = re.search(r"at least ([0-9.]+) (KiB|MiB|GiB|bytes?)", exc.value.problem).groups()
        least = Fraction(Decimal(number)) * {"byte": 1, "bytes": 1, "KiB": 2 ** 10, "MiB": 2 ** 20, "GiB": 2 ** 30}[unit]
        assert least > given
    r = verify_trajectory(robot, "-69,-50,500,0,0,0", "0,0,500,10deg,0,0", max_memory=math.ceil(least),
                          max_seconds=30)
    assert r.path.segments == 1
    with pytest.raises(InputError, match=r"^max_memory: .* at least [0-9.]+ KiB .*1 byte given"):
        verify_trajectory(robot, "-69,-50,500,0,0,0", "0,0,500,1deg,0,0", constraints="leg-length", max_memory=1)


def test_a_polyline_that_takes_longer_to_prepare_than_max_seconds_is_refused_before_it_starts():
    """420 via points with a moving orientation took 30 s at --max-seconds 0.01: their polynomials are
    built before the search (the clock stops them only between chunks).  Refused at once, naming max_seconds; a short
    polyline at the same budget is answered (undecided where the time ran out) within a second or two."""
    import time
    robot = load_robot(MEL)
    via = [f"{(i * 37) % 150 - 70},{(i * 53) % 140 - 50},500,{i % 90}deg,{i % 20}deg,{i % 45}deg" for i in range(120)]
    t = time.perf_counter()
    with pytest.raises(InputError) as exc:
        verify_trajectory(robot, "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0", waypoints=via, max_seconds=0.01)
    assert exc.value.source == "max_seconds" and "121 segments" in exc.value.problem
    assert time.perf_counter() - t < 1
    r = verify_trajectory(robot, "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0", waypoints=via[:5],
                          max_seconds=0.01)
    assert r.stats["budget_exhausted"] and r.path.segments == 6


def _moving_polyline(segments):
    """Via points of a polyline whose orientation moves on every segment (4 pieces each on the MEL robot)."""
    return [f"{10 * k / segments:.6f},0,500,{(-1) ** k * 8}deg,5deg,0" for k in range(1, segments)]


def test_the_piece_polynomials_stop_between_chunks_when_asked(mel):
    """With a moving orientation the polynomials are built PIECE_ROWS rows at a time; ``stop()``, asked
    after each chunk, ends the building there: the rows built are the first rows of the full build."""
    from certkin.trajectory.constraints import PIECE_ROWS, Constraints, piece_plan
    from certkin.trajectory.path import angle_step
    path = parse_path(mel, "0,0,500,0,0,0", "10,0,500,0,0,0", _moving_polyline(40))
    P0, D = path.start_and_step()
    cons = Constraints(mel, ["leg-length"])
    n, degree = piece_plan(angle_step(mel, D))
    seg, k = np.repeat(np.arange(P0.shape[0]), n), np.tile(np.arange(n), P0.shape[0])
    args = (P0[seg], D[seg], k / n, np.full(len(k), 1.0 / n), degree)
    assert len(k) > PIECE_ROWS
    asked = []
    part = cons.piece_polynomials(*args, stop=lambda: asked.append(1) or True)
    full = cons.piece_polynomials(*args)
    assert len(asked) == 1 and part["pose"].legs[0].shape[0] == PIECE_ROWS
    for mine, whole in zip(part["legs_sq"], full["legs_sq"], strict=True):
        assert np.array_equal(mine.lo, whole.lo[:PIECE_ROWS]) and np.array_equal(mine.hi, whole.hi[:PIECE_ROWS])


def test_a_time_budget_spent_while_the_polynomials_are_built_decides_nothing(mel, monkeypatch):
    """A polyline with a moving orientation at --max-seconds 5 took 7 s: its polynomials, the margins'
    seed points and the mean indices were computed whatever the clock said.  With a clock already past
    the budget, the building stops after its first chunk and nothing is searched: every piece is an
    undecided leaf (no guess), no indices, and the certificate checks."""
    from certkin.engine.budgets import Clock
    from certkin.trajectory.families.base import UNKNOWN

    class Expired(Clock):
        def elapsed(self):
            return self.max_seconds + 1.0

    monkeypatch.setattr("certkin.trajectory.verify.Clock", Expired)
    r = verify_trajectory(mel, "0,0,500,0,0,0", "10,0,500,0,0,0", _moving_polyline(40), max_seconds=30)
    assert r.status == "undecided" and r.stats["boxes"] == 0 and r.stats["budget_exhausted"]
    assert r.indices is None and (r.leaves["state"] == UNKNOWN).all()
    assert np.isinf(r.leaves["mlo"]).all() and np.isinf(r.leaves["mhi"]).all()
    checked(r)
