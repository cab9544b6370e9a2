"""Batch throughput: ``certkin batch`` beside the in-process API and separate command-line calls.

Workloads (issue: ``certkin batch`` >= 0.8x the in-process API's per-instance speed on the same
core count):

- 1000 small planar FK jobs: seed 003 planar example 2, a 10x10x10 grid of leg lengths around
  the 6-mode instance 28.99, 13.66, 40.53 (``certkin jobs grid``);
- 1000 seed 000 trajectories: the MEL robot, constant orientation (85deg, 10deg, 0) at z = 520,
  start and goal drawn in [-60, 60]^2 with seed 0 (as benchmarks/trajectory.py).

Methods, the same jobs and the same solve with the same options (default budgets):

- API: one process, one call per job (``forward_kinematics(robot, lengths)`` /
  ``verify_trajectory(robot, start, goal)`` on the robot loaded once), answers only, nothing
  written; the first call (compiling, building the model) is made before the clock starts; after
  ``certkin.keep_freed_memory()``, as the README advises for a loop of calls and as the batch's
  workers do (``--allocator default``: glibc's own thresholds, about 25 % slower on trajectories);
- API, one call (FK): every job's lengths in one ``forward_kinematics(robot, rows, independent=True)``
  call, each row searched as if alone (the same answers), answers only;
- API + files: the same as the first, also writing each job's JSON document and certificate (what a batch
  writes per job; the certificate's search tree is the same, the document without the job echo);
- batch, W workers: ``certkin batch JOBS --out DIR --workers W``, the whole process from start-up
  to exit (imports, fork server, workers, every document and certificate written);
- batch on Dask (``--dask``): ``certkin batch JOBS --out DIR --scheduler ADDRESS`` on a Dask
  ``LocalCluster`` of W single-thread worker processes started (and their imports done) before the
  clock starts; CPU: the batch process, the workers' own count (``client.run(time.process_time)``)
  and the scheduler (this process's CPU meanwhile: it runs the cluster's scheduler);
- CLI calls: ``certkin fk|trajectory ... --json --certificate FILE``, one process per job, W at a time.

The compiled robot models are on disk (``certkin.robots.models``) once the API's first call has
run, so no batch worker nor CLI call compiles them.  Wall ratio: (jobs per second per core of the
method) / (jobs per second of the API on one core), for a quiet machine; CPU ratio: (CPU per job of
the API) / (CPU per job of the method, every process of it counted: the batch process, its workers
as the batch reports them, its fork server sampled with psutil twice a second), which a shared
machine distorts less.  Each figure is the
median of ``--repeat`` runs.  Usage: ``python benchmarks/batch.py [--jobs 1000] [--workers 2]
[--cli-calls 1000] [--repeat 1] [--dask]``.
"""
from __future__ import annotations

import argparse
from concurrent.futures import ThreadPoolExecutor
import json
import os
from pathlib import Path
import resource
import shutil
from statistics import median
import subprocess
import sys
import tempfile
import threading
import time

import psutil

