"""Angle ranges of ``--domain``: a mode is in them when its rotation is, whatever angles name it.

The expected modes come from brute force, not from the filter's own reasoning: rotations sampled
on a fine grid of the angle box, each mode (from the unfiltered search) inside when a sample's
rotation is close to its own, outside when none is near; the cases are chosen with a wide gap
between the two."""
from pathlib import Path

import numpy as np
import pytest

import proofs
from certkin import load_robot, robot_from_dict
from certkin.fk import forward_kinematics
from certkin.fk.angles import in_ranges
from intervals import Interval

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "robots"


def rz(t):
    c, s = np.cos(t), np.sin(t)
    z, o = np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def ry(t):
    c, s = np.cos(t), np.sin(t)
    z, o = np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rx(t):
    c, s = np.cos(t), np.sin(t)
    z, o = np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def sampled_inside(rotations, samples, near=0.02, far=0.1):
    """For each mode's rotation: True when a sampled rotation is within ``near`` (Frobenius), False
    when none is within ``far``; anything between fails the test (a case too close to call)."""
    out = []
    for R in rotations:
        d = np.min(np.linalg.norm((samples - R).reshape(len(samples), -1), axis=1))
        assert d < near or d > far, d
        out.append(bool(d < near))
    return out


def mid(v):
    return 0.5 * (float(v.lo) + float(v.hi))


@pytest.mark.parametrize("phi", [(100.0, 101.0), (0.0, 7.0), (-3.0, -1.0), (2.5, 2.9)])
def test_planar_angle_ranges_are_read_modulo_two_pi(phi):
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    every = forward_kinematics(robot, "28.99,13.66,40.53")
    assert every.complete and len(every.solutions) == 6
    t = np.linspace(*phi, 400001)
    samples = np.stack([np.cos(t), np.sin(t)], -1)
    modes = [np.array([np.cos(mid(s["pose"]["phi"])), np.sin(mid(s["pose"]["phi"]))]) for s in every.solutions]
    expected = sampled_inside(modes, samples, near=1e-4, far=1e-3)
    r = forward_kinematics(robot, "28.99,13.66,40.53", domain=f"x=-50:50,y=-50:50,phi={phi[0]}:{phi[1]}")
    assert r.complete and sum(expected) == len(r.solutions)
    kept = {round(mid(s["pose"]["phi"]), 9) for s in r.solutions}
    assert kept == {round(mid(s["pose"]["phi"]), 9) for s, e in zip(every.solutions, expected) if e}
    assert proofs.check(r.certificate()).ok


def test_spherical_angle_ranges_hold_the_other_euler_triple():
    """(-5pi/6, -pi/3, -5pi/6) names the rotation of one mode, printed (pi/6, pi/3, pi/6): that mode is
    in the box around the first triple; a mode whose second triple is just outside (phi2 -1.15) is not."""
    robot = load_robot(EXAMPLES / "seed003-spherical-example-1.toml")
    lengths = "1.67332005307,2.32606878754,1.74216654891"
    every = forward_kinematics(robot, lengths)
    assert every.complete
    box = {"phi1": (-2.7, -2.5), "phi2": (-1.1, -1.0), "phi3": (-2.7, -2.5)}
    grid = np.meshgrid(*[np.linspace(a, b, 41) for a, b in box.values()], indexing="ij")
    a, b, c = (g.ravel() for g in grid)
    samples = rz(a) @ ry(b) @ rz(c)
    modes = [rz(np.array(mid(s["pose"]["phi1"]))) @ ry(np.array(mid(s["pose"]["phi2"])))
             @ rz(np.array(mid(s["pose"]["phi3"]))) for s in every.solutions]
    expected = sampled_inside(modes, samples, near=0.01, far=0.05)    # (another mode is 0.07 away)
    assert sum(expected) == 1
    r = forward_kinematics(robot, lengths, domain=",".join(f"{k}={lo}:{hi}" for k, (lo, hi) in box.items()))
    assert r.complete and len(r.solutions) == 1
    (s,) = r.solutions
    (e,) = [m for m, inside in zip(every.solutions, expected) if inside]
    assert all(abs(mid(s["pose"][k]) - mid(e["pose"][k])) < 1e-9 for k in box)
    assert proofs.check(r.certificate()).ok


