"""Seed 003 (Constantinescu 2004): the digest's grid classifications and reference values.

Grids (digest §3.6, "Grid classifications"): the full boxes of planar Ex 1 / Ex 2 (x, y in the
boxes of Tab. 3.8 / 3.9, phi in [0, pi/4]), the spherical Ex 1-3 tilt-and-torsion box of Tab. 4.12,
and the 2-D sections at phi = pi/4 and sigma = 0, pi/3 (Tab. 4.16).  The digest's "F" verdicts are
interval proofs and its "S" verdicts strict sign changes at sample points; its "touching" cells
(det = 0 on a line without a strict sign change: x = y = 0, and y = 0 at phi = 0, for Ex 1) can be
proved neither free nor sign-changing, so they must come back undecided.  Cell index (i1, i2, i3):
i_k = 0 for the lowest sub-interval of variable k.

Reference values: det(A) at 40 digits with mpmath from the exact decimals (``seedref``), compared
with the digest's printed values (± half a unit of the last digit) and the comments of the robot
files.  Every certified answer is re-checked by ``proofs``.
"""
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import proofs
from certkin import load_robot
from certkin.certificates import singularity_certificate
from certkin.singularity import classify_cells
from seedref import encloses, planar_det, prints_as, spherical_det

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "robots"
PLANAR_BOX = {1: "x=-20:20,y=-20:20,phi=0:45deg", 2: "x=-50:50,y=-50:50,phi=0:45deg"}
TT_BOX = "phi1=-90deg:90deg,phi2=0:90deg,sigma=-90deg:90deg"      # Tab. 4.12, third angle sigma


def robot(name, tilt_torsion=False):
    r = load_robot(EXAMPLES / f"seed003-{name}.toml")
    return r.with_angles("tilt-torsion") if tilt_torsion else r


def classified(r, box, n):
    """{status: sorted cell indices} of an n-per-side grid; the certificate is re-checked by proofs."""
    cells = classify_cells(r, box, n)
    report = proofs.check(singularity_certificate(cells))
    assert report.ok, report.step
    shape = (n,) * (3 if len(cells) == n ** 3 else 2)
    out = {"singularity-free": [], "singular": [], "undecided": []}
    for k, c in enumerate(cells):
        out[c.status].append(tuple(int(i) for i in np.unravel_index(k, shape)))
    return out


def counts(grid):
    return {s: len(v) for s, v in grid.items()}


# ----- 3-D grids (digest §3.6 table) -------------------------------------------------------------
# (robot, tilt-torsion, box, n, free cells or None, (S, F, touching))
FREE_N3 = {
    "planar-example-1": [(0, 0, 2), (0, 2, 0), (0, 2, 1), (0, 2, 2), (2, 1, 1), (2, 1, 2), (2, 2, 2)],
    "spherical-example-1": [(0, 0, 0), (0, 0, 2), (0, 1, 2), (1, 0, 0), (1, 0, 2), (2, 0, 0), (2, 0, 2), (2, 1, 0)],
    "spherical-example-2": [(0, 0, 0), (0, 0, 2), (0, 1, 0), (0, 1, 2), (1, 0, 0), (1, 0, 2), (1, 1, 0), (1, 1, 2),
                            (2, 0, 0), (2, 0, 2), (2, 1, 0)],
    "spherical-example-3": [(0, 0, 0), (0, 0, 2), (1, 0, 0), (1, 0, 2), (1, 1, 0), (1, 1, 2), (1, 2, 0), (2, 0, 2)],
}


@pytest.mark.parametrize("name", sorted(FREE_N3))
def test_three_cells_per_side_free_lists(name):
    tt = name.startswith("spherical")
    grid = classified(robot(name, tt), TT_BOX if tt else PLANAR_BOX[1], 3)
    assert grid["singularity-free"] == FREE_N3[name]
    assert not grid["undecided"] and len(grid["singular"]) == 27 - len(FREE_N3[name])


