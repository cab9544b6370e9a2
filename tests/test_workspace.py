"""Constant-orientation workspace (seed 004): sections, exact arcs, volumes, certificates, input errors.

Reference values (micro-manipulator, ψ = θ = φ = 0): the exact arc arrangement
at 40 digits with mpmath, derived in ``test_seed004.py`` (which checks TABLE
against it); a printed value is taken as ± half a unit of its last digit.
Closed-form cases (a disk, an annulus, a lens) are recomputed here with
sympy/mpmath from the exact decimals of the robot.
"""
import argparse
import copy
from fractions import Fraction
import json
import random

import mpmath
import numpy as np
import pytest
import sympy as sp

import certkin
import proofs
from certfile import Doc
from certkin import InputError, robot_from_dict
from certkin.engine import EXCLUDED, PROVED, UNDECIDED
from certkin.cli.workspace import add_arguments, describe, run
from certkin.workspace import workspace_section, workspace_volume

MICRO = "examples/robots/seed004-micro-manipulator.toml"
MEL = "examples/robots/seed000-mel-tsukuba.toml"

# z: (area, perimeter, arcs as a string of o/i in circle order of the exact boundary)
TABLE = {
    "20000.5": ("2.53940735719921", "5.94308368401", "iiiiii"),
    "20001": ("10.4554175066593", "12.0493589637", "iiiiii"),
    "20002": ("42.4135913952367", "24.2642699825", "iiiiii"),
    "20003": ("95.8852663558835", "36.4823300008", "iiiiii"),
    "20004": ("170.884809474850", "48.7035410851", "iiiiii"),
    "20005": ("190.795788303254", "51.4552660537", "oooooo"),
    "20006": ("111.016710114575", "39.2510914812", "oooooo"),
    "20007": ("52.6963390944047", "27.0437762940", "oooooo"),
    "20008": ("15.8489906791992", "14.8333184356", "oooooo"),
    "20009": ("0.488993444834434", "2.61971584723", "oooooo"),
}
VOLUME = "697.318163011934"


@pytest.fixture(scope="module")
def micro():
    return certkin.load_robot(MICRO)


def printed(text):
    """The interval of reals that print as ``text`` (± half a unit of the last digit)."""
    q = Fraction(text)
    decimals = len(text.split(".")[1]) if "." in text else 0
    half = Fraction(1, 2 * 10 ** decimals)
    return q - half, q + half


def meets(iv_lo, iv_hi, text):
    lo, hi = printed(text)
    return Fraction(float(iv_lo)) <= hi and lo <= Fraction(float(iv_hi))


def checked(result):
    cert = Doc(result.certificate())
    report = cert.check()
    assert report.ok, report.step
    return cert


# ----- the seed 004 table ------------------------------------------------------
@pytest.mark.parametrize("z", sorted(TABLE))
def test_micro_section_matches_the_reference_table(micro, z):
    area, perimeter, arcs = TABLE[z]
    r = workspace_section(micro, "0,0,0", z, min_width=4e-3)
    assert r.status == "non-empty"
    a, p = r.area, r.perimeter
    assert meets(a.lo, a.hi, area), (z, a, area)
    assert meets(p.lo, p.hi, perimeter), (z, p, perimeter)
    assert float(a.hi - a.lo) < 1e-7 and float(p.hi - p.lo) < 1e-7
    lo, hi = printed(area)
    assert Fraction(r.inner) <= hi and lo <= Fraction(r.outer)
    assert 0 < r.outer - r.inner < 0.05 * float(area) + 0.1
    assert "".join(c["circle"][0] for c in r.boundary.arcs) == arcs and r.boundary.loops == 1
    doc = r.to_json()
    assert doc["area"]["exact"] == [float(a.lo), float(a.hi)] and doc["perimeter"] == [float(p.lo), float(p.hi)]


