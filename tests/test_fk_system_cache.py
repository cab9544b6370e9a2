"""The FK system built once per robot, and leg lengths given as floats or as decimal texts.

``certkin.fk.fk_system`` keeps one ``FKSystem`` per robot object, keyed by the robot's exact
geometry: two robots never share one, and a robot whose geometry was changed gets a new one.
A float leg length stands for the decimal text ``repr(v)`` (docs/soundness.md §8), so it must
give exactly the enclosures, results and certificate of that text.
"""
import numpy as np

import proofs
from certkin import robot_from_dict
from certkin.fk import fk_system, forward_kinematics
from certkin.fk.stacked import StackedFKSystem

SIX = {"kind": "planar-3rpr", "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
       "platform": [["0", "0"], ["17.04", "0"], ["13.236", "16.097"]]}
LENGTHS = ["14.98", "15.38", "12"]
# the same robot with the third base point moved: other postures for the same lengths
OTHER = {"kind": "planar-3rpr", "base": [["0", "0"], ["15.91", "0"], ["0.5", "10"]],
         "platform": [["0", "0"], ["17.04", "0"], ["13.236", "16.097"]]}


def _boxes(result):
    return sorted((tuple(s["box"].lo), tuple(s["box"].hi)) for s in result.solutions)


def test_one_system_per_robot_and_none_shared():
    a, b = robot_from_dict(SIX), robot_from_dict(OTHER)
    sa, sb = fk_system(a), fk_system(b)
    assert fk_system(a) is sa and fk_system(b) is sb and sa is not sb
    assert StackedFKSystem.of(sa) is StackedFKSystem.of(sa)
    assert float(sb.a.lo[2, 0]) == 0.5 and float(sa.a.lo[2, 0]) == 0.0
    # alternating calls on the two robots give each robot's own answer, as fresh robots do
    ra, rb = forward_kinematics(a, LENGTHS), forward_kinematics(b, LENGTHS)
    ra2, rb2 = forward_kinematics(a, LENGTHS), forward_kinematics(b, LENGTHS)
    fa, fb = forward_kinematics(robot_from_dict(SIX), LENGTHS), forward_kinematics(robot_from_dict(OTHER), LENGTHS)
    assert _boxes(ra) == _boxes(ra2) == _boxes(fa)
    assert _boxes(rb) == _boxes(rb2) == _boxes(fb)
    assert _boxes(ra) != _boxes(rb)
    for r in (ra, rb):
        assert proofs.check(r.certificate()).ok


def test_changed_geometry_is_never_answered_from_the_cache():
    robot = robot_from_dict(SIX)
    before = forward_kinematics(robot, LENGTHS)
    old = fk_system(robot)
    robot.base[2] = ("0.5", "10")                      # the robot object is edited in place
    assert fk_system(robot) is not old
    after = forward_kinematics(robot, LENGTHS)
    assert _boxes(after) == _boxes(forward_kinematics(robot_from_dict(OTHER), LENGTHS))
    assert _boxes(after) != _boxes(before)
    report = proofs.check(after.certificate())         # the certificate states the new geometry
    assert report.ok, report.step
    assert after.certificate().header["robot"]["base"][2] == ["0.5", "10"]


def test_float_lengths_are_their_repr_texts():
    robot = robot_from_dict(SIX)
    floats = [14.98, 15.38, 12.0]
    texts = [repr(v) for v in floats]
    a, b = forward_kinematics(robot, floats), forward_kinematics(robot, texts)
    c = forward_kinematics(robot, np.array(floats))
    assert a.lengths == b.lengths == c.lengths == texts
    assert _boxes(a) == _boxes(b) == _boxes(c) and len(a.solutions) == 6
    ca, cb = a.certificate(), b.certificate()
    assert ca.header == cb.header and all(np.array_equal(ca.arrays[k], cb.arrays[k]) for k in ca.arrays)
    # tracking: the same step from float and from text lengths gives the same proof
    pose = ",".join(repr(float(0.5 * (v.lo + v.hi))) for v in b.solutions[0]["pose"].values())
    near = [v + 1e-3 for v in floats]
    ta = forward_kinematics(robot, near, track=pose)
    tb = forward_kinematics(robot, [repr(v) for v in near], track=pose)
    assert ta.tracked and tb.tracked and _boxes(ta) == _boxes(tb)
    assert np.array_equal(ta.domain[0], tb.domain[0]) and np.array_equal(ta.domain[1], tb.domain[1])
    report = proofs.check(ta.certificate())
    assert report.ok, report.step


