"""The ``certkin`` command line, one module per command.

Every command prints a human summary, or one JSON document with ``--json``;
``--certificate FILE`` writes the certificate; exit code 0 for an answer
(whatever the verdict), 1 for a certificate that fails to check, 2 for bad
input with one line naming the file or option and the field.  This package is
the only place that parses argv, names options or prints (``common.options``
renames the library's parameters to options in errors).
"""
from __future__ import annotations

import importlib
import os
import sys
import warnings

import numpy as np

from ..allocator import keep_freed_memory
from ..display import printable
from ..errors import InputError
from .common import Parser, join_negative_values

# command -> (module of its options and its run, help); a command's module (and the capability it
# uses) is imported only when that command runs, so `certkin check` does not load the FK kernels
COMMANDS = {
    "singular": ("certkin.cli.singular", "prove a box of poses singularity-free, or find a singularity in it"),
    "fk": ("certkin.cli.fk", "every real assembly mode for given leg lengths, each proved unique"),
    "trajectory": ("certkin.cli.trajectory", "certify a straight (or polyline) motion, or find where it fails"),
    "plan": ("certkin.cli.plan", "a path whose every segment is certified feasible"),
    "workspace": ("certkin.cli.workspace",
                  "constant-orientation workspace: section (exact arcs, area) or volume bracket"),
    "check": ("certkin.cli.check", "re-verify a certificate with the independent checker"),
    "batch": ("certkin.cli.batch", "answer a file of jobs (JSONL) on a local pool or a Dask cluster, resumably"),
    "jobs": ("certkin.cli.jobs", "print jobs (JSONL) for exhaustive campaigns: certkin jobs grid ..."),
    "demo": ("certkin.cli.demo", "run the seed examples on the bundled robots"),
}


def build_parser(only: str | None = None):
    """The parser of every command (``only``: the options of that command alone are loaded)."""
    p = Parser(prog="certkin", description="Certified answers about parallel robots.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name, (module_name, help_text) in COMMANDS.items():
        s = sub.add_parser(name, help=help_text)
        if only is None or name == only:
            module = importlib.import_module(module_name)
            module.add_arguments(s)
            s.set_defaults(func=module.run)
    return p


def main(argv=None):
    if sys.stderr is None:                   # closed (`2>&-`): messages go nowhere, the exit code still tells
        sys.stderr = open(os.devnull, "w")
    if sys.stdout is None:                   # closed (`>&-`): once an AttributeError after the whole search
        sys.stderr.write("certkin: error: standard output is closed: nowhere to print the answer\n")
        return 2
    argv = join_negative_values(list(sys.argv[1:] if argv is None else argv))
    command = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(command if command in COMMANDS else "")
    args = parser.parse_args(argv)
    keep_freed_memory()                      # a process of its own: freed arrays stay for the next batch
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")          # numpy's overflow warnings are not for the user
            code = args.func(args)
            sys.stdout.flush()                       # (a full disk under stdout fails here, not at exit)
            return code
    except InputError as exc:
        sys.stderr.write(f"certkin: error: {printable(str(exc))}\n")
        return 2
    except MemoryError:
        sys.stderr.write("certkin: error: out of memory: lower the budget (--max-boxes, --max-memory) or the size "
                         "of the question\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("certkin: interrupted\n")
        return 130
    except BrokenPipeError:               # the reader of stdout went away (`certkin ... | head`)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())    # so that the exit's flush is quiet
        return PIPE_CLOSED
    except OSError as exc:                # a full disk, an I/O error: output paths were checked before
        where = exc.filename if exc.filename is not None else "standard output"
        if exc.filename is None:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.stderr.write(f"certkin: error: {printable(str(where))}: {exc.strerror or exc}\n")
        return 2


PIPE_CLOSED = 141        # 128 + SIGPIPE, as a shell reports a command whose output pipe closed
