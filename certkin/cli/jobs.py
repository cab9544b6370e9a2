"""``certkin jobs grid ROBOT --command ...``: print jobs (JSONL) for ``certkin batch``.

``--command fk --lengths "L1=a:b:n,..."``; ``--command singular --box "x=a:b,..." --cells n``;
``--command trajectory --from "x=a:b,...,z=520,..." --to ... [--count N --seed S]`` (see
``certkin.batch.grid``).  ``--set KEY=VALUE`` adds an option to every job (``max_seconds=5``).
"""
from __future__ import annotations

from ..batch.grid import cell_jobs, fk_jobs, trajectory_jobs
from ..batch.jobs import ID, MAX_JOBS, RESERVED, dumps
from ..errors import InputError, shown
from ..robots import load_robot
from .batch import parse_job
from .common import count

MAX_SEED = 2 ** 63 - 1      # the largest seed that is a signed 64-bit integer (numpy takes any, other tools may not)


def add_arguments(j):
    sub = j.add_subparsers(dest="generator", metavar="grid", required=True, parser_class=type(j))
    g = sub.add_parser("grid", help="a grid (or random draw) of jobs of one command on one robot")
    g.add_argument("robot", help="robot file (TOML), written into every job as given")
    g.add_argument("--command", required=True, choices=["fk", "singular", "trajectory"])
    g.add_argument("--lengths", metavar="L1=a:b:n,...", help="fk: the grid of leg lengths (n values from a to b, ends included; n = 1: the midpoint)")
    g.add_argument("--box", metavar="x=a:b,...", help="singular: the box to cut into cells")
    g.add_argument("--cells", type=count(MAX_JOBS), help="singular: cells per varying variable")
    g.add_argument("--from", dest="start", metavar="x=a:b[:n],...", help="trajectory: start poses")
    g.add_argument("--to", dest="goal", metavar="x=a:b[:n],...", help="trajectory: goal poses")
    g.add_argument("--count", type=count(MAX_JOBS), help=f"trajectory: number of random start/goal pairs (at most {MAX_JOBS})")
    g.add_argument("--seed", type=count(MAX_SEED, least=0),
                   help=f"trajectory: seed of the random draw, 0 to {MAX_SEED} (default 0)")
    g.add_argument("--decimals", type=count(15, least=0),
                   help="trajectory: decimal places of drawn values, 0 to 15 (default 3)")
    g.add_argument("--prefix", help="prefix of the job ids (default: the command)")
    g.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="an option of every job, by its long name (repeatable): max_seconds=5")


NEEDS = {"fk": ("lengths",), "singular": ("box", "cells"), "trajectory": ("start", "goal")}
OPTION = {"lengths": "--lengths", "box": "--box", "cells": "--cells", "start": "--from", "goal": "--to"}


GIVEN_BY = {"id": "--prefix", "command": "--command", "robot": "ROBOT", "lengths": "--lengths", "box": "--box and --cells",
            "from": "--from", "to": "--to"}

MAX_PREFIX = 127 - len(str(MAX_JOBS))    # an id (at most 128 characters): the prefix, '-' and the job's number

GENERATOR = {"fk": "--lengths", "singular": "--box", "trajectory": "--from/--to"}


def _check_job(job: dict, robot, option: str) -> None:
    """Refuse (naming the option at fault, else ``option``) a job the batch would answer with an error:
    its options parsed as the batch parses them, then its command run on them with a budget of one box
    and one cell (bad input is refused before anything is searched).  The first and last jobs of a
    grid hold the ends of every range."""
    try:
        module, args = parse_job(job)
    except InputError as exc:
        raise InputError(option, "", str(exc)) from None
    try:
        args.max_boxes = 1
        if getattr(args, "cells", None):    # one cell (the cell count itself is the batch's to weigh)
            args.cells = None
        module.compute(args, robot)
    except InputError as exc:
        raise InputError(exc.source or option, exc.field, f"{exc.problem} (in job {job['id']}, as certkin batch would "
                                                          "run it)") from None


USED = {"fk": ("lengths",), "singular": ("box", "cells"), "trajectory": ("start", "goal", "count", "seed", "decimals")}


def run(args):
    for name in NEEDS[args.command]:
        if getattr(args, name) is None:
            raise InputError(OPTION[name], "", f"--command {args.command} needs {OPTION[name]}")
    for name, option in {**OPTION, "count": "--count", "seed": "--seed", "decimals": "--decimals"}.items():
        if name not in USED[args.command] and name in getattr(args, "given_options", ()):
            raise InputError(option, "", f"not an option of --command {args.command}")
    if args.prefix is not None and not ID.fullmatch(args.prefix + "-" + "0" * len(str(MAX_JOBS))):
        raise InputError("--prefix", "", f"expected letters, digits, '.', '_' or '-' (a file name; at most "
                                         f"{MAX_PREFIX} characters), got {shown(args.prefix)}")
    if args.prefix is not None and RESERVED.fullmatch(args.prefix + "-0"):
        raise InputError("--prefix", args.prefix, "its ids would be line-N, reserved for the lines of a jobs file "
                                                  "that are not jobs")
    extra = {}
    for item in args.set:
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise InputError("--set", item, "expected KEY=VALUE")
        key = key.strip().replace("-", "_")
        if key in extra:
            raise InputError("--set", item, "set twice")
        extra[key] = True if value.strip() == "true" else value.strip()
    robot = load_robot(args.robot)
    prefix = args.prefix or args.command
    if args.command == "fk":
        jobs = fk_jobs(args.robot, robot, args.lengths, prefix)
    elif args.command == "singular":
        jobs = cell_jobs(args.robot, robot, args.box, args.cells, prefix)
    else:
        jobs = trajectory_jobs(args.robot, robot, args.start, args.goal, args.count, args.seed, args.decimals, prefix)
    for key in extra:                   # what the generator writes (id, command, robot, ...) is not overridden
        if jobs and key in jobs[0]:
            raise InputError("--set", key, "written by the generator"
                             + (f" (from {GIVEN_BY[key]})" if key in GIVEN_BY else "") + ", not by --set")
    for job in ([jobs[0], jobs[-1]] if len(jobs) > 1 else jobs):     # every end of every range, and --set
        _check_job({**job, **extra}, robot, "--set" if extra else GENERATOR[args.command])
    for job in jobs:
        print(dumps({**job, **extra}))
    return 0
