"""Seed 004 (Merlet, constant-orientation workspace): the micro-manipulator of Table 1 at psi = theta =
phi = 0, derived here independently of certkin.

The section at height z is {(x, y): R_i(z) <= |(x, y) - u_i| <= R_e(z) for every leg}, u_i = (A_i - b_i)_xy,
R_e,i = sqrt(rho_max,min^2 - z^2) (digest §2, §3.1): an arrangement of 12 circles.  ``section`` finds,
at 40 digits with mpmath, every arc of those circles between consecutive intersection points whose
midpoint satisfies all other constraints; the area follows from Green's theorem on the arcs, the
perimeter from their lengths.  This is the derivation of ``test_workspace.TABLE``, which it
reproduces; certkin's exact-arc enclosures must contain its values.
"""
from pathlib import Path

import mpmath as mp
import pytest

import proofs
from certkin import load_robot, robot_from_dict, verify_trajectory
from certkin.workspace import workspace_section
from seedref import encloses, exact, gough_legs, prints_as
from test_trajectory import _seg_dist
from test_workspace import TABLE

FILE = Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed004-micro-manipulator.toml"
DPS = 40


@pytest.fixture(scope="module")
def micro():
    return load_robot(FILE)


def circles(robot, z):
    """(centre, radius, +1 keep inside / -1 keep outside) for the outer then the inner circle of each leg."""
    z = exact(z)
    (lo, hi), = {tuple(v) for v in robot.limits["leg_length"]}
    u = [(exact(a[0]) - exact(b[0]), exact(a[1]) - exact(b[1])) for a, b in zip(robot.base, robot.platform)]
    out = [(c, mp.sqrt(exact(hi) ** 2 - z ** 2), +1) for c in u]
    return out + [(c, mp.sqrt(exact(lo) ** 2 - z ** 2), -1) for c in u]