def test_section_20005_is_small_bracketed_and_checks(micro):
    r = workspace_section(micro, "0,0,0", "20005")
    assert r.stats["boxes"] < 40_000 and not r.stats["exhausted"]   # the work, not the time (benchmarks time it)
    assert r.inner <= 190.795788303254 <= r.outer and r.outer - r.inner < 1.0
    # bounding box of the exact arcs (spec §6.4): X in [-8.73699, 8.35859], Y in [-7.60889, 7.60889]
    (xlo, ylo), (xhi, yhi) = r.domain
    assert -8.73700 < xlo < -8.73699 and 8.35858 < xhi < 8.35860 and -7.60890 < ylo < -7.60888 < 7.60888 < yhi < 7.60890
    doc = r.to_json()
    json.dumps(doc)
    assert doc["problem"] == "workspace-section" and doc["orientation"] == {"psi": "0", "theta": "0", "phi": "0"}
    assert doc["z"] == "20005" and set(doc["paving"]) == {"inner_boxes", "boundary_boxes", "outside_boxes"}
    assert [a["leg"] for a in doc["arcs"]] and all(a["circle"] == "outer" for a in doc["arcs"])
    assert doc["ignored_limits"] == [] and doc["stats"]["bracket_width"] == r.outer - r.inner
    coarse = workspace_section(micro, "0,0,0", "20005", min_width=1e-2)
    cert = checked(coarse)
    assert cert.claim()["area"] == {"inner": coarse.inner, "outer": coarse.outer}


def test_twelve_and_four_arc_structures(micro):
    r = workspace_section(micro, "0,0,0", "20004.6", min_width=1e-2)
    assert "".join(a["circle"][0] for a in r.boundary.arcs).count("o") == 6 and len(r.boundary.arcs) == 12
    assert 222.70207 < float(r.area.lo) <= float(r.area.hi) < 222.70208   # micro_table.out: 222.7020727
    r = workspace_section(micro, "0,0,0", "20009.2", min_width=1e-2)   # spec: 4 outer arcs above 20009.1691
    assert [a["circle"] for a in r.boundary.arcs] == ["outer"] * 4


def test_mirror_symmetry_of_the_exact_arcs(micro):
    """The design is symmetric under y -> -y (legs 1<->6, 2<->5, 3<->4)."""
    r = workspace_section(micro, "0,0,0", "20003", min_width=1e-2)
    ends = sorted((round(a["from"][0], 9), round(a["from"][1], 9)) for a in r.boundary.arcs)
    mirrored = sorted((x, round(-y, 9) + 0.0) for x, y in ends)
    assert np.allclose(ends, mirrored, atol=1e-8)


@pytest.mark.parametrize("z, min_width", [("20000", 1e-3), ("19999.9", 1e-3), ("20000.03", 1e-4),
                                          ("20009.21", 1e-3), ("20009.25", 1e-3)])
def test_sections_outside_the_z_range_are_proved_empty(micro, z, min_width):
    """Non-empty z range: [20000.034629502, 20009.203160232] (spec §6.4)."""
    r = workspace_section(micro, "0,0,0", z, min_width=min_width)
    assert r.status == "empty" and r.outer == 0.0 and r.inner == 0.0
    assert float(r.area.lo) == float(r.area.hi) == 0.0 and r.boundary.arcs == []
    cert = checked(r)
    claim = cert.claim()
    assert claim["area"] == {"inner": 0.0, "outer": 0.0}


def test_just_inside_the_z_range_is_non_empty(micro):
    r = workspace_section(micro, "0,0,0", "20000.04", min_width=1e-3)
    assert r.status == "non-empty" and float(r.area.lo) > 0


# ----- soundness of the paving against exact rational membership ----------------
def test_paving_leaves_agree_with_exact_membership(micro):
    r = workspace_section(micro, "0,0,0", "20004.6", min_width=3e-3)
    base = [[Fraction(c) for c in p] for p in micro.base]
    plat = [[Fraction(c) for c in p] for p in micro.platform]
    lims = [(Fraction(a) ** 2, Fraction(b) ** 2) for a, b in micro.limits["leg_length"]]
    z = Fraction("20004.6")

    def member(x, y):
        for (ax, ay, az), (bx, by, bz), (lo, hi) in zip(base, plat, lims):
            d2 = (x + bx - ax) ** 2 + (y + by - ay) ** 2 + (z + bz - az) ** 2
            if not lo <= d2 <= hi:
                return False
        return True

    rng = random.Random(4)
    for kind, want in ((PROVED, True), (EXCLUDED, False)):
        lo, hi = r.paving.boxes(kind)
        for k in rng.sample(range(len(lo)), 150):
            for _ in range(2):
                x = Fraction(rng.uniform(lo[k, 0], hi[k, 0]))
                y = Fraction(rng.uniform(lo[k, 1], hi[k, 1]))
                assert member(x, y) is want