def test_planar_newton_in_python_floats_matches_the_float_system():
    """Tracking's planar Newton iterations (Python floats) use FKSystem.float_system's equations."""
    from certkin.fk.tracking import _planar_float_system, _solve
    system = fk_system(robot_from_dict(SIX))
    a, b = system.float_geometry()
    g = np.concatenate([a, b], -1).tolist()
    rng = np.random.default_rng(2)
    for _ in range(50):
        x = rng.uniform(-10, 10, 4)
        L2 = rng.uniform(1, 400, 3)
        f, J = system.float_system(x, L2)
        fp, Jp = _planar_float_system(g, x.tolist(), L2.tolist())
        assert np.allclose(fp, f, rtol=1e-12, atol=1e-9) and np.allclose(Jp, J, rtol=1e-12, atol=1e-9)
        assert np.allclose(_solve(Jp, fp), np.linalg.solve(J, f), rtol=1e-6, atol=1e-9)
    assert _solve([[1.0, 2.0], [2.0, 4.0]], [1.0, 1.0]) is None


def test_tracked_platform_points_are_those_of_the_root_box():
    """The platform points of a tracked step, taken from the proof's evaluation, are exactly
    FKSystem.points of the reported root box."""
    from intervals import Interval
    robot = robot_from_dict(SIX)
    b = forward_kinematics(robot, LENGTHS)
    system = fk_system(robot)
    for s in b.solutions:
        pose = ",".join(repr(float(0.5 * (v.lo + v.hi))) for v in s["pose"].values())
        r = forward_kinematics(robot, [v + 2e-3 for v in (14.98, 15.38, 12.0)], track=pose)
        assert r.tracked
        box = r.solutions[0]["box"]
        ref = system.points(Interval.from_bounds(box.lo[None], box.hi[None]))
        got = r.solutions[0]["platform_points"]
        for i in range(3):
            for c in range(2):
                assert got[i][c].lo == ref.lo[0, i, c] and got[i][c].hi == ref.hi[0, i, c]


def test_direct_length_enclosures_equal_the_parser():
    """One set of leg lengths as floats or plain decimal texts is enclosed directly: the same floats
    and texts as the general parser; anything else goes through the parser (and its errors)."""
    import pytest
    from certkin.errors import InputError
    from certkin.robots.poses import length_enclosures as _length_enclosures, parse_lengths as _parse_lengths
    robot = robot_from_dict(SIX)
    for lengths in (["14.98", "15.38", "12"], " 14.98, 15.38 ,12 ", [14.98, 15.38, 12.0],
                    [np.float64(14.98), 0.1, 1e-300], ["-0", "0.1", "1e5"], ["1000", "2E-3", "7"],
                    [np.float32(14.98), 1.0, 2.0], [15, 15, 12], np.array([14.98, 15.38, 12.0])):
        rho, texts, batch = _length_enclosures(robot, lengths)
        rows, ref_texts, ref_batch = _parse_lengths(robot, lengths)
        assert texts == ref_texts and batch == ref_batch
        assert rho.lo.tolist() == [[float(v.lo) for v in r] for r in rows]
        assert rho.hi.tolist() == [[float(v.hi) for v in r] for r in rows]
    for bad in (["-1", "2", "3"], ["1", "2"], ["1", "2", "3deg"], ["1", "nan", "3"], ["1", "2", "1e400"],
                [1.0, 2.0, -3.0], ["1_000", "2E-3", "7"], ["1e-500", "1", "1"]):
        with pytest.raises(InputError):
            _length_enclosures(robot, bad)
