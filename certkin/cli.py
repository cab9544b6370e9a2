"""The ``certkin`` command line.

Every command prints a human summary, or one JSON document with ``--json``;
``--certificate FILE`` writes the certificate; exit code 0 for an answer
(whatever the verdict), 1 for a certificate that fails to check, 2 for bad
input with one line naming the file or option and the field.
"""
from __future__ import annotations

import argparse
import json
import sys

from . import budgets
from .errors import InputError


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage otherwise)
        sys.stderr.write(f"certkin: error: {message}\n")
        raise SystemExit(2)


def _progress(enabled):
    if not enabled:
        return None
    from tqdm import tqdm
    bar = tqdm(desc="boxes", unit="box", file=sys.stderr, leave=False)

    def update(processed, frontier):
        bar.n = processed
        bar.set_postfix(frontier=frontier, refresh=False)
        bar.refresh()
    return update


def _budget(args):
    from .engine import Budget
    return Budget(max_boxes=args.max_boxes, max_seconds=args.max_seconds, min_width=args.min_width)


def _add_budget(p, default):
    boxes, seconds, width = default["max_boxes"], default["max_seconds"], default["min_width"]
    p.add_argument("--max-boxes", type=int, default=boxes, help=f"box budget (default {boxes})")
    p.add_argument("--max-seconds", type=float, default=seconds, help=f"time budget (default {seconds})")
    p.add_argument("--min-width", type=float, default=width,
                   help=f"smallest scaled box width that is still split (default {width})")


def _add_outputs(p):
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--certificate", metavar="FILE", help="write the certificate to FILE")
    p.add_argument("--report", metavar="FILE.html", help="write a self-contained HTML report")
    p.add_argument("--progress", action="store_true", help="show progress on stderr")


def cmd_singular(args):
    from . import load_robot
    from .certificates import singularity_certificate, write_json
    from .poses import parse_box
    from .singularity import classify_cells, largest_free_box
    robot = _with_angles(load_robot(args.robot), args.angles)
    if args.around:
        result = largest_free_box(robot, args.around, scale=args.scale, budget=_budget(args))
        results = [result]
    else:
        if not args.box:
            raise InputError("--box", "", "give --box \"name=lo:hi,...\" or --around POSE")
        box = parse_box(args.box, robot)
        if args.cells is not None and args.cells < 1:
            raise InputError("--cells", "", "expected a positive number of cells per side")
        results = classify_cells(robot, box, args.cells or 1, _budget(args), _progress(args.progress))
    if args.certificate:
        write_json(args.certificate, singularity_certificate(results))
    if args.plot:
        from .plots import plot_cells
        plot_cells(robot, results, args.plot)
    if args.report:
        from .report import singularity_report
        singularity_report(robot, results, args.report)
    if args.cells:
        doc = {"problem": "singularity", "robot": robot.name, "kind": robot.kind, "cells": args.cells,
               "counts": _counts(results), "results": [r.to_json() for r in results]}
    else:
        doc = results[0].to_json()
    if args.json:
        print(json.dumps(doc))
    elif args.cells:
        c = doc["counts"]
        print(f"{robot.name}: {len(results)} cells: {c['singularity-free']} singularity-free, "
              f"{c['singular']} singular, {c['undecided']} undecided")
    else:
        print(_describe_singular(robot, results[0]))
    return 0


def _with_angles(robot, angles):
    if angles is None:
        return robot
    if robot.kind != "spherical-3dof":
        raise InputError("--angles", "", f"only spherical-3dof robots take --angles (this one is {robot.kind})")
    return robot.with_angles(angles)


def _counts(results):
    counts = {"singularity-free": 0, "singular": 0, "undecided": 0}
    for r in results:
        counts[r.status] += 1
    return counts


def _describe_singular(robot, r):
    box = ", ".join(f"{n}=[{a:.10g}, {b:.10g}]" for n, a, b in zip(robot.pose_names, r.lo, r.hi))
    line = f"{robot.name}: {box}: {r.status}"
    if r.status == "singularity-free":
        line += f" (det(A) {'>' if r.sign > 0 else '<'} 0 on the whole box)"
    elif r.status == "singular":
        p = ", ".join(f"{v:.10g}" for v in r.witnesses["positive"])
        q = ", ".join(f"{v:.10g}" for v in r.witnesses["negative"])
        line += f" (det(A) > 0 at ({p}), < 0 at ({q}))"
    elif r.status == "undecided":
        line += f" ({len(r.undecided)} boxes left undecided)"
    return line + f" [{r.boxes} boxes, {r.seconds:.3f} s]"


