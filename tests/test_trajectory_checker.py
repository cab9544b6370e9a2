"""The independent checker ``proofs`` on trajectory certificates (``"problem": "trajectory"``).

Honest certificates written by certkin must be accepted; every tampered
variant must be rejected with the failing step named.  A few facts are also
checked against an independent mpmath computation (brute-force segment
distance), so the checker and the solver cannot agree on a wrong meaning.
"""
import copy
import math
from pathlib import Path

import pytest
from mpmath import mp

import proofs
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
    cert = verify_trajectory(mel, START, "84,92,500,85deg,10deg,0").certificate()
    assert cert["claims"][0]["status"] == "infeasible"
    return cert


@pytest.fixture(scope="module")
def feasible(mel):
    cert = verify_trajectory(mel, START, "7.5,21,500,85deg,10deg,0").certificate()
    assert cert["claims"][0]["status"] == "feasible"
    return cert


def rejected(cert, *words):
    report = proofs.check(cert)
    assert not report.ok, "a tampered certificate was accepted"
    for w in words:
        assert w in report.step, report.step
    return report.step


def column(claim, constraint, legs):
    return next(k for k, i in enumerate(claim["instances"]) if i["constraint"] == constraint and i["legs"] == legs)


# ----- honest certificates ----------------------------------------------------------------
def test_mel_certificates_accepted(feasible, infeasible):
    for cert in (feasible, infeasible):
        report = proofs.check(cert)
        assert report.ok, report.step
        assert report.checked["leaves"] == len(cert["claims"][0]["leaves"]["t"])


def test_mel_infeasible_agrees_with_brute_force(infeasible):
    """At the goal legs 1 and 2 are closer than 2 + 2 mm (a '-' leaf there), computed here independently."""
    claim = infeasible["claims"][0]
    k = column(claim, "interference", [1, 2])
    assert claim["leaves"]["state"][-1][k] == "-"
    with mp.workdps(30):
        R = lambda a, b, c: _rz(a) * _rx(b) * _rz(c)  # noqa: E731
        rot = R(85 * mp.pi / 180, 10 * mp.pi / 180, 0)
        C = mp.matrix([84, 92, 500])
        robot = infeasible["robot"]
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
    assert cert["model"] == "spherical-3dof-tt/1"
    assert proofs.check(cert).ok


def test_constraint_subset_accepted_and_order_enforced():
    robot = robot_from_dict(PLANAR)
    cert = verify_trajectory(robot, "10,10,22.5deg", "12,8,30deg", constraints=["interference", "singularity"]).certificate()
    assert proofs.check(cert).ok
    bad = copy.deepcopy(cert)
    inst = bad["claims"][0]["instances"]
    inst[0], inst[1] = inst[1], inst[0]
    rejected(bad, "instances[1]", "canonical order")
    bad = copy.deepcopy(cert)
    bad["claims"][0]["instances"][0] = {"constraint": "interference", "legs": [1, 4]}
    rejected(bad, "instances[0]", "not implied")


def _outward(cert):
    """The violation bounds rounded outward (what a sound writer gives when s = k + t is not a float)."""
    for claim in cert["claims"]:
        for v in claim["violations"]:
            if "segment" not in v:
                v["s"] = [math.nextafter(v["s"][0], -math.inf), math.nextafter(v["s"][1], math.inf)]
    return cert


@pytest.fixture(scope="module")
def waypoints():
    return verify_trajectory(robot_from_dict(SPHERICAL), "30deg,60deg,30deg", "50deg,40deg,10deg",
                             waypoints=["40deg,50deg,20deg"]).certificate()


def test_polyline_certificate_accepted(waypoints):
    cert = _outward(copy.deepcopy(waypoints))
    assert len(cert["claims"][0]["path"]) == 3
    report = proofs.check(cert)
    assert report.ok, report.step


def test_polyline_certificate_as_written(mel):
    """The s bounds of violations across segments are rounded outward, so the union covers every leaf."""
    cert = verify_trajectory(mel, START, "84,92,520,95deg,5deg,10deg", waypoints=["7.5,21,480,80deg,12deg,5deg"],
                             constraints=["leg-length"]).certificate()
    report = proofs.check(cert)
    assert report.ok, report.step


