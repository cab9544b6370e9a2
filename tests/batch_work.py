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


def square_or_die_once(job, out):
    """``square_or_die``, except that ``boom`` kills only the first worker that runs it (a file in the
    directory ``out`` remembers it), then answers."""
    if job["id"] == "boom":
        try:
            os.close(os.open(os.path.join(out, "boom-died"), os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            return {"id": job["id"], "square": job["x"] ** 2}
        os.kill(os.getpid(), signal.SIGKILL)
    return {"id": job["id"], "square": job["x"] ** 2}
