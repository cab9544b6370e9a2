"""The forward-backward (HC4) contraction of the FK equations and its re-check by ``proofs``.

- it never loses a root: boxes around proved root boxes keep them;
- the checker's re-computation (``proofs.fk.System.hc4``, its own numpy
  interval arithmetic) lands inside the solver's result once the solver
  widens it (by 2⁻²⁰ of the width), so every recorded contraction re-checks;
- tampered ``hc4`` contractions and ``hc4-empty`` leaves are rejected.
"""

import numpy as np
import pytest

import proofs
from certfile import Doc
import proofs.arith
from certkin import load_robot, robot_from_dict
from certkin.fk import forward_kinematics
from certkin.fk.contract import hc4
from certkin.fk.stacked import StackedFKSystem
from certkin.fk.system import FKSystem
from intervals import Interval, sqr
from proofs.fk_system import System

from test_fk import EXAMPLES, SIX_MODES, SPHERICAL_8, _pose_from_points, planar, quaternion_cases, root_boxes, table_vi2

GOUGH_LENGTHS = ["1.093", "2.280", "2.031", "2.524", "3.136", "1.845"]


@pytest.fixture(scope="module")
def planar_case():
    base, plat, lengths = SIX_MODES[0]
    robot = planar(base, plat)
    return robot, lengths, forward_kinematics(robot, lengths)


@pytest.fixture(scope="module")
def gough_case():
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    pose = ",".join(repr(float(v)) for v in _pose_from_points(robot, table_vi2()[0]))
    result = forward_kinematics(robot, GOUGH_LENGTHS, track=pose)   # one posture, proved near Table VI.2's first
    assert result.tracked
    return robot, GOUGH_LENGTHS, result


def _L(lengths, N):
    rho = [Interval(v) for v in lengths]
    lo = np.array([float(r.lo) for r in rho])
    hi = np.array([float(r.hi) for r in rho])
    return sqr(Interval.from_bounds(np.tile(lo, (N, 1)), np.tile(hi, (N, 1))))


def _boxes_around(R, n_boxes, rng, scale):
    """Random boxes holding the box R (each side grown by a random amount up to ``scale``)."""
    lo = R.lo[None, :] - rng.uniform(0, 1, (n_boxes, len(R.lo))) ** 3 * scale
    hi = R.hi[None, :] + rng.uniform(0, 1, (n_boxes, len(R.hi))) ** 3 * scale
    return lo, hi


@pytest.mark.parametrize("case", ["planar_case", "gough_case"])
def test_hc4_keeps_every_root(case, request):
    robot, lengths, result = request.getfixturevalue(case)
    system = FKSystem(robot)
    rng = np.random.default_rng(5)
    assert result.solutions
    for s in result.solutions:
        R = s["box"]                                    # holds exactly one root
        scale = np.r_[np.full(system.n_pos, 2.0), np.full(system.n - system.n_pos, 0.3)]
        lo, hi = _boxes_around(R, 200, rng, scale)
        nlo, nhi, empty = hc4(system, lo, hi, _L(lengths, len(lo)))
        assert not empty.any()
        # the root lies in R and in the contracted box: they meet
        assert np.all(nlo <= R.hi) and np.all(nhi >= R.lo)
        assert np.all(nlo >= lo) and np.all(nhi <= hi)


