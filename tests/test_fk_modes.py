"""Forward kinematics where roots are hard to place: on the domain's faces and split planes,
symmetric robots at home, double roots (clusters), continua, uncertain leg lengths, large searches.

References are derived independently of the solver: the exact planar elimination of
``test_fk.exact_planar`` (sympy), the generating pose of the lengths, and, for the clusters,
a singular pose located by bisection of det(A) in floats (the solver must cover it, not find it).
"""
import json
import subprocess
import sys
from decimal import Decimal

import mpmath as mp
import numpy as np
import pytest

import proofs
from certfile import Doc
from certkin import load_robot, robot_from_dict
from certkin.engine import budgets
from certkin.engine.budgets import Budget
from certkin.errors import InputError
from certkin.fk import forward_kinematics
from test_fk import EXAMPLES, SIX_MODES, _contains, _points, assert_matches_exact, checked, exact_planar, planar

ISSUE_BASE, ISSUE_PLATFORM = [(0, 0), (10, 0), (3, 10)], [(0, 0), (4, 0), (2, 2)]


def planar_lengths(robot, pose, digits=25):
    """Leg lengths of a planar pose at ``digits`` decimals (mpmath, 40 digits)."""
    with mp.workdps(40):
        x, y, phi = (mp.mpf(v) for v in pose)
        out = []
        for (ax, ay), (bx, by) in zip(robot.base, robot.platform):
            ax, ay, bx, by = (mp.mpf(str(v)) for v in (ax, ay, bx, by))
            lx = x + mp.cos(phi) * bx - mp.sin(phi) * by - ax
            ly = y + mp.sin(phi) * bx + mp.cos(phi) * by - ay
            out.append(mp.nstr(mp.sqrt(lx ** 2 + ly ** 2), digits, strip_zeros=False))
        return out


def pose_points(robot, pose):
    """World platform points of a float pose (mpmath)."""
    x, y, phi = (mp.mpf(v) for v in pose)
    return [(x + mp.cos(phi) * mp.mpf(str(bx)) - mp.sin(phi) * mp.mpf(str(by)),
             y + mp.sin(phi) * mp.mpf(str(bx)) + mp.cos(phi) * mp.mpf(str(by))) for bx, by in robot.platform]


# ----- roots on faces and split planes ------------------------------------------------------------
@pytest.mark.parametrize("pose", [(5, 5, 0), ("5.01", 5, 0), (5, 5, "0.001"), (0, 5, 0)])
def test_a_mode_at_phi_zero_or_on_a_plane_is_proved_unique(pose):
    """Issue #16: the mode x = 5, y = 5, phi = 0 (c = cos phi = 1, on the face of [-1, 1]) was left
    unresolved; every exact posture is now in exactly one unique box, and the answer is complete."""
    robot = planar(ISSUE_BASE, ISSUE_PLATFORM)
    lengths = planar_lengths(robot, pose)
    exact = exact_planar(ISSUE_BASE, ISSUE_PLATFORM, lengths)
    result = forward_kinematics(robot, lengths)
    assert_matches_exact(result, exact)
    gen = pose_points(robot, pose)      # the generating pose, within the rounding of its lengths
    assert any(all(b[0] - 1e-12 <= g <= b[1] + 1e-12 for bp, gp in zip(_points(s), gen) for b, g in zip(bp, gp))
               for s in result.solutions)
    checked(result)


def symmetric_gough(height="1.2"):
    """A hexapod with planar base and platform, joints in symmetric pairs (mirror x -> -x): its home
    pose (0, 0, h, identity) has q = (1, 0, 0, 0) on the face q0 = 1 of the old domain and x = 0,
    q1 = q2 = q3 = 0 on symmetry planes."""
    base = [[-0.9, 0.5, 0], [0.9, 0.5, 0], [1.2, -0.1, 0], [0.3, -1.1, 0], [-0.3, -1.1, 0], [-1.2, -0.1, 0]]
    plat = [[-0.3, 0.6, 0], [0.3, 0.6, 0], [0.7, -0.1, 0], [0.4, -0.5, 0], [-0.4, -0.5, 0], [-0.7, -0.1, 0]]
    return robot_from_dict({"name": "symmetric test hexapod", "kind": "gough-stewart",
                            "base": [[str(c) for c in p] for p in base], "platform": [[str(c) for c in p] for p in plat],
                            "home": [0, 0, height, 0, 0, 0]})


