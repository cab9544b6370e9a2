"""Seed 000 (Merlet 1993, MEL Tsukuba robot): the digest's derived values (§3.3) against mpmath.

- The natural home C = (0, 0, 500), R = I: leg lengths for the printed table (x_a3 = -112.5, leg 3 below
  rho_min, so the pose is outside the workspace) and for the flagged variant x_a3 = +112.5 (erratum E25,
  ``seed000-mel-tsukuba-x_a3-variant.toml``); the nearest leg pairs there.
- The Fig. 1.8 path: leg lengths at its ends (robot-file comments), the variant's path, the pair (1, 4)
  clearance 0.5242 at the goal on the full path, and the mean margins (``indices``) against mpmath
  quadrature.
Reference values: 40-digit mpmath from the exact decimals (``seedref``, the segment distance of
``test_trajectory``); printed values are read as ± half a unit of their last digit.  Every certified
answer is re-checked by ``proofs``.
"""
from pathlib import Path

import mpmath as mp
import pytest

from certfile import checked
from certkin import load_robot, robot_from_dict, verify_trajectory
from seedref import encloses, exact, gough_legs, prints_as
from test_trajectory import GOAL, START, _dist_at, _legs_mp, _pose, _seg_dist

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "robots"
TABLE = EXAMPLES / "seed000-mel-tsukuba.toml"
VARIANT = EXAMPLES / "seed000-mel-tsukuba-x_a3-variant.toml"
HOME = ["0", "0", "500", "0", "0", "0"]


@pytest.fixture(scope="module")
def table():
    return load_robot(TABLE)


@pytest.fixture(scope="module")
def variant():
    return load_robot(VARIANT)


def test_variant_differs_from_the_table_only_in_x_a3(table, variant):
    assert table.base[2][0] == "-112.5" and variant.base[2][0] == "112.5"
    assert [p for k, p in enumerate(table.base) if k != 2] == [p for k, p in enumerate(variant.base) if k != 2]
    assert table.base[2][1:] == variant.base[2][1:]
    assert table.platform == variant.platform and table.limits == variant.limits and table.home == variant.home
    assert "VARIANT" in VARIANT.read_text() and "E25" in VARIANT.read_text()


# ----- natural home (0, 0, 500, 0, 0, 0) --------------------------------------------------------------
@pytest.mark.parametrize("which, printed_lengths", [
    ("table", "563.693 563.693 524.292 528.819 528.819 528.819"),
    ("variant", "563.693 563.693 563.693 528.819 528.819 528.819")])
def test_natural_home_leg_lengths(which, printed_lengths, table, variant):
    """Digest §3.3: with the table data leg 3 is 524.292 < rho_min = 528, so the natural home is outside
    the workspace (a certified infeasible static pose); with x_a3 = +112.5 every leg is inside."""
    robot = table if which == "table" else variant
    lengths = gough_legs(robot, HOME)
    enc = robot.leg_lengths(robot.pose_box(HOME))
    for k, text in enumerate(printed_lengths.split()):
        assert prints_as(lengths[k], text) and encloses(enc, lengths[k], k)
    comment = VARIANT.read_text()
    assert "leg lengths 563.693, 563.693, 563.693, 528.819, 528.819, 528.819" in comment and "524.292" in comment
    r = verify_trajectory(robot, ",".join(HOME), ",".join(HOME), constraints=["leg-length"])
    if which == "table":
        assert r.status == "infeasible"
        assert [v["legs"] for v in r.violations if v["certain"]] == [[3]]
        margin = next(m["margin"] for m in r.margins if m["legs"] == [3])
        assert encloses_pair(margin, lengths[2] - 528)               # -3.708
    else:
        assert r.status == "feasible"
        for m in r.margins:
            i = m["legs"][0] - 1
            lo, hi = (exact(v) for v in robot.limits["leg_length"][i])
            assert encloses_pair(m["margin"], min(lengths[i] - lo, hi - lengths[i]))
    checked(r)


def encloses_pair(pair, value):
    return mp.mpf(pair[0]) <= value <= mp.mpf(pair[1]) and pair[1] - pair[0] < 1e-6


