"""Jobs on a Dask cluster (the ``dask`` extra: ``dask.distributed``, imported here only).

``dask.distributed.Client(address)`` runs the jobs in chunks, as the local pool does (``local.TaskQueue``:
consecutive jobs for about ``local.CHUNK_SECONDS``, at most ``local.IN_FLIGHT`` chunks per worker
thread handed out at once, each run by ``local.run_chunk``): one Dask task per small planar FK job
cost its workers 15 % more CPU and the batch 30 % more time (docs/benchmarks.md).  Dask moves the task of a worker that dies to another one, up
to the scheduler's ``distributed.scheduler.allowed-failures`` (3 by default; start the scheduler
with ``DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES=2`` for the local pool's rule: a job tried
three times, then failed), and then gives up with ``KilledWorker``.  Dask charges a death to every
task its worker held, running or waiting, so a ``KilledWorker`` does not name the job that kills:
the jobs of that task become *suspects*, each run with nothing else in flight on the cluster (the
jobs they had finished are found done on disk and skipped), where a death is the job's own and a
``KilledWorker`` is reported as ``Died``.  A task that Dask moved after a death and that then
succeeded is not counted as retried: Dask charges the death to every task the worker held, running
or waiting, and does not say which one was running.  The work function writes each job's files, so the output
directory and the robot files must be reachable by the workers at the same paths (one machine, or a
shared file system).
"""
from __future__ import annotations

from collections import deque
from concurrent.futures import CancelledError
import os
import sys
import threading
import time

from ..allocator import keep_freed_memory
from ..errors import InputError
from .jobs import BATCH_DIRECTORY
from .local import IN_FLIGHT, Died, TaskQueue, run_chunk, times


def connect(address: str):
    """A client of the Dask scheduler at ``address``; ``InputError`` naming ``scheduler`` when none
    answers there within Dask's connection timeout (``distributed.comm.timeouts.connect``, 30 s by
    default) and a few seconds more.  Dask's own timeout does not cover a service that accepts the
    connection and then stays silent, so the attempt runs in a thread this call stops waiting for
    (a daemon: it cannot keep the process alive); a service that answers with something else than
    Dask's handshake makes Dask read a bogus frame length (``MemoryError``): not a Dask scheduler."""
    import dask
    from dask.distributed import Client
    from dask.utils import parse_timedelta
    seconds = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="s")
    outcome = {}

    def attempt():
        try:
            outcome["client"] = Client(address)
        except BaseException as exc:        # handed to the caller below
            outcome["error"] = exc
    thread = threading.Thread(target=attempt, name="certkin-dask-connect", daemon=True)
    thread.start()
    thread.join(seconds + 5.0)
    if "client" in outcome:
        return outcome["client"]
    exc = outcome.get("error")
    if exc is None:
        reason = f"nothing answered within {seconds:g} s"
    elif isinstance(exc, MemoryError):
        reason = "the service there does not speak Dask's protocol"
    elif isinstance(exc, (OSError, TimeoutError, ValueError, TypeError)):
        reason = str(exc)
    else:
        raise exc
    raise InputError("scheduler", address, f"no Dask scheduler answers there ({reason})")


def run_dask(tasks: list, work, client, report) -> bool:
    """Run ``work(*tasks[i])`` for every i on the Dask cluster of ``client`` (``connect``), closed at
    the end; ``report(i, value)`` as each chunk ends.  Returns True when Ctrl-C stopped the run, or its
    scheduler went away (the client gives up reconnecting after 30 s): the jobs not reported stay pending."""
    from dask.distributed import as_completed
    from distributed.client import ClosedClientError
    from distributed.scheduler import KilledWorker

    with client:
        slots = max(1, sum(client.nthreads().values()))
        queue, running, finished, suspects = TaskQueue(len(tasks)), {}, as_completed(), deque()

        def submit(chunk, alone):
            future = client.submit(_run_chunk_in, os.getcwd(), work, [tasks[i] for i in chunk], pure=False)
            running[future] = (chunk, alone)
            finished.add(future)

        def hand_out():
            if suspects:                    # one at a time, once nothing else runs
                if not running:
                    submit([suspects.popleft()], True)
                return
            while queue and len(running) < IN_FLIGHT * slots:
                submit(queue.chunk(slots), False)
        try:
            hand_out()
            while running:
                future = _next(finished, client)
                if future is None:
                    raise ClosedClientError("the scheduler went away")
                chunk, alone = running.pop(future)
                try:
                    values, seconds = future.result()
                    queue.jobs, queue.seconds = queue.jobs + len(chunk), queue.seconds + seconds
                except CancelledError:      # lost with the scheduler's connection (certkin cancels none)
                    if not _alive(client):
                        raise ClosedClientError("the scheduler went away") from None
                    queue.again(chunk)      # (the client reconnected: run again, uncharged)
                    hand_out()
                    continue
                except KilledWorker:
                    if not alone:           # which job of the task killed its workers is not known
                        suspects.extend(chunk)
                        hand_out()
                        continue
                    if not _alive(client):
                        raise ClosedClientError("the scheduler went away") from None
                    tries = client.run_on_scheduler(_allowed_failures) + 1
                    values = [Died(tries, f"its worker process died {times(tries)} while running it (killed, or "
                                          "out of memory)")]
                except Exception as exc:    # a bug in the work function, or a task lost with its scheduler
                    if not _alive(client):
                        raise ClosedClientError("the scheduler went away") from None
                    values = [Died(1, f"{type(exc).__name__}: {exc}")] * len(chunk)
                for i, value in zip(chunk, values):
                    if alone and isinstance(value, dict) and not value.get("resumed"):
                        value["attempts"] = 2   # run again after a worker died
                    report(i, value)
                hand_out()
        except ClosedClientError:           # the scheduler went away: what was not answered stays pending
            sys.stderr.write("certkin: the Dask scheduler went away during the run: the jobs not answered are "
                             "pending (run the batch again to resume them)\n")
            return True
        except KeyboardInterrupt:
            if _alive(client):
                client.cancel(list(running))
            return True
    return False


POLL = 0.02     # seconds between two looks at a cluster with no task finished


def _next(finished, client):
    """The next finished future of ``finished`` (``as_completed``), or None once the client is closed
    (its scheduler went away: ``as_completed`` would wait for ever)."""
    while not finished.has_ready():
        if not _alive(client):
            return None
        time.sleep(POLL)
    return next(finished)


def _alive(client) -> bool:
    return client.status in ("running", "connecting", "newly-created")


def _run_chunk_in(directory: str, work, tasks: list):
    """``local.run_chunk`` as from the batch's working directory (jobs may name their robot files and the
    output directory relative to it, and a Dask worker was started elsewhere): the tasks' (job, output
    directory) with the directory joined to it, and ``jobs.located`` for the robot files, for this task
    only (a worker's threads may serve several batches: no ``os.chdir``), with freed memory kept in the
    worker process as in the local pool's workers (``certkin.allocator``: a few µs, once is enough)."""
    keep_freed_memory()
    token = BATCH_DIRECTORY.set(directory)
    try:
        return run_chunk(work, [(job, os.path.join(directory, out)) for job, out in tasks])
    finally:
        BATCH_DIRECTORY.reset(token)


def _allowed_failures(dask_scheduler) -> int:
    """On the scheduler: how many deaths of its workers a task survives."""
    return dask_scheduler.allowed_failures
