"""``certkin plan``: a path whose every segment is certified feasible."""
from __future__ import annotations

import sys

from .. import display
from ..engine import budgets
from ..robots import load_robot
from ..trajectory import plan
from .common import (Answer, add_budget, add_outputs, budget, check_outputs, count, options, progress, report_writer,
                     run_answer)

OPTIONS = {"start": "--from", "goal": "--to", "constraints": "--constraints", "divisions": "--divisions",
           "margin": "--margin", "max_edges": "--max-edges"}


def add_arguments(pl):
    pl.add_argument("robot", help="robot file (TOML)")
    pl.add_argument("--from", dest="start", required=True, metavar="POSE")
    pl.add_argument("--to", dest="goal", required=True, metavar="POSE")
    pl.add_argument("--constraints", metavar="LIST", help="as for trajectory (default: all)")
    pl.add_argument("--divisions", type=count(1000), default=6, metavar="N",
                    help="grid steps between start and goal, 1 to 1000 (default 6)")
    pl.add_argument("--margin", type=count(1000, least=0), default=3, metavar="N", help="grid steps beyond them, 0 to 1000 (default 3)")
    pl.add_argument("--max-edges", type=count(10 ** 9), default=4000, metavar="N",
                    help="grid segments verified at most, with the straight one (default 4000; the shortcuts of "
                         "a path found come on top)")
    add_outputs(pl, "write the certificate of every segment of the path found to FILE")
    add_budget(pl, budgets.PLAN, boxes_help="box budget of each batch of segments verified")


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin plan`` (``robot``: the robot file already loaded, else ``args.robot``);
    a certificate only when the plan has segments."""
    with options(OPTIONS):
        robot = robot or load_robot(args.robot)
        result = plan(robot, args.start, args.goal, constraints=args.constraints,
                      divisions=args.divisions, margin=args.margin, max_edges=args.max_edges, budget=budget(args),
                      progress=progress(args.progress, "segments verified", "batch"))
    return Answer(robot, result, result.to_json(), lambda: describe(robot, result),
                  result.certificate if result.segments else None,
                  lambda path, cert: report_writer("plan_report")(robot, result, path, cert, budget(args)))


def run(args):
    check_outputs(args)

    def answer(args):
        a = compute(args)
        if args.certificate and a.certificate is None:     # a note on stderr: no path, no certificate
            sys.stderr.write(f"certkin: {a.result.status}: no certificate written to {args.certificate}\n")
        return a
    return run_answer(args, answer, OPTIONS)


def describe(robot, result):
    lines = [f"{robot.name}: {result.status} [{display.counted(result.stats.get('edges_verified', 0), 'segment')} verified, "
             f"{result.stats.get('seconds', 0):.2f} s]"]
    for w in result.waypoints:
        lines.append("  " + ",".join(w))
    for k, why in result.constraints.unchecked() if result.constraints is not None else ():
        lines.append(f"  not checked: {k} ({why})")
    if result.endpoint:
        lines.append(f"  the {result.endpoint['pose']} pose is {result.endpoint['status']}: {result.failing}")
    stopped = result.stats.get("stopped")
    if stopped:
        lines.append("  " + STOPPED[stopped])
    if result.stats.get("narrow"):
        names = ", ".join(result.stats["narrow"])
        lines.append(f"  note: start and goal differ only a little in {names}: the grid moves there only between "
                     "the two values, so it cannot go around an obstacle in that direction; give both poses the "
                     "same value there (or values further apart)")
    return "\n".join(lines)


STOPPED = {"time": "the time budget ran out (--max-seconds): a longer run may find a path",
           "max-edges": "the segment budget ran out (--max-edges): a larger one may find a path",
           "interrupted": "stopped by Ctrl-C",
           "grid": "every segment of the grid reachable from the start was tried: a finer grid (--divisions) or a "
                   "wider one (--margin) may find a path",
           "undecided": "the end pose could not be decided within the budget (--min-width, --max-boxes)"}