def test_nearest_leg_pairs_at_the_natural_home(table):
    """Digest §3.3: with the table data the nearest leg pairs at home are (1, 6) and (2, 4), 30.388 mm
    apart (exact segment distances at 40 digits); certkin's interference margins d - 4 enclose them."""
    A, B = _legs_mp(table, [exact(v) for v in HOME])
    dist = {(i, j): _seg_dist(A[i], B[i], A[j], B[j]) for i in range(6) for j in range(i + 1, 6)}
    nearest = sorted(dist, key=dist.get)
    assert set(nearest[:2]) == {(0, 5), (1, 3)} and dist[nearest[2]] > dist[(1, 3)] + 1
    assert prints_as(dist[(0, 5)], "30.388") and prints_as(dist[(1, 3)], "30.388")
    r = verify_trajectory(table, ",".join(HOME), ",".join(HOME), constraints=["interference"])
    assert r.status == "feasible"
    for m in r.margins:
        i, j = m["legs"][0] - 1, m["legs"][1] - 1
        assert encloses_pair(m["margin"], dist[(i, j)] - 4)
    checked(r)


# ----- Fig. 1.8 path ---------------------------------------------------------------------------------
@pytest.mark.parametrize("pose, table_text, variant_leg3", [
    (START, "614.960 554.732 614.504 509.691 521.203 517.234", "661.997"),
    (GOAL, "648.612 643.588 565.088 518.848 546.061 503.429", "557.762")])
def test_fig_1_8_end_leg_lengths_and_robot_file_comments(pose, table_text, variant_leg3, table, variant):
    """Digest §3.3 leg lengths at M_1 and M_2 (the start values are in both robot files' comments)."""
    P = pose.split(",")
    for robot, texts in ((table, table_text.split()), (variant, table_text.split()[:2] + [variant_leg3]
                                                       + table_text.split()[3:])):
        lengths = gough_legs(robot, P)
        enc = robot.leg_lengths(robot.pose_box(P))
        for k, text in enumerate(texts):
            assert prints_as(lengths[k], text) and encloses(enc, lengths[k], k)
    assert "614.960, 554.732, 614.504 (661.997 with x_a3 = +112.5), 509.691, 521.203, 517.234" in TABLE.read_text()
    assert "Leg 3 is 661.997 at the start and 557.762 at the goal here" in VARIANT.read_text()


def _leg_range(robot, i):
    """[min, max] of rho_i on the straight Fig. 1.8 path: rho_i^2 = |V + t w|^2 is a convex quadratic."""
    P0, P1 = _pose(START), _pose(GOAL)
    A0, B0 = _legs_mp(robot, P0)
    V, w = B0[i] - A0[i], mp.matrix(P1[:3]) - mp.matrix(P0[:3])
    t_o = -mp.fdot(V, w) / mp.fdot(w, w)
    rho = [mp.norm(V + t * w) for t in [mp.mpf(0), mp.mpf(1)] + ([t_o] if 0 < t_o < 1 else [])]
    return min(rho), max(rho)


def test_variant_fig_1_8_path_has_no_leg_length_violation(variant):
    """Digest §3.3: no leg-length violation on the path for either x_a3; variant leg 3 ranges over
    [557.7623, 661.9966].  certkin's margins enclose the exact minima of min(rho - rho_min, rho_max - rho)."""
    lo3, hi3 = _leg_range(variant, 2)
    assert prints_as(lo3, "557.7623") and prints_as(hi3, "661.9966")
    r = verify_trajectory(variant, START, GOAL, constraints=["leg-length"])
    assert r.status == "feasible"
    for m in r.margins:
        i = m["legs"][0] - 1
        rmin, rmax = (exact(v) for v in variant.limits["leg_length"][i])
        lo, hi = _leg_range(variant, i)
        assert m["margin"][0] <= min(lo - rmin, rmax - hi) <= m["margin"][1]
        assert m["margin"][1] - m["margin"][0] < 1e-3
    checked(r)


def test_pair_1_4_clearance_on_the_full_fig_1_8_path(table):
    """Digest §3.3: on the full path the pair (1, 4) stays clear, least distance 4.5242 at lambda = 1, so
    its margin is 0.5242 (the path is infeasible because of (1, 2) and (2, 5), not (1, 4))."""
    r = verify_trajectory(table, START, GOAL)
    assert r.status == "infeasible"
    assert not [v for v in r.violations if v["legs"] == [1, 4]]
    margin = next(m["margin"] for m in r.margins if m["legs"] == [1, 4])
    d = [_dist_at(table, START, GOAL, 0, 3, mp.mpf(k) / 400) for k in range(401)]
    assert min(d) == d[-1] and d[-2] > d[-1]                 # sampled: least at lambda = 1
    assert prints_as(d[-1], "4.5242") and prints_as(d[-1] - 4, "0.5242")
    assert margin[0] <= d[-1] - 4 and d[-1] - 4 - margin[1] < 1e-9
    assert margin[1] - margin[0] < 1e-6
    checked(r)


