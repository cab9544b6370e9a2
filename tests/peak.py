"""Peak memory of a fresh Python process beyond its start-up: for the tests that hold a whole call
within ``--max-memory`` (the ceiling bounds the work; the interpreter and the imports come on top)."""
import json
import os
import subprocess
import sys

ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}


def beyond_start_up(statement: str, imports: str) -> tuple[object, int, subprocess.CompletedProcess]:
    """Run ``imports`` then ``statement`` (its value is ``result``) in a fresh process: (``result``
    read back as JSON, the peak RSS in bytes beyond that of a process that only ran ``imports``, the
    completed process).  ``statement`` must assign ``result``; stdout is left to it."""
    peak = "print(json.dumps([result, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss]), file=sys.stderr)"
    head = f"import json, resource, sys; {imports}; "
    base = subprocess.run([sys.executable, "-c", head + "result = None; " + peak], capture_output=True, text=True,
                          env=ENV, check=True)
    done = subprocess.run([sys.executable, "-c", f"{head}{statement}; {peak}"], capture_output=True, text=True,
                          env=ENV, timeout=300)
    result, kib = json.loads(done.stderr.strip().splitlines()[-1])
    return result, (kib - json.loads(base.stderr.strip().splitlines()[-1])[1]) * 1024, done
