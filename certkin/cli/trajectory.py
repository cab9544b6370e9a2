"""``certkin trajectory``: certify a straight (or polyline) motion, or find where it fails."""
from __future__ import annotations

from .. import display
from ..engine import budgets
from ..robots import load_robot
from ..trajectory import verify_trajectory
from .common import Answer, add_budget, add_outputs, budget, check_outputs, options, progress, report_writer, run_answer

OPTIONS = {"start": "--from", "goal": "--to", "waypoints": "--via", "constraints": "--constraints"}


def add_arguments(t):
    t.add_argument("robot", help="robot file (TOML)")
    t.add_argument("--from", dest="start", required=True, metavar="POSE", help="start pose, e.g. -69,-50,500,85deg,10deg,0")
    t.add_argument("--to", dest="goal", required=True, metavar="POSE", help="goal pose")
    t.add_argument("--via", action="append", metavar="POSE", help="intermediate pose (repeatable): a polyline")
    t.add_argument("--constraints", metavar="LIST",
                   help="comma-separated subset of leg-length,joints,interference,singularity (default: all)")
    add_outputs(t)
    add_budget(t, budgets.TRAJECTORY, boxes_help="budget of t-intervals")


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin trajectory`` (``robot``: the robot file already loaded, else ``args.robot``)."""
    with options(OPTIONS):
        robot = robot or load_robot(args.robot)
        result = verify_trajectory(robot, args.start, args.goal, waypoints=list(args.via or []),
                                   constraints=args.constraints, budget=budget(args), progress=progress(args.progress))
    return Answer(robot, result, result.to_json(), lambda: describe(robot, result), result.certificate,
                  lambda path, cert: report_writer("trajectory_report")(robot, result, path, cert, budget(args)))


def run(args):
    check_outputs(args)
    return run_answer(args, compute, OPTIONS)


SHOWN = 20      # ranges of each kind (violated, may fail, undecided) listed on the terminal (all of them in --json)


def describe(robot, r):
    """The verdict, each certified minimum margin and each forbidden t-range, printed outward (an
    enclosure); a feasible path's margins are lower bounds that hold along the whole path.  A
    forbidden range holds every failing instant of its run (VIOLATED: a violation in it is proved),
    it is not claimed to fail throughout."""
    j = r.to_json()
    lines = [f"{robot.name}: {r.status.upper()} [{j['stats']['boxes']} boxes, {j['stats']['seconds']:.3f} s]"]
    for k, why in r.constraints.unchecked():
        lines.append(f"  not checked: {k} ({why})")
    for m in j["margins"]:
        extra = "" if "sign" not in m else (f", det sign {m['sign']:+d}" if m["sign"] else
                                             ", det sign not proved constant (det(A) may reach 0)")
        lines.append(f"  {m['constraint']} {'-'.join(map(str, m['legs']))}{' ' + m['detail'] if 'detail' in m else ''}: "
                     f"min margin in {display.pair(m['margin'])}{extra}")
    polyline = r.path.segments > 1        # there, s = k + t on segment k (0-based), as for undecided ranges
    for certain in (True, False):     # each an enclosure of the failing instants, not a range failing throughout
        kind = [v for v in j["violations"] if v["certain"] == certain]
        for v in kind[:SHOWN]:
            where = f"s in {display.outward(*v['s'], 12)}" if polyline or "t" not in v else \
                f"t in {display.outward(*v['t'], 12)}"
            lines.append(f"  {'VIOLATED' if certain else 'may fail'}: {v['constraint']} "
                         f"{'-'.join(map(str, v['legs']))}{' ' + v['detail'] if 'detail' in v else ''}"
                         f"{' (proved)' if certain else ''}, failing instants within {where}")
        if len(kind) > SHOWN:
            lines.append(f"  ... {len(kind) - SHOWN} more {'VIOLATED' if certain else 'may fail'} ranges "
                         "(all of them in --json)")
    for u in j["undecided"][:SHOWN]:        # one segment: s = t
        lines.append(f"  undecided for {'s' if polyline else 't'} in {display.outward(*u['s'], 12)}")
    if len(j["undecided"]) > SHOWN:
        lines.append(f"  ... {len(j['undecided']) - SHOWN} more undecided ranges (all of them in --json)")
    if polyline and (j["violations"] or j["undecided"]):
        lines.append(f"  (s = k + t: instant t ∈ [0, 1] of segment k, k = 0 to {r.path.segments - 1})")
    return "\n".join(lines)
