"""Batch throughput: ``certkin batch`` beside the in-process API and separate command-line calls.

Workloads (DESIGN.md: ``certkin batch`` >= 0.8x the in-process API's per-instance speed):

- 1000 small planar FK jobs: seed 003 planar example 2, a 10x10x10 grid of leg lengths around
  the 6-mode instance 28.99, 13.66, 40.53 (``certkin jobs grid``);
- 1000 seed 000 trajectories: the MEL robot, constant orientation (85deg, 10deg, 0) at z = 520,
  start and goal drawn in [-60, 60]^2 with seed 0 (as benchmarks/trajectory.py).

Methods, same jobs, same outputs where said:

- API: the in-process API in one process, one call per job (``forward_kinematics`` /
  ``verify_trajectory``), answers only;
- API + files: the same, also writing each job's JSON document and certificate (what a batch writes);
- batch, W workers: ``certkin batch JOBS --out DIR --workers W`` as a whole process (start-up included);
- CLI calls: ``certkin fk|trajectory ... --json --certificate FILE``, one process per job, W at a time
  (``--cli-calls`` of them; the per-job figure is what 1000 such calls cost).

Two ratios against the API on one core: wall (jobs / wall) / (W x API jobs/s), for a quiet
machine; CPU (API CPU per job) / (CPU per job of the method, every process of it counted), which a
shared machine does not distort much.  Usage: ``python benchmarks/batch.py [--jobs 1000] [--workers 2] [--cli-calls 1000]``.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path
import resource
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

from certkin import forward_kinematics, load_robot, verify_trajectory
from certkin.batch.grid import fk_jobs, trajectory_jobs
from certkin.batch.jobs import dumps
from certkin.batch.results import write_json

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import describe  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PLANAR = str(ROOT / "examples" / "robots" / "seed003-planar-example-2.toml")
MEL = str(ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml")
SPACE = "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0"


def workloads(n: int):
    side = round(n ** (1 / 3))
    planar, mel = load_robot(PLANAR), load_robot(MEL)
    fk = fk_jobs(PLANAR, planar, f"L1=28.5:29.5:{side},L2=13.2:14.1:{side},L3=40:41:{side}", "fk")[:n]
    traj = trajectory_jobs(MEL, mel, SPACE, SPACE, n, 0, 3, "traj")
    return {"planar FK": (planar, fk), "seed 000 trajectories": (mel, traj)}


def solve(robot, job):
    if job["command"] == "fk":
        return forward_kinematics(robot, job["lengths"])
    return verify_trajectory(robot, job["from"], job["to"])


def api(robot, jobs, out: Path | None):
    """Wall and CPU seconds of the API over the jobs (the first job, compiling, not counted)."""
    solve(robot, jobs[0])
    w, c = time.perf_counter(), time.process_time()
    for job in jobs:
        r = solve(robot, job)
        if out is not None:
            r.certificate().write(out / f"{job['id']}.cert")
            write_json(out / f"{job['id']}.json", r.to_json())
    return time.perf_counter() - w, time.process_time() - c


def children_cpu() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def batch(jobs, workers: int, directory: Path):
    path = directory / "jobs.jsonl"
    path.write_text("".join(dumps(j) + "\n" for j in jobs))
    w = time.perf_counter()
    subprocess.run([sys.executable, "-m", "certkin.cli", "batch", str(path), "--out", str(directory / "out"),
                    "--workers", str(workers)], check=True, capture_output=True)
    wall = time.perf_counter() - w
    summary = json.loads((directory / "out" / "summary.json").read_text())
    assert summary["jobs"] == len(jobs) and not summary["errors"] and not summary["failed"]
    return wall, summary["batch_cpu_seconds"]


def cli_argv(job, cert):
    argv = [sys.executable, "-m", "certkin.cli", job["command"], job["robot"], "--json", "--certificate", str(cert)]
    if job["command"] == "fk":
        return argv + [f"--lengths={job['lengths']}"]
    return argv + [f"--from={job['from']}", f"--to={job['to']}"]


def cli(jobs, workers: int, directory: Path):
    c, w = children_cpu(), time.perf_counter()
    with ThreadPoolExecutor(workers) as pool:
        list(pool.map(lambda j: subprocess.run(cli_argv(j, directory / f"{j['id']}.cert"), check=True,
                                               capture_output=True), jobs))
    return time.perf_counter() - w, children_cpu() - c


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cli-calls", type=int, default=1000)
    args = ap.parse_args()
    print(describe())
    rows = []
    for name, (robot, jobs) in workloads(args.jobs).items():
        n = len(jobs)
        with tempfile.TemporaryDirectory() as d:
            d = Path(d)
            api_wall, api_cpu = api(robot, jobs, None)
            files_wall, files_cpu = api(robot, jobs, d)
            base = {"API": n / api_wall, "API + files": n / files_wall, "cpu": api_cpu / n, "files cpu": files_cpu / n}
            rows.append((name, "API, 1 process", n, api_wall, api_cpu, 1, base))
            rows.append((name, "API + files, 1 process", n, files_wall, files_cpu, 1, base))
            for w in sorted({1, args.workers}):
                (d / f"b{w}").mkdir()
                wall, cpu = batch(jobs, w, d / f"b{w}")
                rows.append((name, f"certkin batch, {w} worker{'s' if w > 1 else ''}", n, wall, cpu, w, base))
            calls = jobs[:args.cli_calls]
            if calls:
                (d / "cli").mkdir()
                wall, cpu = cli(calls, args.workers, d / "cli")
                rows.append((name, f"{len(calls)} CLI calls, {args.workers} at a time", len(calls), wall, cpu,
                             args.workers, base))
    print(f"{'workload':22s} {'method':34s} {'jobs':>5s} {'wall s':>8s} {'ms/job':>8s} {'CPU ms/job':>11s} "
          f"{'wall ratio':>10s} {'CPU ratio':>9s} {'CPU ratio vs API+files':>22s}")
    for name, method, n, wall, cpu, cores, base in rows:
        speed = n / wall / cores
        print(f"{name:22s} {method:34s} {n:5d} {wall:8.2f} {1e3 * wall / n:8.2f} {1e3 * cpu / n:11.2f} "
              f"{speed / base['API']:10.2f} {base['cpu'] * n / cpu:9.2f} {base['files cpu'] * n / cpu:22.2f}")
    print("wall ratio: jobs per second per core against the in-process API on one core (target >= 0.8; "
          "meaningless on a loaded machine); CPU ratio: CPU per job of the API (answers only) / CPU per job of "
          "the method; vs API+files: against the API writing the same documents and certificates")
    print("CPU ms/job: API rows: process_time; CLI rows: the calls' CPU (start-up included); batch rows: the "
          "whole batch (summary.json batch_cpu_seconds: the batch process and its workers, start-up included)")


if __name__ == "__main__":
    main()
