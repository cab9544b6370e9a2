"""``certkin singular``: prove a box of poses singularity-free, or find a singularity in it."""
from __future__ import annotations

from .. import display
from ..certificates import singularity_certificate
from ..engine import budgets
from ..errors import InputError
from ..plots import plot_cells
from ..robots import load_robot
from ..singularity import classify_cells, largest_free_box
from .common import (Answer, add_budget, add_outputs, budget, check_outputs, count, options, progress, refuse,
                     report_writer, run_answer, with_angles)

OPTIONS = {"box": "--box", "pose": "--around", "scale": "--scale", "plot": "--plot", "n": "--cells"}


def add_arguments(s):
    s.add_argument("robot", help="robot file (TOML)")
    s.add_argument("--box", help='box of poses, e.g. "x=-20:20,y=-20:20,phi=0:0.7853981634"')
    s.add_argument("--cells", type=count(10 ** 6), metavar="N",
                   help="split the box into N^k cells (N from 1 to 10^6) and classify each")
    s.add_argument("--plot", metavar="FILE.png", help="picture of the cells (PNG, SVG, PDF, or another type matplotlib writes)")
    s.add_argument("--around", metavar="POSE", help="largest singularity-free box centred at POSE")
    s.add_argument("--scale", metavar="S1,S2,...", help="half-widths of the unit box for --around")
    s.add_argument("--angles", choices=["zyz", "tilt-torsion"],
                   help="spherical robots: ZYZ Euler angles phi1,phi2,phi3 (default) or tilt-and-torsion phi1,phi2,sigma")
    add_outputs(s)
    add_budget(s, budgets.SINGULARITY)


def _check(args):
    """Conflicting or ignored options, before anything is read or solved."""
    if args.around is not None:
        refuse(args, "--box", "give either --box (a box to decide) or --around (the largest free box), not both", "box")
        refuse(args, "--cells", "only with --box (--around looks for one box)", "cells")
        refuse(args, "--plot", "only with --box (a picture of the cells)", "plot")
    else:
        refuse(args, "--scale", "only with --around", "scale")
        if args.box is None:
            raise InputError("--box", "", "give --box \"name=lo:hi,...\" or --around POSE")


def compute(args, robot=None) -> Answer:
    """The answer of ``certkin singular`` (``robot``: the robot file already loaded, else ``args.robot``)."""
    _check(args)
    with options(OPTIONS):
        robot = with_angles(robot or load_robot(args.robot), args.angles)
        if args.around is not None:
            bar = progress(args.progress, "boxes tried", "scale")
            results = [largest_free_box(robot, args.around, scale=args.scale, budget=budget(args), progress=bar)]
        else:
            results = classify_cells(robot, args.box, args.cells or 1, budget(args), progress(args.progress),
                                     certificate=bool(args.certificate))
    counts = _counts(results)
    if args.cells:
        def doc():          # built only when printed (--json) or written (batch): 64 000 cells take seconds
            return {"problem": "singularity", "robot": robot.name, "kind": robot.kind, "cells": args.cells,
                    "counts": counts, "results": [r.to_json() for r in results]}
    else:
        doc = results[0].to_json()
    return Answer(robot, results, doc, lambda: _text(robot, results, counts, args.cells),
                  lambda: singularity_certificate(results),
                  lambda path, cert: report_writer("singularity_report")(robot, results, path, cert, budget(args)),
                  lambda path: plot_cells(robot, results, path))


def run(args):
    _check(args)
    check_outputs(args)
    return run_answer(args, compute, OPTIONS)


def _text(robot, results, counts, cells):
    if cells:
        c = counts
        return (f"{robot.name}: {len(results)} cells: {c['singularity-free']} singularity-free, "
                f"{c['singular']} singular, {c['undecided']} undecided")
    return describe(robot, results[0])


def _counts(results):
    counts = {"singularity-free": 0, "singular": 0, "undecided": 0}
    for r in results:
        counts[r.status] += 1
    return counts


def describe(robot, r):
    """One line: the box (a free box rounded inward, any other outward), the verdict, the witnesses
    (exact floats)."""
    show = display.inward if r.status == "singularity-free" else display.outward
    box = ", ".join(f"{n}={show(a, b)}" for n, a, b in zip(robot.pose_names, r.lo, r.hi))
    line = f"{robot.name}: {box}: {r.status}"
    if r.status == "singularity-free":
        line += f" (det(A) {'>' if r.sign > 0 else '<'} 0 on the whole box)"
    elif r.status == "singular":
        p, q = (", ".join(v if isinstance(v, str) else display.point(v) for v in r.witness(k, text=True))
                for k in ("positive", "negative"))
        line += f" (det(A) > 0 at ({p}), < 0 at ({q}))"
    elif r.status == "undecided":
        line += f" ({len(r.undecided)} boxes left undecided)"
    line += f" [{r.boxes} boxes, {r.seconds:.3f} s]"
    g = r.bisection
    if g and g["stopped"] and r.status == "singularity-free":       # --around, cut short
        cause = "the time budget (--max-seconds) ran out" if g["stopped"] == "time budget" else "Ctrl-C came"
        beyond = f"; the box for s = {display.point(g['not_proved'])} is not proved" if g["not_proved"] is not None else ""
        line += (f"\n  {cause} while the box was grown: s = {display.lower(g['proved'], 9)} proved (rounded down) "
                 f"after {g['tried']} boxes tried"
                 f"{beyond}; a larger box may be proved with more time")
    elif g and g.get("not_proved_status") == "undecided" and r.status == "singularity-free":
        line += (f"\n  the box for s = {display.point(g['not_proved'])} was left undecided (its box budget, --max-boxes, "
                 "or the resolution, --min-width, ran out): a larger box may be proved with a larger budget")
    return line
