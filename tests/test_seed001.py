"""Seed 001 (SMAR thesis, Chapter III §3): the 3-RPR planning example, Tables III.1-III.2.

The geometry is the digest's assumption (equilateral base of side 75 and platform of side 15; the
thesis does not state it), bundled as ``seed001-3rpr-planning.toml``.  Reference values: 40-digit
mpmath from the exact decimals (``seedref``), compared with the digest's derived values (§5.2) read
as ± half a unit of their last digit.  The two singularity crossings of the straight path are
tested in ``test_trajectory.test_seed001_singularity_crossings_are_found`` on the same geometry.
"""
from pathlib import Path

import mpmath as mp
import pytest

from certfile import checked
from certkin import load_robot, verify_trajectory
from seedref import encloses, planar_det, planar_legs, prints_as
from test_trajectory import SEED001

FILE = Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed001-3rpr-planning.toml"
P_I, P_F = ["20", "0", "3.0"], ["60", "-50", "6.0"]       # Table III.2, decoded (digest §5.2)


@pytest.fixture(scope="module")
def robot():
    return load_robot(FILE)


def test_robot_file_is_the_assumed_geometry(robot):
    """Equilateral: base side L = 75, platform side l = 15 (Table III.1), C = (L/2, L sqrt(3)/2) with
    sqrt(3)/2 rounded; the same numbers as the geometry of the trajectory test."""
    d = robot.to_dict()
    assert d["base"] == SEED001["base"] and d["platform"] == SEED001["platform"]
    assert robot.limits["leg_length"] == [["10", "200"]] * 3 and robot.home == P_I
    with mp.workdps(30):
        assert abs(mp.mpf("64.952") - 75 * mp.sqrt(3) / 2) < mp.mpf("5e-4")
        assert abs(mp.mpf("12.990381") - 15 * mp.sqrt(3) / 2) < mp.mpf("5e-7")


def ideal_legs(pose):
    """Leg lengths of the exactly equilateral design (sqrt(3) not rounded) at 40 digits."""
    with mp.workdps(40):
        x, y, th = (mp.mpf(v) for v in pose)
        h = mp.sqrt(3) / 2
        base = [(0, 0), (75, 0), (mp.mpf(75) / 2, 75 * h)]
        plat = [(0, 0), (15, 0), (mp.mpf(15) / 2, 15 * h)]
        c, s = mp.cos(th), mp.sin(th)
        return [mp.hypot(x + c * px - s * py - ax, y + s * px + c * py - ay) for (ax, ay), (px, py) in zip(base, plat)]


@pytest.mark.parametrize("pose, texts, leg3", [(P_I, "20.000 69.882 81.284", "81.2845"),
                                               (P_F, "78.102 54.195 109.758", "109.7580")])
def test_leg_lengths_at_the_end_poses(robot, pose, texts, leg3):
    """Digest §5.2: q at P_i and P_f for the equilateral design; the file's rounded sqrt(3)/2 moves leg 3
    by about 1e-4 (81.2845, 109.7580: the values in its comment).  All lie within [q_min, q_max] =
    [10, 200]: a certified feasible static pose."""
    ideal, lengths = ideal_legs(pose), planar_legs(robot, pose)
    enc = robot.leg_lengths(robot.pose_box(pose))
    for k, text in enumerate(texts.split()):
        assert prints_as(ideal[k], text) and encloses(enc, lengths[k], k)
        assert abs(ideal[k] - lengths[k]) < 2e-4
    assert prints_as(lengths[0], texts.split()[0]) and prints_as(lengths[1], texts.split()[1])
    assert prints_as(lengths[2], leg3)
    comment = " ".join(line.lstrip("# ") for line in FILE.read_text().splitlines())
    assert ", ".join(texts.split()) in comment and leg3 in comment
    r = verify_trajectory(robot, ",".join(pose), ",".join(pose), constraints=["leg-length"])
    assert r.status == "feasible"
    for m in r.margins:
        i = m["legs"][0] - 1
        assert m["margin"][0] <= min(lengths[i] - 10, 200 - lengths[i]) <= m["margin"][1]
    checked(r)


def test_det_has_the_same_sign_at_both_ends_only_in_the_decoded_reading(robot):
    """Digest §5.2: det A has the same sign at P_i and P_f (so a singularity-free detour can exist); the
    other reading (20, 0, 0.3) -> (60, +-50, 0.6) puts the ends on opposite sides."""
    def sign(pose):
        ref = planar_det(robot, pose)
        enc = robot.det_enclosure(robot.pose_box(pose))
        assert encloses(enc, ref) and (enc.lo > 0 or enc.hi < 0)
        return mp.sign(ref)
    assert sign(P_I) == sign(P_F)
    for y in ("50", "-50"):
        assert sign(["20", "0", "0.3"]) == -sign(["60", y, "0.6"])