def _mean(f, pieces, breaks=()):
    """Integral of f over [0, 1] (Gauss-Legendre on pieces, split at the breaks)."""
    nodes = sorted(set([mp.mpf(k) / pieces for k in range(pieces + 1)] + [b for b in breaks if 0 < b < 1]))
    return sum(mp.quad(f, [a, b]) for a, b in zip(nodes, nodes[1:]))


def test_fig_1_8_mean_margins(table):
    """certkin's ``indices``: enclosures of the mean margin over the path.  Reference: mpmath quadrature of
    min(rho_i - rho_min, rho_max - rho_i) (split where rho_i crosses the middle of its range) for the six
    legs, and of d_14 - 4 (the segment distance) for the pair (1, 4)."""
    r = verify_trajectory(table, START, GOAL)
    indices = {(m["constraint"], tuple(m["legs"])): m["mean_margin"] for m in r.indices}
    assert len(indices) == 6 + 15
    P0, P1 = _pose(START), _pose(GOAL)
    A0, B0 = _legs_mp(table, P0)
    w = mp.matrix(P1[:3]) - mp.matrix(P0[:3])
    with mp.workdps(25):
        for i in range(6):
            V = B0[i] - A0[i]
            rmin, rmax = (exact(v) for v in table.limits["leg_length"][i])
            a, b, c, mid = mp.fdot(w, w), 2 * mp.fdot(V, w), mp.fdot(V, V), (rmin + rmax) / 2
            disc = b * b - 4 * a * (c - mid * mid)
            breaks = [(-b + s * mp.sqrt(disc)) / (2 * a) for s in (-1, 1)] if disc > 0 else []

            def margin(t, V=V, rmin=rmin, rmax=rmax):
                rho = mp.norm(V + t * w)
                return min(rho - rmin, rmax - rho)
            ref = _mean(margin, 4, breaks)
            lo, hi = indices[("leg-length", (i + 1,))]
            assert lo <= ref <= hi and hi - lo < 2
        ref = _mean(lambda t: _dist_at(table, START, GOAL, 0, 3, t) - 4, 16)
        lo, hi = indices[("interference", (1, 4))]
        assert lo <= ref <= hi and hi - lo < 1
    checked(r)


def test_interior_minimum_counter_example_e4():
    """Erratum E4 (Rule 7, "rho is monotone on [0, 1]" is false): A at the origin, B moving from (-1, 0.1)
    to (1, 0.1), rho_min = 2.  rho = sqrt(1.01) at both ends, but its minimum is 0.1 at the midpoint, so
    the leg-length margin over the path is 0.1 - 2 = -1.9, not the ends' sqrt(1.01) - 2.  Built as leg 1
    of a planar 3-RPR (B_1 at the platform origin, phi = 0); legs 2 and 3 stay well inside their limits."""
    robot = robot_from_dict({"kind": "planar-3rpr", "base": [["0", "0"], ["100", "0"], ["0", "100"]],
                             "platform": [["0", "0"], ["1", "0"], ["0", "1"]],
                             "limits": {"leg_length": [["2", "1000"], ["1", "1000"], ["1", "1000"]]}})
    r = verify_trajectory(robot, "-1,0.1,0", "1,0.1,0", constraints=["leg-length"])
    assert r.status == "infeasible"
    (v,) = [v for v in r.violations if v["legs"] == [1]]
    assert v["certain"] and v["t"] == [0.0, 1.0]
    margin = next(m["margin"] for m in r.margins if m["legs"] == [1])
    exact_min, ends = mp.mpf("0.1") - 2, mp.sqrt(mp.mpf("1.01")) - 2
    assert mp.mpf(margin[0]) <= exact_min <= mp.mpf(margin[1])
    # a monotone rule would report the ends' -0.995; the enclosure is far below it.  (Margins of violated
    # constraints are not refined, only those of satisfied ones, so this one is not tight.)
    assert margin[1] < ends - mp.mpf("0.8")
    checked(r)