# ----- tampering ------------------------------------------------------------------------------
def test_flipped_violation_rejected(infeasible):
    cert = copy.deepcopy(infeasible)
    claim = cert["claims"][0]
    k = column(claim, "interference", [1, 2])
    states = claim["leaves"]["state"]
    minus = [i for i, s in enumerate(states) if s[k] == "-"]
    i = minus[len(minus) // 2]
    states[i] = states[i][:k] + "+" + states[i][k + 1:]
    rejected(cert, f"leaves[{i}]", "'+' for interference legs 1-2", "refuted")


def test_flipped_det_sign_rejected(feasible):
    cert = copy.deepcopy(feasible)
    states = cert["claims"][0]["leaves"]["state"]
    states[:] = [s[:-1] + ("+" if s[-1] == "-" else "-") for s in states]
    rejected(cert, "singularity", "refuted")


def test_removed_leaf_rejected(feasible):
    cert = copy.deepcopy(feasible)
    leaves = cert["claims"][0]["leaves"]
    middle = len(leaves["state"]) // 2
    assert middle >= 2
    for key in leaves:
        del leaves[key][middle]
    rejected(cert, f"leaves[{middle}]", "do not tile")
    cert = copy.deepcopy(feasible)
    leaves = cert["claims"][0]["leaves"]
    for key in leaves:
        del leaves[key][-1]
    rejected(cert, "leaves", "up to t = 1")


def test_widened_leaf_rejected(infeasible):
    # the last '+' leaf before legs 1-2 interfere, widened over the next two leaves
    cert = copy.deepcopy(infeasible)
    claim = cert["claims"][0]
    k = column(claim, "interference", [1, 2])
    leaves = claim["leaves"]
    i = next(i for i, s in enumerate(leaves["state"]) if s[k] != "+") - 1
    leaves["t"][i][1] = leaves["t"][i + 2][1]
    for key in leaves:
        del leaves[key][i + 1:i + 3]
    rejected(cert, f"leaves[{i}]", "interference legs 1-2")
    # widened without removing its neighbour: the leaves overlap
    cert = copy.deepcopy(infeasible)
    cert["claims"][0]["leaves"]["t"][5][1] = cert["claims"][0]["leaves"]["t"][6][1]
    rejected(cert, "leaves[6]", "do not tile")


def test_status_changed_rejected(infeasible, feasible):
    cert = copy.deepcopy(infeasible)
    cert["claims"][0]["status"] = "feasible"
    rejected(cert, "claims[0].status", "feasible, but")
    cert = copy.deepcopy(feasible)
    cert["claims"][0]["status"] = "infeasible"
    rejected(cert, "claims[0].status", "infeasible, but")
    cert = copy.deepcopy(infeasible)
    cert["claims"][0]["status"] = "undecided"
    assert proofs.check(cert).ok                     # a weaker verdict claims less


def test_shrunk_violation_rejected(infeasible):
    cert = copy.deepcopy(infeasible)
    v = cert["claims"][0]["violations"][0]
    v["t"][0] += 1e-3
    v["s"][0] = float(v["segment"] + v["t"][0])
    rejected(cert, "claims[0].violations", "no violation interval covers it")
    cert = copy.deepcopy(infeasible)
    del cert["claims"][0]["violations"][-1]
    rejected(cert, "no violation interval covers it")


def test_violation_fields_checked(infeasible, feasible):
    cert = copy.deepcopy(infeasible)
    cert["claims"][0]["violations"][0]["s"][0] -= 1e-3     # s no longer the rounding of segment + t
    rejected(cert, "violations[0]", "s must enclose segment + t")
    cert = copy.deepcopy(feasible)
    cert["claims"][0]["violations"] = [{"constraint": "leg-length", "legs": [1], "s": [0.0, 0.5], "certain": True}]
    rejected(cert, "violations[0]", "marked certain")


def test_changed_pose_rejected(infeasible):
    cert = copy.deepcopy(infeasible)
    cert["claims"][0]["path"][1][0] = "95"
    rejected(cert, "claims[0].leaves[", "refuted")
    cert = copy.deepcopy(infeasible)
    cert["claims"][0]["path"][1][0] = "95deg"
    rejected(cert, "path[1].x", "only allowed for angles")


def test_changed_limits_rejected(feasible):
    cert = copy.deepcopy(feasible)
    cert["robot"]["limits"]["leg_length"][0][1] = "600"
    rejected(cert, "leaves[0]", "leg-length leg 1", "refuted")
    cert = copy.deepcopy(feasible)
    cert["robot"]["limits"]["leg_radius"][0] = "40"
    rejected(cert, "interference legs 1-")
    cert = copy.deepcopy(feasible)
    del cert["robot"]["limits"]["leg_radius"]
    rejected(cert, "instances[6]", "not implied")
    cert = copy.deepcopy(feasible)
    cert["robot"]["limits"]["leg_stiffness"] = "1"
    rejected(cert, "robot.limits.leg_stiffness")


def test_joint_limits_validated():
    data = copy.deepcopy(SPHERICAL)
    cert = verify_trajectory(robot_from_dict(data), "30deg,60deg,30deg", "35deg,55deg,30deg").certificate()
    for value in ("-70deg", "350deg", "1.6"):               # the checker only knows cones up to 90deg
        bad = copy.deepcopy(cert)
        bad["robot"]["limits"]["base_joints"][0]["half_angle"] = value
        rejected(bad, "base_joints[0].half_angle")
    bad = copy.deepcopy(cert)
    bad["robot"]["limits"]["platform_joints"][1]["normals"][0] = ["0", "0", "-1"]
    rejected(bad, "platform facet 1")
    planar = verify_trajectory(robot_from_dict(PLANAR), "10,10,22.5deg", "12,8,30deg").certificate()
    planar["robot"]["limits"]["platform_joints"] = [{"normals": [["0", "0", "1"]]}] * 3
    rejected(planar, "platform joint limits are not modelled")


def test_header_checked(feasible):
    cert = copy.deepcopy(feasible)
    cert["model"] = "planar-3rpr/1"
    rejected(cert, "robot.kind")
    cert = copy.deepcopy(feasible)
    cert["claims"][0]["leaves"]["state"][3] += "+"
    rejected(cert, "leaves[3]", "one of")


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
