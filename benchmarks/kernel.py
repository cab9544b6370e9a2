"""Kernel benchmark: enclose det(A) of the planar 3-RPR over many boxes.

Side by side in one run, on the same boxes (seed 003 planar example 2,
random boxes of width ~1 in x, y and 0.05 in phi):

- certkin: the compiled batch evaluator (``robot.det_enclosure``) on all
  boxes at once, and the squared leg lengths (``robot.leg_lengths_squared``,
  sums of ``sqr``: the kernel of the exact-square check) on the same boxes;
- mpmath ``iv``: the same sympy expression evaluated one box at a time
  (the naive rigorous alternative), on a subsample, extrapolated;
- codac: ``AnalyticFunction.eval`` on an ``IntervalVector``, one box at a
  time from Python (codac is a C++ core), on a subsample, extrapolated; in
  its default mode (natural and centred forms, intersected: tighter than
  certkin's natural extension) and in ``EvalMode.NATURAL`` (the same
  enclosure as certkin's);
- numpy float evaluation at the box midpoints (fast, not an enclosure).

Usage: ``python benchmarks/kernel.py [--boxes 100000] [--repeat 5]``.
Prints a table of median times and throughput; run it pinned to one core
(``taskset -c 0``) to measure single-core throughput.  Target (DESIGN.md):
at least 1 000 000 boxes/s for the batched certkin evaluator.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import sympy as sp

from certkin import load_robot
from certkin.robots import Planar3RPR
from intervals import Interval

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import codac_version, describe, median_time  # noqa: E402

ROBOT = Path(__file__).resolve().parent.parent / "examples" / "robots" / "seed003-planar-example-2.toml"


def make_boxes(n, seed=0):
    rng = np.random.default_rng(seed)
    lo = np.column_stack([rng.uniform(-50, 49, n), rng.uniform(-50, 49, n), rng.uniform(0, 0.73, n)])
    hi = lo + np.array([1.0, 1.0, 0.05])
    return lo, hi


def det_expression(robot):
    (x, y, phi), g = Planar3RPR.symbols()
    det = Planar3RPR.symbolic_model()["det"]
    values = [sp.Rational(t) for t in robot.geometry_texts()]
    return (x, y, phi), det.subs(dict(zip(g, values)))


def bench_mpmath(robot, lo, hi, n):
    from mpmath import iv
    (x, y, phi), expr = det_expression(robot)
    # lambdify prints rational constants as mpf(p)/mpf(q): map mpf to iv.mpf so that
    # they become (rigorous) intervals too and do not clash with the iv arguments
    f = sp.lambdify((x, y, phi), expr, modules=[{"sin": iv.sin, "cos": iv.cos, "mpf": iv.mpf}, "mpmath"])

    def run():
        for i in range(n):
            f(iv.mpf([lo[i, 0], hi[i, 0]]), iv.mpf([lo[i, 1], hi[i, 1]]), iv.mpf([lo[i, 2], hi[i, 2]]))
    return run


def to_codac(expr, syms, xvar):
    import codac
    table = {s: xvar[i] for i, s in enumerate(syms)}

    def rec(e):
        if e in table:
            return table[e]
        if e.is_Number:
            q = sp.Rational(e)
            # outward-rounded enclosure of p/q, computed once when the function is built
            return codac.Interval(int(q.p)) / codac.Interval(int(q.q))
        if e.is_Add:
            out = rec(e.args[0])
            for a in e.args[1:]:
                out = out + rec(a)
            return out
        if e.is_Mul:
            out = rec(e.args[0])
            for a in e.args[1:]:
                out = out * rec(a)
            return out
        if e.is_Pow and e.args[1] == 2:
            return codac.sqr(rec(e.args[0]))
        if e.is_Pow and e.args[1].is_Integer and e.args[1] > 0:
            out = rec(e.args[0])
            for _ in range(int(e.args[1]) - 1):
                out = out * rec(e.args[0])
            return out
        if isinstance(e, sp.sin):
            return codac.sin(rec(e.args[0]))
        if isinstance(e, sp.cos):
            return codac.cos(rec(e.args[0]))
        raise NotImplementedError(e)
    return rec(expr)


def bench_codac(robot, lo, hi, n, natural=False):
    import codac
    (x, y, phi), expr = det_expression(robot)
    X = codac.VectorVar(3)
    f = codac.AnalyticFunction([X], to_codac(expr, (x, y, phi), X))
    boxes = [codac.IntervalVector([[lo[i, 0], hi[i, 0]], [lo[i, 1], hi[i, 1]], [lo[i, 2], hi[i, 2]]]) for i in range(n)]
    mode = codac.EvalMode.NATURAL

    def run():
        for b in boxes:
            f.eval(b)

    def run_natural():
        for b in boxes:
            f.eval(mode, b)
    return run_natural if natural else run


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--boxes", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--sample", type=int, default=2000, help="boxes for the one-at-a-time peers")
    args = ap.parse_args()
    robot = load_robot(ROBOT)
    lo, hi = make_boxes(args.boxes)
    box = Interval(lo, hi)
    robot.det_enclosure(box[:10])  # compile once (excluded from timing)
    rows = []
    t = median_time(lambda: robot.det_enclosure(box), args.repeat)
    rows.append(("certkin batch (compiled, outward rounded)", args.boxes, t))
    robot.leg_lengths_squared(box[:10])
    t = median_time(lambda: robot.leg_lengths_squared(box), args.repeat)
    rows.append(("certkin batch, squared leg lengths (sqr)", args.boxes, t))
    mid = 0.5 * (lo + hi)
    t = median_time(lambda: robot.det_float(mid), args.repeat)
    rows.append(("numpy floats at midpoints (not an enclosure)", args.boxes, t))
    n = min(args.sample, args.boxes)
    t = median_time(bench_mpmath(robot, lo, hi, n // 4), args.repeat)
    rows.append(("mpmath iv, one box at a time", n // 4, t))
    version = codac_version()
    if version is None:
        rows.append(("codac: not installed (pip install 'certkin[bench]')", 0, float("nan")))
    else:
        try:
            t = median_time(bench_codac(robot, lo, hi, n), args.repeat)
            rows.append(("codac eval (natural & centred), one box at a time", n, t))
            t = median_time(bench_codac(robot, lo, hi, n, natural=True), args.repeat)
            rows.append(("codac eval (NATURAL), one box at a time", n, t))
        except Exception as exc:  # an API change must not hide the other rows
            rows.append((f"codac {version} failed: {type(exc).__name__}: {exc}"[:52], 0, float("nan")))
    print(f"# det(A) enclosure, planar 3-RPR (seed 003 ex. 2); {describe()}; "
          f"codac {version or 'not installed'}")
    print(f"{'method':52s} {'boxes':>8s} {'median s':>10s} {'boxes/s':>12s} {'peer slower':>11s}")
    base = rows[0][1] / rows[0][2]
    for name, count, secs in rows:
        if not count:
            print(f"{name:52s} {'-':>8s} {'-':>10s} {'-':>12s} {'-':>11s}")
            continue
        rate = count / secs
        print(f"{name:52s} {count:8d} {secs:10.4f} {rate:12.0f} {base / rate:10.1f}x")
    target = 1_000_000
    print(f"target: certkin batch >= {target:,} boxes/s: {'met' if base >= target else 'NOT met'} "
          f"({base:,.0f} boxes/s with {args.boxes:,} boxes per batch)")


if __name__ == "__main__":
    main()
