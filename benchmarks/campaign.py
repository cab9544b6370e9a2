"""A 10 000-job campaign on a Dask ``LocalCluster``: the same answers as on one core, resumable after a kill.

1. ``certkin jobs grid`` writes the jobs: small planar FK jobs of seed 003 planar example 2, a grid
   of leg lengths around the 6-mode instance 28.99, 13.66, 40.53 (the first ``--jobs`` of them);
2. ``certkin batch JOBS --out one --workers 1``: the answers on one core;
3. a Dask ``LocalCluster`` (``--workers`` processes of one thread, ``allowed-failures`` 2 as the
   local pool) and ``certkin batch JOBS --out dask --scheduler ADDRESS``, killed (SIGKILL) once a
   third of the documents are written, then the same command again: it skips every finished job
   (its certificate re-checked by ``proofs``) and answers the others;
4. every document of ``dask`` (timing fields left out) and every certificate (byte for byte)
   compared with ``one``.

Steps 2 and 3 run at the same time (``--one-after`` runs them one after the other).  Prints the
wall and CPU seconds of each step.  Usage: ``python benchmarks/campaign.py [--jobs 10000]
[--workers 2] [--one-after] [--keep DIR]``.
"""
from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path
import resource
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import describe  # noqa: E402
from certkin.batch.results import untimed  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PLANAR = str(ROOT / "examples" / "robots" / "seed003-planar-example-2.toml")
CERTKIN = [sys.executable, "-m", "certkin.cli"]


def generate(n: int, path: Path) -> int:
    side = math.ceil(n ** (1 / 3))
    out = subprocess.run(CERTKIN + ["jobs", "grid", PLANAR, "--command", "fk", "--prefix", "c", "--lengths",
                                    f"L1=28.5:29.5:{side},L2=13.2:14.1:{side},L3=40:41:{side}"],
                         capture_output=True, text=True, check=True).stdout.splitlines()[:n]
    path.write_text("\n".join(out) + "\n")
    return len(out)


def documents(out: Path) -> int:
    try:
        return sum(1 for e in os.scandir(out) if e.name.endswith(".json") and e.name != "summary.json")
    except FileNotFoundError:
        return 0


def cpu_of_children() -> float:
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def compare(one: Path, other: Path, n: int) -> list[str]:
    """The ids whose document (untimed) or certificate (bytes) differ between two result directories."""
    differ = []
    for p in sorted(one.glob("*.json")):
        if p.name == "summary.json":
            continue
        q = other / p.name
        cert_a, cert_b = p.with_suffix(".cert"), q.with_suffix(".cert")
        if not q.exists() or untimed(json.loads(p.read_text())) != untimed(json.loads(q.read_text())) or \
                cert_a.exists() != cert_b.exists() or (cert_a.exists() and cert_a.read_bytes() != cert_b.read_bytes()):
            differ.append(p.stem)
    assert len(list(one.glob("*.json"))) == n + 1, "the one-core run did not answer every job"
    return differ


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=10_000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--one-after", action="store_true", help="run the one-core batch before the Dask one")
    ap.add_argument("--keep", metavar="DIR", help="keep the results in DIR (default: a temporary directory)")
    args = ap.parse_args()
    print(describe(), flush=True)
    import dask
    from dask.distributed import Client, LocalCluster

    d = Path(args.keep or tempfile.mkdtemp(prefix="certkin-campaign-"))
    d.mkdir(parents=True, exist_ok=True)
    jobs = d / "jobs.jsonl"
    n = generate(args.jobs, jobs)
    print(f"{n} jobs in {jobs}", flush=True)
    one, dist = d / "one", d / "dask"
    shutil.rmtree(one, ignore_errors=True)
    shutil.rmtree(dist, ignore_errors=True)
    times = {}

    w0 = time.perf_counter()
    reference = subprocess.Popen(CERTKIN + ["batch", str(jobs), "--out", str(one), "--workers", "1"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if args.one_after:
        reference.wait()
    with dask.config.set({"distributed.scheduler.allowed-failures": 2}), \
            LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        cpu0 = sum(client.run(time.process_time).values())
        t0 = time.perf_counter()
        first = subprocess.Popen(CERTKIN + ["batch", str(jobs), "--out", str(dist), "--scheduler",
                                            cluster.scheduler_address], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, text=True)
        while documents(dist) < n // 3:
            assert first.poll() is None, first.communicate()
            time.sleep(0.5)
        first.kill()
        first.wait()
        killed_at = documents(dist)
        times["dask, until killed"] = time.perf_counter() - t0
        print(f"dask batch killed after {times['dask, until killed']:.1f} s with {killed_at} documents written",
              flush=True)
        t1 = time.perf_counter()
        again = subprocess.run(CERTKIN + ["batch", str(jobs), "--out", str(dist), "--scheduler",
                                          cluster.scheduler_address, "--json"], capture_output=True, text=True)
        assert again.returncode == 0, again.stderr
        times["dask, resumed run"] = time.perf_counter() - t1
        dask_cpu = sum(client.run(time.process_time).values()) - cpu0
    summary = json.loads(again.stdout)
    rc = reference.wait()
    assert rc == 0, reference.stderr.read()
    times["one core (1 local worker)"] = json.loads((one / "summary.json").read_text())["seconds"]
    one_summary = json.loads((one / "summary.json").read_text())
    differ = compare(one, dist, n)
    print(f"{'step':34s} {'wall s':>9s}")
    for k, v in times.items():
        print(f"{k:34s} {v:9.1f}")
    print(f"one core: {one_summary['batch_cpu_seconds']:.1f} CPU s ({1e3 * one_summary['batch_cpu_seconds'] / n:.1f} "
          f"ms/job), counts {one_summary['counts']}")
    print(f"dask: workers' CPU {dask_cpu:.1f} s over both runs; resumed run: {summary['resumed']} jobs skipped "
          f"(certificate re-checked), {n - summary['resumed']} answered; counts {summary['counts']}; "
          f"errors {len(summary['errors'])}, failed {len(summary['failed'])}")
    print(f"run side by side: {not args.one_after}; whole script {time.perf_counter() - w0:.1f} s wall, "
          f"children CPU {cpu_of_children():.1f} s")
    print(f"identical answers (documents without timing, certificates byte for byte): "
          f"{'yes, all ' + str(n) if not differ else 'NO: ' + ', '.join(differ[:10])}")
    if not args.keep:
        shutil.rmtree(d, ignore_errors=True)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