# ----- closed-form cases ----------------------------------------------------------
def gough_with_limits(limits):
    micro = certkin.load_robot(MICRO)
    data = {"kind": "gough-stewart", "name": "micro, one active leg",
            "base": [list(p) for p in micro.base], "platform": [list(p) for p in micro.platform],
            "limits": {"leg_length": limits}}
    return robot_from_dict(data)


def rotated_b1z(psi, theta, phi, b):
    """z of Rz(psi) Rx(theta) Rz(phi) b, at 50 digits."""
    R = sp.rot_axis3(-psi) * sp.rot_axis1(-theta) * sp.rot_axis3(-phi)   # sympy's rot_axis are transposed
    return (R * sp.Matrix(b))[2]


@pytest.mark.parametrize("orientation", ["0,0,0", "10deg,20deg,30deg"])
def test_one_active_leg_gives_a_disk_and_an_annulus(orientation):
    """Leg 1 limited, the others far out of reach: a disk (rho_min = 0) or an annulus, area pi R^2."""
    micro = certkin.load_robot(MICRO)
    angles = [sp.Rational(int(a[:-3]), 180) * sp.pi if a.endswith("deg") else sp.Integer(a)
              for a in orientation.split(",")]
    b1 = [sp.Rational(c) for c in micro.platform[0]]
    z = sp.Rational("20005")
    h = z - (sp.Rational(micro.base[0][2]) - rotated_b1z(*angles, b1))     # z - u_1z
    tenths = int(sp.ceiling(10 * abs(h))) + 1                              # rho_min > |h|: the plane cuts both spheres
    rmin, rmax = sp.Rational(tenths, 10), sp.Rational(tenths + 5, 10)
    big = ["0", "1000000"]
    disk = gough_with_limits([["0", f"{tenths + 5}e-1"]] + [big] * 5)
    ring = gough_with_limits([[f"{tenths}e-1", f"{tenths + 5}e-1"]] + [big] * 5)
    expected_disk = sp.N(sp.pi * (rmax ** 2 - h ** 2), 40)
    expected_ring = sp.N(sp.pi * (rmax ** 2 - rmin ** 2), 40)
    expected_perimeter = sp.N(2 * sp.pi * (sp.sqrt(rmax ** 2 - h ** 2) + sp.sqrt(rmin ** 2 - h ** 2)), 40)
    for robot, area in ((disk, expected_disk), (ring, expected_ring)):
        r = workspace_section(robot, orientation, "20005", min_width=3e-2)
        a = r.area
        assert area > 0 and r.status == "non-empty"
        assert Fraction(float(a.lo)) <= Fraction(str(area)) <= Fraction(float(a.hi)), (a, area)
        assert float(a.hi - a.lo) < 1e-9 * float(area)
        assert r.inner <= float(area) <= r.outer
        checked(r)
    p = r.perimeter
    assert Fraction(float(p.lo)) <= Fraction(str(expected_perimeter)) <= Fraction(float(p.hi))
    assert sorted(a["circle"] for a in r.boundary.arcs) == ["inner", "outer"] and r.boundary.loops == 2


EX2 = {"name": "seed003 example 2 with limits", "kind": "planar-3rpr",
       "base": [["3.78", "4.34"], ["34.47", "-3.78"], ["16.233", "34.76"]],
       "platform": [["-4.83", "-3.19"], ["12.04", "-3.19"], ["8.23", "12.09"]],
       "limits": {"leg_length": [["0", "9"], ["0", "10"], ["0", "100"]]}}