@pytest.mark.parametrize("case", ["planar_case", "gough_case"])
def test_checker_hc4_lands_inside_the_solver_result(case, request):
    robot, lengths, result = request.getfixturevalue(case)
    system = FKSystem(robot)
    checker = System(system.model_name, robot.to_dict())
    rng = np.random.default_rng(7)
    dlo, dhi = result.domain if not result.tracked else system.domain(sqr(Interval.from_bounds(
        np.array([[float(Interval(v).lo) for v in lengths]]), np.array([[float(Interval(v).hi) for v in lengths]]))))
    dlo, dhi = np.atleast_2d(dlo)[0], np.atleast_2d(dhi)[0]
    # boxes all over the domain, of many sizes: some are emptied, some contracted
    N = 60
    c = dlo + (dhi - dlo) * rng.uniform(size=(N, len(dlo)))
    w = (dhi - dlo) * rng.uniform(0.001, 0.3, size=(N, len(dlo)))
    lo, hi = np.maximum(c - w, dlo), np.minimum(c + w, dhi)
    L = _L(lengths, N)
    nlo, nhi, empty = hc4(system, lo, hi, L)
    w = (hi - lo) * 2.0 ** -20                       # the solver's widening of a recorded contraction
    nlo, nhi = np.maximum(lo, nlo - w), np.minimum(hi, nhi + w)
    z, z_empty = checker.hc4(lo, hi, proofs.arith.Iv(L.lo, L.hi))
    assert np.all(z_empty[empty])                     # the solver's "empty" re-checks
    keep = ~empty & ~z_empty                          # the checker may prove more
    assert np.all((z.lo[keep] >= nlo[keep]) & (z.hi[keep] <= nhi[keep]))
    contracted = np.any((nlo[keep] > lo[keep]) | (nhi[keep] < hi[keep]), axis=1).sum()
    assert contracted + empty.sum() > 0


def test_tampered_hc4_steps_are_rejected(planar_case):
    _, _, result = planar_case
    cert = Doc(result.certificate())
    assert cert.check().ok

    shrunk = cert.copy()                         # an hc4 child box that claims more of its parent empty
    node = shrunk.nodes(2, 0)[0]
    shrunk.arrays["tree.box"][shrunk.row("tree.box", node), :, 1] ^= np.uint64(1 << 51)
    assert not shrunk.check().ok

    emptied = cert.copy()                        # a box with a root is not emptied by HC4
    leaf = emptied.nodes(3, 6)[0]
    emptied.arrays["tree.code"][leaf] = 1
    for name, rows in (("tree.C", 1), ("tree.star", 1), ("tree.index", 2)):
        emptied.arrays[name] = np.delete(emptied.arrays[name], [cert.row(name, leaf, k) for k in range(rows)], axis=0)
    report = emptied.check()
    assert not report.ok and "does not empty the box" in report.step

    relabelled = cert.copy()
    relabelled.arrays["tree.code"][relabelled.nodes(3, 1)[0]] = 42
    assert "unknown leaf rule code 42" in relabelled.check().step


def test_planar_stacked_pass_gives_the_generic_floats():
    """The planar pass (``_hc4_planar``: the same operations, stacked) gives exactly the floats and
    empty boxes of the generic pass, on boxes around roots, wide boxes and empty ones."""
    rng = np.random.default_rng(11)
    for base, plat, lengths in SIX_MODES:
        robot = planar(base, plat)
        system = FKSystem(robot)
        result = forward_kinematics(robot, lengths)
        dlo, dhi = system.domain(Interval.from_bounds(*(np.array([[float(Interval(v).lo) for v in lengths]]),
                                                np.array([[float(Interval(v).hi) for v in lengths]]))))
        boxes = [_boxes_around(s["box"], 100, rng, np.r_[2.0, 2.0, 0.3, 0.3]) for s in result.solutions]
        c = rng.uniform(dlo, dhi, (300, 4))
        w = rng.uniform(0, 1, (300, 4)) ** 2 * (dhi - dlo) * 0.2
        boxes.append((c - w, c + w))
        lo = np.concatenate([b[0] for b in boxes])
        hi = np.concatenate([b[1] for b in boxes])
        L = _L(lengths, len(lo))
        for sys_ in (system, StackedFKSystem.of(system)):
            fast = hc4(sys_, lo, hi, L)
            ref = hc4(sys_, lo, hi, L, generic=True)
            assert np.array_equal(fast[2], ref[2]) and 0 < fast[2].sum() < len(lo)
            for a, b in zip(fast[:2], ref[:2]):
                assert np.array_equal(a, b, equal_nan=True)


