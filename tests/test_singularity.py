"""Singularity-free regions: seed 003 examples, hard cases, soundness against sampling, tampering."""

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import proofs
from certfile import Doc
from certkin.certificates import singularity_certificate
from certkin import load_robot, robot_from_dict
from certkin.engine import Budget
from certkin.singularity import certify_singularity_free, classify_cells, largest_free_box

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "robots"

EX2 = {"name": "ex2", "kind": "planar-3rpr",
       "base": [["3.78", "4.34"], ["34.47", "-3.78"], ["16.233", "34.76"]],
       "platform": [["-4.83", "-3.19"], ["12.04", "-3.19"], ["8.23", "12.09"]]}
EX1 = {"name": "ex1", "kind": "planar-3rpr",
       "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
       "platform": [["0", "0"], ["17.04", "0"], ["13.2364", "16.097"]]}
FULL = "x=-50:50,y=-50:50,phi=0:0.7853981634"


def spherical(h, x2, x3, y2):
    """Seed 003 Tables 4.13-4.15 (w1 w2 w3 u2 u3 x1 x2 x3 y2 y3 h), tilt-and-torsion angles."""
    return robot_from_dict({"kind": "spherical-3dof",
                            "base": [["1.6", "0", "-" + h], ["-1.1", "1.2", "-" + h], ["-0.9", "-1", "-" + h]],
                            "platform": [["1", "0", "0"], [x2, y2, "0"], [x3, "-0.5", "0"]]}).with_angles("tilt-torsion")


def checked(results):
    """Every certified answer in these tests is re-checked by the independent checker."""
    cert = singularity_certificate(results) if isinstance(results, list) else results.certificate()
    report = proofs.check(cert)
    assert report.ok, report.step
    return cert


def test_example2_full_box_is_singular_with_certified_witnesses():
    robot = robot_from_dict(EX2)
    r = certify_singularity_free(robot, FULL)
    assert r.status == "singular"
    pos, neg = r.witnesses["positive"], r.witnesses["negative"]
    assert robot.det_enclosure(pos).lo > 0 > robot.det_enclosure(neg).hi
    for w in (pos, neg):
        assert np.all(r.lo <= w) and np.all(w <= r.hi)
    checked(r)


def test_example2_rectangle_at_pi_over_4_needs_the_interior():
    """Digest §3.6: the vertices and edges are all negative; an ellipse of positive det lies inside."""
    robot = robot_from_dict(EX2)
    r = certify_singularity_free(robot, "x=-50:50,y=-50:50,phi=45deg")
    assert r.status == "singular"
    x, y, _ = r.witnesses["positive"]
    assert 5.0 <= x <= 26.5 and -13.0 <= y <= 22.0  # the positive region (digest §3.6)
    checked(r)


def test_example2_three_cells_per_side_match_the_digest():
    robot = robot_from_dict(EX2)
    cells = classify_cells(robot, FULL, 3)
    free = [tuple(int(i) for i in np.unravel_index(k, (3, 3, 3))) for k, c in enumerate(cells) if c.status == "singularity-free"]
    assert free == [(0, 0, 2), (0, 1, 1), (0, 1, 2), (0, 2, 0), (0, 2, 1), (0, 2, 2)]
    assert all(c.status == "singular" for c in cells if c.status != "singularity-free")
    checked(cells)


def test_example2_ten_cells_per_side_counts():
    robot = robot_from_dict(EX2)
    cells = classify_cells(robot, FULL, 10)
    counts = {s: sum(c.status == s for c in cells) for s in ("singularity-free", "singular", "undecided")}
    assert counts == {"singularity-free": 743, "singular": 257, "undecided": 0}
    checked(cells)


def test_example1_touching_cells_are_never_called_free():
    """Digest §3.6: det vanishes on x = y = 0 (B1 = P1) and on y = 0, phi = 0 without changing sign."""
    robot = robot_from_dict(EX1)
    budget = Budget(max_boxes=3000, max_seconds=10, min_width=1e-4)
    for box in ["x=-4:0,y=0:4,phi=0.6:0.7", "x=-8:-4,y=0:4,phi=0:0.0785"]:
        r = certify_singularity_free(robot, box, budget=budget)
        assert r.status in ("undecided", "singular")


