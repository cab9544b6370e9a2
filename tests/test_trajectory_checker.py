"""The independent checker ``proofs`` on trajectory certificates (``"problem": "trajectory"``).

Honest certificates written by certkin must be accepted; every tampered
variant must be rejected with the failing step named.  A few facts are also
checked against an independent mpmath computation (brute-force segment
distance), so the checker and the solver cannot agree on a wrong meaning.
"""
import copy
import math
from pathlib import Path

import numpy as np
import pytest
from mpmath import mp

import proofs
from certfile import Doc
from certkin import load_robot
from certkin.robots import robot_from_dict
from certkin.trajectory import verify_trajectory

MEL = Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed000-mel-tsukuba.toml"
START = "-69,-50,500,85deg,10deg,0"

SPHERICAL = {"name": "sph", "kind": "spherical-3dof",
             "base": [["1.6", "0", "-1.2"], ["-1.1", "1.2", "-1.2"], ["-0.9", "-1", "-1.2"]],
             "platform": [["1", "0", "0"], ["-0.6", "1", "0"], ["-0.2", "-0.5", "0"]],
             "limits": {"leg_length": [["1", "3"], ["1", "3"], ["1", "3"]], "leg_radius": "0.05",
                        "base_joints": [{"axis": ["0", "0", "1"], "half_angle": "70deg"}] * 3,
                        "platform_joints": [{"normals": [["0", "0", "1"]]}] * 3}}
PLANAR = {"name": "pla", "kind": "planar-3rpr", "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
          "platform": [["0", "0"], ["17.04", "0"], ["13.2364", "16.097"]],
          "limits": {"leg_length": [["2", "30"], ["2", "30"], ["2", "30"]], "leg_radius": "0.2",
                     "base_joints": [{"normals": [["0", "1", "0"]]}, {"normals": [["-1", "1", "0"]]},
                                     {"normals": [["1", "0", "0"]]}]}}


@pytest.fixture(scope="module")
def mel():
    return load_robot(MEL)


@pytest.fixture(scope="module")
def infeasible(mel):
    cert = Doc(verify_trajectory(mel, START, "84,92,500,85deg,10deg,0").certificate())
    assert cert.claim()["status"] == "infeasible"
    return cert


@pytest.fixture(scope="module")
def feasible(mel):
    cert = Doc(verify_trajectory(mel, START, "7.5,21,500,85deg,10deg,0").certificate())
    assert cert.claim()["status"] == "feasible"
    return cert


def rejected(cert, *words):
    report = cert.check()
    assert not report.ok, "a tampered certificate was accepted"
    for w in words:
        assert w in report.step, report.step
    return report.step


def column(claim, constraint, legs):
    return next(k for k, i in enumerate(claim["instances"]) if i["constraint"] == constraint and i["legs"] == legs)


def drop_leaves(cert, rows):
    """Leaves removed from the body (and from the claim's count)."""
    for name in ("traj.segment", "traj.t", "traj.state"):
        cert.arrays[name] = np.delete(cert.arrays[name], rows, axis=0)
    cert.claim()["leaves"][1] -= len(np.atleast_1d(rows))
    return cert


MINUS, PLUS = 2, 1


# ----- honest certificates ----------------------------------------------------------------
def test_mel_certificates_accepted(feasible, infeasible):
    for cert in (feasible, infeasible):
        report = cert.check()
        assert report.ok, report.step
        assert report.checked["leaves"] == cert.claim()["leaves"][1] == len(cert.arrays["traj.t"])


