"""Instances searched together as if each were alone (``forward_kinematics(..., independent=True)``)
and FK jobs of a batch chunk answered together: every answer, its box count and its certificate's
bytes are those of the instance or job alone.

(Not byte for byte when a search's record is streamed to files, ``record_limit``: the certificate of
a row searched together is then built from the search run again; ``certkin batch`` answers such jobs
alone.)  The reference is the instance searched on its own, by the same code: these tests check that the
batch-level choices of the search (how many times few open boxes are halved, when Krawczyk runs
again, the scale of the unknowns, when Newton's guesses stop) are made per instance.  Each answer's
certificate is re-checked by the independent checker.
"""
from __future__ import annotations

import hashlib
import json

import mpmath as mp
import numpy as np
import pytest

from certfile import checked
from proofs.checker import check_file
from certkin import load_robot
from certkin.batch.local import run_chunk
from certkin.batch.results import untimed
from certkin.cli import batch as cli_batch
from certkin.cli import fk as cli_fk
from certkin.cli.batch import run_job
from certkin.cli.common import write_certificate
from certkin.engine import budgets
from certkin.fk import forward_kinematics
from test_fk import EXAMPLES, SIX_MODES, planar
from test_fk_families import pose_lengths, random_poses

PLANAR = EXAMPLES / "seed003-planar-example-2.toml"


def _grid(n, seed=0):
    """n leg-length rows around the seed 003 example 2 design (the batch benchmark's grid)."""
    rng = np.random.default_rng(seed)
    lo, hi = np.array([28.5, 13.2, 40.0]), np.array([29.5, 14.1, 41.0])
    return [[f"{v:.3f}" for v in lo + rng.uniform(0, 1, 3) * (hi - lo)] for _ in range(n)]


def _document(result):
    doc = result.to_json()
    doc["stats"].pop("seconds")
    return doc


def _certificate_bytes(result, path):
    write_certificate(path, result.certificate())
    return path.read_bytes()


def assert_each_as_alone(robot, rows, tmp_path, **options):
    """Each row searched together with the others: the answer of the row alone, and its certificate's
    bytes; the certificates re-checked."""
    together = forward_kinematics(robot, rows, independent=True, **options)
    assert len(together) == len(rows)
    for k, (row, b) in enumerate(zip(rows, together)):
        a = forward_kinematics(robot, row, **options)
        assert _document(b) == _document(a), (k, row)
        assert b.boxes == a.boxes > 0
        assert _certificate_bytes(b, tmp_path / "b.cert") == _certificate_bytes(a, tmp_path / "a.cert"), (k, row)
        if a.complete:
            checked(b)
    return together


def test_planar_rows_searched_together_get_their_own_answers(tmp_path):
    robot = load_robot(PLANAR)
    together = assert_each_as_alone(robot, _grid(12), tmp_path)
    assert all(r.complete for r in together)
    assert {len(r.solutions) for r in together} >= {4, 6}     # rows of different mode counts


def test_symmetric_robot_with_its_mode_on_every_split_plane_searched_with_others(tmp_path):
    """Issue 16's planar case: the mode x = 5, y = 5, phi = 0 lies on split planes; with two rows
    whose modes do not, in one search."""
    mp.mp.dps = 40
    base, plat = [(0, 0), (10, 0), (3, 10)], [(0, 0), (4, 0), (2, 2)]
    robot = planar(base, plat)
    home = [mp.nstr(mp.sqrt(50), 25), mp.nstr(mp.sqrt(26), 25), "5"]
    rows = [home, pose_lengths(robot, [5.01, 5.0, 0.0]), pose_lengths(robot, [4.0, 6.0, 0.3])]
    together = assert_each_as_alone(robot, rows, tmp_path)
    first = together[0]
    assert first.complete
    at_home = [s for s in first.solutions
               if all(s["pose"][n].lo <= v <= s["pose"][n].hi for n, v in (("x", 5), ("y", 5), ("phi", 0)))]
    assert len(at_home) == 1, "the mode at (5, 5, phi = 0) is proved unique"