def test_spherical_free_cell_with_small_margin():
    """Digest §3.6: spherical Ex 1, n = 3, cell (2,1,0) is free with max det = -0.019073."""
    robot = spherical("1.2", "-0.6", "-0.2", "1")
    r = certify_singularity_free(robot, "phi1=30deg:90deg,phi2=30deg:60deg,sigma=-90deg:-30deg")
    assert r.status == "singularity-free" and r.sign == -1
    checked(r)


def test_spherical_tiny_singular_pocket_found():
    """Digest §3.6: spherical Ex 2, n = 5, cell (3,2,3) has min det -0.0022 that a 7x7x7 grid misses."""
    robot = spherical("1.4", "-0.6", "-0.2", "1")
    r = certify_singularity_free(robot, "phi1=18deg:54deg,phi2=36deg:54deg,sigma=18deg:54deg")
    assert r.status == "singular"
    checked(r)
    # a 7x7x7 grid of samples indeed sees one sign only
    g = np.stack(np.meshgrid(*[np.linspace(a, b, 7) for a, b in zip(r.lo, r.hi)], indexing="ij"), -1).reshape(-1, 3)
    assert np.all(robot.det_float(g) > 0)


def test_gough_box_away_from_singularities():
    base = [[str(c) for c in p] for p in [[10, 0, 0], [5, 8.66, 0], [-5, 8.66, 0], [-10, 0, 0], [-5, -8.66, 0], [5, -8.66, 0]]]
    plat = [[str(c) for c in p] for p in [[4, 3, 0], [0.6, 5, 0], [-4.6, 2, 0], [-4.6, -2, 0], [0.6, -5, 0], [4, -3, 0]]]
    robot = robot_from_dict({"kind": "gough-stewart", "base": base, "platform": plat})
    r = certify_singularity_free(robot, "x=-0.05:0.05,y=-0.05:0.05,z=9.95:10.05,psi=-0.005:0.005,theta=-0.005:0.005,"
                                        "phi=-0.005:0.005", budget=Budget(max_boxes=5000, max_seconds=20))
    assert r.status == "singularity-free"
    checked(r)


GS_SYM = {"name": "gs-sym", "kind": "gough-stewart",
          "base": [["10.0", "0.0", "0"], ["-1.7365", "9.8481", "0"], ["-5.0", "8.6603", "0"], ["-7.6604", "-6.4279", "0"],
                   ["-5.0", "-8.6603", "0"], ["9.3969", "-3.4202", "0"]],
          "platform": [["3.8302", "3.2139", "0"], ["0.8682", "4.924", "0"], ["-4.6985", "1.7101", "0"],
                       ["-4.6985", "-1.7101", "0"], ["0.8682", "-4.924", "0"], ["3.8302", "-3.2139", "0"]]}


def test_gough_boxes_the_solver_proves_the_checker_proves():
    """The checker eliminated A's transpose (legs as columns), whose preconditioned enclosure of det was
    ten times wider on some boxes; it now eliminates A as the solver does (legs as rows).  The box of this
    robot was refused at its 67th node."""
    r = certify_singularity_free(robot_from_dict(GS_SYM), "x=-6.61:-6.59,y=-8.41:-8.39,z=9.9:10,psi=-0.62,"
                                 "theta=-0.1:0.1,phi=-0.51:-0.49", budget=Budget(max_boxes=5000, max_seconds=20))
    assert r.status == "singularity-free"
    checked(r)


@pytest.mark.parametrize("phi", ["0deg:35.8deg", "1.1deg", "45deg:0.7853981633974484"])
def test_angles_in_degrees_at_the_ends_of_the_box_check(phi):
    """A box end in degrees: the checker's enclosure of q·π/180 is now one float wide, inside the box proved."""
    r = certify_singularity_free(robot_from_dict(EX2), f"x=-20:-10,y=20:30,phi={phi}",
                                 budget=Budget(max_boxes=5000, max_seconds=20))
    assert r.status in ("singularity-free", "singular")
    checked(r)


def test_cells_with_bounds_below_1e_62_check():
    """A cell's requested bounds are the exact decimals of its floats: 1e-300 as a double has some 750
    significant digits, past the checker's former limit of 200 characters a decimal."""
    results = classify_cells(robot_from_dict(EX2), "x=1e-300:2e-300,y=0:1e-320,phi=0:5e-324", 3,
                             budget=Budget(max_boxes=5000, max_seconds=20))
    cert = checked(results)
    assert max(len(v) for c in cert.header["claims"] for pair in c["requested"].values() for v in pair) > 200


