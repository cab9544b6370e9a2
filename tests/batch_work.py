"""Work functions for the batch tests, importable by worker processes."""
import os
import signal

from certkin.cli.batch import run_job


def dies_on_boom(job, out):
    """``run_job``, except that the worker running the job ``boom`` is killed, every time."""
    if job["id"] == "boom":
        os.kill(os.getpid(), signal.SIGKILL)
    return run_job(job, out)


def square_or_die(job, out):
    """``job["x"]`` squared, at once (jobs that short run in chunks); the job ``boom`` kills its worker."""
    if job["id"] == "boom":
        os.kill(os.getpid(), signal.SIGKILL)
    return {"id": job["id"], "square": job["x"] ** 2}