def test_mel_infeasible_agrees_with_brute_force(infeasible):
    """At the goal legs 1 and 2 are closer than 2 + 2 mm (a '-' leaf there), computed here independently."""
    k = column(infeasible.claim(), "interference", [1, 2])
    assert infeasible.arrays["traj.state"][-1, k] == MINUS
    with mp.workdps(30):
        R = lambda a, b, c: _rz(a) * _rx(b) * _rz(c)  # noqa: E731
        rot = R(85 * mp.pi / 180, 10 * mp.pi / 180, 0)
        C = mp.matrix([84, 92, 500])
        robot = infeasible.header["robot"]
        A = [mp.matrix([mp.mpf(c) for c in p]) for p in robot["base"]]
        B = [C + rot * mp.matrix([mp.mpf(c) for c in p]) for p in robot["platform"]]
        assert _segment_distance(A[0], B[0], A[1], B[1]) < 4


def test_spherical_and_planar_certificates_accepted():
    for data, start, goal, via in ((SPHERICAL, "30deg,60deg,30deg", "35deg,55deg,30deg", []),
                                   (PLANAR, "10,10,22.5deg", "12,8,30deg", []),
                                   (PLANAR, "10,10,22.5deg", "10,10,22.5deg", [])):
        cert = verify_trajectory(robot_from_dict(data), start, goal, waypoints=via).certificate()
        report = proofs.check(cert)
        assert report.ok, (data["kind"], report.step)
    tt = robot_from_dict(SPHERICAL).with_angles("tilt-torsion")
    cert = verify_trajectory(tt, "30deg,60deg,30deg", "50deg,40deg,10deg").certificate()
    assert cert.header["model"] == "spherical-3dof-tt/1"
    assert proofs.check(cert).ok


def test_constraint_subset_accepted_and_order_enforced():
    robot = robot_from_dict(PLANAR)
    cert = Doc(verify_trajectory(robot, "10,10,22.5deg", "12,8,30deg", constraints=["interference", "singularity"]).certificate())
    assert cert.check().ok
    bad = cert.copy()
    inst = bad.claim()["instances"]
    inst[0], inst[1] = inst[1], inst[0]
    rejected(bad, "instances[1]", "canonical order")
    bad = cert.copy()
    bad.claim()["instances"][0] = {"constraint": "interference", "legs": [1, 4]}
    rejected(bad, "instances[0]", "not implied")


def test_a_claim_without_some_instances_of_a_constraint_is_rejected(infeasible):
    """A forger drops the two interference pairs the README's motion is proved to collide on (legs 1-2
    and 2-5) and calls the rest feasible: every other leaf is honest, but the claim no longer lists all
    the instances of interference that the robot's limits define."""
    bad = infeasible.copy()
    claim = bad.claim()
    drop = [column(claim, "interference", legs) for legs in ([1, 2], [2, 5])]
    keep = [k for k in range(len(claim["instances"])) if k not in drop]
    claim["instances"] = [claim["instances"][k] for k in keep]
    state = bad.arrays["traj.state"][:, keep]
    assert not np.any(state[:, :-1] == MINUS)     # what is left would be feasible but for the rule (last: det's sign)
    bad.arrays["traj.state"] = np.ascontiguousarray(state)
    claim["status"], claim["violations"] = "feasible", []
    rejected(bad, "instances", "'legs': [1, 2]", "all or none")


PARALLEL = {"name": "legs 1 and 2 stay parallel", "kind": "gough-stewart",
            "base": [["0", "0", "0"], ["10", "0", "0"], ["50", "50", "0"], ["-50", "50", "0"], ["-50", "-50", "0"], ["50", "-50", "0"]],
            "platform": [["0", "0", "0"], ["10", "0", "0"], ["20", "20", "0"], ["-20", "20", "0"], ["-20", "-20", "0"], ["20", "-20", "0"]],
            "limits": {"leg_radius": ["0.2496880846", "0.2496880846", "0.1", "0.1", "0.1", "0.1"]}}