def test_largest_free_box_is_certified_and_maximal_along_the_scale():
    robot = robot_from_dict(EX2)
    r = largest_free_box(robot, "-30,30,0.2", scale="1,1,0.05", budget=Budget(max_boxes=5000, max_seconds=5))
    assert r.status == "singularity-free" and r.scale_factor > 0
    checked(r)
    c = np.array([-30, 30, 0.2])
    assert np.allclose((r.lo + r.hi) / 2, c)
    assert np.allclose((r.hi - r.lo) / 2, r.scale_factor * np.array([1, 1, 0.05]))
    # near-maximal: a box twice as large already contains both signs of det(A)
    rng = np.random.default_rng(0)
    h = (r.hi - r.lo) / 2
    d = robot.det_float(rng.uniform(c - 2 * h, c + 2 * h, size=(20000, 3)))
    assert (d > 0).any() and (d < 0).any()


def test_largest_free_box_cut_by_its_time_budget_says_so_with_its_whole_time():
    """The time budget stopped the bisection on s without a word, and the seconds (and boxes) stated
    were those of the last box proved, not of the whole bisection (40.6 s of work reported as 1.83 s)."""
    from certkin.cli.singular import describe
    mel = str(Path(__file__).resolve().parent.parent / "examples" / "robots" / "seed000-mel-tsukuba.toml")
    r = largest_free_box(mel, "-69,-50,500,85deg,10deg,0", max_seconds=1.5)
    assert r.status == "singularity-free" and 0 < r.scale_factor < 0.125
    g = r.bisection
    assert g["stopped"] == "time budget" and g["proved"] == r.scale_factor and g["tried"] > 5
    assert r.seconds >= 1.5
    assert r.to_json()["bisection"] == g and r.to_json()["stats"]["seconds"] >= 1.5
    assert "the time budget (--max-seconds) ran out while the box was grown" in describe(r.robot, r)
    checked(r)


def test_a_bisection_cut_short_prints_its_proved_scale_rounded_down():
    """The proved s of a cut bisection was printed to 9 digits rounded to nearest: 1.18603515625 as
    1.18603516, more than was proved.  It is rounded down now (terminal and report); the s not proved
    is printed exactly."""
    from types import SimpleNamespace
    from certkin.cli.singular import describe
    from certkin.report.singularity import singularity_verdict
    robot = load_robot(str(EXAMPLES / "seed003-planar-example-2.toml"))
    g = {"stopped": "time budget", "proved": 1.18603515625, "not_proved": 1.1865234375, "tried": 12}
    r = SimpleNamespace(status="singularity-free", sign=1, boxes=10, seconds=0.5, bisection=g, around={},
                        scale_factor=g["proved"], lo=np.zeros(3), hi=np.ones(3), texts=None, name="r")
    line = describe(robot, r)
    assert "s = 1.18603515 proved" in line and "1.18603516" not in line and "s = 1.1865234375 is not" in line
    verdict = singularity_verdict([r])
    assert "s = 1.18603515 proved" in verdict and "1.18603516" not in verdict


def test_largest_free_box_does_not_search_a_box_with_a_corner_of_the_other_sign():
    """A box whose corner has det(A) of the sign opposite to the pose's is singular: it is not searched
    (near the singularity surface the search, depth first, spent the whole time budget on such a box)."""
    import certkin.singularity as singularity
    searched = []
    real = singularity.classify_cells

    def classify(*args, **kwargs):
        out = real(*args, **kwargs)
        searched.append(out[0].status)
        return out
    robot = robot_from_dict(EX2)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(singularity, "classify_cells", classify)
        r = largest_free_box(robot, "10,10,22.5deg", scale="1,1,0.1", max_seconds=20)
    assert r.status == "singularity-free" and r.bisection["stopped"] is None
    assert r.bisection["tried"] > len(searched) and "singular" not in searched
    checked(r)


@pytest.mark.parametrize("unit", [2.0 ** 39, 2.0 ** -1000])
def test_largest_free_box_does_not_depend_on_the_scales_unit(unit):
    """The scale times a power of 2 gives the same box (with the scale 1e12, every box tried was too
    wide and the point itself was returned; with 1e-300, boxes of 1e-294 at most were tried)."""
    robot = robot_from_dict(EX2)
    budget = Budget(max_boxes=5000, max_seconds=20)
    ref = largest_free_box(robot, "-30,30,0.2", scale="1,1,0.05", budget=budget)
    r = largest_free_box(robot, "-30,30,0.2", scale=[unit, unit, 0.05 * unit], budget=budget)
    assert r.status == "singularity-free" and np.allclose(r.lo, ref.lo) and np.allclose(r.hi, ref.hi)
    checked(r)