@pytest.mark.parametrize("phi", ["0", "-0.3"])
def test_planar_lens_of_two_disks(phi):
    """Legs 1 and 2 active: the lens of two disks, area and perimeter in closed form."""
    robot = robot_from_dict(EX2)
    mpmath.mp.dps = 50
    f = mpmath.mpf(phi)
    c, s = mpmath.cos(f), mpmath.sin(f)
    u = []
    for (ax, ay), (bx, by) in zip(EX2["base"][:2], EX2["platform"][:2]):
        ax, ay, bx, by = (mpmath.mpf(v) for v in (ax, ay, bx, by))
        u.append((ax - (c * bx - s * by), ay - (s * bx + c * by)))
    d = mpmath.sqrt((u[0][0] - u[1][0]) ** 2 + (u[0][1] - u[1][1]) ** 2)
    r1, r2 = mpmath.mpf(9), mpmath.mpf(10)
    a1 = 2 * mpmath.acos((d ** 2 + r1 ** 2 - r2 ** 2) / (2 * d * r1))   # angle seen from centre 1
    a2 = 2 * mpmath.acos((d ** 2 + r2 ** 2 - r1 ** 2) / (2 * d * r2))
    area = (r1 ** 2 * (a1 - mpmath.sin(a1)) + r2 ** 2 * (a2 - mpmath.sin(a2))) / 2
    perimeter = r1 * a1 + r2 * a2
    r = workspace_section(robot, phi, min_width=1e-2)
    assert r.status == "non-empty" and len(r.boundary.arcs) == 2
    for got, want in ((r.area, area), (r.perimeter, perimeter)):
        assert mpmath.mpf(float(got.lo)) <= want <= mpmath.mpf(float(got.hi)), (got, want)
        assert float(got.hi - got.lo) < 1e-10
    assert r.inner <= float(area) <= r.outer
    checked(r)


ONE_CENTRE = {"name": "three legs, one centre", "kind": "planar-3rpr",
              "base": [["0", "0"], ["10", "0"], ["5", "8"]], "platform": [["0", "0"], ["10", "0"], ["5", "8"]],
              "limits": {"leg_length": [["0", "5"], ["0", "5"], ["0", "5"]]}}


@pytest.mark.parametrize("robot, phi", [(ONE_CENTRE, "0"), ({**EX2, "limits": {"leg_length": [["0", "30"], ["0", "35"], ["0", "28"]]}}, "0.3")])
def test_boxes_holding_a_leg_centre_with_zero_minimum_length_check(robot, phi):
    """A leg of minimum length 0 whose centre lies in an inside box: the checker's squared distance
    there is [0, ...], never below 0 (it was [-2^-1022, ...] and the box's claim was refused).  At phi = 0
    the one-centre robot's workspace is the disk of radius 5: area 25 pi."""
    r = workspace_section(robot_from_dict(robot), phi, min_width=1e-2)
    assert r.status == "non-empty"
    if robot is ONE_CENTRE:
        assert mpmath.mpf(r.inner) <= 25 * mpmath.pi <= mpmath.mpf(r.outer)
    checked(r)


def test_planar_disjoint_disks_are_empty():
    r = workspace_section(robot_from_dict(EX2), "30deg", min_width=1e-2)
    assert r.status == "empty" and r.domain is None and float(r.area.hi) == 0.0
    assert checked(r).claim()["domain"] == "empty"


# ----- volume ----------------------------------------------------------------------
def test_volume_bracket_contains_the_reference(micro):
    v = workspace_volume(micro, "0,0,0", "20000:20010", 200)
    vin, vout = v.volume()
    assert v.status == "non-empty"
    assert vin <= float(VOLUME) <= vout and vout - vin < 0.12 * float(VOLUME)
    doc = v.to_json()
    json.dumps(doc)
    assert doc["volume"] == {"inner": vin, "outer": vout} and doc["slab_bounds"][0] == 20000.0
    assert doc["sections"][0]["inner"] == 0.0 < doc["sections"][0]["outer"]   # [20000, 20000.05] holds zlo
    assert doc["sections"][-1]["outer"] == 0.0                                 # [20009.95, 20010]: above zhi


def test_volume_of_a_spherical_cap():
    """Leg 1 in [0, 100], the others out of reach, R = I, u_1z = 0: W is a ball of radius 100 around u_1;
    between z = 90 and 101 its volume is the cap pi (R^2 z - z^3/3) from 90 to 100 (sympy)."""
    data = {"kind": "gough-stewart", "base": [list(p) for p in certkin.load_robot(MICRO).base],
            "platform": [list(p) for p in certkin.load_robot(MICRO).platform],
            "limits": {"leg_length": [["0", "100"]] + [["0", "1000000"]] * 5}}
    robot = robot_from_dict(data)
    z = sp.Symbol("z")
    cap = sp.integrate(sp.pi * (100 ** 2 - z ** 2), (z, 90, 100))
    assert cap == sp.Rational(29000, 3) * sp.pi
    v = workspace_volume(robot, "0,0,0", "90:101", 110, min_width=1e-2)
    vin, vout = v.volume()
    assert vin <= float(cap) <= vout and vout - vin < 0.2 * float(cap)
    assert v.to_json()["sections"][-1]["outer"] == 0.0          # [100.9, 101]: above the ball
    coarse = workspace_volume(robot, "0,0,0", "90:101", 22, min_width=1e-2)
    assert coarse.volume()[0] <= float(cap) <= coarse.volume()[1]
    checked(coarse)


