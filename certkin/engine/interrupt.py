"""Ctrl-C as one more budget: the search stops, and what it proved so far stays proved.

Inside ``interruptible()`` (the command line wraps each long command in it), the first Ctrl-C only
asks the searches to stop: every search checks ``requested()`` before each batch, like its time
budget, and leaves its open boxes ``undecided`` (reason ``interrupted``), so the answer, its
certificate and its report are those of an exhausted budget: sound, checkable, incomplete.  A
second Ctrl-C raises ``KeyboardInterrupt`` as usual.  Outside the main thread nothing changes.
"""
from __future__ import annotations

from contextlib import contextmanager
import signal
import threading

_STATE = {"requested": False, "cut": False}


def requested() -> bool:
    """Whether Ctrl-C asked the searches to stop."""
    return _STATE["requested"]


def cut() -> None:
    """Note that a search stopped with boxes left because of the request."""
    _STATE["cut"] = True


def cut_short() -> bool:
    """Whether a search left boxes undecided because of Ctrl-C (an answer cut short)."""
    return _STATE["cut"]


def request() -> None:
    """Ask every search to stop (what the first Ctrl-C does)."""
    _STATE["requested"] = True


@contextmanager
def interruptible():
    """While active, the first Ctrl-C calls ``request()`` instead of raising ``KeyboardInterrupt``."""
    _STATE["requested"] = _STATE["cut"] = False
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        if _STATE["requested"]:
            raise KeyboardInterrupt
        request()
    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        _STATE["requested"] = False     # later searches in this process (the API, a test) run in full;
                                        # ``cut_short()`` still tells what happened inside
