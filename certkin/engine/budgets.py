"""Budgets: how much work a search may do, and every default of the API and the command line.

A budget that runs out gives ``undecided`` (never a guess).  The FK default lets Dietmaier's
40-posture robot finish (~2.5 M boxes); past ``FK_RECORD_NODES`` tree nodes the search forgets
its excluded leaves, so memory stays below 1 GiB.  The workspace's ``min_width`` is relative to
the size of the section (``workspace.paving``).

``max_seconds`` bounds the solving of a whole call (a command, an API function), whatever number
of searches it runs; loading a robot's model comes on top.  ``max_memory`` bounds what the
solvers allocate for their records (the search tree, the cells of a classification): a search
that reaches it stops with ``undecided``, and work that would need more is refused before it
starts; it may not exceed this machine's memory (the default: 2 GiB, or the machine's memory if
less).  Every value is checked: a bad one raises ``InputError`` naming the parameter (so is a
``progress`` that is neither None nor callable: ``progress_callback``).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
import math
import os
import time

from ..errors import InputError, shown

GiB = 2 ** 30


def physical_memory() -> int | None:
    """Bytes of memory of this machine (None where the system does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


PHYSICAL = physical_memory()
MAX_MEMORY = min(2 * GiB, PHYSICAL or 2 * GiB)      # default memory ceiling (bytes)
MAX_BOXES = 2 ** 53                         # a larger box budget is this one (no search decides as many)
MAX_BYTES = 2 ** 53                         # where the machine's memory is unknown, a larger memory budget is this one


@dataclass(frozen=True)
class Budget:
    """A search's budget, checked when made and fixed afterwards (``dataclasses.replace`` makes another)."""

    max_boxes: int = 200_000                # boxes decided (all roots together)
    max_seconds: float = 60.0               # seconds of solving (math.inf: no limit)
    min_width: float = 1e-9                 # scaled width under which a box is not split
    max_memory: int = MAX_MEMORY            # bytes of search records

    def __post_init__(self):
        for name in ("max_boxes", "max_seconds", "min_width", "max_memory"):
            if isinstance(getattr(self, name), (str, bytes)):     # (the command line converts its texts first)
                unit = " of bytes (512 MiB: 512 * 2**20; the command line's --max-memory reads units)" \
                    if name == "max_memory" else ""
                raise InputError(name, "", f"expected a number{unit}, got the text {shown(getattr(self, name))}")
        for name, check in (("max_boxes", positive_integer), ("max_memory", positive_integer),
                            ("min_width", positive_number)):
            object.__setattr__(self, name, check(getattr(self, name), name))
        object.__setattr__(self, "max_boxes", min(self.max_boxes, MAX_BOXES))    # (the searches count in int64)
        if PHYSICAL is not None and self.max_memory > PHYSICAL:
            raise InputError("max_memory", "", f"{self.max_memory} bytes is more than this machine's memory "
                                               f"({PHYSICAL} bytes)")
        object.__setattr__(self, "max_memory", min(self.max_memory, MAX_BYTES))  # (and shares of it are floats)
        object.__setattr__(self, "max_seconds", positive_number(self.max_seconds, "max_seconds", infinite=True))

    def within(self, seconds_left: float) -> Budget:
        """This budget with at most ``seconds_left`` seconds (never less than a millisecond, so a
        search still decides its first batch and says ``undecided`` for the rest)."""
        return replace(self, max_seconds=max(min(self.max_seconds, seconds_left), 1e-3))


def positive_integer(value, parameter: str, most: int | None = None) -> int:
    """An integer >= 1 (and <= ``most``); bools, floats with a fraction, nan and text are refused."""
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    try:
        if isinstance(value, bool) or not isinstance(value, int) and not hasattr(value, "__index__"):
            raise TypeError
        value = int(value)
    except TypeError:                   # (np.array([5]) has __index__, and int() of it raises TypeError)
        raise InputError(parameter, "", f"expected a positive integer, got {shown(value)}") from None
    if value < 1 or (most is not None and value > most):
        bound = f" from 1 to {most}" if most is not None else ""
        raise InputError(parameter, "", f"expected a positive integer{bound}, got {value}")
    return value


def positive_number(value, parameter: str, infinite: bool = False) -> float:
    """A number > 0 (finite unless ``infinite``); bools, nan and text are refused."""
    if isinstance(value, (bool, bytes, bytearray)) or isinstance(value, str) and not value.isascii():
        raise InputError(parameter, "", f"expected a positive number, got {shown(value)}")  # (float() reads '１', b'1')
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(parameter, "", f"expected a positive number, got {shown(value)}") from None
    except OverflowError:               # an int or a Fraction past the floats: as large as a float gets
        x = math.inf if value > 0 else -math.inf
    if math.isnan(x) or x <= 0 or (math.isinf(x) and not infinite):
        raise InputError(parameter, "", f"expected a positive{'' if infinite else ' finite'} number, got {shown(value)}")
    return x


def make_budget(defaults: dict, budget: Budget | None = None, *, max_boxes=None, max_seconds=None,
                min_width=None, max_memory=None) -> Budget:
    """The budget of an API call: ``budget`` (or ``defaults``) with the keywords given overriding it."""
    base = budget if budget is not None else Budget(**defaults)
    if not isinstance(base, Budget):
        raise InputError("budget", "", f"expected a certkin.Budget, got {type(base).__name__}")
    given = {k: v for k, v in (("max_boxes", max_boxes), ("max_seconds", max_seconds), ("min_width", min_width),
                               ("max_memory", max_memory)) if v is not None}
    return replace(base, **given) if given else base


def progress_callback(progress):
    """``progress`` itself if it is None or callable; anything else is refused up front
    (``InputError`` naming ``progress``), before a robot is loaded or a search runs."""
    if progress is None or callable(progress):
        return progress
    raise InputError("progress", "", f"expected None or a callable (called as the work goes on), got {shown(progress)}")


class Clock:
    """The time left of one call's ``max_seconds``, shared by the searches it runs."""

    def __init__(self, max_seconds: float):
        self.t0 = time.perf_counter()
        self.max_seconds = max_seconds

    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def left(self) -> float:
        return self.max_seconds - self.elapsed()

    def out(self) -> bool:
        return self.left() <= 0


SINGULARITY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-7)
LARGEST_FREE_BOX = dict(max_boxes=20_000, max_seconds=60.0, min_width=1e-7)   # boxes: each box tried by the bisection on s
FORWARD_KINEMATICS = dict(max_boxes=4_000_000, max_seconds=300.0, min_width=1e-10)
FK_RECORD_NODES = 2_000_000                 # beyond this many tree nodes an FK search keeps only what its answer
                                            # needs (``engine.search`` record_limit); writing a certificate, it
                                            # hands the rest to temporary files (``certificates.segments``)
FK_BOXES_PER_INSTANCE = 20_000              # a batch of M instances may decide max(max_boxes, this × M) boxes
TRAJECTORY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-9)
PLAN = dict(max_boxes=50_000, max_seconds=120.0, min_width=1e-9)              # boxes: each batch of segments verified
WORKSPACE = dict(max_boxes=1_000_000, max_seconds=60.0, min_width=1e-3)