def test_a_box_around_a_pose_at_the_edge_of_the_value_range_is_never_an_error():
    """Around 1e12 every box but the point leaves the range of user values: those count as not proved
    (the message named --box and a value never typed)."""
    r = largest_free_box(robot_from_dict(EX2), "1e12,1e12,0", budget=Budget(max_boxes=500, max_seconds=10))
    assert r.status == "singularity-free" and np.all(np.abs(r.lo) <= 1e12) and np.all(np.abs(r.hi) <= 1e12)


@pytest.mark.parametrize("pose", ["999999999999.9,10,0.3", "1e12,10,0.3", "10,10,0.3"])
def test_the_scale_factor_is_a_box_held_in_the_proved_one(pose):
    """pose ± s·scale (exact rationals) lies in the box proved: it was computed in round-to-nearest, so at
    999999999999.9 + s the box ended below the pose + s that the scale factor states."""
    from fractions import Fraction
    r = largest_free_box(robot_from_dict(EX2), pose, budget=Budget(max_boxes=500, max_seconds=10))
    assert r.status == "singularity-free"
    s = Fraction(r.scale_factor)
    for k, v in enumerate(pose.split(",")):
        assert Fraction(r.lo[k]) <= Fraction(v) - s and Fraction(v) + s <= Fraction(r.hi[k]), (k, r.lo[k], r.hi[k], s)
    checked(r)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10_000))