@pytest.mark.parametrize("name, singular, free", [
    ("planar-example-1", 71, 54), ("planar-example-2", 61, 64),
    ("spherical-example-1", 60, 65), ("spherical-example-2", 64, 61), ("spherical-example-3", 63, 62)])
def test_five_cells_per_side_counts(name, singular, free):
    tt = name.startswith("spherical")
    box = TT_BOX if tt else PLANAR_BOX[int(name[-1])]
    grid = classified(robot(name, tt), box, 5)
    assert counts(grid) == {"singularity-free": free, "singular": singular, "undecided": 0}
    if name == "spherical-example-2":       # the tiny pocket, min det -0.0022 (digest §3.6 **)
        assert (3, 2, 3) in grid["singular"]


TOUCHING_3D = ([(i, 5, 0) for i in range(5)] + [(8, 5, 0), (9, 5, 0), (4, 4, 9)] + [(4, 5, k) for k in range(1, 8)]
               + [(5, 4, k) for k in range(3, 8)] + [(5, 5, 9)])


def test_planar_example_1_ten_cells_per_side_with_the_21_touching_cells():
    """Digest §3.6: S 307, F 672, and exactly the 21 touching cells (0..4,5,0) (8,5,0) (9,5,0) (4,4,9)
    (4,5,1..7) (5,4,3..7) (5,5,9), which no sound method can call free or singular by a sign change."""
    assert len(TOUCHING_3D) == 21
    grid = classified(robot("planar-example-1"), PLANAR_BOX[1], 10)
    assert counts(grid) == {"singularity-free": 672, "singular": 307, "undecided": 21}
    assert grid["undecided"] == sorted(TOUCHING_3D)


# ----- 2-D sections (digest §3.6 table) ----------------------------------------------------------
SECTIONS = {"planar-1": ("planar-example-1", False, "x=-20:20,y=-20:20,phi=45deg"),
            "planar-2": ("planar-example-2", False, "x=-50:50,y=-50:50,phi=45deg"),
            "sigma-0": ("spherical-example-1", True, "phi1=-90deg:90deg,phi2=0:90deg,sigma=0"),
            "sigma-60": ("spherical-example-1", True, "phi1=-90deg:90deg,phi2=0:90deg,sigma=60deg")}


@pytest.mark.parametrize("section, n, singular, free, undecided", [
    ("planar-1", 3, [(0, 1), (1, 0), (1, 1), (1, 2), (2, 0)], 4, []),
    ("planar-1", 5, 10, 15, []),
    ("planar-1", 10, 23, 75, [(4, 4), (5, 5)]),
    ("planar-2", 3, [(1, 1), (1, 2), (2, 1), (2, 2)], 5, []),
    ("planar-2", 5, 5, 20, []),
    ("sigma-0", 3, [(i, j) for i in range(3) for j in range(3) if (i, j) != (0, 0)], 1, []),
    ("sigma-0", 5, 12, 13, []),
    ("sigma-0", 10, 27, 73, []),
    ("sigma-60", 3, [(0, 2), (1, 2), (2, 1), (2, 2)], 5, []),
    ("sigma-60", 5, 7, 18, []),
])
def test_two_dimensional_sections(section, n, singular, free, undecided):
    name, tt, box = SECTIONS[section]
    grid = classified(robot(name, tt), box, n)
    if isinstance(singular, list):
        assert grid["singular"] == singular
        singular = len(singular)
    assert counts(grid) == {"singularity-free": free, "singular": singular, "undecided": len(undecided)}
    assert grid["undecided"] == undecided


# ----- reference values of det(A) (digest §3.6 "Extra reference values") ------------------------------
@pytest.mark.parametrize("name, pose, text", [
    ("planar-example-1", ["10", "10", "22.5deg"], "-20914.4629762"),
    ("planar-example-1", ["0", "0", "0"], "0"),
    ("planar-example-2", ["10", "10", "22.5deg"], "8868.48667784"),
    ("planar-example-2", ["0", "0", "0"], "28891.66058"),
    ("planar-example-2", ["15.794", "4.4781", "45deg"], "60960.41"),    # centre of the interior ellipse
])
def test_planar_spot_values(name, pose, text):
    r = robot(name)
    with mp.workdps(40):
        ref = planar_det(r, pose)
        assert prints_as(ref, text) and (ref == 0) == (text == "0")     # Ex 1 at x = y = 0: row 1 is zero
        assert encloses(r.det_enclosure(r.pose_box(pose)), ref)