def test_six_mode_designs_and_the_spherical_example_at_random_poses(tmp_path):
    base, plat, lengths = SIX_MODES[1]
    robot = planar(base, plat)
    rows = [lengths] + [pose_lengths(robot, p) for p in ([4.0, 9.0, 0.5], [7.0, 12.0, -0.3], [0.0, 0.0, 0.0])]
    assert_each_as_alone(robot, rows, tmp_path)
    spherical = load_robot(EXAMPLES / "seed003-spherical-example-1.toml")
    rows = [pose_lengths(spherical, spherical.home_box().mid())] + \
        [pose_lengths(spherical, p) for p in random_poses(spherical, 3, seed=2)]
    assert_each_as_alone(spherical, rows, tmp_path)


def test_each_row_has_its_own_box_budget(tmp_path):
    """A box budget too small to finish: each row stops where it would alone (incomplete, the same
    undecided regions, the same boxes counted)."""
    robot = load_robot(PLANAR)
    together = assert_each_as_alone(robot, _grid(4, seed=3), tmp_path, max_boxes=150)
    assert not any(r.complete for r in together)
    assert [r.boxes for r in together] == [150] * 4
    assert all(r.unresolved for r in together)


def test_rows_with_length_ranges_beside_exact_rows(tmp_path):
    """An uncertain row does not change how the exact rows beside it are searched, nor the reverse."""
    robot = load_robot(PLANAR)
    exact = _grid(2, seed=7)
    ranged = [f"{float(v) - 0.001:.4f}:{float(v) + 0.001:.4f}" for v in exact[0]]
    assert_each_as_alone(robot, [exact[0], ranged, exact[1]], tmp_path)


# ----- batch chunks ------------------------------------------------------------------------------
def _jobs(rows, **options):
    return [{"id": f"fk-{k:03d}", "command": "fk", "robot": str(PLANAR), "lengths": ",".join(r), **options}
            for k, r in enumerate(rows)]


def _files(out, jobs):
    docs = {j["id"]: untimed(json.loads((out / f"{j['id']}.json").read_text())) for j in jobs}
    certs = {j["id"]: hashlib.sha256((out / f"{j['id']}.cert").read_bytes()).hexdigest()
             for j in jobs if (out / f"{j['id']}.cert").exists()}
    return docs, certs


def test_a_chunk_answers_its_fk_jobs_together_with_each_job_own_files(tmp_path, monkeypatch):
    """A chunk of FK jobs (one with another budget, one with bad lengths, one trajectory-free robot
    error) gives the files each job alone gives; the jobs that differ only in lengths were answered
    in one search."""
    jobs = _jobs(_grid(6, seed=11))
    jobs[2]["max_boxes"] = 200                       # another budget: answered in a group of its own
    jobs.append({"id": "bad", "command": "fk", "robot": str(PLANAR), "lengths": "1,2"})
    searches = []
    original = cli_fk.compute_together

    def counted(args_list, robot):
        searches.append(len(args_list))
        return original(args_list, robot)
    monkeypatch.setattr(cli_fk, "compute_together", counted)
    alone, together = tmp_path / "alone", tmp_path / "together"
    alone.mkdir(), together.mkdir()
    for job in jobs:
        run_job(job, str(alone))
    values, _ = run_chunk(run_job, [(job, str(together)) for job in jobs])
    assert searches == [6]                           # the 5 alike and "bad" (refused there, answered alone)
    assert [v["verdict"] for v in values] == ["complete"] * 2 + ["incomplete"] + ["complete"] * 3 + ["error"]
    assert _files(together, jobs) == _files(alone, jobs)
    for job in jobs[:-1]:
        report = check_file(str(together / f"{job['id']}.cert"))
        assert report.ok, report.step


def test_a_chunk_whose_grouping_fails_answers_each_job_alone(tmp_path, monkeypatch):
    jobs = _jobs(_grid(3, seed=13))

    def broken(args_list, robot):
        raise RuntimeError("grouping failed")
    monkeypatch.setattr(cli_fk, "compute_together", broken)
    values, _ = run_chunk(run_job, [(job, str(tmp_path)) for job in jobs])
    assert [v["verdict"] for v in values] == ["complete"] * 3
    for job in jobs:
        assert (tmp_path / f"{job['id']}.cert").exists()