@pytest.mark.parametrize("phi", ["0", "1e-300"])
def test_a_section_at_a_tangency_checks(phi):
    """Legs 1 and 2 reach at most 10 and 9 from base points 20 apart (platform point 2 is (1, 0), so the
    ball centres are 19 apart): the two outer circles touch at one point, (10, 0), and the section is
    that point (area 0; 10 + 9 = 19, exact).  Outside boxes 1e-15 wide there were decided by the last bit
    of ρ², and the checker's own ρ², exactly 81 = ρmax², refused one ("outside not proved").  A box now
    needs ``paving.SLACK`` of the limit to be decided; the certificate checks and the bracket holds 0."""
    robot = robot_from_dict({"name": "t1", "kind": "planar-3rpr", "base": [[0, 0], [20, 0], [10, 10]],
                             "platform": [[0, 0], [1, 0], [0, 1]],
                             "limits": {"leg_length": [["0.5", "10"], ["0.5", "9"], ["0.5", "100"]]}})
    s = workspace_section(robot, phi)
    assert s.inner == 0.0 <= s.outer < 1e-15
    checked(s)


def test_the_undecided_boundary_names_the_circles_that_coincide():
    """Base = platform at phi = 0: every leg's circles share one centre, and leg 1's outer circle (radius
    10) is leg 2's inner one (radius 10).  The reason named leg 1's and leg 2's outer circles (radii 10
    and 20, which cannot coincide); it now names the pair whose radii may be equal."""
    robot = robot_from_dict({"name": "co", "kind": "planar-3rpr", "base": [[0, 0], [1, 0], [5, 5]],
                             "platform": [[0, 0], [1, 0], [5, 5]],
                             "limits": {"leg_length": [["0.5", "10"], ["10", "20"], ["0.5", "30"]]}})
    s = workspace_section(robot, "0")
    assert s.boundary.reason == "the outer circle of leg 1 and the inner circle of leg 2 may coincide"
    checked(s)


def test_a_slab_above_the_workspace_is_empty_and_its_certificate_checks():
    """Seed 000 at (5deg, 3deg, 0): the workspace ends near z = 710.9, and over [711, 718] the solver
    proves the slab empty from the disks' boxes and the candidate extreme points together, which the
    checker did not accept ("'empty' not proved": the candidates of a slab, enclosed over its heights,
    are too wide to be ruled out one by one; a third of the volume runs over a range reaching above a
    workspace's top were rejected).  It now accepts that rule (``proofs/workspace.py``, ``_domain``): K's
    extremes are candidates left, and K lies in every disk's box, so crossing bounds prove K empty.  A
    slab that meets the workspace is not empty, and an "empty" forged on it is rejected."""
    above = workspace_volume(MEL, "5deg,3deg,0", "711:718", 1)
    assert above.status == "empty" and above.to_json()["sections"][0]["outer"] == 0.0
    assert above.volume() == (0.0, 0.0)            # (it was [0, 6.7e-308]: each slab's 0 rounded up a step)
    checked(above)
    below = workspace_volume(MEL, "5deg,3deg,0", "500:510", 1)
    assert below.status == "non-empty"
    cert = checked(below)
    cert.claim(0)["domain"] = "empty"
    assert "'empty' not proved" in cert.check().step