VERTEX = {  # digest §3.6: det at the 8 vertices of Tab. 4.12, lexicographic (phi1, phi2, third), min before max
    ("spherical-example-1", True): "-3.4704 3.4704 0.96 -0.96 -3.4704 3.4704 0.96 -0.96",
    ("spherical-example-1", False): "-0.0864 0.0864 0.72 -0.72 0.0864 -0.0864 0.72 -0.72",
    ("spherical-example-2", True): "-4.7236 4.7236 0.96 -0.96 -4.7236 4.7236 0.96 -0.96",
    ("spherical-example-2", False): "-0.1176 0.1176 0.84 -0.84 0.1176 -0.1176 0.84 -0.84",
    ("spherical-example-3", True): "-2.43 2.43 0.768 -0.768 -2.43 2.43 0.768 -0.768",
    ("spherical-example-3", False): "-1.08 1.08 0.72 -0.72 1.08 -1.08 0.72 -0.72",
}


@pytest.mark.parametrize("name, tt", sorted(VERTEX))
def test_spherical_vertex_values(name, tt):
    """At the vertices (all angles multiples of pi/2) the digest's values are exact decimals."""
    r = robot(name, tt)
    for text, (a, b, c) in zip(VERTEX[(name, tt)].split(), [(a, b, c) for a in ("-90deg", "90deg")
                                                             for b in ("0", "90deg") for c in ("-90deg", "90deg")]):
        with mp.workdps(40):
            ref = spherical_det(r, (a, b, c), tt)
            assert abs(ref - mp.mpf(text)) < mp.mpf(10) ** -30
            assert encloses(r.det_enclosure(r.pose_box([a, b, c])), ref)


@pytest.mark.parametrize("name, tilted, home", [
    ("spherical-example-1", "-0.025258874503", "0.223055353282"),
    ("spherical-example-2", "-0.0130010101268", "0.635387267163"),
    ("spherical-example-3", "-0.0576", "1.05204556036"),
])
def test_spherical_reference_values_and_robot_file_comments(name, tilted, home):
    """T&T (0, pi/4, 0) and the home pose Euler (30, 60, 30) deg = T&T (pi/6, pi/3, pi/3): the digest's
    values, printed in the robot file's comment, and enclosed by certkin's det(A)."""
    r, tt = robot(name), robot(name, True)
    comment = (EXAMPLES / f"seed003-{name}.toml").read_text()
    assert f"det A = {home} there" in comment and f"and {tilted} at T&T (0, pi/4, 0)" in comment
    assert r.home == ["30deg", "60deg", "30deg"]
    with mp.workdps(40):
        ref = spherical_det(r, r.home)
        assert abs(ref - spherical_det(tt, ("30deg", "60deg", "60deg"), True)) < mp.mpf(10) ** -35
        assert prints_as(ref, home) and encloses(r.det_enclosure(r.home_box()), ref)
        ref = spherical_det(tt, ("0", "45deg", "0"), True)
        assert prints_as(ref, tilted) and encloses(tt.det_enclosure(tt.pose_box(["0", "45deg", "0"])), ref)


@pytest.mark.parametrize("name, text", [("planar-example-1", "-20914.4629762"), ("planar-example-2", "8868.48667784")])
def test_planar_robot_file_home_comments(name, text):
    r = robot(name)
    assert f"det(10, 10, pi/8) = {text}" in (EXAMPLES / f"seed003-{name}.toml").read_text()
    assert r.home == ["10", "10", "22.5deg"]
    with mp.workdps(40):
        ref = planar_det(r, r.home)
        assert prints_as(ref, text) and encloses(r.det_enclosure(r.home_box()), ref)
