"""What every command shares: the parser, option names for library errors, budgets, outputs.

The command line is the only place that parses argv, names options or prints.  The library names
the *parameter* that took a bad value (``InputError("lengths", "leg 2", ...)``); ``options`` turns
that into the option the user typed (``--lengths: leg 2: ...``), so every error is one line that
names the option and the field.  Every option is checked before any solving starts: numbers and
counts by their types here, output paths by ``check_outputs`` (nothing is written for a run that
fails), conflicting or ignored options by each command.
"""
from __future__ import annotations

import argparse
from contextlib import contextmanager
from dataclasses import dataclass
import os
from pathlib import Path
import re
import sys
import tempfile
from typing import Callable

from ..certificates.writing import atomic_path, replaced_file
from ..engine import Budget, interrupt
from ..engine.budgets import MAX_MEMORY, PHYSICAL, positive_integer, positive_number
from .. import display
from ..errors import InputError, shown
from ..plots.figure import pyplot


class StoreOnce(argparse.Action):
    """The default action of an option that takes one value: given twice, it is an error (not the
    last one silently kept)."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault("given_options", set())
        if self.dest in given:
            parser.error(f"argument {option_string or self.metavar or self.dest}: given twice")
        given.add(self.dest)
        setattr(namespace, self.dest, values)


class FlagOnce(StoreOnce):
    """A flag (``--json``, argparse's ``store_true``): given twice, it is an error, as every repeated option."""

    def __init__(self, option_strings, dest, default=False, required=False, help=None):
        super().__init__(option_strings, dest, nargs=0, const=True, default=default, required=required, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        super().__call__(parser, namespace, True, option_string)


class Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.register("action", None, StoreOnce)
        self.register("action", "store", StoreOnce)
        self.register("action", "store_true", FlagOnce)

    def error(self, message):  # one line, exit 2 (argparse prints usage otherwise)
        sys.stderr.write(f"certkin: error: {message}\n")
        raise SystemExit(2)


@contextmanager
def options(names: dict):
    """Rename the library's parameter in an ``InputError`` to the command's option: ``names`` maps
    parameters to options (``{"lengths": "--lengths"}``; an index suffix ``[k]`` is kept:
    ``waypoints[0]`` → ``--via[0]``).  The budget parameters are renamed on every command.  Other
    errors (a robot file's, an option's) pass unchanged."""
    names = {**BUDGET_OPTIONS, **names}
    try:
        yield
    except InputError as exc:
        base, bracket, rest = exc.source.partition("[")
        if base not in names:
            raise
        raise InputError(names[base] + bracket + rest, exc.field, exc.problem) from None


BUDGET_OPTIONS = {"max_boxes": "--max-boxes", "max_seconds": "--max-seconds", "min_width": "--min-width",
                  "max_memory": "--max-memory"}


def progress(enabled, what="boxes", extra="frontier"):
    """A progress callback ``update(done, value)`` (a bar on stderr counting ``what``, showing
    ``extra=value``; the engine calls it with the boxes processed and the frontier's size), or None."""
    if not enabled:
        return None
    from tqdm import tqdm                 # a bar only with --progress
    try:
        bars = [tqdm(desc=what, unit="", file=sys.stderr, leave=False)]
    except (OSError, ValueError):         # stderr full or closed: the bar is a courtesy, never the answer's end
        bars = []

    def update(done, value):
        for bar in bars:
            try:
                bar.n = done
                bar.set_postfix({extra: value}, refresh=False)
                bar.refresh()
            except (OSError, ValueError):   # (once: an OSError of stderr ended the command, its answer unprinted)
                bars.clear()
    return update


# ----------------------------------------------------------------- option types
def _typed(check):
    """An argparse type from a library check (its ``InputError`` becomes argparse's one-line error)."""
    def convert(text):
        try:
            return check(text)
        except InputError as exc:
            raise argparse.ArgumentTypeError(exc.problem) from None
    convert.__name__ = check.__name__
    return convert


def _integer(text):
    """An integer written in decimal with ASCII digits (``200000``, ``2e5``, ``200_000``)."""
    if not text.isascii():
        raise InputError("", "", f"expected a positive integer, got {shown(text)}")
    try:
        return int(text)
    except ValueError:
        pass
    try:
        x = float(text)
    except ValueError:
        raise InputError("", "", f"expected a positive integer, got {shown(text)}") from None
    if not x.is_integer():
        raise InputError("", "", f"expected a positive integer, got {shown(text)}")
    return int(x)


def count(most=None, least=1):
    """argparse type: an integer from ``least`` (1 or 0) to ``most``; a refused value is quoted as typed."""
    def check(text):
        try:
            value = _integer(text)
            if least == 0 and value == 0:
                return 0
            return positive_integer(value, "", most)
        except InputError:
            bound = f" from {least} to {most}" if most is not None else f" from {least}" if least != 1 else ""
            kind = "a positive integer" if least == 1 else "an integer"
            raise InputError("", "", f"expected {kind}{bound}, got {shown(text)}") from None
    check.__name__ = "count"
    return _typed(check)


positive = _typed(lambda text: positive_number(text, ""))
seconds = _typed(lambda text: positive_number(text, "", infinite=True))

UNITS = {"": 1, "b": 1, "k": 2 ** 10, "kb": 10 ** 3, "kib": 2 ** 10, "m": 2 ** 20, "mb": 10 ** 6, "mib": 2 ** 20,
         "g": 2 ** 30, "gb": 10 ** 9, "gib": 2 ** 30, "t": 2 ** 40, "tb": 10 ** 12, "tib": 2 ** 40,
         "p": 2 ** 50, "pb": 10 ** 15, "pib": 2 ** 50}


def _memory(text):
    """A size in bytes: ``2GiB``, ``512M``, ``1.5G``, ``3000000000``, from 1 MiB to 1 PiB (and at most this
    machine's memory).  Every other value gets the one message that says so."""
    refused = InputError("", "", f"expected a size from 1MiB to 1PiB, a number of bytes or with a unit "
                                 f"(2GiB, 512MiB, 1.5G), got {shown(text)}")
    m = re.fullmatch(r"\s*([0-9.eE+]+)\s*([A-Za-z]*)\s*", text)
    if not m or m.group(2).lower() not in UNITS:
        raise refused
    try:
        size = positive_number(m.group(1), "") * UNITS[m.group(2).lower()]
    except InputError:
        raise refused from None
    if not 2 ** 20 <= size <= 2 ** 50:
        raise refused
    if PHYSICAL is not None and size > PHYSICAL:
        raise InputError("", "", f"{shown(text)} is more than this machine's memory "
                                 f"({display.size_bound(PHYSICAL, up=False)})")
    return int(size)


memory = _typed(_memory)


def budget(args):
    return Budget(max_boxes=args.max_boxes, max_seconds=args.max_seconds, min_width=args.min_width,
                  max_memory=args.max_memory)


SECONDS_HELP = "time budget of the whole command's solving (the pictures of --plot and --report are drawn after it)"


def add_budget(p, default, boxes_help="box budget", seconds_help=SECONDS_HELP,
               width_help="smallest scaled box width that is still split"):
    boxes, secs, width = default["max_boxes"], default["max_seconds"], default["min_width"]
    p.add_argument("--max-boxes", type=count(), default=boxes, metavar="N", help=f"{boxes_help} (default {boxes})")
    p.add_argument("--max-seconds", type=seconds, default=secs, metavar="S",
                   help=f"{seconds_help} (default {secs:g}; inf: no time limit, the other budgets still bound the work)")
    p.add_argument("--min-width", type=positive, default=width, metavar="W", help=f"{width_help} (default {width:g})")
    p.add_argument("--max-memory", type=memory, default=MAX_MEMORY, metavar="SIZE",
                   help="memory ceiling of the work (the search records and the answer built from them; the "
                        "process's start-up, about 0.1 to 0.2 GB, comes on top), e.g. 512MiB (default 2GiB): "
                        "work that would need more is refused or ends undecided")


def add_outputs(p, certificate_help="write the certificate to FILE"):
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--certificate", metavar="FILE", help=certificate_help)
    p.add_argument("--report", metavar="FILE.html", help="write a self-contained HTML report")
    p.add_argument("--progress", action="store_true", help="show progress on stderr")


def report_writer(name: str):
    """The function ``name`` of ``certkin.report``, imported when a report is asked for: the report
    modules and their plots would cost every command about 20 ms of start-up."""
    from .. import report
    return getattr(report, name)


# ----------------------------------------------------------------- output paths
REPORT_SUFFIXES = (".html", ".htm")


def plot_suffixes():
    """The file types matplotlib can write (``InputError`` when it is not installed)."""
    pyplot()
    from matplotlib.figure import Figure
    return tuple("." + k for k in Figure().canvas.get_supported_filetypes())


def check_output_path(path, option: str, suffixes=None, parent: bool = True) -> None:
    """Before solving: ``path`` can be written (its directory exists and is writable, it is not a
    directory nor a device, a pipe or a socket, it has one of ``suffixes`` if given); else
    ``InputError`` naming ``option``.
    ``parent=False``: the directory is made by the run itself (not checked)."""
    p = Path(path)
    if not str(path).strip():
        raise InputError(option, "", "empty file name")
    if str(path) == "-":
        raise InputError(option, "-", "a file name is needed ('-' is not standard output here)")
    if p.is_dir():
        raise InputError(option, str(path), "is a directory; give a file name")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise InputError(option, str(path), f"unknown file type {p.suffix or '(none)'!r}; use one of "
                                            f"{', '.join(suffixes)}")
    try:
        replaced_file(p)                     # /dev/null, a pipe: refused
    except OSError as exc:
        raise InputError(option, str(path), exc.strerror) from None
    if not parent:
        return
    parent = p.parent
    if not parent.is_dir():
        raise InputError(option, str(path), f"directory {str(parent)!r} does not exist")
    try:                                  # a file can be created there (a trial, removed at once)
        with tempfile.TemporaryFile(dir=parent):
            pass
    except OSError as exc:
        raise InputError(option, str(path), f"cannot write in directory {str(parent)!r} ({exc.strerror})") from None
    if p.exists() and not os.access(p, os.W_OK):
        raise InputError(option, str(path), "file exists and cannot be written")


def check_output_directory(path, option: str) -> None:
    """Before running: ``path`` is a directory that exists and can be written, or can be created in
    one that does (its parent is not created); else ``InputError`` naming ``option``."""
    if not str(path).strip():
        raise InputError(option, "", "empty directory name")
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise InputError(option, str(path), "exists and is not a directory")
    where = p if p.is_dir() else p.parent
    if not where.is_dir():
        raise InputError(option, str(path), f"directory {str(where)!r} does not exist")
    try:
        with tempfile.TemporaryFile(dir=where):
            pass
    except OSError as exc:
        raise InputError(option, str(path), f"cannot write in directory {str(where)!r} ({exc.strerror})") from None


def check_outputs(args, **more) -> None:
    """Check every output path of a command before solving (``--certificate``, ``--report``,
    ``--plot``, and ``more``: option -> (path, suffixes)), and that no two name one file."""
    wanted = {"--certificate": (getattr(args, "certificate", None), None),
              "--report": (getattr(args, "report", None), REPORT_SUFFIXES),
              **more}
    plot = getattr(args, "plot", None)
    if plot is not None:
        wanted["--plot"] = (plot, "plot")
    seen = {}
    robot = getattr(args, "robot", None)
    for option, (path, suffixes) in wanted.items():
        if path is None:
            continue
        check_output_path(path, option, plot_suffixes() if suffixes == "plot" else suffixes)
        key = os.path.abspath(path)
        if key in seen:
            raise InputError(option, str(path), f"the same file as {seen[key]}")
        seen[key] = option
        if isinstance(robot, str) and _same_file(path, robot):
            raise InputError(option, str(path), "the robot file itself (writing there would replace it)")


def _same_file(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:                 # one of them does not exist (yet): not the same file
        return False


# ----------------------------------------------------------------- answers
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
    per job.  ``document`` may be given as a function: it is then computed only when asked for
    (a classification of many cells builds its JSON only for ``--json`` or a batch)."""

    robot: object
    result: object
    document_source: dict | Callable[[], dict]
    describe: Callable[[], str]
    certificate: Callable[[], object] | None = None     # a certificates.Document; None: no certificate
    report: Callable[[str, str | None], None] | None = None     # (path, certificate file or None)
    plot: Callable[[str], None] | None = None

    @property
    def document(self) -> dict:
        if callable(self.document_source):
            self.document_source = self.document_source()
        return self.document_source


class NotWritten(InputError):
    """An output file (``--certificate``, ``--report``, ``--plot``) that could not be written (a full
    disk, an I/O error): the answer computed is still printed."""


@contextmanager
def writing(option: str, path):
    """Turn an ``OSError`` of the block, which writes ``path`` for ``option``, into ``NotWritten``
    naming the option, the path and the system's reason."""
    try:
        yield
    except OSError as exc:
        raise NotWritten(option, "", f"cannot write {path}: {exc.strerror or exc}") from None


@contextmanager
def writing_in(option: str, directory):
    """``writing`` for a block that writes files in ``directory`` (``--out``): the error names the file."""
    try:
        yield
    except OSError as exc:
        where = exc.filename if exc.filename is not None else directory
        raise NotWritten(option, "", f"cannot write {where}: {exc.strerror or exc}") from None


def write_certificate(path, document):
    """Write ``--certificate`` (atomically: nothing half-written); a directory or an unwritable path is
    bad input (exit 2, one line).  What ``Document.write`` returns: (size, SHA-256) of a small file."""
    if os.path.isdir(path):
        raise InputError("--certificate", "", f"{path} is a directory")
    with writing("--certificate", path):
        return document.write(path)


def write_outputs(args, answer: Answer) -> None:
    """Write the files the options ask for: ``--certificate``, ``--report``, ``--plot``."""
    written = None
    if getattr(args, "certificate", None) and answer.certificate is not None:
        write_certificate(args.certificate, answer.certificate())
        written = args.certificate
    if getattr(args, "report", None) and answer.report is not None:
        with writing("--report", args.report):
            answer.report(args.report, written)     # (never a file an earlier run left at that name)
    if getattr(args, "plot", None) and answer.plot is not None:
        with writing("--plot", args.plot), atomic_path(args.plot) as path:
            answer.plot(path)


def show(args, answer: Answer, out=None) -> int:
    """Write the outputs of an answer, then print its JSON document (``--json``) or its description
    (on ``out``, default stdout).  An output that cannot be written (``NotWritten``) is raised after
    the answer is printed: a full disk does not lose what was proved."""
    try:
        write_outputs(args, answer)
    except NotWritten:
        _print(args, answer, out)
        raise
    _print(args, answer, out)
    return 0


def _print(args, answer: Answer, out=None) -> None:
    text = display.json_text(answer.document) if args.json else answer.describe()
    write_text_out(out or sys.stdout, text + "\n")


PIECE = 1 << 16


def write_text_out(stream, text: str) -> None:
    """``stream.write(text)`` in pieces of 64 KiB: a reader that goes away (``| head -c 10``) is then
    seen (``BrokenPipeError``, exit 141); one large write loses the rest of the text without an error
    when the pipe closes after its first part (CPython's buffered writer)."""
    for k in range(0, len(text), PIECE):
        stream.write(text[k:k + PIECE])


def run_answer(args, compute, names: dict, out=None) -> int:
    """``compute(args)``, then write and print its answer.  Ctrl-C while it computes stops the
    searches (``engine.interrupt``): the answer proved so far is written (a partial certificate
    that still checks) and printed, marked interrupted, and the exit code is 130."""
    with interrupt.interruptible():         # (also while the answer is built and written: a first Ctrl-C
        answer = compute(args)              # there leaves it whole; a second one aborts)
        stopped = interrupt.cut_short()
        if stopped:
            source = answer.document_source
            answer.document_source = (lambda: {**(source() if callable(source) else source), "interrupted": True})
            describe = answer.describe
            answer.describe = lambda: ("INTERRUPTED (Ctrl-C): what was proved before the interrupt; the boxes "
                                       "not finished are undecided\n" + describe())
        with options(names):
            show(args, answer, out)
        late = interrupt.requested() and not stopped        # Ctrl-C once the searches had ended
    if late:        # the answer is whole: printed and written as the searches left it
        sys.stderr.write("certkin: Ctrl-C came after the searches had ended: the answer above is theirs, "
                         "unchanged\n")
    return 130 if stopped or late else 0


def refuse(args, option: str, reason: str, *given: str) -> None:
    """An option given where it has no effect, or with one it conflicts with, is an error: ``given``
    names the attributes of ``args`` that must not be set (``reason`` says why)."""
    for name in given:
        value = getattr(args, name, None)
        if value is not None and value is not False:
            raise InputError(option, "", reason)


NEGATIVE = re.compile(r"-(?:[0-9.]|inf|nan)", re.IGNORECASE)      # -1, -.5, -inf, -nan: a value, not an option


def join_negative_values(argv):
    """``--from -69,-50,...``, ``--z-range -20010:-20000``: after a long option, a value that starts
    with '-' then a digit, '.', 'inf' or 'nan' is that option's value, not an option (argparse would refuse it)."""
    out, i = [], 0
    while i < len(argv):
        a = argv[i]
        if a.startswith("--") and "=" not in a and i + 1 < len(argv) and NEGATIVE.match(argv[i + 1]):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out