@pytest.mark.parametrize("seed", range(5))
def test_the_other_gough_triple_names_the_same_rotation_and_is_inside(seed):
    """Rz(psi) Rx(theta) Rz(phi) = Rz(psi + pi) Rx(-theta) Rz(phi + pi), checked numerically; a range
    holding only the second triple (shifted by 2 pi) holds the pose, one holding neither does not."""
    rng = np.random.default_rng(seed)
    psi, theta, phi = rng.uniform(-3, 3), rng.uniform(0.2, 2.9), rng.uniform(-3, 3)
    R = rz(np.array(psi)) @ rx(np.array(theta)) @ rz(np.array(phi))
    assert np.allclose(R, rz(np.array(psi + np.pi)) @ rx(np.array(-theta)) @ rz(np.array(phi + np.pi)))
    pose = {k: Interval.from_bounds(np.array(v - 1e-9), np.array(v + 1e-9)) for k, v in
            (("x", 0.0), ("psi", psi), ("theta", theta), ("phi", phi))}
    other = (psi + np.pi + 2 * np.pi, -theta, phi + np.pi - 2 * np.pi)
    near = {k: (v - 0.01, v + 0.01) for k, v in zip(("psi", "theta", "phi"), other)}
    assert in_ranges(pose, near) is True
    assert in_ranges(pose, {"theta": (-theta - 0.01, -theta + 0.01)}) is True
    assert in_ranges(pose, {"theta": (theta + 0.05, theta + 0.06)}) is False
    assert in_ranges(pose, {"psi": (psi + 0.5, psi + 0.6), "theta": (theta - 0.1, theta + 0.1)}) is False
    assert in_ranges(pose, {"psi": (psi - 0.1, psi + 0.1), "theta": (-4.0, 4.0)}) is True


def test_postures_where_the_euler_angles_are_free_are_named_as_such():
    """R = I and R = Rz(pi) Rx(pi) (phi2 = 0 and pi: phi1 and phi3 not determined, only their sum or
    difference) are postures of this spherical robot at lengths 3, 3, 4 (|a_i − b_i| and |a_i − R b_i|,
    exact integers).  With a range on phi1 alone they are neither inside nor outside it; the note said
    they lie "on an edge of the angle ranges", far from any edge: it now names this case too."""
    robot = robot_from_dict({"name": "r6", "kind": "spherical-3dof", "base": [[4, 1, 2], [0, 0, -1], [-2, 0, 4]],
                             "platform": [[2, 0, 0], [2, -2, 0], [-2, 0, 0]]})
    a, b = np.array(robot.base, float), np.array(robot.platform, float)
    assert np.linalg.norm(a - b, axis=1).tolist() == [3.0, 3.0, 4.0]
    flip = np.diag([1.0, -1.0, -1.0])        # Rx(pi): the same lengths (exact: integer coordinates)
    assert np.linalg.norm(a - b @ flip.T, axis=1).tolist() == [3.0, 3.0, 4.0]
    r = forward_kinematics(robot, "3,3,4", domain="phi1=-0.1:0.1")
    assert not r.complete
    assert "angles are not determined (a middle angle of 0 or pi leaves the other two free)" in r.message


def test_an_angle_range_ending_on_a_mode_leaves_it_unresolved_never_dropped():
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    every = forward_kinematics(robot, "28.99,13.66,40.53")
    phi = next(mid(s["pose"]["phi"]) for s in every.solutions)
    r = forward_kinematics(robot, "28.99,13.66,40.53", domain=f"x=-50:50,y=-50:50,phi={phi!r}:{phi + 0.001!r}")
    assert not r.complete and len(r.unresolved) >= 1
    assert "1 posture proved unique in the box searched lies on an edge of the angle ranges" in r.message
    pose = {"phi": Interval.from_bounds(np.array(-np.pi), np.array(np.pi))}
    assert in_ranges(pose, {"phi": (0.0, 1.0)}) is None           # an enclosure of every angle: cannot tell


@pytest.mark.parametrize("domain", ["x=1000:2000,y=-20:0,phi=0:2", "x=40:45,y=-50:50,phi=-4:4"])
def test_a_domain_the_leg_lengths_cannot_reach_is_searched_not_called_empty(domain):
    """A position range that misses the range the leg lengths allow made the domain 'empty', which the
    certificate states as "these lengths allow no posture at all" (6 exist): the user's range is searched."""
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    r = forward_kinematics(robot, "28.991,13.66,40.53", domain=domain)
    assert r.complete and not r.solutions
    cert = r.certificate()
    claim = cert.header["claims"][0]
    assert claim["domain"] != "empty" and claim["covers"] == "box"
    assert proofs.check(cert).ok


def test_track_and_domain_together_are_refused():
    from certkin import InputError
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    with pytest.raises(InputError) as exc:
        forward_kinematics(robot, "28.99,13.66,40.53", track="13.3,-17,1.13", domain="x=1000:2000,y=-20:0,phi=0:2")
    assert exc.value.source == "domain"


def test_a_posture_on_the_domains_boundary_is_unresolved_with_the_reason():
    """The home pose of planar example 2 has x = 10: with x=10:11 it lies on the boundary; the answer is
    incomplete (the root box crosses the bound) and now says why."""
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    lengths = ",".join(repr(float(v)) for v in robot.leg_lengths(robot.home_box()).mid())
    r = forward_kinematics(robot, lengths, domain="x=10:11,y=0:20,phi=-4:4")
    assert not r.complete and len(r.unresolved) == 1
    assert "1 posture lies across the boundary of the domain" in r.message


