"""``certkin demo``: the seed examples on the bundled robots.

Loads every robot file of ``examples/robots``, prints a summary of each
(kind, legs, reference pose, certified leg lengths and det(A) there), then
runs the certified seed examples: seed 003 planar example 2 (the full box
is singular: its vertex signs differ, Annex C.1) and its 10×10×10 cell
classification, with the certificate of the cells re-checked by the
independent checker.
"""
from __future__ import annotations

from pathlib import Path
import time

import numpy as np

from .errors import InputError


def bundled_robots_dir() -> Path:
    """``examples/robots`` of the source tree (the package is installed editable)."""
    here = Path(__file__).resolve().parent.parent / "examples" / "robots"
    return here


def _fmt(iv, digits=10):
    lo, hi = float(iv.lo), float(iv.hi)
    return f"[{lo:.{digits}g}, {hi:.{digits}g}]"


def summarise(robot) -> list[str]:
    lines = [f"{robot.name}  ({robot.kind}, {robot.n_legs} legs)  <- {Path(robot.source).name}"]
    if robot.home is None:
        lines.append("  no reference pose in the file")
        return lines
    box = robot.home_box()
    pose = ", ".join(f"{n}={t}" for n, t in zip(robot.pose_names, robot.home))
    lines.append(f"  pose: {pose}")
    legs = robot.leg_lengths(box)
    lines.append("  leg lengths: " + ", ".join(_fmt(legs[i], 8) for i in range(robot.n_legs)))
    det = robot.det_enclosure(box)
    sign = "> 0" if det.lo > 0 else "< 0" if det.hi < 0 else "sign not decided"
    lines.append(f"  det(A) in {_fmt(det, 8)}  ({sign})")
    return lines


def run_demo(directory=None, out=print) -> int:
    from . import load_robot
    directory = Path(directory) if directory else bundled_robots_dir()
    files = sorted(directory.glob("*.toml"))
    if not files:
        raise InputError(str(directory), "", "no robot files (*.toml) found")
    out(f"== Bundled robots ({directory})")
    robots = {}
    for f in files:
        robot = load_robot(f)
        robots[f.stem] = robot
        for line in summarise(robot):
            out(line)
    _singularity_demo(robots, out)
    return 0


def _singularity_demo(robots, out):
    from .certificates import singularity_certificate
    from .singularity import certify_singularity_free, classify_cells
    robot = next((r for k, r in robots.items() if "planar-example-2" in k or "planar-ex2" in k), None)
    if robot is None:
        return
    out("")
    out("== Seed 003, planar example 2: singularity-free regions")
    box = "x=-50:50,y=-50:50,phi=0:0.7853981634"
    t = time.perf_counter()
    r = certify_singularity_free(robot, box)
    out(f"  full box {box}: {r.status} ({time.perf_counter() - t:.3f} s)")
    if r.witnesses:
        for k, v in r.witnesses.items():
            out(f"    det(A) {'>' if k == 'positive' else '<'} 0 at " + ", ".join(f"{x:.6g}" for x in v))
    t = time.perf_counter()
    cells = classify_cells(robot, box, 10)
    dt = time.perf_counter() - t
    counts = {s: sum(c.status == s for c in cells) for s in ("singularity-free", "singular", "undecided")}
    out(f"  10x10x10 cells: {counts['singularity-free']} singularity-free, {counts['singular']} singular, "
        f"{counts['undecided']} undecided ({dt:.2f} s)")
    try:
        import proofs
    except ImportError:  # pragma: no cover
        return
    t = time.perf_counter()
    report = proofs.check(singularity_certificate(cells))
    out(f"  certificate of the 1000 cells re-checked by proofs: {'OK' if report.ok else 'REJECTED'} "
        f"({time.perf_counter() - t:.1f} s)")
