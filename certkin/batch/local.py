"""Jobs on a local process pool (``concurrent.futures``), resistant to workers that die.

Each worker is a one-process ``ProcessPoolExecutor``, so when a worker dies (killed, out of memory)
the task it was running is known: the oldest of the (at most ``IN_FLIGHT``) tasks handed to it that
has not returned.  A task is a *chunk* of consecutive jobs, sized so that it runs for about
``CHUNK_SECONDS`` (one job at first, then from the mean time per job so far, at most ``MAX_CHUNK``):
short jobs then cost one round trip per chunk, not per job.  When a worker dies in a chunk of
several jobs, they go back to the queue uncharged (but reported as retried), each to run alone (the
jobs it had finished are found done on disk and skipped); a job that runs alone and kills its worker is tried again, at
most ``RETRIES`` times, then reported as ``Died``.  The other tasks of that worker go back to the
queue uncharged, and a fresh worker takes its place.  Workers are started by a fork server that has
imported the work function's module (and ``preload``) once, so a new worker costs no start-up;
robots are loaded once per worker by the work function's own cache.  Workers that die before they
start (``START_FAILURES`` in a row: a main module the fork server cannot import) stop the batch
with ``WorkersCannotStart`` instead of being started again and again.  Workers ignore Ctrl-C (the parent decides what
an interrupt means) and exit when the parent process goes away.
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

from ..allocator import keep_freed_memory
from ..errors import InputError

RETRIES = 2             # a job whose worker dies is tried again at most this many times
START_FAILURES = 3      # workers in a row that die before they start: the batch stops
IN_FLIGHT = 2           # tasks handed to a worker at once: the next one is ready when a task ends
CHUNK_SECONDS = 0.25    # wanted run time of a chunk of jobs
MAX_CHUNK = 32          # jobs per chunk at most
HOLD_SECONDS = 0.25     # computing whose answers a worker holds before it writes them (``run_chunk``)


@dataclass
class Died:
    """A task whose worker died ``attempts`` times while running it."""

    attempts: int
    reason: str


def _worker_setup(batch_pid: int):
    """In each worker: ignore Ctrl-C, keep freed memory (``certkin.allocator``), and exit when the
    batch process is gone (the worker's own parent is the fork server, which lives as long as its
    workers do)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    keep_freed_memory()

    def watch():
        while True:
            try:
                os.kill(batch_pid, 0)
            except ProcessLookupError:
                os.kill(os.getpid(), signal.SIGKILL)     # the batch is gone: so is its worker
            time.sleep(0.5)
    threading.Thread(target=watch, daemon=True).start()


class WorkersCannotStart(InputError):
    """Worker processes that die as they start, ``START_FAILURES`` in a row: no job can run."""

    def __init__(self):
        super().__init__("workers", "", f"{START_FAILURES} worker processes in a row died as they started, before "
                         "any job (see the errors above): calling the batch from a script, guard the call with "
                         "`if __name__ == \"__main__\":` (each worker imports the main module), and run that script "
                         "from a file, not from standard input")


