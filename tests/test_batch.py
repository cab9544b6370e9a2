"""certkin batch: the same answers whatever runs the jobs, resumable, resistant to dead workers and
broken jobs; the job generators."""
from __future__ import annotations

import fcntl
import hashlib
from fractions import Fraction
import itertools
import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import time
import zipfile

import pytest

import proofs
from batch_work import dies_on_boom, square_or_die
from certfile import Doc
from certkin.batch import local, read_jobs, run_batch
from certkin.batch import jobs as jobs_module
from certkin.batch.jobs import dumps
from certkin.batch.results import TIMING_FIELDS, untimed
from certkin.cli import main
from certkin.cli.batch import run_job
from certkin.errors import InputError



ROOT = Path(__file__).resolve().parent.parent
PLANAR = str(ROOT / "examples" / "robots" / "seed003-planar-example-2.toml")
MEL = str(ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml")
MICRO = str(ROOT / "examples" / "robots" / "seed004-micro-manipulator.toml")


def exit_code(argv) -> int:
    """The exit code of the command line (a parser error exits through ``SystemExit``)."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def generate(*argv, capsys) -> list[str]:
    assert main(["jobs", "grid", *argv]) == 0
    return capsys.readouterr().out.splitlines()


@pytest.fixture(scope="module")
def jobs_file(tmp_path_factory):
    """8 singularity cells, 6 seed 000 trajectories and 2 planar FK jobs, generated."""
    path = tmp_path_factory.mktemp("jobs") / "jobs.jsonl"
    lines = []
    out = subprocess.run([sys.executable, "-m", "certkin.cli", "jobs", "grid", PLANAR, "--command", "singular",
                          "--box", "x=-50:50,y=-50:50,phi=0:0.7853981634", "--cells", "2"],
                         capture_output=True, text=True, check=True).stdout
    lines += out.splitlines()
    out = subprocess.run([sys.executable, "-m", "certkin.cli", "jobs", "grid", MEL, "--command", "trajectory",
                          "--from", "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0",
                          "--to", "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0", "--count", "6"],
                         capture_output=True, text=True, check=True).stdout
    lines += out.splitlines()
    lines += [dumps({"id": "fk-a", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}),
              dumps({"id": "fk-b", "command": "fk", "robot": PLANAR, "lengths": [29, "13.7", 40.5],
                     "max_boxes": 100000})]
    path.write_text("\n".join(lines) + "\n")
    return path


def outputs(out: Path) -> dict:
    """Every file of a batch directory: documents and summary without timing, certificates as bytes."""
    files = {}
    for p in sorted(out.iterdir()):
        if p.suffix == ".json":
            files[p.name] = untimed(json.loads(p.read_text()))
        elif p.suffix == ".cert":
            files[p.name] = p.read_bytes()
    return files


@pytest.fixture(scope="module")
def reference(jobs_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("one") / "out"
    assert main(["batch", str(jobs_file), "--out", str(out), "--workers", "1"]) == 0
    return out


def test_one_worker_answers_every_job_as_its_command(reference, jobs_file, capsys):
    summary = json.loads((reference / "summary.json").read_text())
    assert summary["jobs"] == 16 and not summary["errors"] and not summary["failed"]
    by_command = {}
    for key, n in summary["counts"].items():
        by_command[key.split()[0]] = by_command.get(key.split()[0], 0) + n
    assert by_command == {"singular": 8, "trajectory": 6, "fk": 2}
    capsys.readouterr()
    for job in read_jobs(jobs_file)[::5]:       # the same document as the command line prints
        argv = [job["command"], job["robot"], "--json"] + [f"--{k.replace('_', '-')}="
                                                           f"{','.join(map(str, v)) if isinstance(v, list) else v}"
                                                           for k, v in job.items() if k not in ("id", "command", "robot")]
        assert main(argv) == 0
        printed = json.loads(capsys.readouterr().out)
        written = json.loads((reference / f"{job['id']}.json").read_text())
        assert written.pop("job") == json.loads(dumps(job))
        sources = written.pop("sources")        # what the answer came from: the robot file, the certificate beside it
        assert sources["robot_sha256"] == hashlib.sha256(Path(job["robot"]).read_bytes()).hexdigest()
        assert sources["certificate_sha256"] == hashlib.sha256((reference / f"{job['id']}.cert").read_bytes()).hexdigest()
        assert untimed(written) == untimed(printed)
    for row in summary["results"]:
        cert = reference / row["certificate"]["file"]
        assert proofs.check_file(cert).ok
        assert row["certificate"]["bytes"] == cert.stat().st_size


def test_two_workers_and_a_dask_cluster_give_identical_results(reference, jobs_file, tmp_path):
    expected = outputs(reference)
    assert main(["batch", str(jobs_file), "--out", str(tmp_path / "two"), "--workers", "2"]) == 0
    assert outputs(tmp_path / "two") == expected
    distributed = pytest.importorskip("dask.distributed", reason="the dask extra is not installed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        assert main(["batch", str(jobs_file), "--out", str(tmp_path / "dask"),
                     "--scheduler", cluster.scheduler_address]) == 0
    assert outputs(tmp_path / "dask") == expected



def seconds_keys(doc) -> set:
    """Every key of a document (at any depth) that names a time in seconds."""
    if isinstance(doc, dict):
        return {k for k in doc if "seconds" in k} | set().union(*map(seconds_keys, doc.values()))
    if isinstance(doc, list):
        return set().union(set(), *map(seconds_keys, doc))
    return set()


def test_every_commands_answer_and_certificate_are_the_same_on_one_or_two_workers(tmp_path):
    """A workspace section's ``stats.paving_seconds`` was not a timing field: its document and the
    ``document_sha256`` of its certificate changed from run to run.  Every field of a document that
    holds seconds is now one, for every command."""
    planning = str(ROOT / "examples" / "robots" / "seed001-3rpr-planning.toml")
    jobs = [{"id": "f", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"},
            {"id": "c", "command": "singular", "robot": PLANAR, "box": "x=-50:0,y=-50:0,phi=0:0.3925", "cells": 2},
            {"id": "j", "command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0",
             "via": "0,0,500,85deg,10deg,0", "to": "84,92,500,85deg,10deg,0"},
            {"id": "p", "command": "plan", "robot": planning, "from": "20,0,3.0", "to": "40,20,3.0"},
            {"id": "w", "command": "workspace", "robot": planning, "orientation": "0.5"},
            {"id": "s", "command": "workspace", "robot": MICRO, "orientation": "0,0,0", "z": "20005"},
            {"id": "v", "command": "workspace", "robot": MEL, "z_range": "500:520", "slabs": 2}]
    run_batch(jobs, tmp_path / "one", run_job, workers=1)
    run_batch(jobs, tmp_path / "two", run_job, workers=2)
    assert outputs(tmp_path / "one") == outputs(tmp_path / "two")
    for j in jobs:
        document = json.loads((tmp_path / "one" / f"{j['id']}.json").read_text())
        assert seconds_keys(document) <= TIMING_FIELDS, j["id"]


BROKEN = [
    ({"command": "fk", "robot": PLANAR, "lengths": "1,2"}, ["fk", PLANAR, "--lengths", "1,2"]),
    ({"command": "fk", "robot": "no-such-robot.toml", "lengths": "1,2,3"},
     ["fk", "no-such-robot.toml", "--lengths", "1,2,3"]),
    ({"command": "fk", "robot": PLANAR, "lengths": "1,2,3", "max_seconds": "soon"},
     ["fk", PLANAR, "--lengths", "1,2,3", "--max-seconds", "soon"]),
    ({"command": "singular", "robot": PLANAR, "box": "x=0:1,y=0:1"}, ["singular", PLANAR, "--box", "x=0:1,y=0:1"]),
    ({"command": "trajectory", "robot": MEL, "from": "0,0,500,0,0,0"}, ["trajectory", MEL, "--from", "0,0,500,0,0,0"]),
]


def test_broken_jobs_write_the_command_line_message_and_the_batch_carries_on(tmp_path, capsys):
    bad_robot = tmp_path / "bad.toml"
    bad_robot.write_text('kind = "planar-3rpr"\nbase = [[0, 0], [1, 0]]\nplatform = [[0, 0], [1, 0], [0, 1]]\n')
    cases = BROKEN + [({"command": "fk", "robot": str(bad_robot), "lengths": "1,1,1"},
                       ["fk", str(bad_robot), "--lengths", "1,1,1"])]
    lines = [dumps({"id": f"bad-{k}", **job}) for k, (job, _) in enumerate(cases)]
    lines += ["{not json", dumps({"id": "a/b", "command": "fk"}), dumps({"id": "bad-0", "command": "fk"}),
              dumps({"id": "cert", "command": "fk", "robot": PLANAR, "lengths": "1,2,3", "certificate": "x"}),
              dumps({"id": "good", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"})]
    (tmp_path / "jobs.jsonl").write_text("\n".join(lines) + "\n")
    capsys.readouterr()
    assert main(["batch", str(tmp_path / "jobs.jsonl"), "--out", str(tmp_path / "out"), "--workers", "2"]) == 0
    table = capsys.readouterr().out
    for k, (_, argv) in enumerate(cases):
        doc = json.loads((tmp_path / "out" / f"bad-{k}.json").read_text())
        assert doc["status"] == "error" and not (tmp_path / "out" / f"bad-{k}.cert").exists()
        assert exit_code(argv) == 2
        assert capsys.readouterr().err == f"certkin: error: {doc['error']}\n"
    errors = {e["id"]: e["error"] for e in json.loads((tmp_path / "out" / "summary.json").read_text())["errors"]}
    n = len(cases)
    assert "not valid JSON" in errors[f"line-{n + 1}"]
    assert "id: expected a name" in errors[f"line-{n + 2}"]
    assert "is used by an earlier job" in errors[f"line-{n + 3}"]
    assert errors["cert"].startswith("certificate: not an option of a job")
    assert len(errors) == n + 4
    good = json.loads((tmp_path / "out" / "good.json").read_text())
    assert good["complete"] and len(good["solutions"]) == 6
    assert "fk complete" in table and "error bad-1: no-such-robot.toml: no such file" in table


def test_a_job_that_kills_its_worker_is_tried_three_times_then_failed(tmp_path):
    jobs = [{"id": "boom", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"},
            {"id": "fine", "command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0",
             "to": "84,92,500,85deg,10deg,0"}]
    summary = run_batch(jobs, tmp_path, dies_on_boom, workers=2)
    rows = {r["id"]: r for r in summary["results"]}
    assert rows["boom"]["verdict"] == "failed" and rows["boom"]["attempts"] == 3
    assert "died 3 times" in rows["boom"]["error"]
    assert json.loads((tmp_path / "boom.json").read_text())["status"] == "failed"
    assert rows["fine"]["verdict"] == "infeasible" and proofs.check_file(tmp_path / "fine.cert").ok


def test_short_jobs_run_in_chunks_and_a_killer_inside_a_chunk_is_found_alone():
    """400 instant jobs run in chunks; the job that kills its worker in the middle of a chunk is found
    by running that chunk's jobs alone, and fails after 3 tries; every other job is reported once,
    with its own answer (its chunk-mates with ``attempts`` 2: they ran again)."""
    tasks = [({"id": "boom" if k == 300 else f"j{k}", "x": k}, "unused") for k in range(400)]
    reports = []
    interrupted, _ = local.run_local(tasks, square_or_die, 2, lambda i, v: reports.append((i, v)))
    assert not interrupted and sorted(i for i, _ in reports) == list(range(400))
    values = dict(reports)
    assert isinstance(values[300], local.Died) and values[300].attempts == 3 and "died 3 times" in values[300].reason
    again = sorted(k for k in range(400) if k != 300 and values[k].pop("attempts", 1) == 2)
    assert all(values[k] == {"id": f"j{k}", "square": k * k} for k in range(400) if k != 300)
    chunk = sorted(again + [300])                # its chunk-mates ran again, alone, and say so
    assert again and chunk == list(range(chunk[0], chunk[-1] + 1)) and len(chunk) <= local.MAX_CHUNK


def test_on_a_dask_cluster_jobs_run_in_chunks_and_a_killing_job_fails_alone():
    """Dask runs short jobs in chunks too; the jobs of a task whose workers die on every try (Dask
    charges every task a dying worker held) run again one at a time: the killer fails after the
    allowed failures, the others answer (``attempts`` 2), none is failed for another's death."""
    distributed = pytest.importorskip("dask.distributed", reason="the dask extra is not installed")
    import dask
    from certkin.batch.cluster import run_dask
    tasks = [({"id": "boom" if k == 300 else f"j{k}", "x": k}, "unused") for k in range(400)]
    reports, sizes = [], []
    real_chunk = local.TaskQueue.chunk

    def chunk(self, workers):
        out = real_chunk(self, workers)
        sizes.append(len(out))
        return out
    with dask.config.set({"distributed.scheduler.allowed-failures": 2}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     dashboard_address=None) as cluster, \
            pytest.MonkeyPatch.context() as mp:
        mp.setattr(local.TaskQueue, "chunk", chunk)
        assert not run_dask(tasks, square_or_die, distributed.Client(cluster.scheduler_address),
                            lambda i, v: reports.append((i, v)))
    assert sorted(i for i, _ in reports) == list(range(400))
    values = dict(reports)
    assert isinstance(values[300], local.Died) and values[300].attempts == 3 and "died 3 times" in values[300].reason
    again = sorted(k for k in range(400) if k != 300 and values[k].pop("attempts", 1) >= 2)
    assert all(values[k] == {"id": f"j{k}", "square": k * k} for k in range(400) if k != 300)
    assert again and all(abs(k - 300) <= 2 * local.IN_FLIGHT * local.MAX_CHUNK for k in again)   # tasks held near it
    assert max(sizes) > 1 and len(sizes) < 400        # chunks, not one task per job


def test_chunks_last_about_chunk_seconds_and_suspects_run_alone():
    q = local.TaskQueue(1000)
    assert q.chunk(2) == [0]                                     # nothing timed yet: one job
    q.jobs, q.seconds = 10, 10 * local.CHUNK_SECONDS / 8         # 8 jobs fill a chunk
    assert q.chunk(2) == list(range(1, 9))
    q.seconds = 1e-6                                             # instant jobs: the largest chunk
    assert len(q.chunk(2)) == local.MAX_CHUNK
    q.again([3, 4, 5], alone=True)
    assert [q.chunk(2), q.chunk(2), q.chunk(2)] == [[3], [4], [5]]
    assert len(q.chunk(2)) == local.MAX_CHUNK
    tail = local.TaskQueue(6)
    tail.jobs, tail.seconds = 10, 1e-6
    assert [len(tail.chunk(2)) for _ in range(6)] == [1] * 6      # the last jobs spread over the workers


def test_a_phased_chunk_writes_after_computing_and_a_raising_phase_fails_only_its_job(monkeypatch):
    """``run_chunk`` with a ``phased`` work function: every answer of the chunk is computed before any
    is completed (while under ``HOLD_SECONDS``), values come back in task order, and a task that raises
    in either phase is ``Died`` alone."""
    events = []

    def answer(job):
        events.append(("answer", job))
        if job == "bad answer":
            raise ValueError("no answer")
        if job == "exits":                       # (argparse's --help did, and the whole batch ended)
            raise SystemExit(0)

        def complete():
            events.append(("complete", job))
            if job == "bad write":
                raise OSError("disk full")
            return job.upper()
        return complete

    def work(job):                               # the one-phase form, unused when ``phased`` exists
        raise AssertionError("not called")
    work.phased = answer
    tasks = [("a",), ("bad answer",), ("bad write",), ("exits",), ("b",)]
    values, _ = local.run_chunk(work, tasks)
    assert values[0] == "A" and values[4] == "B"
    assert isinstance(values[1], local.Died) and "ValueError: no answer" in values[1].reason
    assert isinstance(values[2], local.Died) and "OSError: disk full" in values[2].reason
    assert isinstance(values[3], local.Died) and "SystemExit" in values[3].reason
    assert [e[0] for e in events] == ["answer"] * 5 + ["complete"] * 3      # computed first, then written
    events.clear()
    monkeypatch.setattr(local, "HOLD_SECONDS", 0.0)                         # nothing held: one at a time
    assert local.run_chunk(work, [("a",), ("b",)])[0] == ["A", "B"]
    assert [e[0] for e in events] == ["answer", "complete", "answer", "complete"]


def test_on_a_dask_cluster_a_job_that_kills_its_worker_is_failed_after_the_allowed_failures(tmp_path):
    distributed = pytest.importorskip("dask.distributed", reason="the dask extra is not installed")
    import dask
    jobs = [{"id": "boom", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"},
            {"id": "fine", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}]
    with dask.config.set({"distributed.scheduler.allowed-failures": 2}), \
            distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                     dashboard_address=None) as cluster:
        summary = run_batch(jobs, tmp_path, dies_on_boom, scheduler=cluster.scheduler_address)
    rows = {r["id"]: r for r in summary["results"]}
    assert rows["boom"]["verdict"] == "failed" and rows["boom"]["attempts"] == 3
    assert "died 3 times" in rows["boom"]["error"]
    assert rows["fine"]["verdict"] == "complete" and proofs.check_file(tmp_path / "fine.cert").ok


def test_an_exhausted_budget_is_an_undecided_answer_with_a_certificate_that_checks(tmp_path):
    jobs = [{"id": "short", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53", "max_boxes": 50},
            {"id": "cells", "command": "singular", "robot": PLANAR, "box": "x=-50:50,y=-50:50,phi=0:0.7853981634",
             "cells": 2, "max_boxes": 8}]
    summary = run_batch(jobs, tmp_path, run_job)
    rows = {r["id"]: r for r in summary["results"]}
    assert rows["short"]["verdict"] == "incomplete" and rows["cells"]["verdict"] == "undecided"
    assert sorted(summary["undecided"]) == ["cells", "short"]
    assert not json.loads((tmp_path / "short.json").read_text())["complete"]
    for job in jobs:
        assert proofs.check_file(tmp_path / f"{job['id']}.cert").ok


def _descendants(pid: int) -> list[int]:
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        for task in Path(f"/proc/{p}/task").glob("*"):
            try:
                kids = [int(c) for c in (task / "children").read_text().split()]
            except OSError:
                kids = []
            out += kids
            todo += kids
    return out


def _start(jobs_file, out):
    return subprocess.Popen([sys.executable, "-m", "certkin.cli", "batch", str(jobs_file), "--out", str(out),
                             "--workers", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for_documents(out: Path, n: int, process, limit=120.0):
    t0 = time.time()
    while len([p for p in out.glob("*.json")]) < n:
        assert process.poll() is None, process.communicate()
        assert time.time() - t0 < limit
        time.sleep(0.05)


def test_temporary_files_a_killed_writer_left_are_removed_and_nothing_else(tmp_path):
    """A worker killed between creating a document's or certificate's temporary file and renaming it
    leaves that file behind; the batch removes those of its own jobs (and of its summary), and no
    other file."""
    out = tmp_path / "out"
    out.mkdir()
    job = {"id": "fk-a", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}
    stale = [out / ".fk-a.cert.abcd1234.tmp.cert", out / ".fk-a.json.x_y9z123.tmp.json",
             out / ".summary.json.qwertyui.tmp.json"]
    kept = [out / ".fk-b.cert.abcd1234.tmp.cert", out / ".fk-a.cert.abc.tmp.cert", out / ".notes", out / "fk-a.cert.bak"]
    for p in stale + kept:
        p.write_bytes(b"")
    summary = run_batch([job], out, run_job)
    assert summary["counts"] == {"fk complete": 1}
    assert not any(p.exists() for p in stale) and all(p.exists() for p in kept)


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc to find the worker processes")
def test_a_killed_worker_loses_no_result_and_its_job_is_retried(reference, jobs_file, tmp_path):
    out = tmp_path / "out"
    process = _start(jobs_file, out)
    _wait_for_documents(out, 3, process)
    parent_kids = set(int(c) for t in Path(f"/proc/{process.pid}/task").glob("*")
                      for c in (t / "children").read_text().split())
    workers = [p for p in _descendants(process.pid) if p not in parent_kids]     # the fork server's children
    assert workers
    for worker in workers:          # every worker, so that one killed is surely running a job
        os.kill(worker, signal.SIGKILL)
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["retried"] and not summary["failed"]
    assert outputs(out) == outputs(reference)


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc to find the worker processes")
def test_a_batch_killed_midway_resumes_where_it_stopped(reference, jobs_file, tmp_path):
    out = tmp_path / "out"
    process = _start(jobs_file, out)
    _wait_for_documents(out, 4, process)
    workers = _descendants(process.pid)
    process.kill()
    process.wait()
    t0 = time.time()
    while any(Path(f"/proc/{p}").exists() and "zombie" not in Path(f"/proc/{p}/status").read_text().lower()
              for p in workers):
        assert time.time() - t0 < 10, "worker processes outlived the batch"
        time.sleep(0.1)
    finished = {p.stem for p in out.glob("*.json")} - {"summary"}
    assert finished and len(finished) < 16 and not (out / "summary.json").exists()
    summary = run_batch(read_jobs(jobs_file), out, run_job, workers=2)
    assert summary["resumed"] == len(finished)
    assert {r["id"] for r in summary["results"] if r.get("resumed")} == finished
    assert outputs(out) == outputs(reference)


def test_a_changed_job_or_a_tampered_certificate_is_run_again(reference, jobs_file, tmp_path):
    jobs = read_jobs(jobs_file)
    cells = [j for j in jobs if j["command"] == "singular"][:2]
    run_batch(cells, tmp_path, run_job)
    cert = tmp_path / f"{cells[0]['id']}.cert"
    data = Doc(cert)
    claim = data.claim()
    if "witnesses" in claim:
        claim["witnesses"]["positive"], claim["witnesses"]["negative"] = \
            claim["witnesses"]["negative"], claim["witnesses"]["positive"]
    else:
        claim["sign"] = -claim["sign"]
    data.write(cert)
    assert not proofs.check_file(cert).ok
    changed = {**cells[1], "max_boxes": 5000}
    summary = run_batch([cells[0], changed], tmp_path, run_job)
    assert summary["resumed"] == 0
    assert proofs.check_file(cert).ok
    assert json.loads((tmp_path / f"{cells[1]['id']}.json").read_text())["job"]["max_boxes"] == 5000



def test_an_edited_robot_file_or_a_swapped_certificate_is_run_again(tmp_path):
    """A document answers its job only with the robot file it was computed from and the certificate
    written beside it: after the robot file is edited, or a valid certificate of another job is put in
    a job's place, the jobs run again (and answer the new geometry), instead of being resumed."""
    robot = tmp_path / "robot.toml"
    robot.write_text(Path(PLANAR).read_text())
    out = tmp_path / "out"
    jobs = [{"id": "a", "command": "fk", "robot": str(robot), "lengths": "28.99,13.66,40.53"},
            {"id": "b", "command": "singular", "robot": str(robot), "box": "x=-20:-10,y=20:30,phi=0:0.3"},
            {"id": "c", "command": "fk", "robot": str(robot), "lengths": "29,13.66,40.53"}]
    first = run_batch(jobs, out, run_job)
    assert first["resumed"] == 0 and len(json.loads((out / "a.json").read_text())["solutions"]) == 6
    assert run_batch(jobs, out, run_job)["resumed"] == 3               # nothing changed: every job resumed
    (out / "c.cert").write_bytes((out / "a.cert").read_bytes())          # another job's valid certificate
    (out / "a.cert").write_bytes((out / "b.cert").read_bytes())          # another kind of certificate
    assert proofs.check_file(out / "a.cert").ok and proofs.check_file(out / "c.cert").ok
    again = run_batch(jobs, out, run_job)
    assert again["resumed"] == 1 and [r["id"] for r in again["results"] if not r.get("resumed")] == ["a", "c"]
    for jid in "ac":                    # each job's own certificate again, the one its document names
        sources = json.loads((out / f"{jid}.json").read_text())["sources"]
        assert sources["certificate_sha256"] == hashlib.sha256((out / f"{jid}.cert").read_bytes()).hexdigest()
    assert len({(out / f"{jid}.cert").read_bytes() for jid in "abc"}) == 3
    text = robot.read_text()
    robot.write_text(text.replace(text[text.index("base ="):].split("\n")[0], "base = [[0, 0], [40, 0], [20, 40]]"))
    edited = run_batch(jobs, out, run_job)
    assert edited["resumed"] == 0
    from certkin import forward_kinematics, load_robot
    expected = forward_kinematics(load_robot(str(robot)), "28.99,13.66,40.53")
    assert len(json.loads((out / "a.json").read_text())["solutions"]) == len(expected.solutions)
    assert proofs.check_file(out / "a.cert", robot=str(robot)).ok


def test_a_document_edited_to_state_what_its_certificate_does_not_prove_is_run_again(tmp_path):
    """Resuming took a job's verdict from its document once the certificate beside it re-checked: a
    singular box edited to ``singularity-free``, an infeasible path edited to ``feasible``, cell counts
    edited, another job's certificate put in place with its hash edited into the document, and a
    document missing a field (which failed the job) are now each run again, and answer as at first; so is
    another job's whole answer with this job's line put back in it (the lengths, box or poses asked are
    compared)."""
    robot = tmp_path / "robot.toml"
    robot.write_text(Path(PLANAR).read_text())
    out = tmp_path / "out"
    jobs = [{"id": "a", "command": "fk", "robot": str(robot), "lengths": "29,13,41"},
            {"id": "b", "command": "fk", "robot": str(robot), "lengths": "29,14,40"},
            {"id": "s", "command": "singular", "robot": str(robot), "box": "x=-50:0,y=-50:0,phi=0:0.3925"},
            {"id": "c", "command": "singular", "robot": str(robot), "box": "x=-50:0,y=-50:0,phi=0:0.3925", "cells": 2},
            {"id": "j", "command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0",
             "to": "84,92,500,85deg,10deg,0"},
            {"id": "k", "command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0",
             "to": "7.5,21,500,85deg,10deg,0"},
            {"id": "t", "command": "singular", "robot": str(robot), "box": "x=-20:-10,y=20:30,phi=0:0.3"}]
    first = {r["id"]: r["verdict"] for r in run_batch(jobs, out, run_job)["results"]}
    assert first["s"] == "singular" and first["c"] == "singular" and first["j"] == "infeasible"
    assert run_batch(jobs, out, run_job)["resumed"] == 7

    def edit(jid, change):
        doc = json.loads((out / f"{jid}.json").read_text())
        change(doc)
        (out / f"{jid}.json").write_text(json.dumps(doc))
    (out / "a.cert").write_bytes((out / "b.cert").read_bytes())
    edit("a", lambda d: d["sources"].update(certificate_sha256=hashlib.sha256((out / "a.cert").read_bytes()).hexdigest()))
    edit("s", lambda d: d.update(status="singularity-free", witnesses=None))
    edit("c", lambda d: d.update(counts={"singularity-free": 8, "singular": 0, "undecided": 0}))
    edit("j", lambda d: d.update(status="feasible"))
    edit("b", lambda d: d.pop("complete"))
    again = run_batch(jobs, out, run_job)
    assert again["resumed"] == 2 and not again["failed"]          # (k and t were left as they were)
    assert {r["id"]: r["verdict"] for r in again["results"]} == first
    for mine, other in (("a", "b"), ("j", "k"), ("s", "t")):     # another job's whole answer, with this job's line put back
        (out / f"{mine}.cert").write_bytes((out / f"{other}.cert").read_bytes())
        (out / f"{mine}.json").write_text(json.dumps({**json.loads((out / f"{other}.json").read_text()),
                                                      "job": json.loads((out / f"{mine}.json").read_text())["job"]}))
    again = run_batch(jobs, out, run_job)
    assert again["resumed"] == 4 and [r["id"] for r in again["results"] if not r.get("resumed")] == ["a", "s", "j"]
    assert {r["id"]: r["verdict"] for r in again["results"]} == first
    assert json.loads((out / "a.json").read_text())["lengths"] == ["29", "13", "41"]
    assert all(proofs.check_file(out / f"{j['id']}.cert").ok for j in jobs)



def test_every_field_of_an_answer_is_bound_to_its_certificate(tmp_path):
    """Resume compared the fields a claim holds: a posture box, a violation's t-interval, the witnesses of a
    singular box, a plan's margins or a section's perimeter could be edited and the job was still taken as
    done.  The certificate now holds the SHA-256 of the document it was written with (``document_sha256``,
    without the job, the sources and the timing fields): any edit runs the job again, and it answers as at
    first; timing fields may change."""
    robot = tmp_path / "robot.toml"
    robot.write_text(Path(PLANAR).read_text())
    out = tmp_path / "out"
    jobs = [{"id": "f", "command": "fk", "robot": str(robot), "lengths": "28.99,13.66,40.53"},
            {"id": "s", "command": "singular", "robot": str(robot), "box": "x=-50:0,y=-50:0,phi=0:0.3925"},
            {"id": "j", "command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0",
             "to": "84,92,500,85deg,10deg,0"},
            {"id": "p", "command": "plan", "robot": MEL, "from": "-90,140,520,0,0,0", "to": "55,140,520,0,0,0"},
            {"id": "w", "command": "workspace", "robot": MICRO, "orientation": "0,0,0", "z": "20005"}]
    first = run_batch(jobs, out, run_job)
    docs = {j["id"]: json.loads((out / f"{j['id']}.json").read_text()) for j in jobs}
    assert docs["s"]["witnesses"] and docs["j"]["violations"] and docs["p"]["segments"][0]["margins"]

    def edit(jid, change):
        doc = json.loads((out / f"{jid}.json").read_text())
        change(doc)
        (out / f"{jid}.json").write_text(json.dumps(doc))
    edit("f", lambda d: d["solutions"][0]["pose"]["x"].__setitem__(0, 0.0))
    edit("s", lambda d: d.pop("witnesses"))
    edit("j", lambda d: d["violations"][0].update(t=[0, 0.01]))
    edit("p", lambda d: d["segments"][0].update(margins=[]))
    edit("w", lambda d: d.update(stats={**d["stats"], "seconds": 123.0}))      # a timing field: still done
    again = run_batch(jobs, out, run_job)
    assert [r["id"] for r in again["results"] if r.get("resumed")] == ["w"]
    assert {r["id"]: r["verdict"] for r in again["results"]} == {r["id"]: r["verdict"] for r in first["results"]}
    for j in jobs[:4]:
        assert untimed(json.loads((out / f"{j['id']}.json").read_text())) == untimed(docs[j["id"]])
        assert proofs.check_file(out / f"{j['id']}.cert").ok


def test_cells_around_plan_and_workspace_answers_are_resumed_only_for_their_own_job(tmp_path):
    """Resume bound a job's line to its certificate for FK lengths, singular boxes and trajectory poses
    only: another job's whole answer (certificate and document, this job's line put back) was taken for
    a cells job with another box or cell count, an ``around`` job at another pose, a plan to another
    goal, a workspace at another orientation, height or slab count.  Each is now run again, and a
    workspace or plan document edited to state what its certificate does not is too."""
    planning = str(ROOT / "examples" / "robots" / "seed001-3rpr-planning.toml")
    jobs = [{"id": "c1", "command": "singular", "robot": PLANAR, "box": "x=-50:0,y=-50:0,phi=0:0.3925", "cells": 2},
            {"id": "c2", "command": "singular", "robot": PLANAR, "box": "x=-50:0,y=-50:0,phi=0.1", "cells": 2},
            {"id": "c3", "command": "singular", "robot": PLANAR, "box": "x=-50:0,y=-50:0,phi=0.1", "cells": 3},
            {"id": "c4", "command": "singular", "robot": PLANAR, "box": "x=-50:0,y=-50:0,phi=0deg:22.5deg", "cells": 2},
            {"id": "c5", "command": "singular", "robot": PLANAR, "box": "x=-50:0,y=-50:0,phi=0.1deg:22.5deg", "cells": 1},
            {"id": "a1", "command": "singular", "robot": PLANAR, "around": "-15,25,0.1"},
            {"id": "a2", "command": "singular", "robot": PLANAR, "around": "-15,25,5deg"},
            {"id": "p1", "command": "plan", "robot": planning, "from": "20,0,3.0", "to": "40,20,3.0"},
            {"id": "p2", "command": "plan", "robot": planning, "from": "20,0,3.0", "to": "40,21,3.0"},
            {"id": "w1", "command": "workspace", "robot": planning, "orientation": "0.5"},
            {"id": "w2", "command": "workspace", "robot": planning},
            {"id": "v1", "command": "workspace", "robot": MEL, "z_range": "500:520", "slabs": 2},
            {"id": "v2", "command": "workspace", "robot": MEL, "z_range": "500:520", "slabs": 3},
            {"id": "s1", "command": "workspace", "robot": MEL, "z": "510"}]
    out = tmp_path / "out"
    first = {r["id"]: r["verdict"] for r in run_batch(jobs, out, run_job)["results"]}
    assert set(first.values()) <= {"singular", "singularity-free", "found", "non-empty"}, first
    assert run_batch(jobs, out, run_job)["resumed"] == len(jobs)
    answers = {j["id"]: ((out / f"{j['id']}.cert").read_bytes(), json.loads((out / f"{j['id']}.json").read_text()))
               for j in jobs}
    swaps = [("c1", "c2"), ("c2", "c3"), ("c4", "c5"), ("c5", "c4"), ("a1", "a2"), ("p1", "p2"), ("w1", "w2"), ("v1", "v2"), ("s1", "v1"),
             ("v2", "s1"), ("a2", "c1")]
    for mine, other in swaps:
        cert, doc = answers[other]
        (out / f"{mine}.cert").write_bytes(cert)
        (out / f"{mine}.json").write_text(json.dumps({**doc, "job": answers[mine][1]["job"]}))
    again = run_batch(jobs, out, run_job)
    rerun = {r["id"] for r in again["results"] if not r.get("resumed")}
    assert rerun == {mine for mine, _ in swaps}
    assert {r["id"]: r["verdict"] for r in again["results"]} == first

    def edit(jid, change):
        doc = json.loads((out / f"{jid}.json").read_text())
        change(doc)
        (out / f"{jid}.json").write_text(json.dumps(doc))
    edit("w1", lambda d: d["area"].update(inner=d["area"]["inner"] * 2))
    edit("v1", lambda d: d.update(status="empty"))
    edit("p1", lambda d: d["waypoints"][-1].update(y="21"))
    edit("s1", lambda d: d.update(orientation={"psi": "1", "theta": "0", "phi": "0"}))
    again = run_batch(jobs, out, run_job)
    assert {r["id"] for r in again["results"] if not r.get("resumed")} == {"w1", "v1", "p1", "s1"}
    assert {r["id"]: r["verdict"] for r in again["results"]} == first
    assert all(proofs.check_file(out / f"{j['id']}.cert").ok for j in jobs)


def test_an_answer_for_another_robot_constraints_domain_or_form_is_not_resumed(tmp_path):
    """A second review's transplants (another job's certificate and document, this job's line and robot
    hash put back) that were still resumed: an FK answer for another robot (6 postures for a robot with
    2), a path checked for fewer constraints (feasible for a colliding motion), an FK answer over a
    domain, or tracked, for a job asking every posture, and forms resume does not compare (a box as a
    list, lengths v+-t) or a cell count the command refuses (2.5).  Each now runs again and answers as at
    first; the untouched answers are resumed."""
    example1 = str(ROOT / "examples" / "robots" / "seed003-planar-example-1.toml")
    t = {"command": "trajectory", "robot": MEL, "from": "-69,-50,500,85deg,10deg,0", "to": "84,92,500,85deg,10deg,0"}
    jobs = [{"id": "fA", "command": "fk", "robot": PLANAR, "lengths": "29,13.5,40.5"},
            {"id": "fB", "command": "fk", "robot": example1, "lengths": "29,13.5,40.5"},
            {"id": "fD", "command": "fk", "robot": PLANAR, "lengths": "29,13.5,40.5", "domain": "x=20:40"},
            {"id": "fT", "command": "fk", "robot": PLANAR, "lengths": "29,13.5,40.5", "track": "21.7,-10.4,1.78"},
            {"id": "fS", "command": "fk", "robot": PLANAR, "lengths": [29, 13.5, 40.5]},
            {"id": "fE", "command": "fk", "robot": PLANAR, "lengths": "2.9e1,13.50,40.5"},
            {"id": "fP", "command": "fk", "robot": PLANAR, "lengths": "29+-0.5,13.5,40.5"},
            {"id": "tA", **t}, {"id": "tB", **t, "constraints": "leg-length,singularity"},
            {"id": "sL", "command": "singular", "robot": PLANAR, "box": ["x=-5:5", "y=-5:5", "phi=0:0.2"]},
            {"id": "sS", "command": "singular", "robot": PLANAR, "box": "x=-5:5,y=-5:5,phi=0:0.1"},
            {"id": "c2", "command": "singular", "robot": PLANAR, "box": "x=-5:5,y=-5:5,phi=0:0.1", "cells": 2},
            {"id": "cF", "command": "singular", "robot": PLANAR, "box": "x=-5:5,y=-5:5,phi=0:0.1", "cells": 2.5}]
    out = tmp_path / "out"
    first = {r["id"]: r["verdict"] for r in run_batch(jobs, out, run_job)["results"]}
    assert first["tA"] == "infeasible" and first["tB"] == "feasible" and first["cF"] == "error"
    assert first["fT"] == "tracked" and first["fA"] == "complete"
    answers = {j["id"]: ((out / f"{j['id']}.cert").read_bytes(), json.loads((out / f"{j['id']}.json").read_text()))
               for j in jobs if (out / f"{j['id']}.cert").exists()}
    swaps = [("fB", "fA"), ("fD", "fS"), ("fT", "fE"), ("tB", "tA"), ("sS", "sL"), ("fA", "fP"), ("c2", "cF")]
    for other, mine in swaps:
        cert, doc = answers[other]
        mine_doc = json.loads((out / f"{mine}.json").read_text())
        (out / f"{mine}.cert").write_bytes(cert)
        doc = {**doc, "job": mine_doc["job"], "sources": {**doc["sources"], "robot_sha256": mine_doc.get(
            "sources", {}).get("robot_sha256", doc["sources"]["robot_sha256"]),
            "certificate_sha256": hashlib.sha256(cert).hexdigest()}}
        (out / f"{mine}.json").write_text(json.dumps(doc))
    again = run_batch(jobs, out, run_job)
    resumed = {r["id"] for r in again["results"] if r.get("resumed")}
    assert not resumed & {mine for _, mine in swaps}
    assert {"fB", "tB", "sS", "c2"} <= resumed
    assert {r["id"]: r["verdict"] for r in again["results"]} == first


def test_a_directory_where_a_certificate_goes_is_an_error_job_not_the_end_of_the_batch(tmp_path):
    """A directory at DIR/<id>.cert stopped the whole batch ("Is a directory", exit 2) and left the
    previous summary.json in place; a seconds field edited to NaN went into summary.json (not JSON).
    The job is now an error result naming the path, the batch carries on, and a resumed job's seconds
    are taken only when they are a plain number."""
    jobs = [{"id": "s2", "command": "singular", "robot": PLANAR, "box": "x=-20:-10,y=20:30,phi=0:0.3"},
            {"id": "f", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}]
    out = tmp_path / "out"
    run_batch(jobs, out, run_job)
    (out / "s2.cert").unlink()
    (out / "s2.cert").mkdir()
    doc = json.loads((out / "f.json").read_text())
    doc["stats"]["seconds"] = float("nan")
    (out / "f.json").write_text(json.dumps(doc))
    summary = run_batch(jobs, out, run_job)
    verdicts = {r["id"]: r["verdict"] for r in summary["results"]}
    assert verdicts == {"s2": "error", "f": "complete"} and "is a directory" in summary["errors"][0]["error"]
    assert json.loads(json.dumps(summary, allow_nan=False))["job_seconds"] >= 0


def test_a_robot_that_is_a_named_pipe_is_an_error_job_not_a_hang(tmp_path):
    """A worker opening a named pipe waits for a writer: the whole batch hung (each job's budget does
    not start before its robot is read).  Such a job is now an error result and the batch carries on."""
    pipe = tmp_path / "robot.toml"
    os.mkfifo(pipe)
    jobs = [{"id": "pipe", "command": "fk", "robot": str(pipe), "lengths": "1,2,3"},
            {"id": "ok", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}]
    summary = run_batch(jobs, tmp_path / "out", run_job)
    verdicts = {r["id"]: r["verdict"] for r in summary["results"]}
    assert verdicts == {"pipe": "error", "ok": "complete"}
    assert "named pipe" in summary["errors"][0]["error"]

# ----------------------------------------------------------------- generators
def test_fk_grid_round_trip(tmp_path, capsys):
    lines = generate(PLANAR, "--command", "fk", "--lengths", "L1=28:29:3,L2=13.66,L3=40:40.5:2",
                     "--set", "max_seconds=30", capsys=capsys)
    jobs = [json.loads(line) for line in lines]
    expected = list(itertools.product([Fraction(28), Fraction(57, 2), Fraction(29)], [Fraction("13.66")],
                                      [Fraction(40), Fraction(81, 2)]))
    assert [tuple(Fraction(v) for v in j["lengths"].split(",")) for j in jobs] == expected
    assert len({j["id"] for j in jobs}) == 6 and all(j["max_seconds"] == "30" for j in jobs)
    (tmp_path / "jobs.jsonl").write_text("\n".join(lines) + "\n")
    assert main(["batch", str(tmp_path / "jobs.jsonl"), "--out", str(tmp_path / "out"), "--workers", "2"]) == 0
    for job in jobs:
        doc = json.loads((tmp_path / "out" / f"{job['id']}.json").read_text())
        assert doc["lengths"] == job["lengths"].split(",") and doc["complete"]


def test_cell_grid_covers_the_box_exactly(capsys):
    jobs = [json.loads(line) for line in generate(PLANAR, "--command", "singular", "--box",
                                                  "x=-50:50,y=0:10,phi=0:1", "--cells", "3", capsys=capsys)]
    assert len(jobs) == 27
    volume = Fraction(0)
    cuts = set()
    for job in jobs:
        v = Fraction(1)
        for part in job["box"].split(","):
            name, rng = part.split("=")
            a, b = (Fraction(t) for t in rng.split(":"))
            assert a < b
            v *= b - a
            cuts |= {(name, a), (name, b)}
        volume += v
    assert volume == 100 * 10 * 1
    assert sorted(a for n, a in cuts if n == "y") == [0, Fraction("3.33333333333333"), Fraction("6.66666666666667"), 10]


def test_trajectory_pairs_are_reproducible_from_their_seed(capsys):
    spec = ["--from", "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0",
            "--to", "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0", "--count", "20"]
    a = generate(MEL, "--command", "trajectory", *spec, "--seed", "7", capsys=capsys)
    b = generate(MEL, "--command", "trajectory", *spec, "--seed", "7", capsys=capsys)
    c = generate(MEL, "--command", "trajectory", *spec, "--seed", "8", capsys=capsys)
    assert a == b and a != c and len(a) == 20
    for job in map(json.loads, a):
        for pose in (job["from"], job["to"]):
            x, y, z, psi, theta, phi = pose.split(",")
            assert -60 <= Fraction(x) <= 60 and -60 <= Fraction(y) <= 60 and (z, psi, theta, phi) == \
                ("520", "85deg", "10deg", "0")
            assert Fraction(x) * 1000 == int(Fraction(x) * 1000)
    grid = [json.loads(line) for line in generate(
        MEL, "--command", "trajectory", "--from", "x=-60:60:3,y=0,z=520,psi=80deg:90deg:2,theta=10deg,phi=0",
        "--to", "x=0,y=0,z=520,psi=85deg,theta=10deg,phi=0", capsys=capsys)]
    assert [j["from"] for j in grid] == [f"{x},0,520,{p},10deg,0" for x in ("-60", "0", "60") for p in ("80deg", "90deg")]


@pytest.mark.parametrize("argv, message", [
    (["--command", "fk", "--lengths", "L1=1:2:0,L2=1,L3=1"], "--lengths: L1: expected a positive count"),
    (["--command", "fk", "--lengths", "L1=1,L2=1"], "--lengths: L3: missing"),
    (["--command", "singular", "--box", "x=0:1,y=0:1,phi=0:1"], "--cells: --command singular needs --cells"),
    (["--command", "trajectory", "--from", "x=0:1,y=0,phi=0", "--to", "x=0,y=0,phi=0"],
     "--count: random start and goal poses need --count"),
])
def test_generator_errors_name_the_option(argv, message, capsys):
    assert main(["jobs", "grid", PLANAR, *argv]) == 2
    assert capsys.readouterr().err.startswith(f"certkin: error: {message}")


def test_a_bad_report_path_is_refused_before_any_job_runs(tmp_path, capsys):
    jobs = tmp_path / "jobs.jsonl"
    jobs.write_text(dumps({"id": "a", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}) + "\n")
    assert main(["batch", str(jobs), "--out", str(tmp_path / "out"), "--report", str(tmp_path / "no" / "r.html")]) == 2
    assert capsys.readouterr().err.startswith("certkin: error: --report: ")
    assert not (tmp_path / "out" / "a.json").exists()
    assert main(["batch", str(jobs), "--out", str(tmp_path / "out"), "--report", str(tmp_path / "r.txt")]) == 2
    assert "unknown file type" in capsys.readouterr().err


def test_reserved_ids_and_ids_differing_in_case_only_are_error_jobs(tmp_path):
    """``summary`` (the batch's summary.json) and ``line-N`` (the id given to a line that is not a job)
    are reserved, in any letter case; an id that differs from an earlier one by case only would be
    the same file on some systems.  Each becomes an error job with its line's id; nothing collides."""
    ids = ["Summary", "line-2", "LINE-7", "a", "A", "b"]
    (tmp_path / "jobs.jsonl").write_text("".join(dumps({"id": i, "command": "fk"}) + "\n" for i in ids))
    jobs = read_jobs(tmp_path / "jobs.jsonl")
    assert [j["id"] for j in jobs] == ["line-1", "line-2", "line-3", "a", "line-5", "b"]
    assert ["is reserved" in j.get("error", "") for j in jobs] == [True, True, True, False, False, False]
    assert "used by an earlier job" in jobs[4]["error"] and "error" not in jobs[3] and "error" not in jobs[5]
    assert len({j["id"].casefold() for j in jobs}) == len(jobs)


def test_a_jobs_file_is_read_line_by_line_within_bounds(tmp_path, monkeypatch):
    """An overlong line is an error job (read past in pieces, never held whole) and the lines after it
    are read as usual; a file of more than ``MAX_JOBS`` jobs is refused (split the campaign)."""
    monkeypatch.setattr(jobs_module, "MAX_LINE", 1000)
    monkeypatch.setattr(jobs_module, "MAX_JOBS", 3)
    path = tmp_path / "jobs.jsonl"
    path.write_text(dumps({"id": "a", "command": "fk"}) + "\n" + "x" * 5000 + "\n" + dumps({"id": "b", "command": "fk"}))
    jobs = read_jobs(path)
    assert [j["id"] for j in jobs] == ["a", "line-2", "b"] and "longer than" in jobs[1]["error"]
    path.write_text("".join(dumps({"id": f"j{k}", "command": "fk"}) + "\n" for k in range(4)))
    with pytest.raises(InputError, match="more than 3 jobs"):
        read_jobs(path)


def test_a_line_that_is_not_utf8_is_an_error_job_naming_it(tmp_path):
    """The file was decoded as a whole: one bad byte on line 5000 refused the file, naming a position in
    the decoder's buffer.  Each line is decoded alone now: that line is an error job naming its number
    and byte, the others are read (a byte-order mark before the first line is no job's text)."""
    path = tmp_path / "jobs.jsonl"
    path.write_bytes(b"\xef\xbb\xbf" + dumps({"id": "a", "command": "fk"}).encode() + b"\n" +
                     b'{"id": "bad\xff", "command": "fk"}\r\n' + dumps({"id": "b", "command": "fk"}).encode() + b"\n")
    jobs = read_jobs(path)
    assert [j["id"] for j in jobs] == ["a", "line-2", "b"]
    assert jobs[1]["error"].endswith("line 2: not UTF-8 text (byte 12)") and "error" not in jobs[0]


def test_nan_and_infinity_in_a_job_line_are_error_jobs_and_no_file_holds_them(tmp_path, capsys):
    """Python's json reads NaN, Infinity and -Infinity: ``"max_seconds": NaN`` was taken (and refused by the
    option), and the job echoed with a bare NaN into DIR/<id>.json, which is not JSON.  Each such line is an
    error job now, wherever the constant is; every file written is strict JSON."""
    good = {"id": "good", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}
    lines = [dumps({**good, "id": "a"})[:-1] + ', "max_seconds": NaN}',
             dumps({**good, "id": "b"})[:-1] + ', "max_seconds": Infinity}',
             dumps({**good, "id": "c", "lengths": [1, 2, 3]}).replace("[1, 2, 3]", "[28.99, -Infinity, 40.53]"),
             dumps(good)]
    (tmp_path / "jobs.jsonl").write_text("\n".join(lines) + "\n")
    jobs = read_jobs(tmp_path / "jobs.jsonl")
    assert [j["id"] for j in jobs] == ["line-1", "line-2", "line-3", "good"]
    for job, constant in zip(jobs, ("NaN", "Infinity", "-Infinity")):
        assert job["error"].endswith(f"line {job['id'][5:]}: not valid JSON ({constant} is not a JSON number)"), job
    out = tmp_path / "out"
    assert main(["batch", str(tmp_path / "jobs.jsonl"), "--out", str(out), "--workers", "1", "--json"]) == 0

    def strict(name):
        raise ValueError(f"{name} in a file written")
    summary = json.loads(capsys.readouterr().out, parse_constant=strict)
    assert summary["counts"] == {"? error": 3, "fk complete": 1}
    for path in out.glob("*.json"):
        json.loads(path.read_text(), parse_constant=strict)


def test_a_second_batch_on_the_same_directory_is_refused_while_the_first_writes(tmp_path, capsys):
    """While a batch holds DIR's lock, another on DIR exits 2 naming --out and writes nothing; once the
    lock is released, the same command runs."""
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "jobs.jsonl").write_text(dumps({"id": "good", "command": "fk", "robot": PLANAR,
                                                "lengths": "28.99,13.66,40.53"}) + "\n")
    fd = os.open(out / ".certkin-batch.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        capsys.readouterr()
        assert main(["batch", str(tmp_path / "jobs.jsonl"), "--out", str(out), "--workers", "1"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("certkin: error: --out") and "another certkin batch" in err
        assert sorted(p.name for p in out.iterdir()) == [".certkin-batch.lock"]
    finally:
        os.close(fd)
    assert main(["batch", str(tmp_path / "jobs.jsonl"), "--out", str(out), "--workers", "1"]) == 0
    assert (out / "good.json").exists() and (out / "summary.json").exists()


@pytest.mark.parametrize("busy", [False, True], ids=["idle", "with chunks in flight"])
def test_a_worker_found_dead_when_handed_a_chunk_is_replaced_and_the_chunk_runs(monkeypatch, busy):
    """A worker that died after its chunks were collected makes ``submit`` raise BrokenProcessPool (a
    race a killed worker can win): the chunk goes back to the queue uncharged, and the worker is
    replaced at once when nothing of it is left to collect; every task is reported once, with its
    answer (the batch crashed before)."""
    from concurrent.futures.process import BrokenProcessPool
    real, raised, workers = local._Worker, [], []

    class DiesOnce(real):
        def __init__(self, context):
            super().__init__(context)
            workers.append(self)
            submit = self.executor.submit

            def flaky(fn, *args):
                if not raised and bool(self.tasks) == busy:
                    raised.append(len(self.tasks))
                    raise BrokenProcessPool("the worker died")
                return submit(fn, *args)
            self.executor.submit = flaky
    monkeypatch.setattr(local, "_Worker", DiesOnce)
    tasks = [({"id": f"j{k}", "x": k}, "unused") for k in range(40)]
    reports = []
    interrupted, _ = local.run_local(tasks, square_or_die, 1, lambda i, v: reports.append((i, v)))
    assert not interrupted and raised and bool(raised[0]) == busy
    assert len(workers) == (1 if busy else 2)
    assert sorted(i for i, _ in reports) == list(range(40))
    assert all(v["square"] == tasks[i][0]["x"] ** 2 for i, v in reports)


def test_an_fk_job_with_a_cluster_is_not_counted_as_plainly_complete(tmp_path):
    """Lengths at a singular pose: the answer is complete but a cluster may hold the (double) posture;
    the batch counts it as ``complete-with-clusters``, never with the answers that proved every mode."""
    from test_fk_modes import ISSUE_BASE, ISSUE_PLATFORM, planar_lengths, singular_pose
    from test_fk import planar
    robot = planar(ISSUE_BASE, ISSUE_PLATFORM)
    lengths = ",".join(planar_lengths(robot, singular_pose(robot), 17))
    inline = {"kind": "planar-3rpr", "base": [list(p) for p in ISSUE_BASE], "platform": [list(p) for p in ISSUE_PLATFORM]}
    job = {"id": "c", "command": "fk", "robot": inline, "lengths": lengths}
    plain = {**job, "id": "p", "lengths": "7.0710678118654752440,5.0990195135927848300,5"}
    summary = run_batch([job, plain], tmp_path, run_job)
    assert summary["counts"] == {"fk complete": 1, "fk complete-with-clusters": 1}, summary["counts"]
    assert proofs.check_file(tmp_path / "c.cert").ok


def test_a_job_whose_files_cannot_be_written_says_why_not_internal_error():
    """A full disk is the machine's state, not a bug: the job's error names the file and the reason."""
    from certkin.cli.batch import _message
    assert _message(OSError(28, "No space left on device", "out/b.json")) == "out/b.json: No space left on device"
    assert _message(ValueError("x")).startswith("internal error: ValueError")


def test_on_a_dask_cluster_relative_paths_are_the_batchs(tmp_path, monkeypatch):
    """Jobs naming their robot file relative to the batch's directory all failed on Dask workers
    started elsewhere ("no such file"): each chunk runs in the batch's working directory."""
    distributed = pytest.importorskip("dask.distributed", reason="the dask extra is not installed")
    import shutil
    shutil.copy(PLANAR, tmp_path / "robot.toml")
    jobs = [{"id": f"j{k}", "command": "fk", "robot": "robot.toml", "lengths": f"28.9{k},13.66,40.53"} for k in range(4)]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        monkeypatch.chdir(tmp_path)                  # the workers were started in another directory
        summary = run_batch(jobs, "out", run_job, scheduler=cluster.scheduler_address)
    assert [r["verdict"] for r in summary["results"]] == ["complete"] * 4, summary["results"]
    assert proofs.check_file(tmp_path / "out" / "j0.cert").ok


def test_workers_that_cannot_start_stop_the_batch_with_a_clear_error(tmp_path):
    """A batch run from a script on standard input: every worker died as it started (it cannot import
    the main module ``<stdin>``) and was started again, tens of thousands of times, before a traceback
    (``BrokenProcessPool``).  Three such deaths in a row now stop the batch with one error naming the
    cause, and no job is charged with them."""
    script = ("from batch_work import square_or_die\n"
              "from certkin.batch.local import run_local\n"
              "from certkin.errors import InputError\n"
              "try:\n"
              "    run_local([({'id': f'j{k}', 'x': k}, 'unused') for k in range(50)], square_or_die, 2, print)\n"
              "except InputError as exc:\n"
              "    print('refused:', exc)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).parent), str(ROOT)])}
    done = subprocess.run([sys.executable, "-"], input=script, capture_output=True, text=True, timeout=120, env=env,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("refused: workers: 3 worker processes in a row died as they started"), done.stdout
    assert done.stderr.count("FileNotFoundError") <= 4


def test_two_batches_on_one_dask_worker_keep_their_own_directories(tmp_path):
    """Each chunk ran ``os.chdir`` into its batch's directory, for the whole worker process: two batches
    from two directories on one worker with two threads read each other's robot files and wrote into each
    other's output directories.  Paths are now joined to the batch's directory per task."""
    distributed = pytest.importorskip("dask.distributed", reason="the dask extra is not installed")
    import shutil
    import threading
    a, b = tmp_path / "a", tmp_path / "b"
    for d in (a, b):
        d.mkdir()
    shutil.copy(PLANAR, a / "robot.toml")
    other = Path(PLANAR).read_text().replace("34.47", "34.57", 1)
    assert other != Path(PLANAR).read_text()
    (b / "robot.toml").write_text(other)
    jobs = [{"id": f"j{k}", "command": "fk", "robot": "robot.toml", "lengths": f"28.9{k % 10},13.66,40.53"}
            for k in range(24)]
    script = ("import json, sys; from certkin.cli import main; "
              "sys.exit(main(['batch', 'jobs.jsonl', '--out', 'out', '--scheduler', sys.argv[1], '--json']))")
    for d in (a, b):
        (d / "jobs.jsonl").write_text("".join(json.dumps(j) + "\n" for j in jobs))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=None) as cluster:
        runs = {}

        def run(d):
            runs[d] = subprocess.run([sys.executable, "-c", script, cluster.scheduler_address], cwd=d,
                                     capture_output=True, text=True, timeout=300)
        threads = [threading.Thread(target=run, args=(d,)) for d in (a, b)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    geometry = {}
    for d in (a, b):
        assert runs[d].returncode == 0, runs[d].stderr[-2000:]
        assert json.loads(runs[d].stdout)["counts"] == {"fk complete": len(jobs)}
        for j in jobs:
            assert proofs.check_file(d / "out" / f"{j['id']}.cert", robot=str(d / "robot.toml")).ok
        geometry[d] = {json.loads(zipfile.ZipFile(d / "out" / f"{j['id']}.cert").read("header.json"))["geometry_sha256"]
                       for j in jobs}
    assert len(geometry[a]) == len(geometry[b]) == 1 and geometry[a] != geometry[b]


def test_scheduler_and_workers_together_are_refused(tmp_path, jobs_file, capsys):
    assert main(["batch", str(jobs_file), "--out", str(tmp_path / "o"), "--scheduler", "tcp://127.0.0.1:1",
                 "--workers", "2"]) == 2
    err = capsys.readouterr().err
    assert "--workers" in err and "not with --scheduler" in err and not (tmp_path / "o").exists()


@pytest.mark.slow
def test_a_scheduler_that_goes_away_leaves_the_rest_pending_not_failed_nor_hanging(tmp_path, jobs_file):
    """The scheduler killed mid-run: the batch waited for ever (``as_completed`` of a closed client), and
    Ctrl-C then gave a traceback; chunks cancelled with the connection were recorded as failed jobs.
    Now, once the client gives up reconnecting (30 s), the batch ends: the jobs answered are kept, the
    others pending, the summary written, exit 130 (as for an interrupt)."""
    pytest.importorskip("dask.distributed", reason="the dask extra is not installed")
    import socket
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    bin_dir = Path(sys.executable).parent
    scheduler = subprocess.Popen([str(bin_dir / "dask"), "scheduler", "--port", str(port), "--no-dashboard"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = None
    try:
        time.sleep(3)
        worker = subprocess.Popen([str(bin_dir / "dask"), "worker", f"tcp://127.0.0.1:{port}", "--nthreads", "1",
                                   "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(4)
        lines = [json.loads(line) for line in jobs_file.read_text().splitlines()]
        many = tmp_path / "many.jsonl"
        many.write_text("".join(json.dumps({**j, "id": f"{j['id']}-{k}"}) + "\n" for k in range(30) for j in lines))
        batch = subprocess.Popen([sys.executable, "-m", "certkin", "batch", str(many), "--out", str(tmp_path / "o"),
                                  "--scheduler", f"tcp://127.0.0.1:{port}"], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
        time.sleep(6)
        scheduler.kill()
        out, err = batch.communicate(timeout=120)
    finally:
        for p in (scheduler, worker):
            if p is not None:
                p.kill()
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert batch.returncode == 130 and "Traceback" not in err and "scheduler went away" in err
    assert summary["interrupted"] and not summary["failed"]
    assert any(k.endswith("pending") for k in summary["counts"])


def test_the_report_of_an_interrupted_batch_lists_its_pending_jobs(tmp_path):
    """An interrupted batch whose finished jobs were all decided: its report said "Every job was answered."
    of the jobs the interrupt kept from running; it lists them as pending."""
    from certkin.batch import PENDING
    from certkin.batch.results import row, summarise
    from certkin.report.batch import batch_report
    job = {"command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}
    rows = [row({**job, "id": "a"}, "complete", 0.1), row({**job, "id": "b"}, PENDING, 0.0, 0)]
    batch_report(summarise(rows, 0.2, True, "1 local"), tmp_path, tmp_path / "r.html")
    page = (tmp_path / "r.html").read_text()
    assert "Every job was answered" not in page
    assert "<td>b</td><td>pending</td>" in page


def test_a_resumed_job_is_timed_by_this_run_not_by_the_run_that_answered_it(tmp_path):
    """A resumed job's row took the seconds of the run that answered it from its document: a run that
    only re-checked listed it among its slowest jobs and counted its old time in the seconds in jobs."""
    jobs = [{"id": "f", "command": "fk", "robot": PLANAR, "lengths": "28.99,13.66,40.53"}]
    out = tmp_path / "out"
    run_batch(jobs, out, run_job)
    doc = json.loads((out / "f.json").read_text())
    doc["stats"]["seconds"] = 1000.0              # (a timing field: the answer is still the same)
    (out / "f.json").write_text(json.dumps(doc))
    summary = run_batch(jobs, out, run_job)
    (r,) = summary["results"]
    assert r["resumed"] and 0 < r["seconds"] < 100 and r["cpu_seconds"] > 0
    assert summary["job_seconds"] < 100 and summary["slowest"][0]["seconds"] < 100


def test_an_output_option_set_to_false_or_null_is_left_out_as_any_option():
    """``"json": false`` or ``"progress": null`` in a job leaves the option out (as false does for any
    option); ``"certificate": "x"`` still names what the batch writes itself."""
    from certkin.cli.batch import job_argv
    assert job_argv({"id": "a", "command": "fk", "robot": PLANAR, "lengths": "1,2,3", "json": False,
                     "progress": None, "report": False}) == [PLANAR, "--lengths=1,2,3"]
    with pytest.raises(InputError, match="certificate: not an option of a job"):
        job_argv({"id": "a", "command": "fk", "robot": PLANAR, "certificate": "x"})


def test_the_campaign_picture_draws_no_job_time_when_no_job_ended(tmp_path, monkeypatch):
    """Every job pending (an interrupt before any ended): the time panel draws no bar and says so; it
    drew one job of 0 s, labelled "1 jobs".  Ended jobs are counted in the legend."""
    import matplotlib.figure
    from certkin.plots.batch import plot_campaign
    drawn = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, *a, **k: drawn.append(fig))
    rows = [{"id": f"j{k}", "command": "fk", "verdict": "pending", "seconds": 0.0} for k in range(3)]
    plot_campaign({"counts": {"fk pending": 3}, "results": rows}, tmp_path / "a.png")
    times = drawn[-1].axes[1]
    assert not times.patches and [t.get_text() for t in times.texts] == ["no job ended"]
    rows[0].update(verdict="complete", seconds=0.5)
    plot_campaign({"counts": {"fk complete": 1, "fk pending": 2}, "results": rows}, tmp_path / "b.png")
    assert [t.get_text() for t in drawn[-1].axes[1].get_legend().get_texts()] == ["1 job"]


def test_a_batch_resumed_from_another_directory_keeps_its_answers(tmp_path, monkeypatch, capsys):
    """Jobs naming their robot by a relative path, answered from one directory; the same batch run
    from another directory (where the path leads nowhere), or with a directory where the file was, is
    refused, exit code 2, naming the job and the file, and every answer stays as it was.  From the first
    directory, with the file back, it resumes."""
    first = tmp_path / "first"
    first.mkdir()
    (first / "robot.toml").write_bytes(Path(PLANAR).read_bytes())
    jobs = first / "jobs.jsonl"
    jobs.write_text("".join(dumps({"id": f"j{k}", "command": "fk", "robot": "robot.toml",
                                   "lengths": f"29,13.{k},40.5"}) + "\n" for k in range(3)))
    out = tmp_path / "out"
    monkeypatch.chdir(first)
    assert main(["batch", str(jobs), "--out", str(out), "--workers", "1"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.suffix in (".json", ".cert") and p.name != "summary.json"}
    assert len(before) == 6
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    capsys.readouterr()
    assert exit_code(["batch", str(jobs), "--out", str(out), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert "job j0" in err and "robot.toml not found" in err and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.name in before} == before
    monkeypatch.chdir(first)
    (first / "robot.toml").rename(first / "kept.toml")      # a directory where the robot file was: refused too
    (first / "robot.toml").mkdir()
    assert exit_code(["batch", str(jobs), "--out", str(out), "--workers", "1"]) == 2
    assert "robot.toml not found" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.name in before} == before
    (first / "robot.toml").rmdir()
    (first / "kept.toml").rename(first / "robot.toml")
    assert main(["batch", str(jobs), "--out", str(out), "--workers", "1", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["resumed"] == 3
