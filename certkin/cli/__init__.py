"""The ``certkin`` command line, one module per command.

Every command prints a human summary, or one JSON document with ``--json``;
``--certificate FILE`` writes the certificate; exit code 0 for an answer
(whatever the verdict), 1 for a certificate that fails to check, 2 for bad
input with one line naming the file or option and the field.  This package is
the only place that parses argv, names options or prints (``common.options``
renames the library's parameters to options in errors).
"""
from __future__ import annotations

import sys

from ..errors import InputError
from . import batch, check, demo, fk, jobs, plan, singular, trajectory, workspace
from .common import Parser, join_pose_values

COMMANDS = (
    ("singular", singular, "prove a box of poses singularity-free, or find a singularity in it"),
    ("fk", fk, "every real assembly mode for given leg lengths, each proved unique"),
    ("trajectory", trajectory, "certify a straight (or polyline) motion, or find where it fails"),
    ("plan", plan, "a path whose every segment is certified feasible"),
    ("workspace", workspace, "constant-orientation workspace: section (exact arcs, area) or volume bracket"),
    ("check", check, "re-verify a certificate with the independent checker"),
    ("batch", batch, "answer a file of jobs (JSONL) on a local pool or a Dask cluster, resumably"),
    ("jobs", jobs, "print jobs (JSONL) for exhaustive campaigns: certkin jobs grid ..."),
    ("demo", demo, "run the seed examples on the bundled robots"),
)


def build_parser():
    p = Parser(prog="certkin", description="Certified answers about parallel robots.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name, module, help_text in COMMANDS:
        s = sub.add_parser(name, help=help_text)
        module.add_arguments(s)
        s.set_defaults(func=module.run)
    return p


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(join_pose_values(list(sys.argv[1:] if argv is None else argv)))
    try:
        return args.func(args)
    except InputError as exc:
        sys.stderr.write(f"certkin: error: {exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("certkin: interrupted\n")
        return 130