from certkin import forward_kinematics, keep_freed_memory, load_robot, verify_trajectory
from certkin.batch.grid import fk_jobs, trajectory_jobs
from certkin.batch.jobs import dumps
from certkin.batch.results import write_json

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import describe  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PLANAR = str(ROOT / "examples" / "robots" / "seed003-planar-example-2.toml")
MEL = str(ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml")
SPACE = "x=-60:60,y=-60:60,z=520,psi=85deg,theta=10deg,phi=0"
CERTKIN = [sys.executable, "-m", "certkin.cli"]


def workloads(n: int):
    side = round(n ** (1 / 3))
    planar, mel = load_robot(PLANAR), load_robot(MEL)
    fk = fk_jobs(PLANAR, planar, f"L1=28.5:29.5:{side},L2=13.2:14.1:{side},L3=40:41:{side}", "fk")[:n]
    traj = trajectory_jobs(MEL, mel, SPACE, SPACE, n, 0, 3, "traj")
    return {"planar FK": (planar, fk), "seed 000 trajectories": (mel, traj)}


def solve(robot, job, record=False):
    if job["command"] == "fk":       # record: the search keeps its tree for the certificate, as a batch job's does
        return forward_kinematics(robot, job["lengths"], record=record)
    return verify_trajectory(robot, job["from"], job["to"])


def api(robot, jobs, out: Path | None):
    """Wall and CPU seconds of the API over the jobs (a first call before the clock starts)."""
    solve(robot, jobs[0])
    w, c = time.perf_counter(), time.process_time()
    for job in jobs:
        r = solve(robot, job, record=out is not None)
        if out is not None:
            r.certificate().write(out / f"{job['id']}.cert")
            write_json(out / f"{job['id']}.json", r.to_json())
    return time.perf_counter() - w, time.process_time() - c


def api_together(robot, jobs):
    """Wall and CPU seconds of one API call over every FK job's lengths, each row searched as if
    alone (``forward_kinematics(robot, rows, independent=True)``: the same answers as one call per
    job), answers only."""
    solve(robot, jobs[0])
    w, c = time.perf_counter(), time.process_time()
    forward_kinematics(robot, [job["lengths"].split(",") for job in jobs], independent=True)
    return time.perf_counter() - w, time.process_time() - c


def api_parallel(robot, jobs, workers: int):
    """Wall and CPU seconds of the API answering only in ``workers`` forked processes at once (job k
    in process k mod workers), after a first call in this process (inherited, so not repeated): the
    in-process API on the same core count as a batch of ``workers`` workers."""
    solve(robot, jobs[0])
    c, w = children_cpu(), time.perf_counter()
    pids = []
    for k in range(workers):
        pid = os.fork()
        if pid == 0:
            try:
                for job in jobs[k::workers]:
                    solve(robot, job)
            finally:
                os._exit(0)
        pids.append(pid)
    for pid in pids:
        os.waitpid(pid, 0)
    return time.perf_counter() - w, children_cpu() - c, workers


class ForkServerCPU:
    """CPU seconds (user + system) of the batch process's children, its fork server and resource
    tracker (not waited for by it), sampled every ``period`` seconds: their CPU is spent at start-up
    (the fork server's imports).  Sampling is rare on purpose: scanning every process every 50 ms
    took a few per cent of a core from the workers being measured."""

    def __init__(self, popen, period=0.5):
        self.top, self.seen, self.period = psutil.Process(popen.pid), {}, period
        self.thread = threading.Thread(target=self._watch, daemon=True)
        self.thread.start()

    def _watch(self):
        while True:
            try:
                if self.top.status() == psutil.STATUS_ZOMBIE:
                    return
                children = self.top.children(recursive=False)     # resource tracker, fork server
            except psutil.Error:
                return
            for p in children:
                try:
                    t = p.cpu_times()
                    self.seen[p.pid] = t.user + t.system
                except psutil.Error:
                    pass
            time.sleep(self.period)

    def total(self) -> float:
        self.thread.join()
        return sum(self.seen.values())


def children_cpu() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def batch(jobs, workers: int, directory: Path):
    """Wall and CPU seconds of ``certkin batch`` as a whole process tree."""
    path = directory / "jobs.jsonl"
    path.write_text("".join(dumps(j) + "\n" for j in jobs))
    out = directory / "out"
    shutil.rmtree(out, ignore_errors=True)
    c, w = children_cpu(), time.perf_counter()
    p = subprocess.Popen(CERTKIN + ["batch", str(path), "--out", str(out), "--workers", str(workers)],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    server = ForkServerCPU(p)
    _, err = p.communicate()
    wall = time.perf_counter() - w
    assert p.returncode == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["jobs"] == len(jobs) and not summary["errors"] and not summary["failed"]
    # the batch process whole (exact: waited for), its workers (their own count, in the summary, which
    # also counts the batch process's run once more: a slight overcount) and the fork server (sampled)
    cpu = children_cpu() - c + summary["batch_cpu_seconds"] + server.total()
    return wall, cpu


def dask_batch(jobs, workers: int, directory: Path):
    """Wall and CPU seconds of ``certkin batch --scheduler`` on a cluster started for it (see the docstring;
    started and closed around each run: idle Dask workers take about a tenth of a core each, which the
    other methods would pay)."""
    cluster, client = dask_cluster(workers)
    try:
        return _dask_run(jobs, client, cluster.scheduler_address, directory)
    finally:
        client.close()
        cluster.close()


def _dask_run(jobs, client, address: str, directory: Path):
    path = directory / "jobs.jsonl"
    path.write_text("".join(dumps(j) + "\n" for j in jobs))
    out = directory / "out"
    shutil.rmtree(out, ignore_errors=True)
    workers0, own0 = sum(client.run(time.process_time).values()), time.process_time()
    c, w = children_cpu(), time.perf_counter()
    p = subprocess.run(CERTKIN + ["batch", str(path), "--out", str(out), "--scheduler", address],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = time.perf_counter() - w
    assert p.returncode == 0, p.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["jobs"] == len(jobs) and not summary["errors"] and not summary["failed"]
    cpu = children_cpu() - c + sum(client.run(time.process_time).values()) - workers0 + time.process_time() - own0
    return wall, cpu


def dask_cluster(workers: int):
    """A ``LocalCluster`` of ``workers`` single-thread processes with certkin's batch imported, and its client."""
    from dask.distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    client = Client(cluster)
    client.run(lambda: __import__("certkin.cli.batch"))
    return cluster, client


def cli_argv(job, cert):
    argv = CERTKIN + [job["command"], job["robot"], "--json", "--certificate", str(cert)]
    if job["command"] == "fk":
        return argv + [f"--lengths={job['lengths']}"]
    return argv + [f"--from={job['from']}", f"--to={job['to']}"]


def cli(jobs, workers: int, directory: Path):
    c, w = children_cpu(), time.perf_counter()
    with ThreadPoolExecutor(workers) as pool:
        list(pool.map(lambda j: subprocess.run(cli_argv(j, directory / f"{j['id']}.cert"), check=True,
                                               capture_output=True), jobs))
    return time.perf_counter() - w, children_cpu() - c


def medians(runs):
    return median(r[0] for r in runs), median(r[1] for r in runs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cli-calls", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=1, help="runs of each method (medians)")
    ap.add_argument("--dask", action="store_true", help="also certkin batch on a Dask LocalCluster of --workers")
    ap.add_argument("--allocator", choices=("kept", "default"), default="kept",
                    help="kept: the API rows run after certkin.keep_freed_memory(), as the README advises for a loop "
                         "of calls and as the batch's workers do; default: glibc's own thresholds for the API rows")
    args = ap.parse_args()
    if args.allocator == "kept":
        assert keep_freed_memory(), "keep_freed_memory: no glibc malloc here; run with --allocator default"
    print(describe(), time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), f"API allocator: {args.allocator}", flush=True)
    rows = []
    for name, (robot, jobs) in workloads(args.jobs).items():
        n = len(jobs)
        with tempfile.TemporaryDirectory() as d:
            d = Path(d)
            runs = {}
            for _ in range(args.repeat):
                runs.setdefault("API, 1 process, answers only", []).append(api(robot, jobs, None))
                if jobs[0]["command"] == "fk":
                    runs.setdefault("API, one call, rows independent", []).append(api_together(robot, jobs))
                if args.workers > 1:
                    runs.setdefault(f"API, {args.workers} processes at once", []).append(
                        api_parallel(robot, jobs, args.workers))
                (d / "api").mkdir(exist_ok=True)
                runs.setdefault("API + files, 1 process", []).append(api(robot, jobs, d / "api"))
                for w in sorted({1, args.workers}):
                    (d / f"b{w}").mkdir(exist_ok=True)
                    runs.setdefault(f"certkin batch, {w} worker{'s' if w > 1 else ''}", []).append(
                        (*batch(jobs, w, d / f"b{w}"), w))
                if args.dask:
                    (d / "dask").mkdir(exist_ok=True)
                    runs.setdefault(f"batch, Dask, {args.workers} workers", []).append(
                        (*dask_batch(jobs, args.workers, d / "dask"), args.workers))
                print(f"{name}: run {_ + 1} of {args.repeat} done", file=sys.stderr, flush=True)
            calls = jobs[:args.cli_calls]
            if calls:
                (d / "cli").mkdir()
                runs[f"{len(calls)} CLI calls, {args.workers} at a time"] = [(*cli(calls, args.workers, d / "cli"),
                                                                             args.workers, len(calls))]
            base = {k: medians(runs[k]) for k in ("API, 1 process, answers only", "API + files, 1 process")}
            for method, rs in runs.items():
                wall, cpu = medians(rs)
                cores = rs[0][2] if len(rs[0]) > 2 else 1
                count = rs[0][3] if len(rs[0]) > 3 else n
                rows.append((name, method, count, wall, cpu, cores, base, n))
    api_key, files_key = "API, 1 process, answers only", "API + files, 1 process"
    print(f"{'workload':22s} {'method':32s} {'jobs':>5s} {'wall s':>8s} {'wall ms/job':>11s} {'CPU ms/job':>10s} "
          f"{'wall ratio vs API':>17s} {'vs API+files':>12s} {'CPU ratio vs API':>16s} {'vs API+files':>12s}")
    for name, method, count, wall, cpu, cores, base, n in rows:
        per_core_wall = wall * cores / count            # seconds of one core per job
        api_wall, api_cpu = base[api_key][0] / n, base[api_key][1] / n
        files_wall, files_cpu = base[files_key][0] / n, base[files_key][1] / n
        print(f"{name:22s} {method:32s} {count:5d} {wall:8.2f} {1e3 * wall / count:11.2f} {1e3 * cpu / count:10.2f} "
              f"{api_wall / per_core_wall:17.2f} {files_wall / per_core_wall:12.2f} "
              f"{api_cpu * count / cpu:16.2f} {files_cpu * count / cpu:12.2f}")
    same = {(name, method): (wall, cpu) for name, method, count, wall, cpu, cores, base, n in rows}
    for name in dict.fromkeys(r[0] for r in rows):
        a = same.get((name, f"API, {args.workers} processes at once"))
        for method in (f"certkin batch, {args.workers} workers", f"batch, Dask, {args.workers} workers"):
            b = same.get((name, method))
            if a and b:
                print(f"{name}: {method} / API, {args.workers} processes at once (the same core count): wall ratio "
                      f"{a[0] / b[0]:.2f}, CPU ratio {a[1] / b[1]:.2f}")
    print("wall ratio: (jobs per second per core of the method) / (jobs per second of the in-process API on one core); "
          "target >= 0.8 against the API answering only; meaningful on a quiet machine only.\n"
          "CPU ratio: (CPU per job of the API) / (CPU per job of the method); batch rows: every process of the batch "
          "(start-up, fork server, workers: the batch's own count, slightly over); CLI rows: the calls' processes (start-up included).\n"
          f"medians of {args.repeat} run(s) per method (CLI calls: one run).")


if __name__ == "__main__":
    main()
