"""Jobs on a local process pool (``concurrent.futures``), resistant to workers that die.

Each worker is a one-process ``ProcessPoolExecutor``, so when a worker dies (killed, out of memory)
the job it was running is known: the oldest of the (at most ``IN_FLIGHT``) tasks handed to it that
has not returned.  That job is tried again, at most ``RETRIES`` times, then reported as ``Died``;
the other tasks of that worker go back to the queue uncharged, and a fresh worker takes its place.
Workers are started by a fork server that has imported the work function's module once, so a new
worker costs no start-up; robots are loaded once per worker by the work function's own cache.  Workers ignore
Ctrl-C (the parent decides what an interrupt means) and exit when the parent process goes away.
"""
from __future__ import annotations

from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
import multiprocessing
import os
import signal
import threading
import time

RETRIES = 2             # a job whose worker dies is tried again at most this many times
IN_FLIGHT = 2           # tasks handed to a worker at once: the next one is ready when a job ends


@dataclass
class Died:
    """A task whose worker died ``attempts`` times while running it."""

    attempts: int
    reason: str


def _worker_setup(batch_pid: int):
    """In each worker: ignore Ctrl-C, and exit when the batch process is gone (the worker's own
    parent is the fork server, which lives as long as its workers do)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch():
        while True:
            try:
                os.kill(batch_pid, 0)
            except ProcessLookupError:
                os.kill(os.getpid(), signal.SIGKILL)     # the batch is gone: so is its worker
            time.sleep(0.5)
    threading.Thread(target=watch, daemon=True).start()


class _Worker:
    """One worker process and the tasks handed to it, oldest first."""

    def __init__(self, context):
        self.executor = ProcessPoolExecutor(1, mp_context=context, initializer=_worker_setup,
                                            initargs=(os.getpid(),))
        self.pid = self.executor.submit(os.getpid)
        self.tasks = deque()                # (task index, future)

    def stop(self):
        if self.pid.done() and not self.pid.exception():
            try:
                os.kill(self.pid.result(), signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.executor.shutdown(wait=False, cancel_futures=True)


def run_local(tasks: list, work, workers: int, report, retries: int = RETRIES) -> tuple[bool, float | None]:
    """Run ``work(*tasks[i])`` for every i on ``workers`` processes; ``report(i, value)`` in this
    process as each ends (``value``: what ``work`` returned, or ``Died``).  Returns (interrupted,
    CPU seconds of the workers): interrupted is True when Ctrl-C stopped the run (unreported tasks
    were not run; the CPU is then None); the CPU is that of the workers alive at the end (a worker
    that died took its own count with it)."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([work.__module__])
    queue = deque(range(len(tasks)))
    attempts = [0] * len(tasks)
    pool = [_Worker(context) for _ in range(max(1, min(workers, len(tasks))))]
    try:
        while queue or any(w.tasks for w in pool):
            for w in pool:
                while queue and len(w.tasks) < IN_FLIGHT:
                    i = queue.popleft()
                    w.tasks.append((i, w.executor.submit(work, *tasks[i])))
            wait([f for w in pool for _, f in w.tasks], return_when=FIRST_COMPLETED)
            for k, w in enumerate(pool):
                if _collect(w, report, queue, attempts, retries):
                    w.stop()
                    pool[k] = _Worker(context)
        cpu = sum(_cpu(f) for f in [w.executor.submit(time.process_time) for w in pool])
    except KeyboardInterrupt:
        for w in pool:
            w.stop()
        return True, None
    for w in pool:
        w.executor.shutdown(wait=True)
    return False, cpu


def _cpu(future) -> float:
    """The CPU seconds a worker reports (0 if it died meanwhile)."""
    try:
        return future.result()
    except BrokenProcessPool:
        return 0.0


def _collect(worker, report, queue, attempts, retries) -> bool:
    """Report the finished tasks of a worker; True when the worker died (its tasks are requeued,
    the one it was running charged with an attempt)."""
    while worker.tasks and worker.tasks[0][1].done():
        i, f = worker.tasks[0]
        try:
            value = f.result()
        except BrokenProcessPool:
            break
        except Exception as exc:        # the work function answers every job; this is a bug in it
            value = Died(1, f"the job raised {type(exc).__name__}: {exc}")
        worker.tasks.popleft()
        if attempts[i] and isinstance(value, dict):
            value["attempts"] = attempts[i] + 1
        report(i, value)
    if not worker.tasks or not isinstance(worker.tasks[0][1].exception() if worker.tasks[0][1].done() else None,
                                          BrokenProcessPool):
        return False
    running, _ = worker.tasks.popleft()
    attempts[running] += 1
    waiting = [i for i, _ in worker.tasks]
    worker.tasks.clear()
    queue.extendleft(reversed(waiting))
    if attempts[running] > retries:
        report(running, Died(attempts[running], f"its worker process died {attempts[running]} times while "
                                                "running it (killed, or out of memory)"))
    else:
        queue.appendleft(running)
    return True