def test_parallel_legs_grazing_each_other_check():
    """Legs 1 and 2 are l = (20, 1, z) from (0, 0, 0) and (10, 0, 0) for every pose (20, 1, z, 0, 0, 0):
    parallel, their distance 10 sqrt(1 + z^2) / sqrt(401 + z^2), least at z = 0 (t = 1/2), 2.4e-10 above
    r_1 + r_2.  The checker's l_1 x l_2 was wide there (l_1 and l_2 each hold the moving centre) and its
    bisection ran out: l_1 x l_2 is now l_1 x (l_2 - l_1), and l_2 - l_1 does not hold the centre."""
    mp.dps = 50
    margin = 10 / mp.sqrt(401) - 2 * mp.mpf("0.2496880846")
    assert 2e-10 < margin < 3e-10
    r = verify_trajectory(robot_from_dict(PARALLEL), "20,1,5,0,0,0", "20,1,-5,0,0,0", constraints=["interference"])
    assert r.status == "feasible"
    lo, hi = next(m["margin"] for m in r.margins if m["legs"] == [1, 2])
    assert mp.mpf(lo) <= margin <= mp.mpf(hi)
    assert proofs.check(r.certificate()).ok


def _outward(cert):
    """The violation bounds rounded outward (what a sound writer gives when s = k + t is not a float)."""
    for claim in cert.header["claims"]:
        for v in claim["violations"]:
            if "segment" not in v:
                v["s"] = [math.nextafter(v["s"][0], -math.inf), math.nextafter(v["s"][1], math.inf)]
    return cert


@pytest.fixture(scope="module")
def waypoints():
    return Doc(verify_trajectory(robot_from_dict(SPHERICAL), "30deg,60deg,30deg", "50deg,40deg,10deg",
                                 waypoints=["40deg,50deg,20deg"]).certificate())


def test_polyline_certificate_accepted(waypoints):
    cert = _outward(waypoints.copy())
    assert len(cert.claim()["path"]) == 3
    report = cert.check()
    assert report.ok, report.step


def test_polyline_certificate_as_written(mel):
    """The s bounds of violations across segments are rounded outward, so the union covers every leaf."""
    cert = verify_trajectory(mel, START, "84,92,520,95deg,5deg,10deg", waypoints=["7.5,21,480,80deg,12deg,5deg"],
                             constraints=["leg-length"]).certificate()
    report = proofs.check(cert)
    assert report.ok, report.step