def test_soundness_against_dense_sampling(seed):
    """Random robots and boxes: 'singularity-free' never meets a sign change, sign changes give 'singular'."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(-10, 10, (3, 2)).round(2)
    plat = rng.uniform(-4, 4, (3, 2)).round(2)
    robot = robot_from_dict({"kind": "planar-3rpr", "base": [[str(v) for v in p] for p in base],
                             "platform": [[str(v) for v in p] for p in plat]})
    c = np.array([rng.uniform(-8, 8), rng.uniform(-8, 8), rng.uniform(-3, 3)])
    h = np.array([rng.uniform(0.1, 4), rng.uniform(0.1, 4), rng.uniform(0.01, 0.5)])
    box = {n: (repr(float(a)), repr(float(b))) for n, a, b in zip(robot.pose_names, c - h, c + h)}
    r = certify_singularity_free(robot, box, budget=Budget(max_boxes=4000, max_seconds=5, min_width=1e-6))
    g = rng.uniform(r.lo, r.hi, size=(4000, 3))
    d = robot.det_float(g)
    both = (d > 1e-6 * np.abs(d).max()).any() and (d < -1e-6 * np.abs(d).max()).any()
    if r.status == "singularity-free":
        assert not both
        assert np.all(np.sign(d[np.abs(d) > 1e-9 * np.abs(d).max()]) == r.sign)
    if both:
        assert r.status == "singular"
    if r.status != "undecided":
        checked(r)


@pytest.fixture(scope="module")
def free_certificate():
    robot = robot_from_dict(EX2)
    r = certify_singularity_free(robot, "x=-50:-30,y=20:40,phi=0.5:0.7")
    assert r.status == "singularity-free"
    cert = Doc(r.certificate())
    assert cert.check().ok
    return cert


def test_tampered_certificates_are_rejected(free_certificate):
    cert = free_certificate
    assert cert.arrays["tree.kind"][0] <= 1, "the test needs a tree with at least one split"

    flipped = cert.copy()
    flipped.claim()["sign"] = -flipped.claim()["sign"]
    assert not flipped.check().ok

    dropped = cert.copy()                        # the root split and its lower half's subtree gone
    for name in ("tree.kind", "tree.code"):
        dropped.arrays[name] = dropped.arrays[name][1:]
    assert not dropped.check().ok

    geometry = cert.copy()
    geometry.header["robot"]["base"][2][1] = "-34.76"  # a changed character: det(A) > 0 somewhere on this box then
    geometry.header["geometry_sha256"] = proofs.geometry_sha256(geometry.header["robot"])
    assert not geometry.check().ok

    grown = cert.copy()                          # grown to a box that holds a singularity (FULL is singular)
    grown.claim()["box"] = [[-50.0, 50.0], [-50.0, 50.0], [0.0, 0.7853981634000001]]
    grown.claim().pop("requested")
    assert not grown.check().ok

    swapped = cert.copy()           # the root split along another dimension: the checker re-proves the rules,
    swapped.arrays["tree.code"][0] = (swapped.arrays["tree.code"][0] + 1) % 3      # bisecting as it needs
    report = swapped.check()        # (the claim is true: still a proof of it), or names the leaf it cannot
    assert report.ok or report.step.startswith("claims[0].tree: node ")


def test_tampered_witness_rejected():
    robot = robot_from_dict(EX2)
    cert = Doc(certify_singularity_free(robot, FULL).certificate())
    assert cert.check().ok
    bad = cert.copy()
    bad.claim()["witnesses"]["negative"] = bad.claim()["witnesses"]["positive"]
    assert not bad.check().ok
    outside = cert.copy()
    outside.claim()["witnesses"]["negative"][0] = 1000.0
    assert not outside.check().ok
    free = cert.copy()                           # issue item 5: a requested box edited to a free region
    free.claim()["requested"] = {"x": ["10", "10.001"], "y": ["10", "10.001"], "phi": ["0.39", "0.3901"]}
    assert "outside the requested" in free.check().step


# ----- a coordinate given one value is fixed (never split into cells, never bisected) -----------------
def test_fixed_irrational_angle_planar_section_matches_the_digest():
    """Digest §3.6 grid table, planar Ex 2 at phi = pi/4, n = 10: S 12 / F 88.  phi = 45deg is an
    irrational angle enclosed in a one-ulp interval; splitting it into cells once left 280 of 1000
    cells undecided."""
    robot = robot_from_dict(EX2)
    cells = classify_cells(robot, "x=-50:50,y=-50:50,phi=45deg", 10)
    assert len(cells) == 100
    assert all(c.lo[2] == cells[0].lo[2] and c.hi[2] == cells[0].hi[2] for c in cells)
    counts = {s: sum(c.status == s for c in cells) for s in ("singularity-free", "singular", "undecided")}
    assert counts == {"singularity-free": 88, "singular": 12, "undecided": 0}
    checked(cells)


def test_fixed_torsion_spherical_section_matches_the_digest():
    """Digest §3.6 grid table, spherical Ex 1 at sigma = pi/3, n = 10: S 16 / F 84."""
    robot = spherical("1.2", "-0.6", "-0.2", "1")
    cells = classify_cells(robot, "phi1=-90deg:90deg,phi2=0:90deg,sigma=60deg", 10)
    counts = {s: sum(c.status == s for c in cells) for s in ("singularity-free", "singular", "undecided")}
    assert counts == {"singularity-free": 84, "singular": 16, "undecided": 0}
    checked(cells)


def test_budget_keywords_and_paths_are_accepted():
    from pathlib import Path
    from certkin import InputError
    path = Path(__file__).resolve().parents[1] / "examples" / "robots" / "seed003-planar-example-2.toml"
    r = certify_singularity_free(str(path), "x=-20:-10,y=20:30,phi=0:0.3", max_boxes=5000, max_seconds=10,
                                 min_width=1e-6)
    assert r.status == "singularity-free" and len(repr(r)) < 200
    for bad in (dict(max_boxes=0), dict(max_seconds=float("nan")), dict(min_width=-1.0), dict(max_memory=0)):
        with pytest.raises(InputError) as exc:
            certify_singularity_free(str(path), "x=-20:-10,y=20:30,phi=0:0.3", **bad)
        assert exc.value.source == next(iter(bad))
    with pytest.raises(InputError) as exc:
        classify_cells(str(path), "x=-1:1,y=0:1,phi=0:0.1", 1000, max_boxes=10 ** 10)
    assert exc.value.source == "n"



def test_a_time_budget_spent_before_the_search_gives_undecided_not_an_error():
    """max_seconds=1e-9 raised "n: 1 cells per side make 1 cells, whose answers take about 0 s, more than
    the time budget": an error naming a parameter certify_singularity_free does not have."""
    r = certify_singularity_free(robot_from_dict(EX2), FULL, max_seconds=1e-9)
    assert r.status in ("undecided", "singular")
    checked(r)

ISOSCELES = {"name": "isosceles mirror", "kind": "planar-3rpr", "base": [[-10, 0], [10, 0], [0, 15]],
             "platform": [[-3, 0], [3, 0], [0, 4]]}