def test_symmetric_hexapod_home_posture_is_proved_unique_and_certified():
    """The identity rotation on the domain's old face, x = 0 and q1 = q2 = q3 = 0 on symmetry planes:
    the home posture lies in exactly one unique box.  The position is narrowed so that the checker
    re-verifies the certificate quickly; the rotation keeps its full range (the face is tested)."""
    robot = symmetric_gough()
    home = robot.home_box()
    lengths = [Decimal(str(v)) for v in robot.leg_lengths(home).mid()]
    texts = [format(v, "f") for v in lengths]
    result = forward_kinematics(robot, texts, domain="x=-0.1:0.1,y=-0.1:0.1,z=1.1:1.3,psi=-4:4,theta=-4:4,phi=-4:4")
    assert result.complete
    home_points = robot.platform_points(home)
    hits = [s for s in result.solutions
            if all(float(c.lo) - 1e-9 <= float(h.lo) and float(h.hi) <= float(c.hi) + 1e-9
                   for p, hp in zip(s["platform_points"], home_points) for c, h in zip(p, hp))]
    assert len(hits) == 1
    q = hits[0]["box"]
    assert float(q.lo[3]) <= 1.0 <= float(q.hi[3])     # the identity: q0 = 1, inside the box
    checked(result)


def test_domain_reaches_beyond_the_unit_sphere_and_checker_accepts_it():
    robot = symmetric_gough()
    r = forward_kinematics(robot, "1,1,1,1,1,1", budget=Budget(max_boxes=2000, max_seconds=60, min_width=1e-10))
    lo, hi = r.domain
    assert lo[3] < 0 and hi[3] > 1 and np.all(lo[4:] < -1) and np.all(hi[4:] > 1)
    claim = r.certificate().header["claims"][0]
    assert claim["covers"] == "all-postures"
    assert proofs.check(r.certificate()).ok


# ----- clusters and continua ------------------------------------------------------------------------
def singular_pose(robot):
    """A pose with det(A) = 0 (floats, bisection in phi at x = y = 5)."""
    f = lambda t: robot.det_float(np.array([5.0, 5.0, t]))  # noqa: E731
    a, b = -3.0, -2.9
    assert f(a) * f(b) < 0
    for _ in range(60):
        m = 0.5 * (a + b)
        a, b = (m, b) if f(a) * f(m) > 0 else (a, m)
    return (5.0, 5.0, 0.5 * (a + b))


def test_lengths_at_a_singular_pose_give_a_cluster_and_a_complete_answer():
    """A double root (lengths of a singular pose): reported as a cluster, never unique; the rest of
    the domain is excluded, so the answer is complete; the cluster holds the singular pose."""
    robot = planar(ISSUE_BASE, ISSUE_PLATFORM)
    pose = singular_pose(robot)
    lengths = planar_lengths(robot, pose, 17)
    result = forward_kinematics(robot, lengths)
    assert result.complete and result.solutions == [] and len(result.clusters) == 1
    assert repr(result).startswith("<FKResult 0 solutions, complete, 1 cluster (not resolved), 0 unresolved;")
    doc = result.to_json()
    assert [s["status"] for s in doc["solutions"]] == ["cluster"]
    assert _contains([[(float(c.lo), float(c.hi)) for c in p] for p in result.clusters[0]["platform_points"]],
                     pose_points(robot, pose))
    cert = Doc(result.certificate())
    report = cert.check()
    assert report.ok and cert.claim()["figures"]["leaves"]["in-cluster"] > 0, report.step
    shrunk = cert.copy()
    box = shrunk.claim()["clusters"][0]
    box[0][1] = box[0][0] + 0.25 * (box[0][1] - box[0][0])      # some cluster leaf now sticks out
    report = shrunk.check()
    assert not report.ok and "not inside the named box" in report.step
    complete_without = cert.copy()
    del complete_without.claim()["clusters"]
    assert not complete_without.check().ok