def test_a_job_answered_before_is_not_searched_again_in_a_group(tmp_path, monkeypatch):
    jobs = _jobs(_grid(3, seed=17))
    run_job(jobs[0], str(tmp_path))
    seen = []
    original = cli_fk.compute_together
    monkeypatch.setattr(cli_fk, "compute_together", lambda a, r: seen.append(len(a)) or original(a, r))
    values, _ = run_chunk(run_job, [(job, str(tmp_path)) for job in jobs])
    assert seen == [2]
    assert [v["verdict"] for v in values] == ["complete"] * 3


@pytest.fixture(autouse=True)
def _no_held_robots():
    yield
    cli_batch._ROBOTS.clear()


def test_a_gough_stewart_robot_at_home_and_near_it_rows_together(tmp_path):
    """The spatial search (slope steps, per-instance position scale from each instance's domain)."""
    robot = load_robot(EXAMPLES / "seed000-mel-tsukuba.toml")
    rows = [pose_lengths(robot, robot.home_box().mid())] + [pose_lengths(robot, p) for p in random_poses(robot, 2, seed=1)]
    together = assert_each_as_alone(robot, rows, tmp_path)
    assert all(r.complete and r.solutions for r in together)


def test_a_group_search_has_the_seconds_of_its_jobs_and_no_more(tmp_path, monkeypatch):
    """20 jobs of 0.002 s each (a planar job alone takes about 10 times that): the search of the group
    has 0.04 s; the jobs it did not finish are answered as they stand, incomplete because the seconds
    ran out, and none is searched again alone (its seconds are spent)."""
    jobs = _jobs(_grid(20, seed=19), max_seconds=0.002)
    alone = []
    monkeypatch.setattr(cli_fk, "compute", lambda args, robot=None: alone.append(args))
    values, _ = run_chunk(run_job, [(job, str(tmp_path)) for job in jobs])
    assert alone == []
    assert {v["verdict"] for v in values} <= {"complete", "incomplete"} and "incomplete" in {v["verdict"] for v in values}
    for job, value in zip(jobs, values):
        doc = json.loads((tmp_path / f"{job['id']}.json").read_text())
        if value["verdict"] == "incomplete":
            assert "time budget" in doc["message"] and doc["unresolved"]
        else:
            assert doc["solutions"] == forward_kinematics(load_robot(PLANAR), job["lengths"]).to_json()["solutions"]
        assert check_file(str(tmp_path / f"{job['id']}.cert")).ok


def test_jobs_of_a_roomy_budget_searched_together_are_all_answered(tmp_path):
    """The same 20 jobs with 0.03 s each (0.6 s for the group's search): every job complete."""
    jobs = _jobs(_grid(20, seed=19), max_seconds=0.03)
    values, _ = run_chunk(run_job, [(job, str(tmp_path)) for job in jobs])
    assert [v["verdict"] for v in values] == ["complete"] * 20


def test_a_row_out_of_its_boxes_says_so_when_the_seconds_of_the_others_run_out():
    """Two rows with 500 boxes each; the seconds run out after the fourth batch (its progress call
    sleeps them away): by then both rows have spent their own 500 boxes, the box budget stopped them
    as it stops each row alone, and their messages say so (not "the time budget")."""
    import time
    robot = load_robot(PLANAR)
    grid = _grid(6, seed=5)
    rows = [grid[0], grid[4]]                        # 500 boxes: after 3 batches, after 4 (of 4, of 5)
    calls = []

    def slow(boxes, frontier):
        calls.append(boxes)
        if len(calls) == 4:
            time.sleep(1.0)
    together = forward_kinematics(robot, rows, independent=True, max_boxes=500, max_seconds=1.0, progress=slow)
    for row, b in zip(rows, together):
        a = forward_kinematics(robot, row, max_boxes=500)
        assert b.boxes == a.boxes == 500
        assert "box budget" in a.message
        assert b.message == a.message


# ----- the engine --------------------------------------------------------------------------------
class _Spheres:
    """A toy problem: the points of the sphere |x - c_k| = r_k in root k's box (boxes that miss it
    excluded, narrow boxes that meet it proved); a box decided from that box and its root only."""
    reasons = ("outside", "meets")

    def __init__(self, c, r):
        self.c, self.r = np.asarray(c, dtype=float), np.asarray(r, dtype=float)

    def decide(self, lo, hi, roots):
        from certkin.engine.search import EXCLUDED, OPEN, PROVED, Decisions
        c, r = self.c[roots], self.r[roots]
        a, b = lo - c, hi - c
        near = np.where((a <= 0) & (b >= 0), 0.0, np.minimum(a * a, b * b)).sum(axis=1)
        far = np.maximum(a * a, b * b).sum(axis=1)
        out = (near > r * r) | (far < r * r)
        found = ~out & (np.max(hi - lo, axis=1) < 0.1 * r)
        return Decisions(np.where(out, EXCLUDED, np.where(found, PROVED, OPEN)).astype(np.int8), found.astype(int))