def test_volume_certificate_checks_and_rejects_a_raised_bound(micro):
    v = workspace_volume(micro, "0,0,0", "20000:20010", 12, min_width=1 / 32)
    vin, vout = v.volume()
    assert vin <= float(VOLUME) <= vout
    cert = checked(v)
    bad = cert.copy()
    bad.header["volume"]["inner"] = vin * 1.001
    assert "volume.inner" in bad.check().step
    bad = cert.copy()
    bad.claim(3)["slab"][0] = float(np.nextafter(bad.claim(3)["slab"][0], 0))
    assert "does not start" in bad.check().step
    bad = cert.copy()
    bad.header["requested"]["z"] = ["19999", "20010"]
    assert "requested.z" in bad.check().step
    bad = cert.copy()             # a requested range narrower than the slabs: their inner volume is not its own
    bad.header["requested"]["z"] = ["20001", "20001.001"]
    assert "volume.inner" in bad.check().step


def test_domains_without_time_for_the_candidates_are_wider_and_still_check(micro, monkeypatch):
    """A deadline already passed leaves every slab with the disks' own boxes (bound (1) of
    section_domain): each contains the refined box, the bracket still holds the reference
    volume and the certificate checks; slabs whose disks' boxes cross get a box the checker accepts."""
    from certkin.workspace import leg_data, section_domain, volume
    from intervals import Interval
    legs = leg_data(micro, [0.0, 0.0, 0.0])
    z = np.linspace(19990.0, 20012.0, 45)
    _, r2 = legs.radii2(Interval.from_bounds(z[:-1].copy(), z[1:].copy()))
    lo, hi, empty = section_domain(legs.ux, legs.uy, r2)
    wlo, whi, wempty = section_domain(legs.ux, legs.uy, r2, deadline=-np.inf)
    assert not wempty[~empty].any() and empty.any() and (~empty).any()
    assert (wlo[~empty] <= lo[~empty]).all() and (whi[~empty] >= hi[~empty]).all()
    assert (wlo <= whi).all()
    assert (empty & ~wempty).any()                      # crossed disks' boxes, empty by (2) only
    monkeypatch.setattr(volume, "section_domain", lambda cx, cy, r2, deadline: section_domain(cx, cy, r2, -np.inf))
    v = workspace_volume(micro, "0,0,0", "19990:20012", 44, min_width=1 / 32)
    vin, vout = v.volume()
    assert v.status != "empty" and vin <= float(VOLUME) <= vout
    checked(v)


# ----- tampering ---------------------------------------------------------------------
INSIDE, OUTSIDE, BOUNDARY = 0, 1, 2


@pytest.fixture(scope="module")
def section_cert(micro):
    return checked(workspace_section(micro, "0,0,0", "20005", min_width=1e-2))


def test_outside_box_moved_inside_is_rejected(section_cert):
    bad = section_cert.copy()
    leaf = bad.nodes(3, OUTSIDE)[0]
    bad.arrays["tree.index"] = np.delete(bad.arrays["tree.index"], bad.row("tree.index", leaf))
    bad.arrays["tree.code"][leaf] = INSIDE
    report = bad.check()
    assert not report.ok and report.step.startswith(f"claims[0].tree: node {leaf} (inside)") and \
        "inside not proved" in report.step


def test_boundary_box_called_inside_or_outside_is_rejected(section_cert):
    for kind in (INSIDE, OUTSIDE):
        bad = section_cert.copy()
        leaf = bad.nodes(3, BOUNDARY)[0]
        bad.arrays["tree.code"][leaf] = kind
        if kind == OUTSIDE:
            bad.arrays["tree.index"] = np.insert(bad.arrays["tree.index"], bad.row("tree.index", leaf), 1)
        assert f"{('inside', 'outside')[kind]} not proved" in bad.check().step


def test_widened_domain_is_rejected(section_cert):
    bad = section_cert.copy()
    bad.claim()["domain"][0][1] += 0.5                        # a wider domain: every derived box moves
    assert not bad.check().ok


def test_cut_domain_wrong_leg_and_raised_area_are_rejected(section_cert):
    bad = section_cert.copy()
    bad.claim()["domain"][1][1] = 7.0                          # cuts the section (y reaches 7.6089)
    assert "domain: the hi bound of y may cut the section" in bad.check().step
    bad = section_cert.copy()
    row = bad.row("tree.index", bad.nodes(3, OUTSIDE)[0])
    bad.arrays["tree.index"][row] = bad.arrays["tree.index"][row] % 6 + 1
    step = bad.check().step
    assert "outside not proved" in step or not step     # another leg may exclude it too: then it is still true
    bad = section_cert.copy()
    bad.claim()["area"]["inner"] += 1.0
    assert "area.inner" in bad.check().step
    bad = section_cert.copy()
    bad.claim()["area"]["outer"] -= 1.0
    assert "area.outer" in bad.check().step