def cmd_fk(args):
    from . import load_robot
    from .certificates import fk_certificate, write_json
    from .fk import forward_kinematics
    robot = _with_angles(load_robot(args.robot), args.angles)
    result = forward_kinematics(robot, args.lengths, domain=args.domain, budget=_budget(args),
                                progress=_progress(args.progress), track=args.track)
    if args.certificate:
        write_json(args.certificate, fk_certificate(result))
    if args.report:
        from .report import fk_report
        fk_report(robot, result, args.report)
    if args.json:
        print(json.dumps(result.to_json()))
    else:
        print(_describe_fk(robot, result))
    return 0


def _describe_fk(robot, r):
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


def _constraints(text):
    if not text:
        return None
    return [c.strip() for c in text.split(",") if c.strip()]


def cmd_trajectory(args):
    from . import load_robot
    from .certificates import trajectory_certificate, write_json
    from .trajectory import verify_trajectory
    robot = load_robot(args.robot)
    via = [w for w in (args.via or [])]
    result = verify_trajectory(robot, args.start, args.goal, waypoints=via, constraints=_constraints(args.constraints),
                               budget=_budget(args), progress=_progress(args.progress))
    if args.certificate:
        write_json(args.certificate, trajectory_certificate(result))
    if args.report:
        from .report import trajectory_report
        trajectory_report(robot, result, args.report)
    if args.json:
        print(json.dumps(result.to_json()))
    else:
        print(_describe_trajectory(robot, result))
    return 0


def _describe_trajectory(robot, r):
    j = r.to_json()
    lines = [f"{robot.name}: {r.status.upper()} [{j['stats']['boxes']} boxes, {j['stats']['seconds']:.3f} s]"]
    for k, why in j["skipped"].items():
        lines.append(f"  not checked: {k} ({why})")
    for m in j["margins"]:
        extra = f", det sign {m['sign']:+d}" if "sign" in m else ""
        lines.append(f"  {m['constraint']} {'-'.join(map(str, m['legs']))}{' ' + m['detail'] if 'detail' in m else ''}: "
                     f"min margin in [{m['margin'][0]:.9g}, {m['margin'][1]:.9g}]{extra}")
    for v in j["violations"]:
        where = f"t in [{v['t'][0]:.12g}, {v['t'][1]:.12g}]" if "t" in v else f"s in [{v['s'][0]:.12g}, {v['s'][1]:.12g}]"
        lines.append(f"  {'VIOLATED' if v['certain'] else 'may fail'}: {v['constraint']} "
                     f"{'-'.join(map(str, v['legs']))} for {where}")
    for u in j["undecided"]:
        lines.append(f"  undecided for s in [{u['s'][0]:.12g}, {u['s'][1]:.12g}]")
    return "\n".join(lines)


def cmd_plan(args):
    from . import load_robot
    from .certificates import write_json
    from .planning import plan
    robot = load_robot(args.robot)
    result = plan(robot, args.start, args.goal, constraints=_constraints(args.constraints),
                  divisions=args.divisions, max_seconds=args.max_seconds)
    if args.certificate and result.segments:
        write_json(args.certificate, result.certificate())
    if args.json:
        print(json.dumps(result.to_json()))
    else:
        lines = [f"{robot.name}: {result.status} [{result.stats.get('edges_verified', 0)} segments verified, "
                 f"{result.stats.get('seconds', 0):.2f} s]"]
        for w in result.waypoints:
            lines.append("  " + ",".join(w))
        if result.endpoint:
            lines.append(f"  the {result.endpoint['pose']} pose is {result.endpoint['status']}: " +
                         "; ".join(f"{v['constraint']} {'-'.join(map(str, v['legs']))}" for v in result.endpoint["violations"]))
        print("\n".join(lines))
    return 0


def cmd_check(args):
    import proofs
    try:
        report = proofs.check_file(args.certificate)
    except (OSError, ValueError) as exc:
        raise InputError(args.certificate, "", f"cannot read the certificate ({exc})") from None
    print(("OK: " if report.ok else "REJECTED: ") + report.summary())
    return 0 if report.ok else 1


def cmd_demo(args):
    from .demo import run_demo
    return run_demo(args.robots)