def test_a_report_names_the_cluster(tmp_path):
    """The report of an answer with a cluster once said "0 assembly modes, each proved unique in its
    box; the rest of the domain is proved to hold none" and "No posture.": the cluster may hold the
    (double) posture, so the verdict names it and the table lists its box."""
    from certkin.report.fk import fk_report, fk_verdict
    robot = planar(ISSUE_BASE, ISSUE_PLATFORM)
    result = forward_kinematics(robot, planar_lengths(robot, singular_pose(robot), 17))
    assert result.complete and len(result.clusters) == 1
    verdict = fk_verdict(result)
    assert verdict.startswith("0 assembly modes proved unique in their boxes, 1 cluster that may hold postures")
    fk_report(robot, result, tmp_path / "r.html")
    page = (tmp_path / "r.html").read_text()
    assert "cluster 1" in page and "No posture." not in page
    cut = forward_kinematics(robot, planar_lengths(robot, (5.0, 5.0, 0.0), 17), max_boxes=10)
    assert not cut.complete
    assert fk_verdict(cut).endswith("left unresolved (the box budget ran out before every region was decided).")


def test_a_continuum_of_modes_ends_undecided_with_a_message():
    """Congruent base and platform with equal legs: the platform translates on a circle (phi = 0),
    a continuum; the search cannot finish, says so, and claims nothing about it."""
    robot = planar(ISSUE_BASE, ISSUE_BASE)
    result = forward_kinematics(robot, "5,5,5", budget=Budget(max_boxes=60_000, max_seconds=120, min_width=1e-10))
    assert not result.complete
    assert "continuum" in result.message
    assert "continuum" in result.to_json()["message"]
    assert all(abs(float(s["pose"]["phi"].lo)) > 1e-3 for s in result.solutions)   # only isolated modes proved
    checked(result)     # its steps next to the continuum (singular midpoints) re-checked too


def test_a_certificate_next_to_a_continuum_checks():
    """The self-motion of a congruent robot on the circle x² + y² = 25 (phi = 0): every Jacobian
    midpoint there is singular to rounding (cond 10¹⁵), and a contraction whose preconditioner was a
    pseudo-inverse (no inverse at all) was rejected by the checker, whose own inverse of the same
    midpoint is another matrix (``step.fragile`` now keeps such a C in the certificate)."""
    robot = planar([(0, 0), (10, 0), (0, 10)], [(0, 0), (10, 0), (0, 10)])
    result = forward_kinematics(robot, "5,5,5", budget=Budget(max_boxes=20_000))
    assert not result.complete and "continuum" in result.message
    assert all(abs(float(s["pose"]["phi"].lo)) > 1e-3 for s in result.solutions)   # only isolated modes proved
    checked(result)


@pytest.mark.parametrize("platform, h", [([[1, 0, 0], [-0.5, 1.5, 0], [-0.5, -1.5, 0]], "4"),
                                         ([[1, 0, 0], [-0.5, 1.5, 0], [-0.5, -1.5, 0]], "3"),
                                         ([[1, 0.2, 0], [-0.7, 1.1, 0], [0.3, -1.4, 0]], "1")])
def test_spherical_robot_with_vertical_legs_at_home_gives_a_cluster_its_checker_accepts(platform, h):
    """Base points straight below the platform's (a_i = b_i − (0, 0, h)), lengths h: home (q = 1) is a
    posture, and a singular one (a turn about z changes the lengths at second order only), so the
    answer is a cluster holding home, complete.  Its certificate was rejected ("the checker's result is
    not inside the child box on q2") at 12 of 18 such robots: slope steps over boxes 1e-15 wide in q1, q2
    were decided by the equations' rounding, which the checker's own evaluation does not reproduce;
    the contractions now keep ``ROOM`` of 1 (the quaternion's scale) for the checker."""
    robot = robot_from_dict({"name": "above", "kind": "spherical-3dof", "platform": platform,
                             "base": [[x, y, f"-{h}"] for x, y, _ in platform]})
    result = forward_kinematics(robot, f"{h},{h},{h}")
    assert result.complete and result.solutions == [] and len(result.clusters) == 1
    home = [[mp.mpf(str(v)) for v in b] for b in platform]
    assert _contains([[(float(c.lo), float(c.hi)) for c in p] for p in result.clusters[0]["platform_points"]], home)
    report = Doc(result.certificate()).check()
    assert report.ok, report.step