def test_kept_centred_form_gives_the_same_floats(gough_case):
    """HC4 keeps the centred form of R b_i over the given boxes (``keep``); handed to
    ``rotated_centred`` for the same boxes it gives the floats of a fresh evaluation, bit for bit."""
    robot, lengths, result = gough_case
    system = FKSystem(robot)
    rng = np.random.default_rng(11)
    R = result.solutions[0]["box"]
    lo, hi = _boxes_around(R, 50, rng, np.r_[np.full(3, 1.0), np.full(4, 0.2)])
    kept = {}
    hc4(system, lo, hi, _L(lengths, len(lo)), keep=kept)
    X = Interval.from_bounds(lo, hi)
    fresh = system.rotated_centred(X, parts=True)
    reused = system.rotated_centred(X, parts=True, form=kept["form"])
    for a, b in [(fresh[0], reused[0]), (fresh[1], reused[1])]:
        assert np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi)
    for a, b in zip(fresh[2], reused[2]):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("which", ["gough", "spherical"])
def test_native_centred_form_matches_numpy(which, gough_case):
    """The machine-code centred form of R b_i (``fk.centred``) and the numpy one, on boxes around a
    root, all over the domain and with infinite sides: the same floats to a few ulps (only the sums of
    the midpoint-radius products may be taken in another order), the same non-finite entries."""
    robot = gough_case[0] if which == "gough" else robot_from_dict(SPHERICAL_8)
    system = FKSystem(robot)
    rng = np.random.default_rng(17)
    n = system.n
    c = rng.uniform(-1.2, 1.2, (2000, n))
    w = rng.uniform(0, 1, (2000, n)) * 10.0 ** rng.uniform(-9, 0, (2000, 1))
    lo, hi = c - w, c + w
    lo[:5, -1], hi[5:10, -2] = -np.inf, np.inf
    X = Interval.from_bounds(lo, hi)
    for a, b in zip(system.centred_form(X), system.centred_form(X, native=False)):
        assert np.array_equal(np.isfinite(a), np.isfinite(b))
        ok = np.isfinite(b)
        assert np.all(np.abs(a[ok] - b[ok]) <= 2.0 ** -48 * (1.0 + np.abs(b[ok])))


@pytest.mark.parametrize("which", ["gough", "spherical"])
def test_native_quaternion_pass_matches_numpy(which, gough_case):
    """The machine-code pass (``fk_native``) and the numpy one, on boxes around every root and
    on boxes all over the domain: the same empty boxes and, elsewhere, the same bounds to a few ulps
    (only the sums of R b_i may be taken in another order); every root is kept."""
    robot, lengths = gough_case[:2] if which == "gough" else quaternion_cases()[0]
    system = FKSystem(robot)
    rng = np.random.default_rng(13)
    n = system.n
    root_lo, root_hi = root_boxes(robot, lengths, 3000, rng)      # one root each
    near_c = 0.5 * (root_lo + root_hi)
    near_w = rng.uniform(0.1, 1, (3000, n)) * 10.0 ** rng.uniform(-7, -0.5, (3000, 1))
    L = _L(lengths, 1)
    dlo, dhi = (np.atleast_2d(v)[0] for v in system.domain(L))
    far_c = rng.uniform(dlo, dhi, (3000, n))
    far_w = rng.uniform(0, 1, (3000, n)) ** 2 * (dhi - dlo) * 0.1
    lo = np.concatenate([np.minimum(root_lo, near_c - near_w * rng.uniform(0, 1, (3000, n))), far_c - far_w])
    hi = np.concatenate([np.maximum(root_hi, near_c + near_w * rng.uniform(0, 1, (3000, n))), far_c + far_w])
    L = _L(lengths, len(lo))
    fast = hc4(system, lo, hi, L)
    ref = hc4(system, lo, hi, L, native=False)
    assert np.array_equal(fast[2], ref[2]) and 0 < fast[2].sum() < len(lo)
    assert not fast[2][:3000].any()
    live = ~fast[2]
    for a, b in zip(fast[:2], ref[:2]):
        assert np.all(np.abs(a[live] - b[live]) <= 2.0 ** -48 * (1.0 + np.abs(b[live])))
    assert np.all((fast[0][:3000] <= root_hi) & (root_lo <= fast[1][:3000]))   # the root's box is met


