"""Gough-Stewart forward kinematics: certkin beside msolve, PHCpack, codac and a multistart Newton, in one run.

For each case (robot file + exact leg lengths) every method runs as a whole
process on one thread (OMP/OpenBLAS/MKL/numba threads set to 1, msolve
``-t 1``, ``phc -b`` without tasks), after one warm-up run that is not
counted; the table gives the median wall and CPU time over ``--repeat`` runs
and the peak resident memory of the process (GNU ``/usr/bin/time``: the
kernel's own accounting of the finished child):

- certkin: ``python -m certkin fk ROBOT --lengths L --json`` (default
  budget; interpreter start, imports, the search and the printing included).
  Its answer is compared with msolve's postures (``tests/oracle/msolve_fk.py``,
  ``compare``): "agrees" means every posture in exactly one proved box and
  ``complete: true``;
- msolve 0.10 (exact Groebner basis + real root isolation): the binary alone
  on the Study-parameter system of ``msolve_fk`` (one random rational chart
  c·q = 1; q, y, Study quadric, six leg quadrics), written to a file first;
- PHCpack (``phc -b``, blackbox homotopy continuation, uncertified): the same
  system with float coefficients; real solutions as PHCpack classifies them,
  and how many of them are msolve's postures (relative distance < 1e-6);
- codac (``CtcInverse`` + ``pave`` to ``--codac-eps`` on certkin's own
  equations and domain, ``benchmarks/fk.py``), capped at ``--codac-cap`` s:
  outer boxes, nothing proved; the number of connected subsets is reported;
- multistart Newton (numpy, ``benchmarks/fk.py``): batches of random starts
  until the process has used certkin's median CPU time; distinct converged roots, and
  how many of msolve's postures are among them (a Newton root proves nothing).

Usage: ``python benchmarks/fk_peers.py [--case ROBOT LENGTHS]... [--repeat 3] [--cpu 1]``
(default cases: Dietmaier's 40-posture robot and seed 002's 24-posture robot).
Needs the ``test`` extra (msolve), the ``bench`` extra (codac) and the Debian
package ``phcpack``; a missing peer is reported, not fatal.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests"))
from machine import codac_version, describe  # noqa: E402
from oracle import msolve_fk  # noqa: E402

EXAMPLES = ROOT / "examples" / "robots"
CASES = [(EXAMPLES / "dietmaier-6-6-40.toml", "1,0.645275,1.086284,1.503439,1.281933,0.771071"),
         (EXAMPLES / "seed002-general-6-6-24-solutions.toml", "1.093,2.280,2.031,2.524,3.136,1.845")]
GNU_TIME = "/usr/bin/time" if Path("/usr/bin/time").exists() else None   # Debian package "time"
ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "NUMBA_NUM_THREADS": "1", "PYTHONHASHSEED": "0"}


# ----- running a whole process ----------------------------------------------------------------------
def run_process(cmd, timeout=None, cpu=None):
    """Run ``cmd``; returns (wall s, CPU s, peak RSS MiB, exit status, stdout text, timed out).

    The command runs under GNU time (``/usr/bin/time``), which reports its child's peak RSS: a child
    forked from this Python process directly would count this process's memory in its peak."""
    # as on a user's machine, Python keeps the modules' bytecode (the warm-up run writes it)
    env = {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}, **ONE_THREAD}
    preexec = (lambda: os.sched_setaffinity(0, {cpu})) if cpu is not None else None
    with tempfile.TemporaryDirectory(prefix="fk_peers_run_") as tmp:
        usage = Path(tmp, "usage")
        full = ([GNU_TIME, "-f", "%U %S %M", "-o", str(usage)] + list(cmd)) if GNU_TIME else list(cmd)
        with open(Path(tmp, "out"), "w+") as out:
            t = time.perf_counter()
            proc = subprocess.Popen(full, stdout=out, stderr=subprocess.DEVNULL, env=env, preexec_fn=preexec,
                                    start_new_session=True)
            try:
                proc.wait(timeout=timeout)
                timed_out = False
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)     # the command and GNU time: its own process group
                proc.wait()
                timed_out = True
            wall = time.perf_counter() - t
            out.seek(0)
            text = out.read()
        cpu_s, rss = None, None
        if GNU_TIME and usage.exists():
            fields = usage.read_text().split()[-3:]
            if len(fields) == 3:
                cpu_s, rss = float(fields[0]) + float(fields[1]), float(fields[2]) / 1024
    return wall, cpu_s, rss, proc.returncode, text, timed_out