def test_a_cluster_that_is_a_mode_again_with_its_quaternion_negated_is_named_so(monkeypatch):
    """A rotation about x by nearly pi (q0 about 2^-10) is a posture of this spherical robot; its other
    quaternion −q lies on the domain's face q0 = −2^-10.  With ε-inflation started from the last
    Krawczyk contraction, −q is proved there too and recognised as a mode's twin: 4 modes, no cluster
    (a reviewer's solver finds 4 real postures).  With inflation kept to slivers (2^-40, as when it
    started from the box before the contraction) the search ends in a cluster on the face: the answer
    listed it as "holding any number of postures", though it is mode 2 again (its platform points are
    mode 2's).  With the cluster's box negated inside mode 2's uniqueness box, it is named as that mode's
    twin (``twin_of``); the certificate, which still lists the cluster, checks."""
    import certkin.fk.search as fk_search
    robot = robot_from_dict({"name": "r6", "kind": "spherical-3dof", "base": [[4, 1, 2], [0, 0, -1], [-2, 0, 4]],
                             "platform": [[2, 0, 0], [2, -2, 0], [-2, 0, 0]]})
    result = forward_kinematics(robot, "3,2.998697634594940,4")
    assert result.complete and len(result.solutions) == 4 and not result.clusters
    assert Doc(result.certificate()).check().ok
    monkeypatch.setattr(fk_search, "INFLATE_BELOW", 2.0 ** -40)
    result = forward_kinematics(robot, "3,2.998697634594940,4")
    assert result.complete and len(result.solutions) == 4 and len(result.clusters) == 1
    k = result.clusters[0]["twin_of"]
    same = [[max(float(a.lo), float(b.lo)) <= min(float(a.hi), float(b.hi)) for a, b in zip(pa, pb)]
            for pa, pb in zip(result.clusters[0]["platform_points"], result.solutions[k]["platform_points"])]
    assert all(all(row) for row in same)              # the same world points: the same posture
    assert result.message.startswith(f"cluster 1 is mode {k + 1} again") and "any number" not in result.message
    assert result.to_json()["solutions"][-1] == {**result.to_json()["solutions"][-1], "status": "cluster", "twin_of": k + 1}
    report = Doc(result.certificate()).check()
    assert report.ok, report.step


# ----- uncertain leg lengths ------------------------------------------------------------------------
def corners(lengths, tol):
    """The 2^3 corner length vectors of [v - tol, v + tol] as exact decimal texts."""
    out = [[]]
    for v in lengths:
        out = [c + [str(Decimal(v) + s * Decimal(tol))] for c in out for s in (-1, 1)]
    return out


@pytest.mark.parametrize("base,plat,lengths", SIX_MODES)
def test_uncertain_lengths_each_mode_box_holds_the_postures_of_every_corner(base, plat, lengths):
    """±0.001 on every leg: each of the 6 modes is one box proved to hold, for every length vector,
    exactly one posture; the exact postures at the corners of the length box (sympy elimination)
    lie each in exactly one box, and each box is at most 2x their spread per unknown (x, y, cos phi,
    sin phi).  (Platform points are evaluated over the box, so they are wider: the box does not
    know that x and phi move together.)"""
    robot = planar(base, plat)
    tol = "0.001"
    result = forward_kinematics(robot, [f"{v}+-{tol}" for v in lengths])
    assert result.complete and len(result.solutions) == 6 and not result.clusters
    assert result.lengths == [f"{Decimal(v) - Decimal(tol)}:{Decimal(v) + Decimal(tol)}" for v in lengths]
    members = {k: [] for k in range(6)}
    for c in corners(lengths, tol):
        exact = exact_planar(base, plat, c)
        assert len(exact) == 6
        for e in exact:
            hits = [k for k, s in enumerate(result.solutions) if _contains(_points(s), e)]
            assert len(hits) == 1
            members[hits[0]].append(e)
    for k, s in enumerate(result.solutions):
        exact_unknowns = np.array([unknowns(plat, e) for e in members[k]])
        spread = exact_unknowns.max(axis=0) - exact_unknowns.min(axis=0)
        width = s["box"].hi - s["box"].lo
        assert np.all(width <= 2.0 * spread + 1e-12)
    checked(result)