FACE = {"name": "posture (0, 0, 0) at lengths 5, 10, 13", "kind": "planar-3rpr",
        "base": [["3", "4"], ["10", "8"], ["-5", "16"]], "platform": [["0", "0"], ["4", "0"], ["0", "4"]]}


@pytest.mark.parametrize("domain", ["x=-5:0", "y=-3:0"])
def test_a_posture_on_a_face_of_the_domain_says_so(domain, monkeypatch):
    """The posture x = y = phi = 0 (exact: |a_i - b_i| = 5, 10, 13, a regular posture) on the upper face of
    the domain: it is proved unique in a box across the face, reported unresolved (the answer incomplete),
    and the note says to move the bound.  With ε-inflation kept to slivers (2^-40) the search ends there in
    a cluster, which holds it, and the note names the face."""
    import certkin.fk.search as fk_search
    from certkin import robot_from_dict
    r = forward_kinematics(robot_from_dict(FACE), "5,10,13", domain=domain)
    assert not r.complete and len(r.unresolved) == 1 and not r.clusters
    box = r.unresolved[0]["pose"]
    assert all(float(box[n].lo) <= 0 <= float(box[n].hi) for n in ("x", "y", "phi"))
    assert "1 posture lies across the boundary of the domain" in r.message
    assert proofs.check(r.certificate()).ok
    monkeypatch.setattr(fk_search, "INFLATE_BELOW", 2.0 ** -40)
    r = forward_kinematics(robot_from_dict(FACE), "5,10,13", domain=domain)
    assert r.complete and len(r.clusters) == 1
    box = r.clusters[0]["box"]
    assert np.all(box.lo[:2] <= 0) and np.all(box.hi[:2] >= 0)
    assert "a posture on a face of the domain" in r.message
    assert proofs.check(r.certificate()).ok


def test_a_domain_names_only_the_variables_it_narrows():
    """--domain "x=30:40" was refused (every variable needed); the modes it holds are those of the full
    answer with x in [30, 40] (the three at x = 30.1, 34.9 and 38.5), each proved, complete."""
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    every = forward_kinematics(robot, "28.99,13.66,40.53")
    r = forward_kinematics(robot, "28.99,13.66,40.53", domain="x=30:40")
    expected = sorted(round(mid(s["pose"]["x"]), 9) for s in every.solutions if 30 < mid(s["pose"]["x"]) < 40)
    assert r.complete and sorted(round(mid(s["pose"]["x"]), 9) for s in r.solutions) == expected
    assert len(expected) == 3
    assert len(forward_kinematics(robot, "28.99,13.66,40.53", domain={"phi": (-0.5, 0.5)}).solutions) == 3
    assert in_ranges({"phi": Interval.from_bounds(np.array(0.1), np.array(0.2))}, {"phi": (-1e12, 1e12)}) is True


def test_a_planar_posture_at_phi_pi_is_enclosed_near_pi_and_filtered():
    """Seed 003 example 2 with the leg lengths of the pose (20, 5, pi) to 30 digits (mpmath): the root box
    crosses phi = ±pi, and atan2 gave phi = [-pi, pi], so any angle range of --domain left the posture
    unresolved (blaming "a middle angle of 0 or pi", which a planar robot does not have).  Its angle is
    now enclosed near pi; phi in [3.1, 3.2] keeps it, phi in [-1, 1] drops it, both complete."""
    import mpmath
    robot = load_robot(str(EXAMPLES / "seed003-planar-example-2.toml"))
    a = [("3.78", "4.34"), ("34.47", "-3.78"), ("16.233", "34.76")]
    b = [("-4.83", "-3.19"), ("12.04", "-3.19"), ("8.23", "12.09")]
    with mpmath.workdps(40):
        lengths = ",".join(mpmath.nstr(mpmath.sqrt((20 - mpmath.mpf(bx) - mpmath.mpf(ax)) ** 2
                                                   + (5 - mpmath.mpf(by) - mpmath.mpf(ay)) ** 2), 30)
                           for (ax, ay), (bx, by) in zip(a, b))
    everything = forward_kinematics(robot, lengths)
    near = [s for s in everything.solutions if float(s["box"].lo[0]) <= 20 <= float(s["box"].hi[0])]
    assert len(near) == 1 and near[0]["box"].lo[3] <= 0 <= near[0]["box"].hi[3]          # sin phi ∋ 0
    phi = near[0]["pose"]["phi"]
    assert 3.1415 < float(phi.lo) <= np.pi <= float(phi.hi) < 3.1417
    kept = forward_kinematics(robot, lengths, domain="x=-100:100,y=-100:100,phi=3.1:3.2")
    assert kept.complete and any(float(s["box"].lo[0]) <= 20 <= float(s["box"].hi[0]) for s in kept.solutions)
    dropped = forward_kinematics(robot, lengths, domain="x=-100:100,y=-100:100,phi=-1:1")
    assert dropped.complete and not any(float(s["box"].lo[0]) <= 20 <= float(s["box"].hi[0]) for s in dropped.solutions)
    assert proofs.check(kept.certificate()).ok
