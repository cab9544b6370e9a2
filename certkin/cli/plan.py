"""``certkin plan``: a path whose every segment is certified feasible."""
from __future__ import annotations

import json

from ..engine import budgets
from ..robots import load_robot
from ..trajectory import plan
from .common import constraint_list, options, write_certificate

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


def run(args):
    with options(OPTIONS):
        robot = load_robot(args.robot)
        result = plan(robot, args.start, args.goal, constraints=constraint_list(args.constraints),
                      divisions=args.divisions, max_seconds=args.max_seconds)
        if args.certificate and result.segments:
            write_certificate(args.certificate, result.certificate())
    if args.json:
        print(json.dumps(result.to_json()))
    else:
        print(describe(robot, result))
    return 0


def describe(robot, result):
    lines = [f"{robot.name}: {result.status} [{result.stats.get('edges_verified', 0)} segments verified, "
             f"{result.stats.get('seconds', 0):.2f} s]"]
    for w in result.waypoints:
        lines.append("  " + ",".join(w))
    if result.endpoint:
        lines.append(f"  the {result.endpoint['pose']} pose is {result.endpoint['status']}: " +
                     "; ".join(f"{v['constraint']} {'-'.join(map(str, v['legs']))}" for v in result.endpoint["violations"]))
    return "\n".join(lines)