def test_the_readme_tolerance_example_proves_all_six_modes():
    """README: ``--lengths 28.99:29.01,13.66,40.53`` (±0.01 on leg 1): six modes, each proved unique for
    every length in the ranges, no cluster; the exact postures at both ends of the range (sympy
    elimination) lie each in exactly one box, every box holding one of each end."""
    base, plat, _ = SIX_MODES[1]
    result = forward_kinematics(planar(base, plat), "28.99:29.01,13.66,40.53")
    assert result.complete and len(result.solutions) == 6 and not result.clusters
    for end in ("28.99", "29.01"):
        exact = exact_planar(base, plat, [end, "13.66", "40.53"])
        hits = sorted(k for e in exact for k, s in enumerate(result.solutions) if _contains(_points(s), e))
        assert len(exact) == 6 and hits == list(range(6))
    checked(result)


def unknowns(plat, points):
    """(x, y, c, s) of a posture given by its world platform points: R (b2 − b1) = P2 − P1."""
    b = [np.array([float(v) for v in p]) for p in plat]
    P = [np.array([float(v) for v in p]) for p in points]
    u, v = b[1] - b[0], P[1] - P[0]
    c = (u @ v) / (u @ u)
    s = (u[0] * v[1] - u[1] * v[0]) / (u @ u)
    origin = P[0] - np.array([c * b[0][0] - s * b[0][1], s * b[0][0] + c * b[0][1]])
    return [origin[0], origin[1], c, s]


def test_uncertain_lengths_tampered_certificate_is_rejected():
    base, plat, lengths = SIX_MODES[0]
    result = forward_kinematics(planar(base, plat), [f"{v}+-0.001" for v in lengths])
    cert = Doc(result.certificate())
    assert cert.check().ok and len(cert.claim()["length_ranges"]) == 3
    wider = cert.copy()                                # the claim stated for wider ranges than solved
    lo, hi = wider.claim()["length_ranges"][0]
    wider.claim()["length_ranges"][0] = [str(float(lo) - 1), str(float(hi) + 1)]
    assert not wider.check().ok
    tight = cert.copy()                                # a solution's box R shrunk to the nominal posture
    R = tight.arrays["fk.region.box"][0]
    mid = 0.5 * (R[:, 0] + R[:, 1])
    R[:, 0], R[:, 1] = mid - 1e-9 * abs(mid) - 1e-12, mid + 1e-9 * abs(mid) + 1e-12
    report = tight.check()
    assert not report.ok and "regions[0]" in report.step


def test_length_ranges_are_parsed_exactly_and_checked():
    robot = planar(*SIX_MODES[1][:2])
    from certkin.robots.poses import parse_lengths
    rows, texts, _ = parse_lengths(robot, "28.99:29.01,13.66+-0.005,40.53")
    assert texts == [["28.99:29.01", "13.655:13.665", "40.53"]]
    assert float(rows[0][0].lo) <= 28.99 and float(rows[0][0].hi) >= 29.01
    for bad in ("29.01:28.99,13.66,40.53", "29:30:31,13.66,40.53", "29+-x,13.66,40.53", "29+--1,13.66,40.53"):
        with pytest.raises(InputError):
            parse_lengths(robot, bad)