def section(robot, z):
    """(area, perimeter, number of outer arcs, number of inner arcs) of the exact section at z."""
    with mp.workdps(DPS):
        circ = circles(robot, z)

        def inside(p, skip):
            for k, (c, r, s) in enumerate(circ):
                d2 = (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2
                if k != skip and (d2 > r * r if s > 0 else d2 < r * r):
                    return False
            return True

        area, perimeter, arcs = mp.mpf(0), mp.mpf(0), [0, 0]
        for i, (c, r, s) in enumerate(circ):
            cuts = []
            for j, (c2, r2, _) in enumerate(circ):
                dx, dy = c2[0] - c[0], c2[1] - c[1]
                D = mp.hypot(dx, dy)
                if j == i or D == 0 or D > r + r2 or D < abs(r - r2):
                    continue
                a = (D * D + r * r - r2 * r2) / (2 * D)
                off = mp.atan2(mp.sqrt(max(r * r - a * a, 0)), a)
                cuts += [(mp.atan2(dy, dx) + off) % (2 * mp.pi), (mp.atan2(dy, dx) - off) % (2 * mp.pi)]
            cuts.sort()
            for t0, t1 in zip(cuts, cuts[1:] + cuts[:1]):
                t1 = t1 + 2 * mp.pi if t1 <= t0 else t1
                tm = (t0 + t1) / 2
                if not inside((c[0] + r * mp.cos(tm), c[1] + r * mp.sin(tm)), i):
                    continue
                if s < 0:                            # an inner circle is run clockwise around the region
                    t0, t1 = t1, t0
                area += (r * r * (t1 - t0) + c[0] * r * (mp.sin(t1) - mp.sin(t0))
                         - c[1] * r * (mp.cos(t1) - mp.cos(t0))) / 2
                perimeter += r * abs(t1 - t0)
                arcs[s < 0] += 1
        return area, perimeter, arcs[0], arcs[1]


# ----- the reference table of test_workspace ------------------------------------------------------------
@pytest.mark.parametrize("z", sorted(TABLE))
def test_reference_table_is_the_exact_arc_arrangement(micro, z):
    area, perimeter, arcs = TABLE[z]
    a, p, outer, inner = section(micro, z)
    assert prints_as(a, area) and prints_as(p, perimeter)
    assert (outer, inner) == (arcs.count("o"), arcs.count("i"))


@pytest.mark.parametrize("z, digest_area, arcs, outer", [
    ("20004.6", "222.70207", 12, 6),       # 6 inner + 6 outer (digest: 20004.55 <= z <= 20004.65)
    ("20004.7", None, 8, None),            # digest: 8 arcs
    ("20009.2", None, 4, 4),               # 4 outer arcs near the top of the z range
])
def test_arc_structures_and_certkin_enclosures(micro, z, digest_area, arcs, outer):
    a, p, o, i = section(micro, z)
    assert o + i == arcs and outer in (None, o)
    if digest_area:
        assert prints_as(a, digest_area)
    r = workspace_section(micro, "0,0,0", z, min_width=1e-2)
    assert r.status == "non-empty"
    assert encloses(r.area, a) and encloses(r.perimeter, p)
    assert sum(arc["circle"] == "outer" for arc in r.boundary.arcs) == o
    assert sum(arc["circle"] == "inner" for arc in r.boundary.arcs) == i
    report = proofs.check(r.certificate())
    assert report.ok, report.step


def test_maximum_area_near_20004_613(micro):
    """Digest §3.1: maximum area about 222.79 at z about 20004.613 (golden-section search on the exact area)."""
    with mp.workdps(DPS):
        lo, hi = mp.mpf("20004.5"), mp.mpf("20004.7")
        g = (mp.sqrt(5) - 1) / 2
        for _ in range(30):
            m1, m2 = hi - g * (hi - lo), lo + g * (hi - lo)
            if section(micro, m1)[0] < section(micro, m2)[0]:
                lo = m1
            else:
                hi = m2
        assert prints_as(lo, "20004.613") and prints_as(section(micro, lo)[0], "222.79")


def test_non_empty_z_range(micro):
    """Digest §3.1: the section is non-empty for z in [20000.0346, 20009.2032] (bisection on the exact
    arrangement); test_workspace proves 20000.03 and 20009.21 empty and 20000.04 non-empty."""
    def edge(empty, full):
        empty, full = mp.mpf(empty), mp.mpf(full)
        for _ in range(30):
            m = (empty + full) / 2
            if section(micro, m)[0] > 0:
                full = m
            else:
                empty = m
        return full
    with mp.workdps(DPS):
        z_min, z_max = edge("20000", "20000.5"), edge("20009.5", "20009")
        assert prints_as(z_min, "20000.0346") and prints_as(z_max, "20009.2032")
        assert 20000.03 < z_min < 20000.04 and 20009.2 < z_max < 20009.21


def test_table_pose_leg_lengths_and_home(micro):
    """Digest §3.1 (and the robot file's comment): at C = (0, 0, 20000), R = I the legs are 23004.19042
    (1, 6), 23004.16846 (2, 5), 23004.20643 (3, 4).  rho_min = 23004.2, so legs 2 and 5 are 0.032 below
    it (the digest's words) and legs 1 and 6 are 0.0096 below it too (the digest does not say so): that
    pose is certified outside the workspace, with exactly those four legs short.  The file's home
    (0, 0, 20005) is inside."""
    pose = ["0", "0", "20000", "0", "0", "0"]
    lengths = gough_legs(micro, pose)
    enc = micro.leg_lengths(micro.pose_box(pose))
    for k, text in enumerate(["23004.19042", "23004.16846", "23004.20643"] * 2):
        k = [0, 1, 2, 5, 4, 3][k]
        assert prints_as(lengths[k], text) and encloses(enc, lengths[k], k)
    assert prints_as(exact("23004.2") - lengths[1], "0.032") and prints_as(exact("23004.2") - lengths[0], "0.0096")
    short = [[k + 1] for k in range(6) if lengths[k] < exact("23004.2")]
    assert short == [[1], [2], [5], [6]]
    assert "23004.19042 (1, 6), 23004.16846 (2, 5),\n# 23004.20643 (3, 4)" in FILE.read_text()
    r = verify_trajectory(micro, ",".join(pose), ",".join(pose), constraints=["leg-length"])
    assert r.status == "infeasible" and sorted(v["legs"] for v in r.violations if v["certain"]) == short
    assert proofs.check(r.certificate()).ok
    home = verify_trajectory(micro, "0,0,20005,0,0,0", "0,0,20005,0,0,0", constraints=["leg-length"])
    assert home.status == "feasible" and proofs.check(home.certificate()).ok


def test_u_vectors_and_least_pair_distances(micro):
    """Digest §3.1: |u_i| = 11366.3000 (1, 6), 11366.2556 (2, 5), 11366.3325 (3, 4); least base distance
    1399.42 (pair 1-6), 1399.46 (2-4, 3-5); least plate distances 799.66 (1-4, 3-6), 799.67 (2-5)."""
    with mp.workdps(DPS):
        c = circles(micro, "0")[:6]
        for k, text in enumerate(["11366.3000", "11366.2556", "11366.3325", "11366.3325", "11366.2556", "11366.3000"]):
            assert prints_as(mp.hypot(*c[k][0]), text)

        def distances(which):
            P = [[exact(v) for v in p] for p in getattr(micro, which)]
            return {(i + 1, j + 1): mp.sqrt(sum((a - b) ** 2 for a, b in zip(P[i], P[j])))
                    for i in range(6) for j in range(i + 1, 6)}
        for which, printed_pairs in (("base", {(1, 6): "1399.42", (2, 4): "1399.46", (3, 5): "1399.46"}),
                                     ("platform", {(1, 4): "799.66", (3, 6): "799.66", (2, 5): "799.67"})):
            d = distances(which)
            assert sorted(d, key=d.get)[:3] == sorted(printed_pairs, key=d.get)     # the three least
            for pair, text in printed_pairs.items():
                assert prints_as(d[pair], text)


def test_segment_distance_counter_example_of_section_5_1():
    """Digest seed-004 §5 item 1: A1 = (0,0,0), B1 = (10,0,0), A2 = (-1,1,0), B2 = (20,30,0).  The paper's
    rule (only endpoints projecting inside the other segment) gives 9.496 (B1 to line 2); the true distance
    is |A1A2| = sqrt(2).  Legs 3-6 are far away; with radius 0.1 the (1, 2) margin is sqrt(2) - 0.2."""
    base = [["0", "0", "0"], ["-1", "1", "0"], ["100", "0", "0"], ["0", "100", "0"], ["-100", "0", "0"],
            ["0", "-100", "0"]]
    plat = [["10", "0", "0"], ["20", "30", "0"], ["100", "0", "50"], ["0", "100", "50"], ["-100", "0", "50"],
            ["0", "-100", "50"]]
    robot = robot_from_dict({"kind": "gough-stewart", "base": base, "platform": plat,
                             "limits": {"leg_radius": ["0.1"] * 6}})
    with mp.workdps(DPS):
        A, B = [mp.matrix([exact(c) for c in p]) for p in base], [mp.matrix([exact(c) for c in p]) for p in plat]
        assert abs(_seg_dist(A[0], B[0], A[1], B[1]) - mp.sqrt(2)) < mp.mpf(10) ** -30
        u = B[1] - A[1]
        rule = mp.norm(B[0] - A[1] - (mp.fdot(B[0] - A[1], u) / mp.fdot(u, u)) * u)   # B1 to line 2
        assert prints_as(rule, "9.496")
        expected = mp.sqrt(2) - mp.mpf("0.2")
    pose = "0,0,0,0,0,0"
    r = verify_trajectory(robot, pose, pose, constraints=["interference"])
    assert r.status == "feasible"
    m = next(m["margin"] for m in r.margins if m["legs"] == [1, 2])
    assert mp.mpf(m[0]) <= expected <= mp.mpf(m[1]) and m[1] - m[0] < 1e-9
    assert proofs.check(r.certificate()).ok
