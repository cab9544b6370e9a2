"""Every bundled robot, with the default budget: at its home pose and at 20 random poses inside its
limits, the forward kinematics is complete and every mode is proved unique (slow).

Reference: the pose the leg lengths come from (lengths rounded to 9 decimals, so the pose is within
about 1e-8 of a posture): exactly one solution box lies near it.  The counts of postures are
compared with an exact solver (msolve) in the oracle tests.
"""
import numpy as np
import pytest

from certkin import load_robot
from certkin.fk import forward_kinematics
from test_fk import EXAMPLES

ROBOTS = sorted(f.name for f in EXAMPLES.glob("*.toml") if "\nhome =" in f.read_text())
POSES = 20


def _near(result, robot, pose, tol):
    """Solution boxes whose platform points lie within ``tol`` (relative to the robot) of the pose's."""
    pts = robot.platform_points(robot.pose_box(list(pose))).mid()
    size = max(1.0, float(np.max(np.abs(pts))))
    return [s for s in result.solutions
            if all(float(c.lo) - tol * size <= g <= float(c.hi) + tol * size
                   for p, gp in zip(s["platform_points"], pts) for c, g in zip(p, gp))]


def _solve_at(robot, pose):
    lengths = [f"{v:.9f}" for v in robot.leg_lengths_float(np.asarray(pose, dtype=np.float64))]
    result = forward_kinematics(robot, lengths)
    assert result.complete, (robot.name, pose, result.message)
    assert not result.clusters and all(s["status"] == "unique" for s in result.solutions)
    assert len(_near(result, robot, pose, 1e-6)) == 1
    return result


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


@pytest.mark.slow
@pytest.mark.parametrize("name", ROBOTS)
def test_bundled_robot_at_home(name):
    robot = load_robot(EXAMPLES / name)
    _solve_at(robot, robot.home_box().mid())


@pytest.mark.slow
@pytest.mark.parametrize("name", ROBOTS)
def test_bundled_robot_at_random_poses_inside_its_limits(name):
    robot = load_robot(EXAMPLES / name)
    for pose in random_poses(robot, POSES):
        _solve_at(robot, pose)


@pytest.mark.slow
def test_dietmaier_forty_postures():
    """Dietmaier (1998): 40 real postures, the worst case of a general 6-6 robot, with the default
    budget (the postures are compared with msolve's in the oracle tests)."""
    path = EXAMPLES / "dietmaier-6-6-40.toml"
    if not path.exists():
        pytest.skip("the Dietmaier robot file is not bundled yet")
    result = forward_kinematics(load_robot(path), "1,0.645275,1.086284,1.503439,1.281933,0.771071")
    assert result.complete and len(result.solutions) == 40 and not result.clusters