@pytest.mark.parametrize("phi, value", [("0.001", 0.001), ("0.1deg", float(np.pi / 1800))])
def test_a_witness_on_a_fixed_coordinate_shows_its_value_not_the_bound_of_its_enclosure(phi, value):
    """A mirror-symmetric robot, singular on x = 0 near phi = 0: the witnesses' phi was printed as the
    lower bound of the enclosure of 0.001 (0.0009999999999999998, outside the box asked about)."""
    from certkin.cli.singular import describe
    robot = robot_from_dict(ISOSCELES)
    r = certify_singularity_free(robot, f"x=-3:3,y=-3:3,phi={phi}")
    assert r.status == "singular"
    doc = r.to_json()
    for key in ("positive", "negative"):
        assert doc["witnesses"][key]["phi"] == value
    assert describe(robot, r).count(f"{phi})") == 2
    assert proofs.check(r.certificate()).ok


def _drawn_panels(monkeypatch):
    """The axes of every figure ``plt.subplots`` makes from now on (the panels of a plot)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    drawn, real = [], plt.subplots

    def subplots(*a, **k):
        fig, axes = real(*a, **k)
        drawn.append(axes)
        return fig, axes
    monkeypatch.setattr(plt, "subplots", subplots)
    return drawn


def _shown(panel, status):
    """Where the panel's image shows ``status`` (rows from the bottom, columns from the left)."""
    from certkin.plots import singularity as splot
    colour = [int(splot.COLOURS[status][k:k + 2], 16) / 255 for k in (1, 3, 5)]
    return np.all(np.isclose(panel.get_images()[0].get_array(), colour), axis=-1)


