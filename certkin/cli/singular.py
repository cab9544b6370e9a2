"""``certkin singular``: prove a box of poses singularity-free, or find a singularity in it."""
from __future__ import annotations

from ..certificates import singularity_certificate
from ..engine import budgets
from ..errors import InputError
from ..plots import plot_cells
from ..report import singularity_report
from ..robots import load_robot
from ..robots.poses import parse_box
from ..singularity import classify_cells, largest_free_box
from .common import Answer, add_budget, add_outputs, budget, options, progress, run_answer, with_angles

OPTIONS = {"box": "--box", "pose": "--around", "scale": "--scale", "plot": "--plot"}


def add_arguments(s):
    s.add_argument("robot", help="robot file (TOML)")
    s.add_argument("--box", help='box of poses, e.g. "x=-20:20,y=-20:20,phi=0:0.7853981634"')
    s.add_argument("--cells", type=int, help="split the box into n^d cells and classify each")
    s.add_argument("--plot", metavar="FILE.png", help="picture of the cells")
    s.add_argument("--around", metavar="POSE", help="largest singularity-free box centred at POSE")
    s.add_argument("--scale", metavar="S1,S2,...", help="half-widths of the unit box for --around")
    s.add_argument("--angles", choices=["zyz", "tilt-torsion"],
                   help="spherical robots: ZYZ Euler angles phi1,phi2,phi3 (default) or tilt-and-torsion phi1,phi2,sigma")
    add_outputs(s)
    add_budget(s, budgets.SINGULARITY)


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin singular`` (``robot``: the robot file already loaded, else ``args.robot``)."""
    with options(OPTIONS):
        robot = with_angles(robot or load_robot(args.robot), args.angles)
        if args.around:
            results = [largest_free_box(robot, args.around, scale=args.scale, budget=budget(args))]
        else:
            if not args.box:
                raise InputError("--box", "", "give --box \"name=lo:hi,...\" or --around POSE")
            box = parse_box(args.box, robot)
            if args.cells is not None and args.cells < 1:
                raise InputError("--cells", "", "expected a positive number of cells per side")
            results = classify_cells(robot, box, args.cells or 1, budget(args), progress(args.progress))
    if args.cells:
        doc = {"problem": "singularity", "robot": robot.name, "kind": robot.kind, "cells": args.cells,
               "counts": _counts(results), "results": [r.to_json() for r in results]}
    else:
        doc = results[0].to_json()
    return Answer(robot, results, doc, lambda: _text(robot, results, doc, args.cells),
                  lambda: singularity_certificate(results),
                  lambda path, cert: singularity_report(robot, results, path, cert, budget(args)),
                  lambda path: plot_cells(robot, results, path))


def run(args):
    return run_answer(args, compute, OPTIONS)


def _text(robot, results, doc, cells):
    if cells:
        c = doc["counts"]
        return (f"{robot.name}: {len(results)} cells: {c['singularity-free']} singularity-free, "
                f"{c['singular']} singular, {c['undecided']} undecided")
    return describe(robot, results[0])


def _counts(results):
    counts = {"singularity-free": 0, "singular": 0, "undecided": 0}
    for r in results:
        counts[r.status] += 1
    return counts


def describe(robot, r):
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
