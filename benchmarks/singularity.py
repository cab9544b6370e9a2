"""Singularity benchmark: seed 003 planar example 2, n×n×n cells classified.

Side by side in one run:

- certkin: ``classify_cells`` for n = 10 (1000 cells) and n = 25 (15 625
  cells); every cell ends singularity-free (proved), singular (two
  certified witnesses) or undecided;
- codac ``sivia`` on det(A) ∈ [0, 0] over the same box (scaled to the unit
  cube so that one ``eps`` means the same resolution in every variable),
  with eps = 1/n: its "outside" boxes are proved det ≠ 0, its boundary
  boxes are undecided (sivia cannot prove a zero);
- the fraction of the box each one decides.

Memory: a 6-D Gough-Stewart box with a tight budget, peak RSS reported.

Usage: ``python benchmarks/singularity.py [--repeat 3]``.
"""
from __future__ import annotations

import argparse
import platform
import resource
import statistics
import time
from pathlib import Path

import numpy as np
import sympy as sp

from certkin import load_robot
from certkin.engine import Budget
from certkin.robots import Planar3RPR
from certkin.singularity import certify_singularity_free, classify_cells

ROOT = Path(__file__).resolve().parent.parent / "examples" / "robots"
BOX = "x=-50:50,y=-50:50,phi=0:0.7853981634"
LO = np.array([-50.0, -50.0, 0.0])
HI = np.array([50.0, 50.0, 0.7853981634])


def certkin_cells(robot, n, repeat):
    times, cells = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        cells = classify_cells(robot, BOX, n)
        times.append(time.perf_counter() - t)
    counts = {s: sum(c.status == s for c in cells) for s in ("singularity-free", "singular", "undecided")}
    decided = (counts["singularity-free"] + counts["singular"]) / len(cells)
    return statistics.median(times), counts, decided


def _kernel_module():
    import importlib.util
    spec = importlib.util.spec_from_file_location("kernel_bench", Path(__file__).with_name("kernel.py"))
    kb = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(kb)
    return kb


def sivia(robot, n, repeat):
    """codac sivia over the unit cube mapped onto the box; returns (median s, fraction proved det != 0)."""
    import codac
    kb = _kernel_module()
    (x, y, phi), expr = kb.det_expression(robot)
    u = sp.symbols("u0 u1 u2")
    scaled = expr.subs({x: LO[0] + u[0] * (HI[0] - LO[0]), y: LO[1] + u[1] * (HI[1] - LO[1]),
                        phi: LO[2] + u[2] * (HI[2] - LO[2])})
    U = codac.VectorVar(3)
    f = codac.AnalyticFunction([U], kb.to_codac(scaled, u, U))
    times, paving = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        paving = codac.sivia(codac.IntervalVector([[0, 1], [0, 1], [0, 1]]), f, codac.Interval(0, 0), 1.0 / n)
        times.append(time.perf_counter() - t)
    outside = sum(b.volume() for b in paving.boxes(codac.PavingInOut.outer_complem))
    return statistics.median(times), outside


def gough_memory():
    robot = load_robot(ROOT / "seed002-main-gauche.toml")
    t = time.perf_counter()
    r = certify_singularity_free(robot, "x=-5:5,y=-5:5,z=40:60,psi=-0.5:0.5,theta=-0.5:0.5,phi=-0.5:0.5",
                                 budget=Budget(max_boxes=50_000, max_seconds=60))
    dt = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return r.status, r.boxes, dt, peak


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    robot = load_robot(ROOT / "seed003-planar-example-2.toml")
    classify_cells(robot, BOX, 2)  # compile once
    print(f"# seed 003 planar example 2, box {BOX}; {platform.machine()}, Python {platform.python_version()}")
    print(f"{'method':40s} {'n':>3s} {'cells':>6s} {'median s':>9s} {'decided':>8s}  detail")
    for n in (10, 25):
        t, counts, decided = certkin_cells(robot, n, args.repeat if n == 10 else 1)
        print(f"{'certkin classify_cells':40s} {n:3d} {n**3:6d} {t:9.3f} {decided:8.1%}  {counts}")
        try:
            ts, vol = sivia(robot, n, args.repeat if n == 10 else 1)
            print(f"{'codac sivia (det in [0,0], eps=1/n)':40s} {n:3d} {'-':>6s} {ts:9.3f} {vol:8.1%}  "
                  f"outside volume proved det != 0; ratio certkin/codac = {t / ts:.2f}")
        except ImportError:
            print("codac not installed: pip install 'certkin[bench]'")
    status, boxes, dt, peak = gough_memory()
    print(f"gough 6-D box, budget 50000 boxes: {status}, {boxes} boxes, {dt:.1f} s, peak RSS {peak:.0f} MiB")


if __name__ == "__main__":
    main()
