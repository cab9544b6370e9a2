"""What every command shares: the parser, option names for library errors, budgets, outputs.

The command line is the only place that parses argv, names options or prints.  The library names
the *parameter* that took a bad value (``InputError("lengths", "leg 2", ...)``); ``options`` turns
that into the option the user typed (``--lengths: leg 2: ...``), so every error is one line that
names the option and the field.
"""
from __future__ import annotations

import argparse
from contextlib import contextmanager
from dataclasses import dataclass
import json
import sys
from typing import Callable

from tqdm import tqdm

from ..certificates import write_json
from ..engine import Budget, interrupt
from ..errors import InputError


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage otherwise)
        sys.stderr.write(f"certkin: error: {message}\n")
        raise SystemExit(2)


@contextmanager
def options(names: dict):
    """Rename the library's parameter in an ``InputError`` to the command's option: ``names`` maps
    parameters to options (``{"lengths": "--lengths"}``; an index suffix ``[k]`` is kept:
    ``waypoints[0]`` → ``--via[0]``).  Other errors (a robot file's, an option's) pass unchanged."""
    try:
        yield
    except InputError as exc:
        base, bracket, rest = exc.source.partition("[")
        if base not in names:
            raise
        raise InputError(names[base] + bracket + rest, exc.field, exc.problem) from None


def progress(enabled):
    """A progress callback for the engine (a bar on stderr), or None."""
    if not enabled:
        return None
    bar = tqdm(desc="boxes", unit="box", file=sys.stderr, leave=False)

    def update(processed, frontier):
        bar.n = processed
        bar.set_postfix(frontier=frontier, refresh=False)
        bar.refresh()
    return update


def budget(args):
    return Budget(max_boxes=args.max_boxes, max_seconds=args.max_seconds, min_width=args.min_width)


def add_budget(p, default):
    boxes, seconds, width = default["max_boxes"], default["max_seconds"], default["min_width"]
    p.add_argument("--max-boxes", type=int, default=boxes, help=f"box budget (default {boxes})")
    p.add_argument("--max-seconds", type=float, default=seconds, help=f"time budget (default {seconds})")
    p.add_argument("--min-width", type=float, default=width,
                   help=f"smallest scaled box width that is still split (default {width})")


def add_outputs(p):
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--certificate", metavar="FILE", help="write the certificate to FILE")
    p.add_argument("--report", metavar="FILE.html", help="write a self-contained HTML report")
    p.add_argument("--progress", action="store_true", help="show progress on stderr")


def with_angles(robot, angles):
    """A spherical robot with the pose angles of ``--angles``."""
    if angles is None:
        return robot
    if robot.kind != "spherical-3dof":
        raise InputError("--angles", "", f"only spherical-3dof robots take --angles (this one is {robot.kind})")
    return robot.with_angles(angles)


@dataclass
class Answer:
    """What a command computed, before anything is written or printed: the robot, the result (or
    results), the ``--json`` document, and how to describe, certify, report and plot it.  ``run``
    writes and prints it (``show``); ``certkin batch`` writes the same document and certificate
    per job."""

    robot: object
    result: object
    document: dict
    describe: Callable[[], str]
    certificate: Callable[[], dict] | None = None       # None: no certificate for this answer
    report: Callable[[str, str | None], None] | None = None     # (path, certificate file or None)
    plot: Callable[[str], None] | None = None


def write_certificate(path, answer: Answer) -> None:
    """The certificate of an answer, written to ``path`` (the one writer of the commands and the batch)."""
    write_json(path, answer.certificate())


def write_outputs(args, answer: Answer) -> None:
    """Write the files the options ask for: ``--certificate``, ``--report``, ``--plot``."""
    if getattr(args, "certificate", None) and answer.certificate is not None:
        write_certificate(args.certificate, answer)
    if getattr(args, "report", None) and answer.report is not None:
        answer.report(args.report, getattr(args, "certificate", None))
    if getattr(args, "plot", None) and answer.plot is not None:
        answer.plot(args.plot)


def show(args, answer: Answer, out=None) -> int:
    """Write the outputs of an answer, then print its JSON document (``--json``) or its description
    (on ``out``, default stdout)."""
    write_outputs(args, answer)
    (out or sys.stdout).write((json.dumps(answer.document) if args.json else answer.describe()) + "\n")
    return 0


def run_answer(args, compute, names: dict, out=None) -> int:
    """``compute(args)``, then write and print its answer.  Ctrl-C while it computes stops the
    searches (``engine.interrupt``): the answer proved so far is written (a partial certificate
    that still checks) and printed, marked interrupted, and the exit code is 130."""
    with interrupt.interruptible():
        answer = compute(args)
    stopped = interrupt.cut_short()
    if stopped:
        answer.document["interrupted"] = True
        describe = answer.describe
        answer.describe = lambda: ("INTERRUPTED (Ctrl-C): what was proved before the interrupt; the boxes "
                                   "not finished are undecided\n" + describe())
    with options(names):
        show(args, answer, out)
    return 130 if stopped else 0


def constraint_list(text):
    if not text:
        return None
    return [c.strip() for c in text.split(",") if c.strip()]


POSE_OPTIONS = ("--from", "--to", "--via", "--track", "--around", "--lengths")


def join_pose_values(argv):
    """``--from -69,-50,...``: a pose that starts with '-' is a value, not an option."""
    out, i = [], 0
    while i < len(argv):
        a = argv[i]
        if a in POSE_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-") and argv[i + 1][1:2].isdigit() | (argv[i + 1][1:2] == "."):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out