def measured(cmd, repeat, cpu=None, timeout=None, warmup=True):
    """Median wall, median CPU, max peak RSS over ``repeat`` counted runs (after one warm-up) and the
    last run's (exit status, stdout, timed out)."""
    if warmup:
        run_process(cmd, timeout, cpu)
    runs = [run_process(cmd, timeout, cpu) for _ in range(repeat)]
    last = runs[-1]
    return (statistics.median(r[0] for r in runs), _median([r[1] for r in runs]),
            _max([r[2] for r in runs]), last[3], last[4], last[5])


def _median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def _max(values):
    values = [v for v in values if v is not None]
    return max(values) if values else None


# ----- the systems -----------------------------------------------------------------------------------
def study_polys(robot_file, lengths, seed=0):
    """The Study-parameter system of the oracle (one chart), as (symbols, integer polynomials, chart)."""
    import random
    base, plat = msolve_fk.robot_geometry(robot_file)
    chart = msolve_fk.random_chart(random.Random(seed))
    syms, polys = msolve_fk.study_system(base, plat, msolve_fk.parse_lengths(lengths), chart)
    return syms, polys, chart


def phc_input(syms, polys) -> str:
    """PHCpack's input format: the number of equations, then each polynomial ending with ';'.
    Each polynomial is divided by its largest coefficient, then written with float coefficients."""
    lines = [str(len(polys))]
    for P in polys:
        scale = max(abs(int(c)) for c in P.coeffs())
        terms = []
        for m, c in zip(P.monoms(), P.coeffs()):
            factors = [f"{s}^{e}" if e > 1 else str(s) for s, e in zip(syms, m) if e]
            terms.append("*".join([repr(float(Fraction(int(c), scale)))] + factors))
        lines.append(" + ".join(terms).replace("+ -", "- ") + ";")
    return "\n".join(lines) + "\n"


def phc_real_solutions(text, syms):
    """Real solutions of a ``phc -b`` output file (PHCpack's own real/complex classification)."""
    sols = []
    for block in text.split("the solution for t :")[1:]:
        values = {}
        for line in block.splitlines()[1:]:
            m = re.match(r"\s*(\w+)\s*:\s*(\S+)\s+(\S+)", line)
            if not m:
                break
            values[m.group(1)] = (float(m.group(2)), float(m.group(3)))
        tail = block[block.find("== err"):].split("\n", 1)[0]
        if "real" in tail and all(str(s) in values for s in syms):
            sols.append([values[str(s)][0] for s in syms])
    return sols


# ----- child modes (whole processes for codac and Newton) ----------------------------------------------
def codac_child(robot_file, lengths, eps, cap):
    from fk import codac_pave
    from certkin import load_robot
    seconds, boxes, subsets, finished = codac_pave(load_robot(robot_file), lengths.split(","), eps, cap)
    print(json.dumps({"seconds": seconds, "boxes": boxes, "subsets": subsets, "finished": finished}))


def newton_child(robot_file, lengths, seconds, seed):
    """Newton from batches of random starts until the process has used ``seconds`` of CPU time (imports
    included); prints the distinct roots."""
    import numpy as np
    from fk import FloatFK, newton
    from certkin import load_robot
    fk = FloatFK(load_robot(robot_file))
    L = np.array([float(Fraction(v)) for v in lengths.split(",")])
    lo, hi = fk.domain(L)
    rng = np.random.default_rng(seed)
    roots, starts = [], 0
    while time.process_time() < seconds:
        X, conv = newton(fk, fk.random_starts(lo, hi, 2000, rng), L ** 2)
        starts += 2000
        for x in X[conv]:
            x = x.copy()
            x[3:] *= 1.0 if x[3] >= 0 else -1.0
            if not any(np.max(np.abs(x - r)) < 1e-6 for r in roots):
                roots.append(x)
    print(json.dumps({"starts": starts, "roots": [list(map(float, r)) for r in roots]}))


