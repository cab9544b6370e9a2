"""Forward-kinematics cases of issue #16, each in a fresh process: the planar mode at phi = 0, the
seed 002 24-solution robot, main gauche at home, Dietmaier's 40 postures, random general 6-6
robots, and uncertain leg lengths (box / spread of the postures at the corners of the length box).

Per case: postures proved unique, clusters, complete, boxes, CPU seconds of the search (in the
process), CPU and wall seconds of the whole process (imports, robot file, search, printing) and its
peak RSS.  One thread (OPENBLAS_NUM_THREADS=1).  Prints a markdown table.

    python benchmarks/fk_cases.py [--only NAME ...]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "robots"

CASES = {
    "planar-phi0": ("planar", '{"kind": "planar-3rpr", "base": [[0, 0], [10, 0], [3, 10]], "platform": [[0, 0], [4, 0], [2, 2]]}',
                    "7.071067811865475244008444,5.099019513592784830028224,5"),
    "seed002-24": ("file", EXAMPLES / "seed002-general-6-6-24-solutions.toml", "1.093,2.280,2.031,2.524,3.136,1.845"),
    "main-gauche-home": ("file", EXAMPLES / "seed002-main-gauche.toml", "home"),
    "dietmaier-40": ("file", EXAMPLES / "dietmaier-6-6-40.toml", "1,0.645275,1.086284,1.503439,1.281933,0.771071"),
    "planar-6-tolerance": ("planar", '{"kind": "planar-3rpr", "base": [[3.78, 4.34], [34.47, -3.78], [16.233, 34.76]], '
                           '"platform": [[-4.83, -3.19], [12.04, -3.19], [8.23, 12.09]]}', "28.99:29.01,13.66,40.53"),
    "seed002-tolerance": ("file", EXAMPLES / "seed002-general-6-6-24-solutions.toml",
                          "1.093+-0.000001,2.280+-0.000001,2.031+-0.000001,2.524+-0.000001,3.136+-0.000001,1.845+-0.000001"),
}

CHILD = r'''
import json, sys, time
t0 = time.process_time()
from certkin import load_robot, robot_from_dict
from certkin.fk import forward_kinematics
kind, spec, lengths = sys.argv[1:4]
robot = robot_from_dict(json.loads(spec)) if kind == "planar" else load_robot(spec)
if lengths == "home":
    lengths = ",".join(repr(float(v)) for v in robot.leg_lengths(robot.home_box()).mid())
t1 = time.process_time()
r = forward_kinematics(robot, lengths)
t2 = time.process_time()
ratio = None
if ":" in ",".join(r.lengths) and r.solutions:
    import itertools
    import numpy as np
    lo = [float(t.split(":")[0]) if ":" in t else float(t) for t in r.lengths]
    hi = [float(t.split(":")[-1]) for t in r.lengths]
    worst = 0.0
    for s in r.solutions:
        x0, pts = s["box"].mid(), []
        for corner in itertools.product(*zip(lo, hi)):
            x, L2 = x0.copy(), np.array(corner) ** 2
            for _ in range(30):
                f, J = r.system.float_system(x, L2)
                x = x - np.linalg.solve(J, f)
            pts.append(x)
        pts = np.array(pts)
        spread = np.maximum(pts.max(0) - pts.min(0), 1e-300)
        worst = max(worst, float(np.max((s["box"].hi - s["box"].lo) / spread)))
    ratio = worst
print(json.dumps({"unique": len(r.solutions), "clusters": len(r.clusters), "complete": r.complete, "boxes": r.boxes,
                  "search_cpu": t2 - t1, "setup_cpu": t1 - t0, "ratio": ratio}))
'''


def run(name):
    kind, spec, lengths = CASES[name]
    if kind == "file" and not Path(spec).exists():
        return None
    env = dict({k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"},   # bytecode kept, as for a user
               OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    w = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", CHILD, kind, str(spec), lengths], capture_output=True, text=True,
                         env=env, check=True)
    wall = time.perf_counter() - w
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    doc = json.loads(out.stdout.strip().splitlines()[-1])
    doc.update(name=name, wall=wall, cpu=(after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime),
               rss_mib=after.ru_maxrss / 1024)
    return doc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=list(CASES), help="cases to run (default: all)")
    args = ap.parse_args()
    print("| case | unique | clusters | complete | boxes | search CPU s | process CPU s | process wall s | peak RSS MiB | box/spread |")
    print("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|")
    for name in args.only or CASES:
        d = run(name)
        if d is None:
            print(f"| {name} | (robot file missing) |")
            continue
        ratio = "" if d["ratio"] is None else f"{d['ratio']:.2f}"
        print(f"| {name} | {d['unique']} | {d['clusters']} | {d['complete']} | {d['boxes']} | {d['search_cpu']:.2f} | "
              f"{d['cpu']:.2f} | {d['wall']:.2f} | {d['rss_mib']:.0f} | {ratio} |", flush=True)


if __name__ == "__main__":
    main()