def test_removed_leaf_and_changed_geometry_are_rejected(section_cert):
    bad = section_cert.copy()
    leaf = bad.nodes(3, BOUNDARY)[-1]                         # one leaf disappears
    for name in ("tree.kind", "tree.code"):
        bad.arrays[name] = np.delete(bad.arrays[name], leaf)
    assert not bad.check().ok
    for edit in (lambda h: h["robot"]["limits"]["leg_length"].__setitem__(2, ["23004.2", "23012.0"]),
                 lambda h: h["orientation"].__setitem__("psi", "1deg"),
                 lambda h: h["claims"][0].__setitem__("z", "20004")):
        bad = section_cert.copy()
        edit(bad.header)
        bad.header["geometry_sha256"] = proofs.geometry_sha256(bad.header["robot"])
        assert not bad.check().ok


# ----- input, CLI hooks, outputs -------------------------------------------------------
def parse(argv):
    p = argparse.ArgumentParser()
    add_arguments(p)
    return p.parse_args(argv)


@pytest.mark.parametrize("argv, option, fld", [
    ([MICRO, "--z", "abc"], "--z", "z"),
    ([MICRO, "--z", "nan"], "--z", "z"),
    ([MICRO, "--z", "20005", "--orientation", "0,0"], "--orientation", ""),
    ([MICRO, "--z", "20005", "--orientation", "0,x,0"], "--orientation", "theta"),
    ([MICRO, "--z", "20005", "--z-range", "1:2"], "--z-range", ""),
    ([MICRO, "--z-range", "20010:20000"], "--z-range", "z"),
    ([MICRO], "--z", "z"),
])
def test_bad_input_raises_input_error_naming_the_field(argv, option, fld):
    with pytest.raises(InputError) as exc:
        run(parse(argv), out=open("/dev/null", "w"))
    assert exc.value.source == option and exc.value.field == fld
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("argv, message", [
    ([MICRO, "--z-range", "20000:20010", "--slabs", "ten"], "--slabs: expected a positive integer"),
    ([MICRO, "--z-range", "20000:20010", "--slabs", "0"], "--slabs: expected a positive integer"),
    ([MICRO, "--z", "20005", "--min-width", "0"], "--min-width: expected a positive"),
])
def test_bad_numbers_are_refused_by_the_command_line(argv, message, capsys):
    from certkin.cli import main
    with pytest.raises(SystemExit) as exc:
        main(["workspace", *argv])
    assert exc.value.code == 2 and message in capsys.readouterr().err


def test_api_input_errors(micro):
    with pytest.raises(InputError) as exc:
        workspace_section(micro, "0,0,0", "20005abc")
    assert exc.value.field == "z"
    with pytest.raises(InputError) as exc:
        workspace_section(robot_from_dict(EX2), "0", "1")
    assert exc.value.field == "z"
    no_limits = dict(EX2, limits={})
    with pytest.raises(InputError) as exc:
        workspace_section(robot_from_dict(no_limits), "0")
    assert exc.value.field == "limits.leg_length"
    with pytest.raises(InputError):
        workspace_volume(robot_from_dict(EX2), "0", "0:1")


def test_run_prints_json_writes_certificate_and_plot(tmp_path, micro):
    import io
    out = io.StringIO()
    cert, png = tmp_path / "w.cert", tmp_path / "w.png"
    args = parse([MICRO, "--orientation", "0,0,0", "--z", "20005", "--json", "--min-width", "0.01",
                  "--certificate", str(cert), "--plot", str(png)])
    assert run(args, out) == 0
    doc = json.loads(out.getvalue())
    assert doc["status"] == "non-empty" and doc["area"]["exact"][0] <= 190.795788303254 <= doc["area"]["exact"][1]
    assert proofs.check(cert).ok
    pytest.importorskip("matplotlib")
    assert png.read_bytes()[:4] == b"\x89PNG"
    out = io.StringIO()
    run(parse([MICRO, "--z-range", "20000:20010", "--slabs", "10", "--min-width", "0.05"]), out)
    assert "volume in [" in out.getvalue()