# ----- one case ----------------------------------------------------------------------------------------
def oracle_match(oracle, unknowns_list, tol=1e-6):
    """How many oracle postures are within ``tol`` of one of the given (x, y, z, q0..q3) points."""
    found = 0
    for p in oracle.postures:
        ref = p.floats()
        alt = ref[:3] + [-v for v in ref[3:]]
        if any(max(abs(a - b) for a, b in zip(u, ref)) < tol or max(abs(a - b) for a, b in zip(u, alt)) < tol
               for u in unknowns_list):
            found += 1
    return found


def run_case(robot_file, lengths, args, rows):
    name = Path(robot_file).stem
    oracle = msolve_fk.solve(robot_file, lengths)
    n = len(oracle)
    print(f"# {name}: msolve finds {n} real postures of {oracle.complex_count} complex", flush=True)
    tmp = Path(tempfile.mkdtemp(prefix="fk_peers_"))

    # certkin
    cmd = [sys.executable, "-m", "certkin", "fk", str(robot_file), "--lengths", lengths, "--json"] + args.certkin_arg
    wall, cpu, rss, code, out, _ = measured(cmd, args.repeat, args.cpu, timeout=args.timeout)
    certkin_wall, certkin_cpu = wall, cpu
    try:
        doc = json.loads(out)
        try:
            msolve_fk.compare(doc, oracle)
            agree = "agrees with msolve"
        except AssertionError as exc:
            agree = "differs from msolve: " + str(exc).splitlines()[1].strip()
        note = (f"{len(doc['solutions'])} proved unique, {len(doc['unresolved'])} unresolved, "
                f"complete={doc['complete']}, {doc['stats']['boxes']} boxes; {agree}")
        found = len(doc["solutions"])
    except (json.JSONDecodeError, KeyError):
        note, found = f"exit {code}, no JSON", "-"
    rows.append((name, "certkin fk (certified)", wall, cpu, rss, found, n, note))

    # msolve
    syms, polys, chart = study_polys(robot_file, lengths)
    src = tmp / "study.ms"
    src.write_text(msolve_fk.msolve_input(syms, polys))
    dst = tmp / "study.out"
    cmd = [msolve_fk.msolve_binary(), "-f", str(src), "-o", str(dst), "-t", "1"]
    wall, cpu, rss, code, _, _ = measured(cmd, args.repeat, args.cpu, timeout=args.timeout)
    status, _, boxes = msolve_fk.parse_msolve_output(dst.read_text())
    rows.append((name, "msolve (exact, one chart)", wall, cpu, rss, len(boxes), n,
                 f"{status}; real root isolation, 128-bit boxes"))

    # PHCpack
    if shutil.which("phc"):
        src = tmp / "study.phc"
        src.write_text(phc_input(syms, polys))
        dst = tmp / "study.phc.out"

        def phc():
            dst.unlink(missing_ok=True)
            return run_process(["phc", "-b", str(src), str(dst)], args.timeout, args.cpu)
        phc()
        runs = [phc() for _ in range(args.repeat)]
        reals = phc_real_solutions(dst.read_text(), syms)
        matched = 0
        for p in oracle.postures:        # those of the chart written for msolve and PHCpack (the first)
            ref = [float(Fraction(lo + hi) / 2) for lo, hi in p.study]
            if p.chart == chart and any(
                    max(abs(a - b) for a, b in zip(s, ref)) < 1e-6 * max(1.0, max(map(abs, ref))) for s in reals):
                matched += 1
        rows.append((name, "PHCpack phc -b (homotopy, uncertified)", statistics.median(r[0] for r in runs),
                     _median([r[1] for r in runs]), _max([r[2] for r in runs]), len(reals), n,
                     f"{matched} of msolve's postures among its real solutions"))
    else:
        rows.append((name, "PHCpack", None, None, None, "-", n, "phc not installed (apt-get install phcpack)"))

    # codac
    if codac_version():
        cmd = [sys.executable, __file__, "--codac-child", str(robot_file), lengths, str(args.codac_eps),
               str(args.codac_cap)]
        wall, cpu, rss, code, out, timed_out = measured(cmd, 1, args.cpu, timeout=args.codac_cap + 30,
                                                        warmup=False)
        if timed_out or not out.strip():
            note, found = f"did not finish in {args.codac_cap:.0f} s (killed)", "-"
        else:
            o = json.loads(out)
            found = "-" if not o["finished"] else o["subsets"]
            note = (f"{o['subsets']} connected subsets, {o['boxes']} boxes, none proved"
                    + ("" if o["finished"] else f"; stopped by its {args.codac_cap:.0f} s cap"))
        rows.append((name, f"codac CtcInverse+pave eps={args.codac_eps:g} (one run)", wall, cpu, rss, found, n, note))
    else:
        rows.append((name, "codac", None, None, None, "-", n, "codac not installed (pip install 'certkin[bench]')"))

    # multistart Newton, for certkin's CPU time
    budget = certkin_cpu if certkin_cpu is not None else certkin_wall
    cmd = [sys.executable, __file__, "--newton-child", str(robot_file), lengths, f"{budget:.3f}", "0"]
    wall, cpu, rss, code, out, _ = measured(cmd, 1, args.cpu, timeout=4 * budget + 120, warmup=False)
    o = json.loads(out)
    matched = oracle_match(oracle, o["roots"])
    rows.append((name, f"multistart Newton, {budget:.1f} s CPU of starts (one run)", wall, cpu, rss,
                 len(o["roots"]), n, f"{o['starts']} starts; {matched} of msolve's postures found"))
    shutil.rmtree(tmp, ignore_errors=True)


