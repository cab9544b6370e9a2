"""Trajectory benchmark: seed 000 MEL robot, constant orientation, all constraints.

Side by side in one run:

- certkin ``verify_trajectory`` on the Fig. 1.8 path (single trajectory, certified, with
  margins refined to 1e-4 relative and the mean indices) and in feasibility-only mode;
- certkin ``verify_trajectories`` on a batch of random constant-orientation paths (one search);
- dense numpy sampling at a step of 1e-4 (10 001 instants, leg lengths and exact segment
  distances of the 15 pairs, uncertified), the fast alternative a user might write;
- a varying-orientation path (psi 85deg -> 95deg, theta 10deg -> 5deg), with margins and
  feasibility only.

Usage: ``taskset -c 0 python benchmarks/trajectory.py [--repeat 5] [--batch 200]``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from certkin import load_robot, verify_trajectories, verify_trajectory
from certkin.trajectory import parse_path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import describe, median_time  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
START, GOAL = "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"


def sampled(robot, step=1e-4):
    """Uncertified dense sampling: leg lengths and pairwise segment distances at every step."""
    from certkin.robots.spherical import rotation_float
    ts = np.arange(0.0, 1.0 + step / 2, step)
    P0 = np.array([-69, -50, 500, np.deg2rad(85), np.deg2rad(10), 0.0])
    P1 = np.array([84, 92, 500, np.deg2rad(85), np.deg2rad(10), 0.0])
    poses = P0 + ts[:, None] * (P1 - P0)
    A = np.array([[float(c) for c in p] for p in robot.base])
    b = np.array([[float(c) for c in p] for p in robot.platform])
    R = rotation_float("gough-stewart", poses)
    B = poses[:, None, :3] + np.einsum("tij,kj->tki", R, b)
    rho = np.linalg.norm(B - A, axis=-1)
    i, j = np.triu_indices(6, 1)
    p1, q1, p2, q2 = A[i][None], B[:, i], A[j][None], B[:, j]
    u, v, w0 = q1 - p1, q2 - p2, p1 - p2
    dot = lambda x, y: np.sum(x * y, axis=-1)  # noqa: E731
    a, bb, c, d, e = dot(u, u), dot(u, v), dot(v, v), dot(u, w0), dot(v, w0)
    den = a * c - bb * bb
    s = np.clip((bb * e - c * d) / den, 0, 1)
    t = np.clip((bb * s + e) / c, 0, 1)
    s = np.clip((bb * t - d) / a, 0, 1)
    dist = np.linalg.norm(w0 + s[..., None] * u - t[..., None] * v, axis=-1)
    return rho.min(0), dist.min(0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--batch", type=int, default=200)
    args = ap.parse_args()
    print(describe())
    robot = load_robot(ROOT / "examples" / "robots" / "seed000-mel-tsukuba.toml")
    verify_trajectory(robot, START, GOAL)          # compile once
    rows = []
    t_cert = median_time(lambda: verify_trajectory(robot, START, GOAL), args.repeat)
    t_feas = median_time(lambda: verify_trajectories(robot, [parse_path(robot, START, GOAL)], indices=False,
                                                     rtol=None), args.repeat)
    t_samp = median_time(lambda: sampled(robot), args.repeat)
    rng = np.random.default_rng(0)
    paths = []
    for _ in range(args.batch):
        a, b = rng.uniform(-60, 60, 2), rng.uniform(-60, 60, 2)
        paths.append(parse_path(robot, f"{a[0]:.2f},{a[1]:.2f},520,85deg,10deg,0", f"{b[0]:.2f},{b[1]:.2f},520,85deg,10deg,0"))
    t_batch = median_time(lambda: verify_trajectories(robot, paths, indices=False, rtol=None), max(1, args.repeat // 2))
    t_batch_m = median_time(lambda: verify_trajectories(robot, paths, indices=False), max(1, args.repeat // 2))
    vary = ("-69,-50,500,85deg,10deg,0", "84,92,500,95deg,5deg,0")
    t_vary = median_time(lambda: verify_trajectory(robot, *vary, indices=False), args.repeat)
    t_vary_f = median_time(lambda: verify_trajectories(robot, [parse_path(robot, *vary)], indices=False, rtol=None),
                           args.repeat)
    rows.append(("Fig. 1.8 path, certified + margins + indices", t_cert * 1e3, "ms"))
    rows.append(("Fig. 1.8 path, certified feasibility only", t_feas * 1e3, "ms"))
    rows.append(("Fig. 1.8 path, numpy sampling step 1e-4 (uncertified)", t_samp * 1e3, "ms"))
    rows.append((f"batch of {args.batch} paths, feasibility only", args.batch / t_batch, "paths/s"))
    rows.append((f"batch of {args.batch} paths, with margins", args.batch / t_batch_m, "paths/s"))
    rows.append(("varying orientation path, certified + margins", t_vary * 1e3, "ms"))
    rows.append(("varying orientation path, certified feasibility only", t_vary_f * 1e3, "ms"))
    print(f"{'workload':58s} {'median':>12s}")
    for name, v, unit in rows:
        print(f"{name:58s} {v:10.2f} {unit}")
    print(f"ratio certified (feasibility only) / sampling: {t_feas / t_samp:.2f}")


if __name__ == "__main__":
    main()