class _Worker:
    """One worker process and the tasks handed to it, oldest first."""

    def __init__(self, context):
        self.executor = ProcessPoolExecutor(1, mp_context=context, initializer=_worker_setup,
                                            initargs=(os.getpid(),))
        self.pid = self.executor.submit(os.getpid)
        self.tasks = deque()                # (task index, future)

    def started(self) -> bool:
        """Whether the worker process ran at all (it answered its first task, its pid)."""
        return self.pid.done() and self.pid.exception() is None

    def stop(self):
        if self.pid.done() and not self.pid.exception():
            try:
                os.kill(self.pid.result(), signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.executor.shutdown(wait=False, cancel_futures=True)


def run_chunk(work, tasks: list) -> tuple[list, float]:
    """In a worker: ``work(*task)`` for each task of a chunk; (their values, wall seconds).  A task
    that raises (a bug in ``work``, which answers every job), or tries to end the process
    (``SystemExit``), is reported as ``Died``.

    A work function with ``phased`` (``work.phased(*task)`` computes a task's answer and returns a
    function that completes it: writes its files, gives its value) has the answers of consecutive
    tasks computed first, then completed together once ``HOLD_SECONDS`` of computing has passed or
    the chunk ends: the writing code then runs warm (about 0.7 ms less per small planar FK job).
    What is held meanwhile is at most the answers of that much computing (a few MB).
    A work function with ``prepare`` as well (``work.prepare(tasks)``: per task, None or what
    ``phased(*task, early)`` takes instead of computing it) answers some tasks of the chunk together
    first (``certkin.cli.batch.answer_together``); if it raises, each task is computed on its own."""
    t0, values, phased = time.perf_counter(), [None] * len(tasks), getattr(work, "phased", None)
    early = [None] * len(tasks)
    if phased is not None and getattr(work, "prepare", None) is not None:
        try:
            early = work.prepare(tasks)
        except Exception:
            pass
    held, since = [], time.perf_counter()
    for k, task in enumerate(tasks):
        try:
            if phased is None:
                values[k] = work(*task)
            else:
                held.append((k, phased(*task) if early[k] is None else phased(*task, early[k])))
        except (Exception, SystemExit) as exc:
            values[k] = _raised(exc)
        if held and (k == len(tasks) - 1 or time.perf_counter() - since >= HOLD_SECONDS):
            for j, complete in held:
                try:
                    values[j] = complete()
                except (Exception, SystemExit) as exc:
                    values[j] = _raised(exc)
            held, since = [], time.perf_counter()
    return values, time.perf_counter() - t0


def times(n: int) -> str:
    """'once', 'twice' or 'N times'."""
    return {1: "once", 2: "twice"}.get(n, f"{n} times")


def _raised(exc: Exception) -> Died:
    return Died(1, f"the job raised {type(exc).__name__}: {exc}")


class TaskQueue:
    """The tasks not yet handed out, in order, and the chunks they are handed out in."""

    def __init__(self, n: int):
        self.todo, self.alone = deque(range(n)), set()
        self.requeued = {}                         # job -> times its chunk's worker died (not charged)
        self.jobs, self.seconds = 0, 0.0          # jobs run in chunks so far, and their wall time

    def __bool__(self):
        return bool(self.todo)

    def chunk(self, workers: int) -> list:
        """The next chunk: one job that must run alone, or consecutive jobs for ``CHUNK_SECONDS``."""
        size = 1 if not self.jobs else int(CHUNK_SECONDS * self.jobs / max(self.seconds, 1e-9))
        size = max(1, min(size, MAX_CHUNK, len(self.todo) // (IN_FLIGHT * workers)))
        out = [self.todo.popleft()]
        while len(out) < size and self.todo and out[0] not in self.alone and self.todo[0] not in self.alone:
            out.append(self.todo.popleft())
        return out

    def again(self, indices, alone: bool = False) -> None:
        """Put tasks back at the front of the queue (``alone``: each to run in a chunk of its own)."""
        self.todo.extendleft(reversed(indices))
        if alone:
            self.alone.update(indices)


def run_local(tasks: list, work, workers: int, report, retries: int = RETRIES,
              preload=()) -> tuple[bool, float | None]:
    """Run ``work(*tasks[i])`` for every i on ``workers`` processes; ``report(i, value)`` in this
    process as each chunk ends (``value``: what ``work`` returned, or ``Died``).  Returns (interrupted,
    CPU seconds of the workers): interrupted is True when Ctrl-C stopped the run (unreported tasks
    were not run; the CPU is then None); the CPU is that of the workers alive at the end (a worker
    that died took its own count with it).  ``preload``: modules to import in the fork server, besides
    the work function's."""
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([work.__module__, *preload])
    queue = TaskQueue(len(tasks))
    attempts = [0] * len(tasks)
    pool = [_Worker(context) for _ in range(max(1, min(workers, len(tasks))))]
    unstarted = 0                               # workers in a row that died before they started

    def replace(k):
        nonlocal unstarted
        unstarted = 0 if pool[k].started() else unstarted + 1
        pool[k].stop()
        if unstarted >= START_FAILURES:
            raise WorkersCannotStart()
        pool[k] = _Worker(context)
    try:
        while queue or any(w.tasks for w in pool):
            for k, w in enumerate(pool):
                while queue and len(w.tasks) < IN_FLIGHT:
                    chunk = queue.chunk(len(pool))
                    try:
                        future = w.executor.submit(run_chunk, work, [tasks[i] for i in chunk])
                    except BrokenProcessPool:      # the worker died since its tasks were last collected
                        queue.again(chunk)         # (this chunk never ran: back, uncharged)
                        if not w.tasks:            # nothing of it left to collect: a fresh worker now
                            replace(k)
                        break
                    w.tasks.append((chunk, future))
            wait([f for w in pool for _, f in w.tasks], return_when=FIRST_COMPLETED)
            for k, w in enumerate(pool):
                if _collect(w, report, queue, attempts, retries):
                    replace(k)
        cpu = sum(_cpu(w) for w in pool)
    except KeyboardInterrupt:
        for w in pool:
            w.stop()
        return True, None
    except WorkersCannotStart:
        for w in pool:
            w.stop()
        raise
    for w in pool:
        w.executor.shutdown(wait=True)
    return False, cpu


def _cpu(worker) -> float:
    """The CPU seconds a worker reports (0 if it died meanwhile)."""
    try:
        return worker.executor.submit(time.process_time).result()
    except BrokenProcessPool:
        return 0.0


def _collect(worker, report, queue, attempts, retries) -> bool:
    """Report the finished chunks of a worker; True when the worker died (its chunks are requeued:
    the jobs of the one it was running each to run alone, or that job charged with an attempt when
    it ran alone)."""
    while worker.tasks and worker.tasks[0][1].done():
        chunk, f = worker.tasks[0]
        try:
            values, seconds = f.result()
        except BrokenProcessPool:
            break
        worker.tasks.popleft()
        queue.jobs, queue.seconds = queue.jobs + len(chunk), queue.seconds + seconds
        for i, value in zip(chunk, values):
            again = attempts[i] + queue.requeued.get(i, 0)
            if again and isinstance(value, dict) and not value.get("resumed"):
                value["attempts"] = again + 1          # run again after a worker died: "retried"
            report(i, value)
    if not worker.tasks or not isinstance(worker.tasks[0][1].exception() if worker.tasks[0][1].done() else None,
                                          BrokenProcessPool):
        return False
    if not worker.started():                # it died before it ran anything: nothing is charged
        queue.again([i for chunk, _ in worker.tasks for i in chunk])
        worker.tasks.clear()
        return True
    running, _ = worker.tasks.popleft()
    waiting = [i for chunk, _ in worker.tasks for i in chunk]
    worker.tasks.clear()
    queue.again(waiting)
    if len(running) > 1:                    # which of its jobs killed the worker is not known
        queue.again(running, alone=True)
        for i in running:
            queue.requeued[i] = queue.requeued.get(i, 0) + 1
        return True
    (i,) = running
    attempts[i] += 1
    if attempts[i] > retries:
        report(i, Died(attempts[i], f"its worker process died {times(attempts[i])} while running it (killed, or out "
                                    "of memory)"))
    else:
        queue.again([i], alone=True)
    return True