def test_cli_takes_length_ranges(tmp_path):
    """The issue's form: ``--lengths 28.99:29.01,13.66,40.53``."""
    base, plat, _ = SIX_MODES[1]
    path = tmp_path / "robot.toml"
    path.write_text('kind = "planar-3rpr"\nbase = [' + ", ".join(f"[{a}, {b}]" for a, b in base) + "]\n"
                    "platform = [" + ", ".join(f"[{a}, {b}]" for a, b in plat) + "]\n")
    cert = tmp_path / "c.json"
    out = subprocess.run([sys.executable, "-m", "certkin", "fk", str(path), "--lengths", "28.99:29.01,13.66,40.53",
                          "--json", "--certificate", str(cert)], capture_output=True, text=True, check=True)
    doc = json.loads(out.stdout)
    assert doc["complete"] and doc["lengths"][0] == "28.99:29.01"
    assert all(s["status"] in ("unique", "cluster") for s in doc["solutions"])
    assert proofs.check(str(cert)).ok


# ----- large searches -------------------------------------------------------------------------------
def test_a_search_past_the_record_limit_gives_the_same_answer_and_a_valid_certificate(monkeypatch):
    robot = load_robot(EXAMPLES / "seed003-spherical-example-1.toml")
    lengths = [repr(float(v)) for v in robot.leg_lengths(robot.home_box()).mid()]
    whole = forward_kinematics(robot, lengths)
    monkeypatch.setattr(budgets, "FK_RECORD_NODES", 500)
    light = forward_kinematics(robot, lengths)
    assert whole.tree.complete_record and not light.tree.complete_record
    assert len(light.tree.kind) < len(whole.tree.kind)
    assert light.boxes == whole.boxes and light.complete and whole.complete
    assert [[float(v.lo) for v in s["pose"].values()] for s in light.solutions] == \
        [[float(v.lo) for v in s["pose"].values()] for s in whole.solutions]
    checked(light)                                     # the certificate runs the search again, tree kept


def test_many_separate_cluster_leaves_are_grouped_in_bounded_work():
    """10 000 separate boxes (a budget cut a search with cluster leaves everywhere): at most
    ``MAX_GROUPS`` groups, every box in exactly one (runs of neighbours joined first: the pairwise
    joining of 10 000 groups outlasted the search's own time budget)."""
    from certkin.fk import api
    rng = np.random.default_rng(0)
    lo = rng.uniform(0, 1, (10_000, 3))
    hi = lo + 1e-7
    groups = api._touching(lo, hi)
    assert len(groups) <= api.MAX_GROUPS
    members = np.concatenate(groups)
    assert sorted(members.tolist()) == list(range(10_000))
    few = api._touching(lo[:50], hi[:50])                       # few separate boxes: one group each
    assert len(few) == 50


def test_newton_reach_is_small_for_a_thin_jacobian_and_large_beside_a_singular_one():
    """|I − C J| with C the inverse of J's midpoint: 0 for a point matrix, about rad/σ for a matrix
    of radius rad whose midpoint has smallest singular value σ (near 1e-3 here: far above 1)."""
    from certkin.fk.search import newton_reach
    from intervals import Interval
    J = np.array([[[2.0, 1.0], [1.0, 3.0]], [[1.0, 1.0], [1.0, 1.001]]])
    C = np.linalg.inv(J)
    thin = newton_reach(C, Interval.from_bounds(J, J))
    wide = newton_reach(C, Interval.from_bounds(J - 0.01, J + 0.01))
    assert thin[0] < 1e-12 and thin[1] < 1e-9
    assert wide[0] < 0.1 and wide[1] > 10


@pytest.mark.slow
def test_uncertain_lengths_beside_nearly_singular_jacobians_give_one_posture_a_cluster():
    """Seed 002's 24-solution robot with every length within ±1e-4 (relative): complete, and each of
    the 24 postures of the nominal lengths (proved unique, the certificate checked) lies in exactly one
    unique box or cluster, no cluster holding two.  Boxes up to 0.06 wide beside nearly singular
    Jacobians were given up as clusters, and one cluster held 4 postures (``newton_reach``)."""
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    nominal = ["1.093", "2.280", "2.031", "2.524", "3.136", "1.845"]
    exact = forward_kinematics(robot, ",".join(nominal))
    assert exact.complete and len(exact.solutions) == 24 and proofs.check(exact.certificate()).ok
    t = Decimal("1e-4")
    r = forward_kinematics(robot, ",".join(f"{Decimal(v) * (1 - t)}:{Decimal(v) * (1 + t)}" for v in nominal))
    assert r.complete
    boxes = [s["box"] for s in r.solutions] + [c["box"] for c in r.clusters]
    held = np.zeros(len(boxes), dtype=int)
    for s in exact.solutions:
        x = s["box"].mid()
        inside = [k for k, b in enumerate(boxes) if np.all((b.lo <= x) & (x <= b.hi))]
        assert len(inside) == 1
        held[inside] += 1
    assert np.all(held[:len(r.solutions)] == 1) and np.all(held[len(r.solutions):] <= 1)
    assert proofs.check(r.certificate()).ok