def print_table(rows):
    print("| robot | method | wall s (median) | CPU s (median) | peak RSS MiB | real postures | msolve | notes |")
    print("|---|---|---:|---:|---:|---:|---:|---|")
    fmt = lambda v, d: "-" if v is None else f"{v:.{d}f}"  # noqa: E731
    for name, method, wall, cpu, rss, found, n, note in rows:
        print(f"| {name} | {method} | {fmt(wall, 2)} | {fmt(cpu, 2)} | {fmt(rss, 0)} | {found} | {n} | {note} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", nargs=2, action="append", metavar=("ROBOT", "LENGTHS"),
                    help="robot file and exact leg lengths (repeatable; default: Dietmaier and seed 002)")
    ap.add_argument("--repeat", type=int, default=3, help="counted runs per method (median)")
    ap.add_argument("--cpu", type=int, help="pin every process to this CPU")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds allowed to each run")
    ap.add_argument("--codac-cap", type=float, default=60.0, help="seconds allowed to codac's pave")
    ap.add_argument("--codac-eps", type=float, default=1e-9, help="codac pave resolution")
    ap.add_argument("--certkin-arg", action="append", default=[], help="extra argument for certkin fk")
    ap.add_argument("--codac-child", nargs=4, help=argparse.SUPPRESS)
    ap.add_argument("--newton-child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.codac_child:
        robot, lengths, eps, cap = args.codac_child
        return codac_child(robot, lengths, float(eps), float(cap))
    if args.newton_child:
        robot, lengths, seconds, seed = args.newton_child
        return newton_child(robot, lengths, float(seconds), int(seed))
    phc = subprocess.run(["phc", "--version"], capture_output=True, text=True).stdout.strip() \
        if shutil.which("phc") else "phc not installed"
    ms = subprocess.run([msolve_fk.msolve_binary(), "-V"], capture_output=True, text=True).stdout.strip()
    print(f"# FK peers; {describe()}; msolve {ms}; {phc}; codac {codac_version() or 'not installed'}; "
          f"{time.strftime('%Y-%m-%d %H:%M')}", flush=True)
    rows = []
    for robot, lengths in (args.case or [(str(r), l) for r, l in CASES]):
        run_case(robot, lengths, args, rows)
    print()
    print_table(rows)


if __name__ == "__main__":
    sys.exit(main())
