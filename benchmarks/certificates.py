"""Certificates of every benchmark workload: size, write overhead, check time and memory.

For each workload (those of ``docs/benchmarks.md``), in fresh processes:

- the solve alone and the solve with its certificate written (``Document.write``): median CPU
  time of ``--repeat`` runs and peak RSS (the write overhead is the ratio; targets <= 1.3x the
  time and <= 1.2x the memory);
- the file's size;
- ``proofs.check(FILE)`` in a fresh process: median CPU time of the check itself (imports
  excluded, as for the solve) and the process's peak RSS; targets: the seed 002 certificate
  <= 60 s and <= 1 GiB, the 1000 cells <= 1 s, any certificate <= 10x its solve time.

CPU time (``os.wait4``) is reported because other jobs share the machine; the load average is in
the header line.  Usage: ``python benchmarks/certificates.py [--repeat 3] [--only NAME]``.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
ROBOTS = ROOT / "examples" / "robots"
sys.path.insert(0, str(HERE))
from machine import describe  # noqa: E402

GOUGH_LENGTHS = "1.093,2.280,2.031,2.524,3.136,1.845"
MEL_START, MEL_GOAL = "-69,-50,500,85deg,10deg,0", "84,92,500,85deg,10deg,0"

WORKLOADS = {
    "cells": "seed 003 planar example 2, 10x10x10 cells",
    "planar-fk": "planar 3-RPR FK, 6-mode instance",
    "planar-batch": "planar 3-RPR FK, batch of 1000 leg-length sets",
    "gough-track": "Gough-Stewart FK tracking step (seed 002)",
    "gough-fk": "Gough-Stewart FK, seed 002 24-solution robot",
    "gough-box": "Gough-Stewart 6-D singularity box (50 000 boxes)",
    "trajectory": "seed 000 straight-line trajectory, all constraints",
    "trajectory-batch": "batch of 200 trajectories, feasibility",
    "varying": "varying orientation trajectory",
    "workspace": "seed 004 workspace section z = 20005",
}


def prepare(name):
    """A function that solves the workload (its inputs prepared here, outside the timing)."""
    import numpy as np
    from certkin import load_robot, robot_from_dict
    from certkin.engine import Budget
    from certkin.fk import forward_kinematics
    from certkin.singularity import certify_singularity_free, classify_cells
    from certkin.trajectory import parse_path, verify_trajectories, verify_trajectory
    from certkin.workspace import workspace_section
    if name == "cells":
        ex2 = load_robot(ROBOTS / "seed003-planar-example-2.toml")
        return lambda: classify_cells(ex2, "x=-50:50,y=-50:50,phi=0:0.7853981634", 10)
    planar = robot_from_dict({"kind": "planar-3rpr", "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
                              "platform": [["0", "0"], ["17.04", "0"], ["13.236", "16.097"]]})
    if name == "planar-fk":
        return lambda: forward_kinematics(planar, ["14.98", "15.38", "12"])
    if name == "planar-batch":
        home = np.array([float(0.5 * (v.lo + v.hi)) for v in forward_kinematics(planar, ["14.98", "15.38", "12"])
                         .solutions[0]["pose"].values()])
        poses = home + np.random.default_rng(0).uniform(-1, 1, (1000, 3)) * np.array([1.0, 1.0, 0.1])
        L = planar.leg_lengths_float(poses)
        return lambda: forward_kinematics(planar, L)
    gough = load_robot(ROBOTS / "seed002-general-6-6-24-solutions.toml")
    if name == "gough-track":
        full = forward_kinematics(gough, GOUGH_LENGTHS)
        pose = ",".join(repr(float(0.5 * (v.lo + v.hi))) for v in full.solutions[0]["pose"].values())
        return lambda: forward_kinematics(gough, GOUGH_LENGTHS, track=pose)
    if name == "gough-fk":
        return lambda: forward_kinematics(gough, GOUGH_LENGTHS)
    if name == "gough-box":
        main_gauche = load_robot(ROBOTS / "seed002-main-gauche.toml")
        return lambda: certify_singularity_free(main_gauche, "x=-5:5,y=-5:5,z=40:60,psi=-0.5:0.5,theta=-0.5:0.5,"
                                                "phi=-0.5:0.5", budget=Budget(max_boxes=50_000, max_seconds=60))
    mel = load_robot(ROBOTS / "seed000-mel-tsukuba.toml")
    if name == "trajectory":
        return lambda: verify_trajectory(mel, MEL_START, MEL_GOAL)
    if name == "trajectory-batch":
        rng, paths = np.random.default_rng(0), []
        for _ in range(200):
            a, b = rng.uniform(-60, 60, 2), rng.uniform(-60, 60, 2)
            paths.append(parse_path(mel, f"{a[0]:.2f},{a[1]:.2f},520,85deg,10deg,0", f"{b[0]:.2f},{b[1]:.2f},520,85deg,10deg,0"))
        return lambda: verify_trajectories(mel, paths, indices=False, rtol=None)
    if name == "varying":
        return lambda: verify_trajectory(mel, "-69,-50,500,85deg,10deg,0", "84,92,500,95deg,5deg,0", indices=False)
    if name == "workspace":
        micro = load_robot(ROBOTS / "seed004-micro-manipulator.toml")
        return lambda: workspace_section(micro, "0,0,0", "20005")
    raise SystemExit(f"unknown workload {name}")


def document(result):
    from certkin.certificates import fk_certificate, singularity_certificate, trajectory_certificate
    if isinstance(result, list):
        kind = type(result[0]).__name__
        return {"SingularityResult": singularity_certificate, "FKResult": fk_certificate,
                "TrajectoryResult": trajectory_certificate}[kind](result)
    return result.certificate()


def child(name, path, warm):
    """One run in this process: (optionally) a warm-up solve, then the measured solve and write."""
    solve = prepare(name)
    if warm:                         # compiled kernels and models, modules loaded: a user's second run
        first = solve()
        if path:
            document(first).write(path)
    t = time.process_time()
    result = solve()
    if path:
        document(result).write(path)
    print(f"cpu {time.process_time() - t}")


def run(argv):
    """(CPU seconds of the child, peak RSS in MiB)."""
    proc = subprocess.Popen([sys.executable, *argv], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, cwd=ROOT)
    out = proc.stdout.read().decode()
    _, status, usage = os.wait4(proc.pid, 0)
    if status:
        raise SystemExit(f"{argv} failed: {out}")
    cpu = next((float(line.split()[1]) for line in out.splitlines() if line.startswith("cpu ")), None)
    return (cpu if cpu is not None else usage.ru_utime + usage.ru_stime), usage.ru_maxrss / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--child", nargs=2, metavar=("NAME", "PATH"), help=argparse.SUPPRESS)
    ap.add_argument("--check", metavar="PATH", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args.child[0], None if args.child[1] == "-" else args.child[1], warm=True)
    if args.check:
        import proofs
        t = time.process_time()
        report = proofs.check(args.check)
        assert report.ok, report.step
        return print(f"cpu {time.process_time() - t}")
    print(f"# {describe()}")
    print(f"{'workload':52s} {'solve s':>8s} {'+cert s':>8s} {'ratio':>6s} {'solve MiB':>9s} {'+cert MiB':>9s} "
          f"{'ratio':>6s} {'size':>9s} {'check s':>8s} {'check MiB':>9s}")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.only or WORKLOADS:
            path = Path(tmp) / f"{name}.cert"
            me = [str(Path(__file__).resolve()), "--child", name]
            alone = [run(me + ["-"]) for _ in range(args.repeat)]
            both = [run(me + [str(path)]) for _ in range(args.repeat)]
            check = [run([str(Path(__file__).resolve()), "--check", str(path)]) for _ in range(args.repeat)]
            s0, s1 = statistics.median(a[0] for a in alone), statistics.median(b[0] for b in both)
            m0, m1 = max(a[1] for a in alone), max(b[1] for b in both)
            c, cm = statistics.median(c[0] for c in check), max(c[1] for c in check)
            size = path.stat().st_size
            print(f"{WORKLOADS[name]:52s} {s0:8.3f} {s1:8.3f} {s1 / s0:6.2f} {m0:9.0f} {m1:9.0f} {m1 / m0:6.2f} "
                  f"{size / 1e6:8.3f}M {c:8.2f} {cm:9.0f}", flush=True)


if __name__ == "__main__":
    main()