@pytest.mark.parametrize("which", ["gough", "spherical"])
def test_native_gap_splits_give_the_numpy_floats(which, gough_case):
    """The machine-code split hints (``kernels.gap_splits_quaternion``) and the numpy ones
    (``gap_splits(..., native=False)``), on boxes all over the domain, around roots, thin and with
    infinite sides: the same dimensions and the same cut points, bit for bit; many boxes get one."""
    from certkin.fk.contract import gap_splits
    robot, lengths = gough_case[:2] if which == "gough" else quaternion_cases()[0]
    system = FKSystem(robot)
    rng = np.random.default_rng(29)
    n = system.n
    dlo, dhi = (np.atleast_2d(v)[0] for v in system.domain(_L(lengths, 1)))
    N = 4000
    c = rng.uniform(dlo, dhi, (N, n))
    w = rng.uniform(0, 1, (N, n)) ** 2 * (dhi - dlo) * 10.0 ** rng.uniform(-6, 0, (N, 1))
    lo, hi = np.maximum(c - w, dlo), np.minimum(c + w, dhi)
    root_lo, root_hi = root_boxes(robot, lengths, 500, rng)
    lo[:500] = np.minimum(lo[:500], root_lo)
    hi[:500] = np.maximum(hi[:500], root_hi)
    lo[500:505, 0], hi[505:510, -1], hi[510:515, 1] = -np.inf, np.inf, lo[510:515, 1]   # infinite, point sides
    for at_least in (0.5, 0.0):
        fast = gap_splits(system, lo, hi, _L(lengths, N), at_least)
        ref = gap_splits(system, lo, hi, _L(lengths, N), at_least, native=False)
        assert np.array_equal(fast[0], ref[0]) and np.array_equal(fast[1], ref[1], equal_nan=True)
        assert 0.05 * N < np.count_nonzero(fast[0] >= 0) < N or at_least == 0.0


def test_leg_pairs_rechecked_and_narrowed_child_rejected(monkeypatch):
    """Gough-Stewart HC4 contracts with the leg pairs too (e_i − e_j holds no p): the certificate of a
    search relies on them (a checker pass without them rejects it), the checker repeats them (accepts),
    and an "hc4" child box narrowed past the pass with the pairs is rejected."""
    from test_certificates_v2 import node_boxes
    robot = load_robot(EXAMPLES / "seed002-general-6-6-24-solutions.toml")
    result = forward_kinematics(robot, GOUGH_LENGTHS, domain="x=-0.9:-0.8,y=-0.4:-0.3,z=0.5:0.6,psi=-4:4,theta=-4:4,phi=-4:4")
    assert result.complete and len(result.solutions) == 1
    doc = Doc(result.certificate())
    assert doc.check().ok
    with monkeypatch.context() as m:
        m.setattr(proofs.fk_system, "PAIR_ROUNDS", 0)
        assert not doc.check().ok
    kind = doc.arrays["tree.kind"]
    lo, hi, child = node_boxes(doc)
    i = next(j for j in doc.nodes(2, 0) if kind[child[j]] == 3)        # an hc4 contraction above a leaf
    c = child[i]
    L = _L(GOUGH_LENGTHS, 1)
    z, _ = System(doc.header["model"], doc.header["robot"]).hc4(lo[i:i + 1], hi[i:i + 1], proofs.arith.Iv(L.lo, L.hi))
    d = int(np.argmax(z.hi[0] - z.lo[0]))
    new = np.stack([lo[c], hi[c]], -1)
    new[d, 1] = z.hi[0, d] - 0.01 * (z.hi[0, d] - z.lo[0, d])          # its child cut 1 % into the checker's result
    bad = doc.copy()
    bad.arrays["tree.box"][bad.row("tree.box", i)] = np.stack([lo[i], hi[i]], -1).view(np.uint64) ^ new.view(np.uint64)
    assert "not inside the child box" in bad.check().step