def test_separate_sets_of_cluster_leaves_stay_separate_clusters():
    """1500 separate sets of 20 overlapping boxes each (in random order, 30 000 boxes: more first
    groups than ``MAX_GROUPS``): one group per set, found by cutting at gaps.  Joining runs of
    neighbouring groups to bound the work, as before, merged such sets (seed 002 with lengths
    within 1e-4: 16 sets, one cluster as wide as the domain)."""
    from certkin.fk import api
    rng = np.random.default_rng(1)
    centres = rng.uniform(0, 1000, (1500, 3))
    steps = np.cumsum(rng.uniform(0, 0.01, (1500, 20, 3)), axis=1)      # a chain of overlapping boxes
    lo = (centres[:, None, :] + steps).reshape(-1, 3)
    hi = lo + 0.02
    shuffle = rng.permutation(len(lo))
    groups = api._touching(lo[shuffle], hi[shuffle])
    sets = sorted(sorted((shuffle[g] // 20).tolist()) for g in groups)
    assert sets == [[k] * 20 for k in range(1500)]


def test_cut_groups_partition_the_boxes_and_their_hulls_never_meet():
    """Random boxes: every box in exactly one group, and no box (nor hull) of one group meets one of
    another: a group's hull is a sound cluster box holding every posture of its boxes."""
    from certkin.fk import api
    rng = np.random.default_rng(2)
    for _ in range(200):
        n, d = rng.integers(1, 40), rng.integers(1, 5)
        lo = rng.uniform(0, 10, (n, d))
        hi = lo + rng.uniform(0, 2, (n, d))
        groups = api._touching(lo, hi)
        assert sorted(np.concatenate(groups).tolist()) == list(range(n))
        label = np.empty(n, dtype=int)
        for k, g in enumerate(groups):
            label[g] = k
        meet = np.all((lo[:, None] <= hi[None]) & (lo[None] <= hi[:, None]), axis=2)
        assert not np.any(meet & (label[:, None] != label[None]))
        H = np.array([lo[g].min(axis=0) for g in groups]), np.array([hi[g].max(axis=0) for g in groups])
        hulls_meet = np.all((H[0][:, None] <= H[1][None]) & (H[0][None] <= H[1][:, None]), axis=2)
        assert np.array_equal(hulls_meet, np.eye(len(groups), dtype=bool))


def test_wide_length_ranges_are_not_said_to_exhaust_a_budget():
    """Lengths 28.9:29.1 leave clusters within a small budget's reach (1700 boxes, no budget hit): the
    note says what happened (the swept regions could not be told apart), not that a budget ran out."""
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    r = forward_kinematics(robot, "28.9:29.1,13.66,40.53", max_seconds=20)
    assert len(r.clusters) > 1 and r.boxes < 20_000     # (complete since inflation starts from contracted boxes)
    assert "budget" not in r.message and "length ranges" in r.message and "self-motion" not in r.message
    assert proofs.check(r.certificate()).ok


def test_a_complete_answer_with_a_cluster_says_what_the_cluster_is_and_how_large():
    """--min-width 1 on the 6-mode planar instance: "0 modes, 1 cluster; complete" said nothing, though
    the cluster is the whole domain."""
    robot = load_robot(EXAMPLES / "seed003-planar-example-2.toml")
    r = forward_kinematics(robot, "28.99,13.66,40.53", min_width=1)
    assert r.complete and len(r.clusters) == 1 and not r.solutions
    assert "1 cluster at the resolution limit, holding any number of postures" in r.message
    assert "spans 100% of the domain" in r.message and r.to_json()["message"] == r.message
