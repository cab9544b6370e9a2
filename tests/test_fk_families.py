"""The robot families of the FK issue, each with certkin's default budget, against references derived
independently of the solver.

- Planar robots of ``examples/robots/``: every posture by exact elimination (``test_fk.exact_planar``,
  sympy); spherical robots: by a lex Groebner basis (``test_fk.exact_spherical``); Gough-Stewart robots:
  by msolve on the Study form (``oracle.msolve_fk``).  The answer must be ``complete``, every mode
  ``unique``, each exact posture in exactly one box and each box holding exactly one.
- Each robot at its ``home`` pose and at 20 random poses inside its leg-length limits (seeded); the
  lengths are the pose's, rounded to 9 decimals.  (Gough-Stewart robots at home: ``test_oracle``.)
- Dietmaier's general 6-6 robot with its published lengths (40 real postures) against msolve.
- Every certificate is re-checked by ``proofs`` (Gough-Stewart ones unless
  ``CERTKIN_ORACLE_CHECK_CERTIFICATES=0``, ``test_oracle.CHECK_CERTIFICATES``).

Also in other files: the planar robot with a mode on a bisection plane and the symmetric hexapod at
home (``test_fk_modes``), 100 random general 6-6 robots and 20 symmetric hexapods at home and at a
random pose against msolve (``test_oracle``).  The default suite keeps one cheap case per family.
"""
import time

import numpy as np
import pytest

from certkin import load_robot
from certkin.fk import forward_kinematics
from oracle import robots as G
from test_fk import EXAMPLES, assert_matches_exact, checked, exact_planar, exact_spherical
from test_oracle import DIETMAIER, DIETMAIER_LENGTHS, _certkin_vs_oracle, needs_msolve

POSES = 20


def _robots(kind):
    return sorted(f.name for f in EXAMPLES.glob("*.toml") if f'kind = "{kind}"' in f.read_text())


PLANAR, SPHERICAL, GOUGH = _robots("planar-3rpr"), _robots("spherical-3dof"), _robots("gough-stewart")


def random_poses(robot, count, seed=0):
    """Poses near home (position within 10 % of the robot's size, angles within 0.3 rad) whose leg
    lengths lie inside the robot's leg-length limits, if it has some."""
    rng = np.random.default_rng(seed)
    home = robot.home_box().mid()
    size = max(1.0, float(np.max(np.abs(np.array([[float(c) for c in p] for p in robot.base])))))
    limits = robot.limits.get("leg_length") if robot.limits else None
    out = []
    while len(out) < count:
        step = np.array([0.3 if n in robot.angle_names else 0.1 * size for n in robot.pose_names])
        pose = home + rng.uniform(-1, 1, home.shape) * step
        if limits is not None:
            L = robot.leg_lengths_float(pose)
            lo = np.array([float(a) for a, _ in limits])
            hi = np.array([float(b) for _, b in limits])
            if not np.all((L >= lo) & (L <= hi)):
                # shrink towards home until inside (the limits may be narrow: micro-manipulator)
                for t in (0.3, 0.1, 0.03, 0.01, 0.003):
                    p2 = home + t * (pose - home)
                    L = robot.leg_lengths_float(p2)
                    if np.all((L >= lo) & (L <= hi)):
                        pose = p2
                        break
                else:
                    continue
        out.append(pose)
    return out


def pose_lengths(robot, pose):
    """The pose's leg lengths rounded to 9 decimals (texts)."""
    return [f"{v:.9f}" for v in robot.leg_lengths_float(np.asarray(pose, dtype=np.float64))]


def _exact(robot, lengths):
    """Every real posture (world platform points) by exact algebra (sympy)."""
    base = [[str(c) for c in p] for p in robot.base]
    plat = [[str(c) for c in p] for p in robot.platform]
    return (exact_planar if robot.kind == "planar-3rpr" else exact_spherical)(base, plat, lengths)


def _against_exact(robot, lengths, record):
    t = time.process_time()
    result = forward_kinematics(robot, lengths)
    seconds = time.process_time() - t
    record("lengths", ",".join(lengths))
    record("certkin_cpu_seconds", round(seconds, 3))
    record("certkin_boxes", result.to_json()["stats"]["boxes"])
    record("certkin_complete", result.complete)
    record("certkin_solutions", len(result.solutions))
    assert not result.clusters and all(s["status"] == "unique" for s in result.solutions)
    assert_matches_exact(result, _exact(robot, lengths))
    checked(result)


def test_a_planar_and_a_spherical_robot_at_home_match_exact_algebra(record_property):
    """The cheap representative of the two families below (default suite)."""
    for name in ("seed003-planar-example-1.toml", "seed003-spherical-example-1.toml"):
        robot = load_robot(EXAMPLES / name)
        _against_exact(robot, pose_lengths(robot, robot.home_box().mid()), record_property)


@pytest.mark.slow
@pytest.mark.parametrize("name", PLANAR + SPHERICAL)
def test_planar_and_spherical_robots_at_home(name, record_property):
    robot = load_robot(EXAMPLES / name)
    _against_exact(robot, pose_lengths(robot, robot.home_box().mid()), record_property)


CASES = [(n, k) for n in PLANAR + SPHERICAL for k in range(POSES)]


@pytest.mark.slow
@pytest.mark.parametrize("name,k", CASES, ids=[f"{n[:-5]}-{k}" for n, k in CASES])
def test_planar_and_spherical_robots_at_random_poses_inside_their_limits(name, k, record_property):
    robot = load_robot(EXAMPLES / name)
    _against_exact(robot, pose_lengths(robot, random_poses(robot, POSES)[k]), record_property)


GOUGH_CASES = [(n, k) for n in GOUGH for k in range(POSES)]


@pytest.mark.slow
@needs_msolve
@pytest.mark.parametrize("name,k", GOUGH_CASES, ids=[f"{n[:-5]}-{k}" for n, k in GOUGH_CASES])
def test_gough_stewart_robots_at_random_poses_inside_their_limits(name, k, record_property):
    robot = load_robot(EXAMPLES / name)
    pose = random_poses(robot, POSES)[k]
    _certkin_vs_oracle(G.load_dict(EXAMPLES / name), pose_lengths(robot, pose), record_property, pose=pose)


@pytest.mark.slow
@needs_msolve
def test_dietmaier_forty_postures_against_msolve(record_property):
    """Dietmaier (1998): 40 real postures for the published lengths, the worst case of a general 6-6
    robot, each proved unique by certkin with its default budget."""
    counts = _certkin_vs_oracle(G.load_dict(DIETMAIER), DIETMAIER_LENGTHS, record_property)
    assert counts["postures"] == counts["solutions"] == 40


@needs_msolve
def test_dietmaier_at_the_identity_pose_proves_both_close_postures(record_property):
    """Lengths of Dietmaier's robot at x = y = 0, z = 1, no rotation: two postures 0.005 apart (det(A)
    about -0.0037 and +0.0037, against 0.26 at home).  The one at the identity was left a cluster at
    the resolution: ε-inflation started from the box before the Krawczyk rounds, which they had
    contracted to 1e-10; it now starts from the last contraction.  msolve gives every posture."""
    robot = load_robot(DIETMAIER)
    pose = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    counts = _certkin_vs_oracle(G.load_dict(DIETMAIER), pose_lengths(robot, pose), record_property, pose=pose)
    assert counts["postures"] == counts["solutions"] == 2