def test_a_projected_cell_grid_shows_the_least_favourable_status_of_its_cells(tmp_path, monkeypatch):
    """Cells of a 4-D grid drawn on (x, y) slices overlapped: the last drawn won, and a free square could
    cover a singular cell.  Each square now shows the worst status of the cells drawn on it: the square
    (x, y) = (0, 0) of the slice z in [0, 1] holds a free cell (psi in [0, 1]) and a singular one (psi in
    [1, 2]): red, and the opposite square (all free) not."""
    from types import SimpleNamespace
    from certkin.plots import singularity as splot
    robot = SimpleNamespace(name="r", pose_names=["x", "y", "z", "psi"], angle_names=["psi"])
    cells = [SimpleNamespace(lo=np.array([x, y, z, p]), hi=np.array([x + 1, y + 1, z + 1, p + 1]), sign=1,
                             status="singular" if (x, y, z, p) == (0, 0, 0, 1) else "singularity-free")
             for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0) for p in (0.0, 1.0, 2.0)]
    drawn = _drawn_panels(monkeypatch)
    splot.plot_cells(robot, cells, tmp_path / "c.png")
    red = _shown(drawn[0].flat[0], "singular")          # the panel of z in [0, 1]
    h, w = red.shape
    assert red[:h // 2 - 1, :w // 2 - 1].all() and not red[h // 2 + 1:, w // 2 + 1:].any()
    assert not _shown(drawn[0].flat[1], "singular").any()


def test_a_singular_cell_smaller_than_a_pixel_is_still_red(tmp_path, monkeypatch):
    """A 200 x 200 grid at fixed phi: its 542 singular cells, a band one or two cells wide, were drawn
    as squares under a pixel and their neighbours' borders covered them: no red pixel at all, in the
    picture and in the report.  Each panel is now an image where every pixel a singular cell touches is
    red: the pixel under each singular cell's centre is red."""
    from certkin.plots import singularity as splot
    robot = load_robot(str(EXAMPLES / "seed003-planar-example-2.toml"))
    cells = classify_cells(robot, "x=-50:50,y=-50:50,phi=0.3", 200)
    singular = [c for c in cells if c.status == "singular"]
    assert len(singular) > 100 and any(c.status == "singularity-free" for c in cells)
    drawn = _drawn_panels(monkeypatch)
    splot.plot_cells(robot, cells, tmp_path / "c.png")
    panel = drawn[0].flat[0]
    red = _shown(panel, "singular")
    (x0, x1), (y0, y1) = panel.get_images()[0].get_extent()[:2], panel.get_images()[0].get_extent()[2:]
    centre = np.array([(c.lo[:2] + c.hi[:2]) / 2 for c in singular])
    col = ((centre[:, 0] - x0) / (x1 - x0) * red.shape[1]).astype(int)
    row = ((centre[:, 1] - y0) / (y1 - y0) * red.shape[0]).astype(int)
    assert red[row, col].all()
    assert panel.get_xlabel().startswith("x") and panel.get_ylabel().startswith("y")


def test_a_fixed_coordinate_is_never_a_drawn_axis(tmp_path, monkeypatch):
    """y fixed at 5.1 (an enclosure one float wide) was taken for a drawn axis: the cells were drawn a
    float high, and the panels were blank.  The drawn axes are those the cells vary along (here x and
    phi: the first panel shows every status the cells have); with one such axis, the other is a band."""
    from certkin.plots import singularity as splot
    robot = load_robot(str(EXAMPLES / "seed003-planar-example-2.toml"))
    cells = classify_cells(robot, "x=-50:50,y=5.1,phi=0:45deg", 12)
    drawn = _drawn_panels(monkeypatch)
    splot.plot_cells(robot, cells, tmp_path / "c.png")
    panel = drawn[0].flat[0]
    assert panel.get_xlabel().startswith("x (") and panel.get_ylabel().startswith("phi (")
    assert {c.status for c in cells} == {"singular", "singularity-free"}
    assert _shown(panel, "singular").sum() > 1000 and _shown(panel, "free-").sum() > 1000
    cells = classify_cells(robot, "x=10,y=10,phi=0:90deg", 20)
    drawn.clear()
    splot.plot_cells(robot, cells, tmp_path / "d.png")
    panel = drawn[0].flat[0]
    assert panel.get_xlabel().startswith("phi (") and "every cell" in panel.get_ylabel()
    assert _shown(panel, "singular").any() and _shown(panel, "free+").sum() > 1000


def test_the_cell_plot_never_leaves_a_singular_cell_out(tmp_path):
    """12 slices of phi and 6 panels: slices were picked (0, 2, 4, 7, 9, 11) and a singular cell in
    slice 1 was not drawn at all.  Consecutive slices now share a panel, each square its least
    favourable cell."""
    pytest.importorskip("matplotlib")
    from pathlib import Path
    from types import SimpleNamespace
    from PIL import Image
    from certkin.plots.singularity import COLOURS, plot_cells
    from certkin import load_robot
    robot = load_robot(str(Path(__file__).resolve().parent.parent / "examples" / "robots" / "seed003-planar-example-2.toml"))
    cells = [SimpleNamespace(lo=np.array([x, y, 0.1 * k]), hi=np.array([x + 1.0, y + 1.0, 0.1 * (k + 1)]),
                             status="singular" if (x, y, k) == (0.0, 0.0, 1) else "singularity-free", sign=1)
             for x in (0.0, 1.0) for y in (0.0, 1.0) for k in range(12)]
    plot_cells(robot, cells, tmp_path / "c.png")
    rgb = np.asarray(Image.open(tmp_path / "c.png").convert("RGB")).astype(int)
    red = np.all(np.abs(rgb - [int(COLOURS["singular"][i:i + 2], 16) for i in (1, 3, 5)]) < 10, axis=2)
    assert red.sum() > 1000        # a square of a panel (the legend's patch is about 200 pixels)


def test_the_memory_cells_need_is_shown_rounded_up_and_the_budget_rounded_down():
    """The memory refusal showed both sizes rounded to nearest ('1 MiB, more than the memory budget
    (1 MiB)' could be printed) and '1 bytes': the need is now rounded up, the budget down."""
    from certkin import InputError
    from certkin.singularity import CELL_BYTES
    path = str(EXAMPLES / "seed003-planar-example-2.toml")
    with pytest.raises(InputError, match=r"^max_memory: the box needs about 6\.84 KiB, more than the memory budget "
                                         r"\(1 byte\)$"):
        certify_singularity_free(path, "x=-20:-10,y=20:30,phi=0:0.3", max_memory=1)
    assert 150 * CELL_BYTES > 2 ** 20 + 1 > 149 * CELL_BYTES    # 150 cells: 1.0014 MiB, more than 1 MiB + 1 byte
    with pytest.raises(InputError, match=r"^n: 150 cells per side make 150 cells, about 1\.01 MiB, more than the "
                                         r"memory budget \(1 MiB\)$"):
        classify_cells(path, "x=-20:-10,y=25,phi=0.1", 150, max_memory=2 ** 20 + 1)
