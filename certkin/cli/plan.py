"""``certkin plan``: a path whose every segment is certified feasible."""
from __future__ import annotations

from ..engine import budgets
from ..report import plan_report
from ..robots import load_robot
from ..trajectory import plan
from .common import Answer, constraint_list, options, run_answer

OPTIONS = {"start": "--from", "goal": "--to", "constraints": "--constraints"}


def add_arguments(pl):
    pl.add_argument("robot", help="robot file (TOML)")
    pl.add_argument("--from", dest="start", required=True, metavar="POSE")
    pl.add_argument("--to", dest="goal", required=True, metavar="POSE")
    pl.add_argument("--constraints", metavar="LIST", help="as for trajectory (default: all)")
    pl.add_argument("--divisions", type=int, default=6, help="grid steps between start and goal (default 6)")
    pl.add_argument("--max-seconds", type=float, default=budgets.PLAN_SECONDS,
                    help=f"time budget (default {budgets.PLAN_SECONDS:g})")
    pl.add_argument("--json", action="store_true", help="print one JSON document")
    pl.add_argument("--certificate", metavar="FILE", help="write the certificate of every segment to FILE")
    pl.add_argument("--report", metavar="FILE.html", help="write a self-contained HTML report")


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin plan`` (``robot``: the robot file already loaded, else ``args.robot``);
    a certificate only when the plan has segments."""
    with options(OPTIONS):
        robot = robot or load_robot(args.robot)
        result = plan(robot, args.start, args.goal, constraints=constraint_list(args.constraints),
                      divisions=args.divisions, max_seconds=args.max_seconds)
    return Answer(robot, result, result.to_json(), lambda: describe(robot, result),
                  result.certificate if result.segments else None,
                  lambda path, cert: plan_report(robot, result, path, cert))


def run(args):
    return run_answer(args, compute, OPTIONS)


def describe(robot, result):
    lines = [f"{robot.name}: {result.status} [{result.stats.get('edges_verified', 0)} segments verified, "
             f"{result.stats.get('seconds', 0):.2f} s]"]
    for w in result.waypoints:
        lines.append("  " + ",".join(w))
    if result.endpoint:
        lines.append(f"  the {result.endpoint['pose']} pose is {result.endpoint['status']}: " +
                     "; ".join(f"{v['constraint']} {'-'.join(map(str, v['legs']))}" for v in result.endpoint["violations"]))
    return "\n".join(lines)
