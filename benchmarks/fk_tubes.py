"""Where a Gough-Stewart FK search spends its boxes: near which posture, and how ill-conditioned it is.

For one robot and exact leg lengths, the search runs twice in this process: with the Cayley-Menger
rule as the solver has it (single quads, then their combinations: ``certkin/fk/cayley_menger.py``),
and with the single quads only (the combinations switched off by giving the kernel no rows of
weights).  Every box the engine decides is recorded; per posture (the proved boxes' midpoints,
refined by float Newton steps) it prints the smallest singular value of the Jacobian and the
number of boxes whose quaternion is nearest to that posture's rotation (q and −q alike), for both
runs.  A figure of docs/benchmarks.md ("Cayley-Menger combinations"); floats, no claim.

    python benchmarks/fk_tubes.py [--robot FILE] [--lengths L1,...] [--top 10]
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from certkin import load_robot
from certkin.engine import PROVED
from certkin.fk import cayley_menger, forward_kinematics, search
from certkin.fk.system import fk_system

ROOT = Path(__file__).resolve().parents[1]
DIETMAIER = (ROOT / "examples" / "robots" / "dietmaier-6-6-40.toml", "1,0.645275,1.086284,1.503439,1.281933,0.771071")


def recorded(robot, lengths, combine: bool):
    """(boxes lo, hi, kinds, seconds) of one search; ``combine`` False: single quads only."""
    seen = []
    decide, excluded = search.FKProblem.decide, cayley_menger.excluded

    def recording(self, lo, hi, roots):
        d = decide(self, lo, hi, roots)
        seen.append((lo.copy(), hi.copy(), d.status.copy()))
        return d

    def single(Am, Ar, P, R, qlo, qhi, order, weights):
        return excluded(Am, Ar, P, R, qlo, qhi, order, np.zeros((0, 15), np.float32))
    search.FKProblem.decide = recording
    if not combine:
        cayley_menger.excluded = single
    try:
        t = time.perf_counter()
        result = forward_kinematics(robot, lengths)
        seconds = time.perf_counter() - t
    finally:
        search.FKProblem.decide, cayley_menger.excluded = decide, excluded
    assert result.complete, "the search did not complete"
    return tuple(np.concatenate(x) for x in zip(*seen)) + (seconds,)


def postures(system, lo, hi, kind, L2):
    """The proved boxes' midpoints after 5 float Newton steps, and the Jacobian's smallest singular value there."""
    x = 0.5 * (lo[kind == PROVED] + hi[kind == PROVED])
    for _ in range(5):
        f, J = system.float_system(x, np.broadcast_to(L2, (len(x), len(L2))))
        x = x - np.linalg.solve(J, f[..., None])[..., 0]
    _, J = system.float_system(x, np.broadcast_to(L2, (len(x), len(L2))))
    x, keep = np.unique(np.round(x, 9), axis=0, return_index=True)      # a posture proved in two boxes: once
    return x, np.linalg.svd(J[keep], compute_uv=False)[:, -1]


def nearest(lo, hi, x, p):
    """Per box, the posture whose rotation is nearest to the box's quaternion midpoint."""
    q = 0.5 * (lo[:, p:] + hi[:, p:])
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    r = np.concatenate([x[:, p:], -x[:, p:]])
    out = np.empty(len(q), np.int64)
    for s in range(0, len(q), 20000):
        out[s:s + 20000] = np.argmin(np.linalg.norm(q[s:s + 20000, None] - r[None], axis=2), axis=1) % len(x)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", default=str(DIETMAIER[0]))
    ap.add_argument("--lengths", default=DIETMAIER[1])
    ap.add_argument("--top", type=int, default=10, help="postures listed (the most boxes first)")
    args = ap.parse_args()
    robot = load_robot(args.robot)
    system = fk_system(robot)
    L2 = np.array([float(v) for v in args.lengths.split(",")]) ** 2
    forward_kinematics(robot, args.lengths, max_boxes=64)        # numba's start-up and the kernels, before the clocks
    with_c = recorded(robot, args.lengths, True)
    without = recorded(robot, args.lengths, False)
    x, smin = postures(system, *without[:3], L2)
    counts = [np.bincount(nearest(lo, hi, x, system.n_pos), minlength=len(x)) for lo, hi, _, _ in (without, with_c)]
    print(f"# {Path(args.robot).stem}, lengths {args.lengths}: {len(x)} postures")
    print(f"# single quads only: {len(without[0])} boxes, {without[3]:.2f} s; with combinations: {len(with_c[0])} boxes, "
          f"{with_c[3]:.2f} s (search in this process)")
    print("| posture | smallest singular value of J | boxes nearest, single quads | with combinations |")
    print("|---:|---:|---:|---:|")
    order = np.argsort(-counts[0])
    for i in order[:args.top]:
        print(f"| {i + 1} | {smin[i]:.1e} | {counts[0][i]} | {counts[1][i]} |")
    rest = order[args.top:]
    print(f"| the other {len(rest)} | {np.min(smin[rest]) if len(rest) else 0:.1e} to {np.max(smin[rest]) if len(rest) else 0:.1e} "
          f"| {counts[0][rest].sum()} | {counts[1][rest].sum()} |")


if __name__ == "__main__":
    main()
