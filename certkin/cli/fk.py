"""``certkin fk``: every real assembly mode for given leg lengths, each proved unique."""
from __future__ import annotations

from ..certificates import fk_certificate
from ..engine import budgets
from ..fk import forward_kinematics
from ..report import fk_report
from ..robots import load_robot
from .common import add_budget, add_outputs, answer, budget, options, progress, with_angles

OPTIONS = {"lengths": "--lengths", "domain": "--domain", "track": "--track"}


def add_arguments(f):
    f.add_argument("robot", help="robot file (TOML)")
    f.add_argument("--lengths", required=True, metavar="L1,L2,...",
                   help="leg lengths (exact decimals); a range 'lo:hi' or 'value+-tolerance' for an uncertain leg")
    f.add_argument("--domain", help='narrow the search: "x=a:b,..." (positions narrow the box, angles filter)')
    f.add_argument("--track", metavar="POSE", help="previous pose: prove the unique posture near it first")
    f.add_argument("--angles", choices=["zyz", "tilt-torsion"], help="spherical robots: pose angles of the output")
    add_outputs(f)
    add_budget(f, budgets.FORWARD_KINEMATICS)


def run(args):
    with options(OPTIONS):
        robot = with_angles(load_robot(args.robot), args.angles)
        result = forward_kinematics(robot, args.lengths, domain=args.domain, budget=budget(args),
                                    progress=progress(args.progress), track=args.track,
                                    record=bool(args.certificate))
        answer(args, robot, result, fk_certificate, fk_report, describe)
    return 0


def describe(robot, r):
    ranges = any(":" in t for t in r.lengths)     # uncertain lengths: each mode is a box, not a point
    clusters = f", {len(r.clusters)} clusters (postures not resolved)" if r.clusters else ""
    head = (f"{robot.name}: {len(r.solutions)} assembly modes, each proved unique"
            + (" for every length in the ranges" if ranges else "")
            + (" (tracked from the previous pose)" if r.tracked else
               f"{clusters}; complete" if r.complete else f"{clusters}; INCOMPLETE, {len(r.unresolved)} unresolved regions"))
    lines = [head + f" [{r.boxes} boxes, {r.seconds:.3f} s]"]
    for k, s in enumerate(r.solutions):
        if ranges:
            pose = ", ".join(f"{n}=[{float(v.lo):.8g}, {float(v.hi):.8g}]" for n, v in s["pose"].items())
        else:
            pose = ", ".join(f"{n}={0.5 * (float(v.lo) + float(v.hi)):.10g}" for n, v in s["pose"].items())
        lines.append(f"  {k + 1}: {pose}")
    for name, regions in (("cluster", r.clusters), ("unresolved", r.unresolved)):
        for k, s in enumerate(regions):
            pose = ", ".join(f"{n}=[{float(v.lo):.6g}, {float(v.hi):.6g}]" for n, v in s["pose"].items())
            lines.append(f"  {name} {k + 1}: {pose}")
    if r.message:
        lines.append(f"  note: {r.message}")
    return "\n".join(lines)
