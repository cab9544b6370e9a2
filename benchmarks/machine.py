"""One line describing the machine and the load, printed by every benchmark."""
from __future__ import annotations

import os
import platform

import numpy as np


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def describe() -> str:
    try:
        cores = len(os.sched_getaffinity(0))
        load = "load avg %.2f %.2f %.2f" % os.getloadavg()
    except (AttributeError, OSError):
        cores, load = os.cpu_count(), "load n/a"
    return (f"{cpu_model()}, {os.cpu_count()} cores ({cores} allowed to this process), {load}; "
            f"Python {platform.python_version()}, numpy {np.__version__}")


def codac_version() -> str | None:
    """codac's version, or None when it is not installed."""
    try:
        import codac  # noqa: F401
    except ImportError:
        return None
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("codac")
    except PackageNotFoundError:
        return "installed"


def median_time(fn, repeat):
    """Median wall time of ``repeat`` calls of ``fn()`` (the machine is noisy: quote medians)."""
    import statistics
    import time
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)
