"""``certkin fk``: every real assembly mode for given leg lengths, each proved unique."""
from __future__ import annotations

from ..certificates import fk_certificate
from ..engine import budgets
from ..fk import forward_kinematics
from ..report import fk_report
from ..robots import load_robot
from .common import Answer, add_budget, add_outputs, budget, options, progress, run_answer, with_angles

OPTIONS = {"lengths": "--lengths", "domain": "--domain", "track": "--track"}


def add_arguments(f):
    f.add_argument("robot", help="robot file (TOML)")
    f.add_argument("--lengths", required=True, metavar="L1,L2,...", help="leg lengths (exact decimals)")
    f.add_argument("--domain", help='narrow the search: "x=a:b,..." (positions narrow the box, angles filter)')
    f.add_argument("--track", metavar="POSE", help="previous pose: prove the unique posture near it first")
    f.add_argument("--angles", choices=["zyz", "tilt-torsion"], help="spherical robots: pose angles of the output")
    add_outputs(f)
    add_budget(f, budgets.FORWARD_KINEMATICS)


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin fk`` (``robot``: the robot file already loaded, else ``args.robot``)."""
    with options(OPTIONS):
        robot = with_angles(robot or load_robot(args.robot), args.angles)
        result = forward_kinematics(robot, args.lengths, domain=args.domain, budget=budget(args),
                                    progress=progress(args.progress), track=args.track)
    return Answer(robot, result, result.to_json(), lambda: describe(robot, result),
                  lambda: fk_certificate(result),
                  lambda path, cert: fk_report(robot, result, path, cert, budget(args)))


def run(args):
    return run_answer(args, compute, OPTIONS)


def describe(robot, r):
    head = (f"{robot.name}: {len(r.solutions)} assembly modes, each proved unique"
            + (" (tracked from the previous pose)" if r.tracked else
               "; complete" if r.complete else f"; INCOMPLETE, {len(r.unresolved)} unresolved regions"))
    lines = [head + f" [{r.boxes} boxes, {r.seconds:.3f} s]"]
    for k, s in enumerate(r.solutions):
        pose = ", ".join(f"{n}={0.5 * (float(v.lo) + float(v.hi)):.10g}" for n, v in s["pose"].items())
        lines.append(f"  {k + 1}: {pose}")
    for k, s in enumerate(r.unresolved):
        pose = ", ".join(f"{n}=[{float(v.lo):.6g}, {float(v.hi):.6g}]" for n, v in s["pose"].items())
        lines.append(f"  unresolved {k + 1}: {pose}")
    return "\n".join(lines)
