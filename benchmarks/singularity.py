"""Singularity benchmark: seed 003 planar example 2, n×n×n cells classified.

Side by side in one run:

- certkin: ``classify_cells`` for n = 10 (1000 cells) and n = 25 (15 625
  cells); every cell ends singularity-free (proved), singular (two
  certified witnesses) or undecided;
- codac ``sivia`` on det(A) ∈ [0, 0] over the same box (scaled to the unit
  cube so that one ``eps`` means the same resolution in every variable),
  with eps = 1/n: its "outside" boxes are proved det ≠ 0, its boundary
  boxes are undecided (sivia cannot prove a zero);
- dense numpy sampling (fast, uncertified): det(A) in floats at k^3 points
  per cell; a cell is called "singular" when the samples change sign, else
  "free".  It proves nothing; the table shows how many cells it gets wrong
  against certkin's proved verdicts (a sign change between samples missed);
- the fraction of the box each one decides.

Memory: a 6-D Gough-Stewart box with a tight budget, peak RSS reported.

Usage: ``taskset -c 0 python benchmarks/singularity.py [--repeat 5]``.
Target (DESIGN.md): n = 10 (1000 cells) classified in at most 2 s.
"""
from __future__ import annotations

import argparse
import resource
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import sympy as sp

from certkin import load_robot
from certkin.engine import Budget
from certkin.singularity import certify_singularity_free, classify_cells

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import codac_version, describe  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent / "examples" / "robots"
TARGET_10 = 2.0   # seconds for n = 10
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
    return statistics.median(times), counts, decided, [c.status for c in cells]


def numpy_sampling(robot, n, k, repeat):
    """Dense float sampling: (median s, verdict per cell: True = sign change seen), cells in
    classify_cells order (x slowest, phi fastest)."""
    def run():
        u = (np.arange(k) + 0.5) / k                      # k samples per cell and axis, cell-relative
        w = (HI - LO) / n
        cells = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), -1).reshape(-1, 3)
        off = np.stack(np.meshgrid(u, u, u, indexing="ij"), -1).reshape(-1, 3)
        pts = LO + (cells[:, None, :] + off[None, :, :]) * w   # (cells, k^3, 3)
        d = robot.det_float(pts.reshape(-1, 3)).reshape(len(cells), -1)
        return (d.min(axis=1) < 0) & (d.max(axis=1) > 0)
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = run()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


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
    ap.add_argument("--repeat", type=int, default=5, help="repeats for n = 10 (n = 25 runs once)")
    ap.add_argument("--samples", type=int, default=4, help="numpy peer: samples per cell and axis")
    args = ap.parse_args()
    robot = load_robot(ROOT / "seed003-planar-example-2.toml")
    classify_cells(robot, BOX, 2)  # compile once
    version = codac_version()
    print(f"# seed 003 planar example 2, box {BOX}; {describe()}; codac {version or 'not installed'}")
    print(f"{'method':40s} {'n':>3s} {'cells':>6s} {'median s':>9s} {'decided':>8s}  detail")
    t10 = None
    for n in (10, 25):
        rep = args.repeat if n == 10 else 1
        t, counts, decided, statuses = certkin_cells(robot, n, rep)
        t10 = t if n == 10 else t10
        print(f"{'certkin classify_cells':40s} {n:3d} {n**3:6d} {t:9.3f} {decided:8.1%}  {counts}")
        tn, change = numpy_sampling(robot, n, args.samples, rep)
        wrong = sum((st == "singular" and not c) or (st == "singularity-free" and c) for st, c in zip(statuses, change))
        print(f"{f'numpy sampling, {args.samples}^3 points per cell':40s} {n:3d} {n**3:6d} {tn:9.3f} {'0.0%':>8s}  "
              f"nothing proved; {int(change.sum())} cells with a sign change seen, {wrong} cells disagree "
              f"with certkin; ratio certkin/numpy = {t / tn:.2f}")
        if version is None:
            print("codac not installed (pip install 'certkin[bench]'): codac sivia row skipped")
            continue
        try:
            ts, vol = sivia(robot, n, rep)
            print(f"{'codac sivia (det in [0,0], eps=1/n)':40s} {n:3d} {'-':>6s} {ts:9.3f} {vol:8.1%}  "
                  f"outside volume proved det != 0; ratio certkin/codac = {t / ts:.2f}")
        except Exception as exc:  # an API change must not hide the other rows
            print(f"codac {version} sivia failed: {type(exc).__name__}: {exc}")
    print(f"target: n = 10 (1000 cells) in <= {TARGET_10:.0f} s: {'met' if t10 <= TARGET_10 else 'NOT met'} "
          f"({t10:.3f} s)")
    status, boxes, dt, peak = gough_memory()
    print(f"gough 6-D box, budget 50000 boxes: {status}, {boxes} boxes, {dt:.1f} s, peak RSS {peak:.0f} MiB "
          f"(whole process; target <= 1024 MiB: {'met' if peak <= 1024 else 'NOT met'})")


if __name__ == "__main__":
    main()