def build_parser():
    p = _Parser(prog="certkin", description="Certified answers about parallel robots.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    s = sub.add_parser("singular", help="prove a box of poses singularity-free, or find a singularity in it")
    s.add_argument("robot", help="robot file (TOML)")
    s.add_argument("--box", help='box of poses, e.g. "x=-20:20,y=-20:20,phi=0:0.7853981634"')
    s.add_argument("--cells", type=int, help="split the box into n^d cells and classify each")
    s.add_argument("--plot", metavar="FILE.png", help="picture of the cells (needs matplotlib)")
    s.add_argument("--around", metavar="POSE", help="largest singularity-free box centred at POSE")
    s.add_argument("--scale", metavar="S1,S2,...", help="half-widths of the unit box for --around")
    s.add_argument("--angles", choices=["zyz", "tilt-torsion"],
                   help="spherical robots: ZYZ Euler angles phi1,phi2,phi3 (default) or tilt-and-torsion phi1,phi2,sigma")
    _add_outputs(s)
    _add_budget(s, budgets.SINGULARITY)
    s.set_defaults(func=cmd_singular)

    f = sub.add_parser("fk", help="every real assembly mode for given leg lengths, each proved unique")
    f.add_argument("robot", help="robot file (TOML)")
    f.add_argument("--lengths", required=True, metavar="L1,L2,...", help="leg lengths (exact decimals)")
    f.add_argument("--domain", help='narrow the search: "x=a:b,..." (positions narrow the box, angles filter)')
    f.add_argument("--track", metavar="POSE", help="previous pose: prove the unique posture near it first")
    f.add_argument("--angles", choices=["zyz", "tilt-torsion"], help="spherical robots: pose angles of the output")
    _add_outputs(f)
    _add_budget(f, budgets.FORWARD_KINEMATICS)
    f.set_defaults(func=cmd_fk)

    t = sub.add_parser("trajectory", help="certify a straight (or polyline) motion, or find where it fails")
    t.add_argument("robot", help="robot file (TOML)")
    t.add_argument("--from", dest="start", required=True, metavar="POSE", help="start pose, e.g. -69,-50,500,85deg,10deg,0")
    t.add_argument("--to", dest="goal", required=True, metavar="POSE", help="goal pose")
    t.add_argument("--via", action="append", metavar="POSE", help="intermediate pose (repeatable): a polyline")
    t.add_argument("--constraints", metavar="LIST",
                   help="comma-separated subset of leg-length,joints,interference,singularity (default: all)")
    _add_outputs(t)
    _add_budget(t, budgets.TRAJECTORY)
    t.set_defaults(func=cmd_trajectory)

    pl = sub.add_parser("plan", help="a path whose every segment is certified feasible")
    pl.add_argument("robot", help="robot file (TOML)")
    pl.add_argument("--from", dest="start", required=True, metavar="POSE")
    pl.add_argument("--to", dest="goal", required=True, metavar="POSE")
    pl.add_argument("--constraints", metavar="LIST", help="as for trajectory (default: all)")
    pl.add_argument("--divisions", type=int, default=6, help="grid steps between start and goal (default 6)")
    pl.add_argument("--max-seconds", type=float, default=120.0, help="time budget (default 120)")
    pl.add_argument("--json", action="store_true", help="print one JSON document")
    pl.add_argument("--certificate", metavar="FILE", help="write the certificate of every segment to FILE")
    pl.set_defaults(func=cmd_plan)

    from . import workspace
    w = sub.add_parser("workspace", help="constant-orientation workspace: section (exact arcs, area) or volume bracket")
    workspace.add_arguments(w)
    w.set_defaults(func=lambda args: workspace.run(args))

    c = sub.add_parser("check", help="re-verify a certificate with the independent checker")
    c.add_argument("certificate")
    c.set_defaults(func=cmd_check)

    d = sub.add_parser("demo", help="run the seed examples on the bundled robots")
    d.add_argument("--robots", help="directory of robot files (default: the bundled examples)")
    d.set_defaults(func=cmd_demo)
    return p


_POSE_OPTIONS = ("--from", "--to", "--via", "--track", "--around", "--lengths")


def _join_pose_values(argv):
    """``--from -69,-50,...``: a pose that starts with '-' is a value, not an option."""
    out, i = [], 0
    while i < len(argv):
        a = argv[i]
        if a in _POSE_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-") and argv[i + 1][1:2].isdigit() | (argv[i + 1][1:2] == "."):
            out.append(f"{a}={argv[i + 1]}")
            i += 2
            continue
        out.append(a)
        i += 1
    return out


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(_join_pose_values(list(sys.argv[1:] if argv is None else argv)))
    try:
        return args.func(args)
    except InputError as exc:
        sys.stderr.write(f"certkin: error: {exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("certkin: interrupted\n")
        return 130


if __name__ == "__main__":
    sys.exit(main())
