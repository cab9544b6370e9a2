"""Keep freed memory in the process instead of handing it back to the system at every call.

The searches and the trajectory bounds work on numpy arrays of a few hundred KB to a few MB, made and
freed many times a second.  glibc's malloc gives the top of its heap back to the system as soon as
more than its trim threshold is free there (an adaptive 128 KB to 64 MB), so the next call faults
the same pages in again: a seed 000 trajectory check (``verify_trajectory``) took about 1 800 page
faults and 3.5 ms of system time of its 17 ms (``benchmarks/batch.py``, "Allocator" in
``docs/benchmarks.md``).  ``keep_freed_memory`` sets fixed thresholds instead: arrays up to
``MMAP_THRESHOLD`` come from the heap, and up to ``TRIM_THRESHOLD`` of free heap (plus ``TOP_PAD``
when it grows) stays in the process for the next call.  The cost is at most that much resident
memory kept after a peak; no answer changes (the arithmetic is the same).

The command line and the batch's workers call it (processes running certkin's jobs); a program calling the
API in a loop may call it once.  It changes the whole process's allocator, so importing certkin does
not.  Elsewhere than glibc (macOS, musl) it does nothing and says so.
"""
from __future__ import annotations

import ctypes
import sys

M_TRIM_THRESHOLD, M_TOP_PAD, M_MMAP_THRESHOLD = -1, -2, -3     # glibc's <malloc.h>
TRIM_THRESHOLD = 64 << 20       # free heap kept at its top (bytes)
TOP_PAD = 16 << 20              # extra heap taken each time it grows
MMAP_THRESHOLD = 32 << 20       # larger blocks get their own mapping (given back when freed)


def keep_freed_memory() -> bool:
    """Set glibc's malloc thresholds as above for this process; True when they were set (glibc on
    Linux), False where there is no such allocator (nothing changed)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return all(mallopt(option, value) == 1 for option, value in
               ((M_MMAP_THRESHOLD, MMAP_THRESHOLD), (M_TRIM_THRESHOLD, TRIM_THRESHOLD), (M_TOP_PAD, TOP_PAD)))
