"""Uncertain leg lengths (issue #16 item 6): how tight are the mode boxes?

For each case and relative tolerance t, the lengths become ranges [L (1 − t), L (1 + t)] (exact
decimals) and certkin returns one box per mode, proved to hold that mode's posture for every length
vector in the ranges.  The reference is the true spread of each mode: its postures at the 2^n corners
of the length box, found by Newton's method (float64, own equations: |p + R b_i − a_i|² = ρ_i² and the
unit constraint, written here, not certkin's) started at the box midpoint.  Per unknown, the ratio
box width / spread is reported (max and median over the modes proved unique; a mode whose
uniqueness cannot be proved over the whole length box is returned as a cluster and counted); a ratio below 1 would mean a corner
posture outside its box, which is counted and must be 0.

    python benchmarks/fk_tolerance.py [--only NAME ...] [--tolerances 1e-3 1e-6]

CPU seconds (``time.process_time``) of the FK call, in this process.
"""
from __future__ import annotations

import argparse
import itertools
import time
from decimal import Decimal
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "robots"

CASES = {   # name: (robot, nominal lengths)
    "planar-6-modes": ({"kind": "planar-3rpr", "base": [["3.78", "4.34"], ["34.47", "-3.78"], ["16.233", "34.76"]],
                        "platform": [["-4.83", "-3.19"], ["12.04", "-3.19"], ["8.23", "12.09"]]},
                       ["28.99", "13.66", "40.53"]),
    "seed002-24": (EXAMPLES / "seed002-general-6-6-24-solutions.toml", ["1.093", "2.280", "2.031", "2.524", "3.136", "1.845"]),
}


def ranges(lengths, tol: str):
    """Exact decimal ranges [L (1 − t), L (1 + t)] as "lo:hi" texts."""
    t = Decimal(tol)
    return [f"{Decimal(v) * (1 - t)}:{Decimal(v) * (1 + t)}" for v in lengths]


def rotation(u):
    """R of the unknowns' rotation part: (c, s) planar, unit quaternion (q0..q3) spatial."""
    if len(u) == 2:
        c, s = u
        return np.array([[c, -s], [s, c]])
    q0, q1, q2, q3 = u
    return np.array([[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                     [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
                     [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]])


def residual(x, a, b, L2):
    """Leg equations |p + R b_i − a_i|² − ρ_i² and |u|² − 1 at unknowns x = (p, u)."""
    d = a.shape[1]
    p, u = x[:d], x[d:]
    legs = p + b @ rotation(u).T - a
    return np.concatenate([(legs * legs).sum(1) - L2, [u @ u - 1]])


def newton(x, a, b, L2, steps=40):
    """Newton's method with a forward-difference-free Jacobian (complex step), float64; the system
    is square for planar (3 legs + 1) and Gough-Stewart (6 legs + 1) robots."""
    for _ in range(steps):
        f = residual(x, a, b, L2)
        J = np.empty((len(f), len(x)))
        for j in range(len(x)):
            h = np.zeros(len(x), dtype=complex)
            h[j] = 1e-30j
            J[:, j] = residual(x + h, a, b, L2).imag / 1e-30
        dx = np.linalg.lstsq(J, -f, rcond=None)[0]
        x = x + dx
        if np.max(np.abs(dx)) < 1e-15 * max(1.0, np.max(np.abs(x))):
            break
    return x, float(np.max(np.abs(residual(x, a, b, L2))))


def measure(name, tol):
    from certkin import load_robot, robot_from_dict
    from certkin.fk import forward_kinematics
    spec, nominal = CASES[name]
    robot = robot_from_dict(spec) if isinstance(spec, dict) else load_robot(spec)
    texts = ranges(nominal, tol)
    t = time.process_time()
    r = forward_kinematics(robot, texts)
    cpu = time.process_time() - t
    a = np.array([[float(c) for c in p] for p in robot.base])
    b = np.array([[float(c) for c in p] for p in robot.platform])
    lo = [float(v.split(":")[0]) for v in texts]
    hi = [float(v.split(":")[1]) for v in texts]
    ratios, outside, worst_res = [], 0, 0.0
    for s in r.solutions:
        box_lo, box_hi = np.asarray(s["box"].lo, dtype=float), np.asarray(s["box"].hi, dtype=float)
        pts = []
        for corner in itertools.product(*zip(lo, hi)):
            x, res = newton(0.5 * (box_lo + box_hi), a, b, np.array(corner) ** 2)
            worst_res = max(worst_res, res)
            outside += int(np.any(x < box_lo) or np.any(x > box_hi))
            pts.append(x)
        pts = np.array(pts)
        spread = pts.max(0) - pts.min(0)
        ratios.append((box_hi - box_lo) / np.maximum(spread, 1e-300))
    ratios = np.array(ratios)
    return {"case": name, "tol": tol, "modes": len(r.solutions), "clusters": len(r.clusters), "complete": r.complete,
            "boxes": r.boxes, "cpu": cpu, "names": list(r.system.names) if hasattr(r.system, "names") else None,
            "max": ratios.max(0) if len(ratios) else None, "median": np.median(ratios, 0) if len(ratios) else None,
            "outside": outside, "residual": worst_res}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=list(CASES))
    ap.add_argument("--tolerances", nargs="*", default=["1e-3", "1e-6"])
    args = ap.parse_args()
    print("| case | relative tolerance | unique modes | clusters | complete | boxes | CPU s "
          "| box/spread per unknown, max over unique modes | median | corner postures outside their box |")
    print("|---|---|---:|---:|---|---:|---:|---|---|---:|")
    for name in args.only or CASES:
        for tol in args.tolerances:
            d = measure(name, tol)
            fmt = lambda v: "-" if v is None else " ".join(f"{x:.2f}" for x in v)  # noqa: E731
            print(f"| {name} | {tol} | {d['modes']} | {d['clusters']} | {d['complete']} | {d['boxes']} | {d['cpu']:.2f} | {fmt(d['max'])} | "
                  f"{fmt(d['median'])} | {d['outside']} |", flush=True)


if __name__ == "__main__":
    main()