def test_describe_mentions_ignored_joint_limits():
    data = copy.deepcopy(EX2)
    data["limits"]["leg_radius"] = "0.1"
    r = workspace_section(robot_from_dict(data), "0", min_width=5e-2)
    assert r.to_json()["ignored_limits"] == ["leg_radius"]
    assert "ignored: leg_radius" in describe(r)


def test_the_memory_ceiling_bounds_the_whole_command_not_only_the_paving(tmp_path):
    """With boxes, width and time unbounded the paving's records reach the ceiling; its areas, the
    certificate and the JSON document came on top (1.15 to 1.35 times the ceiling, 2.78 GB under the
    default 2 GiB).  In a fresh process, the peak beyond the start-up stays within the ceiling."""
    from peak import beyond_start_up
    ceiling = 640 * 2 ** 20
    rc, extra, done = beyond_start_up(
        f"result = main(['workspace', {MICRO!r}, '--z', '20005', '--min-width', '1e-300', '--max-boxes', '1e15', "
        f"'--max-seconds', 'inf', '--max-memory', '640MiB', '--json', '--certificate', {str(tmp_path / 'w.cert')!r}])",
        "from certkin.cli import main; import certkin.workspace, certkin.certificates")
    assert rc == 0 and json.loads(done.stdout)["stats"]["exhausted"]
    assert extra <= ceiling, extra
    assert proofs.check_file(tmp_path / "w.cert").ok


def test_a_paving_of_many_boxes_is_drawn_as_an_image_with_boundary_on_top(micro, monkeypatch, tmp_path):
    """Millions of boxes drawn one by one took 172 s and 3.6 GB after a 5 s search: past
    ``MAX_PATCHES`` the paving is an image; a pixel touched by a boundary box is never shown inside."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from certkin.plots import workspace as wplot
    r = workspace_section(micro, "0,0,0", "20005", min_width=1e-3)
    monkeypatch.setattr(wplot, "MAX_PATCHES", 10)
    monkeypatch.setattr(wplot, "PIXELS", 200)
    fig, ax = plt.subplots()
    dlo, dhi = r.domain
    wplot._raster(ax, r.paving, dlo, dhi)
    rgb = ax.get_images()[0].get_array()
    colour = {n: np.array([int(wplot.COLOURS[n][k:k + 2], 16) / 255 for k in (1, 3, 5)]) for n in wplot.COLOURS}
    shown = {n: np.all(np.isclose(rgb, c), axis=-1) for n, c in colour.items() if n != "arc"}
    assert all(m.any() for m in shown.values())
    lo, hi = r.paving.boxes(UNDECIDED)       # a boundary box's pixels and their neighbours: none shown inside
    step = float(np.max(np.asarray(dhi) - np.asarray(dlo))) / 200
    i0, j0 = np.maximum(np.floor((lo[0] - dlo) / step).astype(int) - 1, 0)
    i1, j1 = np.ceil((hi[0] - dlo) / step).astype(int) + 1
    assert shown["boundary"][j0:j1, i0:i1].all()
    plt.close(fig)
    wplot.plot_section(r, tmp_path / "p.png")
    assert (tmp_path / "p.png").stat().st_size > 10_000


def test_a_small_paving_shows_its_boundary_boxes(micro, tmp_path):
    """A paving of fewer than ``MAX_PATCHES`` boxes, its boundary boxes far below a pixel (the README's
    example): the inside boxes drawn one by one painted over them, and the plot showed no boundary at
    all.  Boundary boxes narrower than a pixel now send the paving to the image, where a pixel a boundary
    box touches is boundary."""
    pytest.importorskip("matplotlib")
    from PIL import Image
    from certkin.plots import workspace as wplot
    r = workspace_section(micro, "0,0,0", "20005")
    lo, hi = r.paving.boxes(UNDECIDED)
    assert 0 < sum(r.paving.counts().values()) <= wplot.MAX_PATCHES and len(lo)
    wplot.plot_section(r, tmp_path / "p.png")
    rgb = np.asarray(Image.open(tmp_path / "p.png").convert("RGB")).astype(int)
    yellow = np.all(np.abs(rgb - [int(wplot.COLOURS["boundary"][k:k + 2], 16) for k in (1, 3, 5)]) < 12, axis=2)
    assert yellow.sum() > 2000          # the legend's patch is about 200 pixels
