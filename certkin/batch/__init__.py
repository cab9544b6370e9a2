"""``certkin batch``: many jobs, each answered as its command would answer it, on a local process
pool or a Dask cluster, resumable and resistant to workers that die.

``jobs`` reads the jobs file, ``grid`` writes jobs for exhaustive campaigns, ``local`` and
``cluster`` run them, ``results`` writes what each job answered and the summary.  The work done
per job (parse its options with its command's own parser, compute, write its document and
certificate) is given by the command line (``certkin.cli.batch.run_job``); this package knows no
command.
"""
from __future__ import annotations

from pathlib import Path
import time

from .cluster import connect, run_dask
from .jobs import ERROR, read_jobs
from .local import Died, run_local
from .results import FAILED, locked, remove_leftovers, row, summarise, write_error, write_summary

PENDING = "pending"          # verdict of a job an interrupt kept from running


def run_batch(jobs: list, out, work, workers: int = 1, scheduler: str | None = None, on_row=None,
              preload=()) -> dict:
    """Answer every job into ``out`` with ``work(job, out)`` (which returns the job's summary row,
    skipping a job already done there); write and return ``summary.json``.  ``on_row(row)`` is
    called as each job ends.  Jobs that could not be read are answered here with their error.
    ``preload``: modules the local workers import once, before the first job (in their fork server)."""
    client = connect(scheduler) if scheduler else None       # before anything is written
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with locked(out):
        return _run(jobs, out, work, workers, scheduler, client, on_row, preload)


def _run(jobs, out: Path, work, workers, scheduler, client, on_row, preload) -> dict:
    t0, c0 = time.perf_counter(), time.process_time()
    ids = [job["id"] for job in jobs]
    remove_leftovers(out, ids)              # of an earlier run killed while writing
    rows = [None] * len(jobs)

    def record(i, value):
        if isinstance(value, Died):
            value = write_error(out, jobs[i], FAILED, value.reason, attempts=value.attempts)
        rows[i] = value
        if on_row:
            on_row(value)

    todo = []
    for i, job in enumerate(jobs):
        if ERROR in job:
            record(i, write_error(out, job, ERROR, job[ERROR]))
        else:
            todo.append(i)
    tasks = [(jobs[i], str(out)) for i in todo]

    def report(k, value):
        record(todo[k], value)

    if scheduler:
        interrupted, workers_cpu = run_dask(tasks, work, client, report), None
    else:
        interrupted, workers_cpu = run_local(tasks, work, workers, report, preload=preload) if tasks else (False, 0.0)
    if not (scheduler and interrupted):     # (a cancelled Dask task may still be writing)
        remove_leftovers(out, ids)          # of workers killed while writing: none is writing now
    for i, r in enumerate(rows):
        if r is None:
            rows[i] = row(jobs[i], PENDING, 0.0, 0)
    cpu = None if workers_cpu is None else time.process_time() - c0 + workers_cpu
    summary = summarise(rows, time.perf_counter() - t0, interrupted, scheduler or f"{workers} local", cpu)
    write_summary(out, summary)
    return summary


__all__ = ["run_batch", "read_jobs", "PENDING"]