# ----- tampering ------------------------------------------------------------------------------
def test_flipped_violation_rejected(infeasible):
    cert = infeasible.copy()
    k = column(cert.claim(), "interference", [1, 2])
    minus = np.nonzero(cert.arrays["traj.state"][:, k] == MINUS)[0]
    i = minus[len(minus) // 2]
    cert.arrays["traj.state"][i, k] = PLUS
    rejected(cert, f"leaves[{i}]", "'+' for interference legs 1-2", "refuted")


def test_batch_checked_together_and_named_per_claim(mel):
    """Two paths in one file (their leaves are checked together): a flipped state in the second one is
    named by its claim and its own leaf number."""
    from certkin.certificates import trajectory_certificate
    results = [verify_trajectory(mel, START, goal) for goal in ("7.5,21,500,85deg,10deg,0", "84,92,500,85deg,10deg,0")]
    cert = Doc(trajectory_certificate(results))
    report = cert.check()
    assert report.ok and "1 path feasible, 1 path infeasible" in " ".join(report.proved), report.step
    first, count = cert.claim(1)["leaves"]
    k = column(cert.claim(1), "interference", [1, 2])
    minus = np.nonzero(cert.arrays["traj.state"][first:first + count, k] == MINUS)[0]
    cert.arrays["traj.state"][first + minus[0], k] = PLUS
    rejected(cert, f"claims[1].leaves[{minus[0]}]", "'+' for interference legs 1-2", "refuted")


def test_flipped_det_sign_rejected(feasible):
    cert = feasible.copy()
    cert.arrays["traj.state"][:, -1] = 3 - cert.arrays["traj.state"][:, -1]
    rejected(cert, "singularity", "refuted")


def test_removed_leaf_rejected(feasible):
    middle = len(feasible.arrays["traj.t"]) // 2
    assert middle >= 2
    rejected(drop_leaves(feasible.copy(), middle), f"leaves[{middle}]", "do not tile")
    rejected(drop_leaves(feasible.copy(), len(feasible.arrays["traj.t"]) - 1), "leaves", "up to t = 1")


def test_widened_leaf_rejected(infeasible):
    # the last '+' leaf before legs 1-2 interfere, widened over the next two leaves
    cert = infeasible.copy()
    k = column(cert.claim(), "interference", [1, 2])
    i = int(np.nonzero(cert.arrays["traj.state"][:, k] != PLUS)[0][0]) - 1
    cert.arrays["traj.t"][i, 1] = cert.arrays["traj.t"][i + 2, 1]
    rejected(drop_leaves(cert, [i + 1, i + 2]), f"leaves[{i}]", "interference legs 1-2")
    # widened without removing its neighbour: the leaves overlap
    cert = infeasible.copy()
    cert.arrays["traj.t"][5, 1] = cert.arrays["traj.t"][6, 1]
    rejected(cert, "leaves[6]", "do not tile")


def test_status_changed_rejected(infeasible, feasible):
    cert = infeasible.copy()
    cert.claim()["status"] = "feasible"
    rejected(cert, "claims[0].status", "feasible, but")
    cert = feasible.copy()
    cert.claim()["status"] = "infeasible"
    rejected(cert, "claims[0].status", "infeasible, but")
    cert = infeasible.copy()
    cert.claim()["status"] = "undecided"
    assert cert.check().ok                           # a weaker verdict claims less


def test_shrunk_violation_rejected(infeasible):
    cert = infeasible.copy()
    v = cert.claim()["violations"][0]
    v["t"][0] += 1e-3
    v["s"][0] = float(v["segment"] + v["t"][0])
    rejected(cert, "claims[0].violations", "no violation interval covers it")
    cert = infeasible.copy()
    del cert.claim()["violations"][-1]
    rejected(cert, "no violation interval covers it")


def test_violation_fields_checked(infeasible, feasible):
    cert = infeasible.copy()
    cert.claim()["violations"][0]["s"][0] -= 1e-3     # s no longer the rounding of segment + t
    rejected(cert, "violations[0]", "s must enclose segment + t")
    cert = feasible.copy()
    cert.claim()["violations"] = [{"constraint": "leg-length", "legs": [1], "s": [0.0, 0.5], "certain": True}]
    rejected(cert, "violations[0]", "marked certain")


def test_changed_pose_rejected(infeasible):
    cert = infeasible.copy()
    cert.claim()["path"][1][0] = "95"
    rejected(cert, "claims[0].leaves[", "refuted")
    cert = infeasible.copy()
    cert.claim()["path"][1][0] = "95deg"
    rejected(cert, "path[1].x", "only allowed for angles")


def test_changed_limits_rejected(feasible):
    cert = feasible.copy()
    cert.header["robot"]["limits"]["leg_length"][0][1] = "600"
    rejected(cert, "geometry_sha256")                # the geometry's hash no longer fits, then the proofs
    rejected(cert.robot_edited(), "leaves[0]", "leg-length leg 1", "refuted")
    cert = feasible.copy()
    cert.header["robot"]["limits"]["leg_radius"][0] = "40"
    rejected(cert.robot_edited(), "interference legs 1-")
    cert = feasible.copy()
    del cert.header["robot"]["limits"]["leg_radius"]
    rejected(cert.robot_edited(), "instances[6]", "not implied")
    cert = feasible.copy()
    cert.header["robot"]["limits"]["leg_stiffness"] = "1"
    rejected(cert.robot_edited(), "robot.limits.leg_stiffness")


def test_joint_limits_validated():
    data = copy.deepcopy(SPHERICAL)
    cert = Doc(verify_trajectory(robot_from_dict(data), "30deg,60deg,30deg", "35deg,55deg,30deg").certificate())
    for value in ("-70deg", "350deg", "1.6"):               # the checker only knows cones up to 90deg
        bad = cert.copy()
        bad.header["robot"]["limits"]["base_joints"][0]["half_angle"] = value
        rejected(bad.robot_edited(), "base_joints[0].half_angle")
    bad = cert.copy()
    bad.header["robot"]["limits"]["platform_joints"][1]["normals"][0] = ["0", "0", "-1"]
    rejected(bad.robot_edited(), "platform facet 1")
    planar = Doc(verify_trajectory(robot_from_dict(PLANAR), "10,10,22.5deg", "12,8,30deg").certificate())
    planar.header["robot"]["limits"]["platform_joints"] = [{"normals": [["0", "0", "1"]]}] * 3
    rejected(planar.robot_edited(), "platform joint limits are not modelled")


def test_header_checked(feasible):
    cert = feasible.copy()
    cert.header["model"] = "planar-3rpr/1"
    rejected(cert, "robot.kind")
    cert = feasible.copy()
    cert.arrays["traj.state"] = np.concatenate([cert.arrays["traj.state"], cert.arrays["traj.state"][:, :1]], 1)
    rejected(cert, "claims[0].leaves: rows")
    cert = feasible.copy()
    cert.arrays["traj.state"][3, 0] = 3
    rejected(cert, "a state is not 0, 1, 2")


# ----- independent reference (mpmath, brute force) ------------------------------------------
def _rz(a):
    return mp.matrix([[mp.cos(a), -mp.sin(a), 0], [mp.sin(a), mp.cos(a), 0], [0, 0, 1]])


def _rx(a):
    return mp.matrix([[1, 0, 0], [0, mp.cos(a), -mp.sin(a)], [0, mp.sin(a), mp.cos(a)]])


def _point_segment(P, X, Y):
    s = Y - X
    tau = min(max(((P - X).T * s)[0] / (s.T * s)[0], 0), 1)
    return mp.norm(P - (X + tau * s))


def _segment_distance(A1, B1, A2, B2):
    """min over the first segment of the (convex) distance to the second: golden-section search."""
    lo, hi = mp.mpf(0), mp.mpf(1)
    f = lambda s: _point_segment(A1 + s * (B1 - A1), A2, B2)  # noqa: E731
    for _ in range(80):
        m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        lo, hi = (lo, m2) if f(m1) < f(m2) else (m1, hi)
    return f((lo + hi) / 2)


def test_many_undecided_leaves_against_many_violations_are_checked_in_a_sweep(feasible):
    """'?' leaves were each compared with every violation interval in Python (20 000 leaves and 8 000
    intervals: 245 s for a 795 KB file).  Sorted once, then a bisection per leaf: about a second."""
    import time
    cert = feasible.copy()
    claim = cert.claim()
    claim.update(instances=[claim["instances"][-1]], status="undecided", leaves=[0, 20000])   # (singularity: whole)
    edges = np.linspace(0.0, 1.0, 20001)
    cert.arrays.update({"traj.segment": np.zeros(20000, np.int32), "traj.t": np.stack([edges[:-1], edges[1:]], 1),
                        "traj.state": np.zeros((20000, 1), np.uint8)})
    key = {k: claim["instances"][0][k] for k in ("constraint", "legs", "detail") if k in claim["instances"][0]}
    cert.arrays["traj.state"][0] = feasible.arrays["traj.state"][0, -1]     # leaf 0 proved (det's sign there)
    tiny = [float(np.nextafter(0.0, 1.0)) * (2 * k + 1) for k in range(8000)]      # disjoint, within leaf 0
    claim["violations"] = [{**key, "s": [x, x], "certain": False} for x in tiny] + \
        [{**key, "s": [float(edges[1]), 1.0], "certain": False}]
    t = time.perf_counter()
    report = cert.check()
    assert report.ok, report.step
    assert time.perf_counter() - t < 30
    claim["violations"][-1]["s"] = [float(edges[2]), 1.0]       # leaf 1 is '?' and now covered by nothing
    assert "leaf 1 (segment 0" in rejected(cert, "no violation interval covers it")