def _subtree(tree, k):
    """Root k's nodes in the order they were made: boxes, kinds, reasons, links (as local indices)."""
    ids = np.nonzero(tree.root == k)[0]
    local = np.full(len(tree.root) + 1, -1)
    local[ids] = np.arange(len(ids))
    return [tree.lo[ids].tobytes(), tree.hi[ids].tobytes(), tree.kind[ids].tobytes(), tree.reason[ids].tobytes(),
            local[tree.parent[ids]].tobytes(), local[tree.first_child[ids]].tobytes(), tree.split_dim[ids].tobytes()]


def test_engine_roots_of_different_extents_without_a_scale_each_as_alone():
    """Without ``scale``, a root alone has its own extent as the scale: so it has searched together."""
    from certkin.engine.budgets import Budget
    from certkin.engine.search import search
    rng = np.random.default_rng(0)
    c, r = rng.uniform(-1, 1, (4, 3)), rng.uniform(0.3, 1.0, 4)
    lo = -2.0 * rng.uniform(0.5, 1.5, (4, 3))
    hi = 2.0 * rng.uniform(0.5, 1.5, (4, 3))
    budget = Budget(min_width=1e-2)
    together = search(_Spheres(c, r), lo, hi, budget=budget, independent=True)
    for k in range(4):
        alone = search(_Spheres(c[k:k + 1], r[k:k + 1]), lo[k:k + 1], hi[k:k + 1], budget=budget)
        assert _subtree(together.tree, k) == _subtree(alone.tree, 0), k
        assert together.boxes_per_root[k] == alone.boxes


def test_a_chunk_of_jobs_whose_memory_bounds_their_batches_gives_each_job_own_files(tmp_path):
    """Spherical jobs with 4 MiB: alone, the memory left shortens some of a job's batches (it does not
    run out); searched together their batches would be whole: such jobs are answered alone."""
    robot = load_robot(EXAMPLES / "seed003-spherical-example-1.toml")
    rows = [pose_lengths(robot, robot.home_box().mid())] + [pose_lengths(robot, p) for p in random_poses(robot, 2, seed=2)]
    jobs = [{"id": f"fk-{k:03d}", "command": "fk", "robot": str(EXAMPLES / "seed003-spherical-example-1.toml"),
             "lengths": ",".join(map(str, r)), "max_memory": "4MiB"} for k, r in enumerate(rows)]
    alone, together = tmp_path / "alone", tmp_path / "together"
    alone.mkdir(), together.mkdir()
    for job in jobs:
        run_job(job, str(alone))
    values, _ = run_chunk(run_job, [(job, str(together)) for job in jobs])
    assert [v["verdict"] for v in values] == ["complete"] * 3
    assert _files(together, jobs) == _files(alone, jobs)


def test_jobs_whose_record_alone_goes_to_files_are_answered_alone(tmp_path, monkeypatch):
    """With a record limit of 1250 nodes, a planar job of more nodes alone hands its record to files
    (its certificate built from them); searched together it would not: such jobs are answered alone,
    the others together, and every job's files are its own."""
    monkeypatch.setattr(budgets, "FK_RECORD_NODES", 1250)
    jobs = _jobs(_grid(8, seed=23))
    alone_dir, together_dir = tmp_path / "alone", tmp_path / "together"
    alone_dir.mkdir(), together_dir.mkdir()
    for job in jobs:
        run_job(job, str(alone_dir))
    computed = []
    original = cli_fk.compute
    monkeypatch.setattr(cli_fk, "compute", lambda args, robot=None: computed.append(args.lengths) or original(args, robot))
    run_chunk(run_job, [(job, str(together_dir)) for job in jobs])
    assert 0 < len(computed) < len(jobs)            # some alone (more than 1250 nodes), some together
    assert _files(together_dir, jobs) == _files(alone_dir, jobs)
