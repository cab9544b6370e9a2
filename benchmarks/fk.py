"""Forward-kinematics benchmark: certkin's certified FK against its peers, in one run.

Workloads (DESIGN.md "Performance targets"):

- planar 3-RPR, a 6-mode instance (base (0,0) (15.91,0) (0,10), platform
  (0,0) (17.04,0) (13.236,16.097), lengths 14.98, 15.38, 12): one instance,
  and a batch of ``--batch`` leg-length sets from random poses near a home
  pose (one of the six modes), computed by ``robot.leg_lengths_float``;
- spherical 3-DOF, an 8-mode instance (seed 003 Table 4.13 design, lengths
  2.277, 2.473, 1.902);
- Gough-Stewart, seed 002 general 6-6 robot (24 real postures): tracking
  (``track=`` a pose fitted to posture 1 of Table VI.2, as in
  tests/test_fk.py), and optionally (``--gough-full SECONDS``) the
  full-domain search for all 24 postures under a time cap (median of
  ``--gough-repeat`` runs, and in 3 fresh processes, from their first
  statement: imports, robot file and search, the machine-code kernels
  already compiled and cached);
- tracking sequences (``--steps`` steps, ``certkin.fk.track_sequence``):
  Gough from that posture out and back along a smooth motion (up to 2 cm
  and 0.6 deg), planar from mode 1 of the 6-mode instance around a smooth
  closed motion (x ± 0.5, y up to +0.6, phi ± 0.05 rad); and the planar
  steps one call at a time (``forward_kinematics(track=)`` from the
  previous pose).  Peer: numpy Newton from the previous pose, step after
  step.  ``--only tracking`` runs the tracking rows alone.

Peers, on the same equations (platform origin + rotation as unit complex
number / unit quaternion, ``certkin.fk.system``) and the same domain:

- numpy Newton from many starts (vectorised over starts and instances;
  Jacobian by complex step): fast, finds roots, proves nothing (a root may be
  missed, and nothing says two converged starts are distinct roots);
- codac (if installed): ``CtcInverse`` + ``pave`` down to ``eps``; its boxes
  are an outer enclosure of the solution set (no existence or uniqueness
  proof); runs are capped by ``--codac-cap`` seconds.

Usage: ``taskset -c 0 python benchmarks/fk.py [--repeat 5] [--batch 1000] [--only tracking]``.
Prints one table: workload, certkin median, peer median, ratio
(certkin / peer: below 1 means certkin is faster), target, met?
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import statistics
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from certkin import load_robot, robot_from_dict
from certkin.engine import Budget
from certkin.fk import forward_kinematics

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import describe  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
GOUGH_FILE = ROOT / "examples" / "robots" / "seed002-general-6-6-24-solutions.toml"
TABLE_VI2 = ROOT / "tests" / "data" / "seed002_table_vi2.txt"

PLANAR = {"kind": "planar-3rpr", "base": [["0", "0"], ["15.91", "0"], ["0", "10"]],
          "platform": [["0", "0"], ["17.04", "0"], ["13.236", "16.097"]]}
PLANAR_LENGTHS = ["14.98", "15.38", "12"]
SPHERICAL = {"kind": "spherical-3dof", "base": [["1.6", "0", "-1.2"], ["-1.1", "1.2", "-1.2"], ["-0.9", "-1", "-1.2"]],
             "platform": [["1", "0", "0"], ["-0.6", "1", "0"], ["-0.2", "-0.5", "0"]]}
SPHERICAL_LENGTHS = ["2.277", "2.473", "1.902"]
GOUGH_LENGTHS = "1.093,2.280,2.031,2.524,3.136,1.845"
DELTA = 2.0 ** -10   # q0 >= -DELTA, as certkin's domain (one representative per rotation)


def fresh_process_seconds(repeat=3):
    """Median wall seconds of the Gough robot's full-domain FK in a new Python process, from its first
    statement (imports, reading the robot file, the search; the machine-code kernels already cached on
    disk), over ``repeat`` processes."""
    import subprocess
    code = ("import time; t = time.perf_counter(); from certkin import load_robot; "
            "from certkin.fk import forward_kinematics; "
            f"r = forward_kinematics(load_robot({str(GOUGH_FILE)!r}), {GOUGH_LENGTHS!r}); "
            "assert r.complete and len(r.solutions) == 24; print(time.perf_counter() - t)")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)     # fills the kernel cache
    runs = [subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
            for _ in range(repeat)]
    return statistics.median(float(out.stdout.strip().splitlines()[-1]) for out in runs)


def timed(fn, repeat):
    """(median wall seconds, last result) over ``repeat`` calls; the median CPU seconds of the
    process are left in ``timed.cpu`` (on a shared core, wall time includes waiting for it)."""
    times, cpu, out = [], [], None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    timed.cpu = statistics.median(cpu)
    return statistics.median(times), out


# ----- the FK equations in floats (peers) ----------------------------------------------------
class FloatFK:
    """The FK system of ``certkin.fk.system`` in plain floats (works on complex too).

    Unknowns: planar (x, y, c, s); spherical (q0..q3); Gough (x, y, z, q0..q3).
    """

    def __init__(self, robot):
        n, dim = robot.n_legs, robot.dim
        geom = np.array([float(Fraction(t)) for t in robot.geometry_texts()])
        self.a = geom[:n * dim].reshape(n, dim)
        self.b = geom[n * dim:].reshape(n, dim)
        self.kind = robot.kind
        self.n_pos = {"planar-3rpr": 2, "spherical-3dof": 0, "gough-stewart": 3}[robot.kind]
        self.n = self.n_pos + (2 if robot.kind == "planar-3rpr" else 4)

    def rotation(self, X):
        p = self.n_pos
        if self.kind == "planar-3rpr":
            c, s = X[..., 2], X[..., 3]
            return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
        q0, q1, q2, q3 = (X[..., p + k] for k in range(4))
        rows = [[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
                [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]]
        return np.stack([np.stack(r, -1) for r in rows], -2)

    def residual(self, X, L2):
        """X (..., n), L2 (..., legs) squared lengths (broadcast) -> (..., n)."""
        R = self.rotation(X)
        ell = np.einsum("...ij,lj->...li", R, self.b) - self.a
        if self.n_pos:
            ell = ell + X[..., None, :self.n_pos]
        legs = np.sum(ell * ell, -1) - L2
        rot = X[..., self.n_pos:]
        return np.concatenate([legs, np.sum(rot * rot, -1, keepdims=True) - 1], -1)

    def jacobian(self, X, L2):
        """Complex-step Jacobian (exact to rounding for these polynomials)."""
        h = 1e-30
        Z = X[..., None, :] + 1j * h * np.eye(self.n)          # (..., n perturbations, n)
        F = self.residual(Z, np.asarray(L2)[..., None, :])    # (..., n perturbations, n equations)
        return np.swapaxes(F.imag / h, -1, -2)

    def domain(self, L):
        """Float box (n,) lo, hi: as certkin's (|p - a_i| <= rho_i + |b_i|; rotation in [-1, 1])."""
        lo, hi = np.full(self.n, -1.0), np.full(self.n, 1.0)
        if self.kind != "planar-3rpr":
            lo[self.n_pos] = -DELTA
        if self.n_pos:
            reach = np.asarray(L, float) + np.linalg.norm(self.b, axis=1)
            lo[:self.n_pos] = np.max(self.a - reach[:, None], axis=0)
            hi[:self.n_pos] = np.min(self.a + reach[:, None], axis=0)
        return lo, hi

    def random_starts(self, lo, hi, k, rng):
        X = rng.uniform(lo, hi, (k, self.n))
        rot = X[:, self.n_pos:]
        X[:, self.n_pos:] = rot / np.linalg.norm(rot, axis=1, keepdims=True)
        if self.kind != "planar-3rpr":
            X[:, self.n_pos:] *= np.sign(X[:, self.n_pos:self.n_pos + 1] + 1e-300)
        return X


def newton(fk, X, L2, iters=30):
    """Newton on every start at once; returns (X, converged mask)."""
    X = X.copy()
    with np.errstate(all="ignore"):
        for _ in range(iters):
            F = fk.residual(X, L2)
            if np.all(np.abs(F) < 1e-12):
                break
            J = fk.jacobian(X, L2)
            ok = np.all(np.isfinite(J), axis=(-1, -2)) & (np.abs(np.linalg.det(J)) > 1e-300)
            J = np.where(ok[..., None, None], J, np.eye(fk.n))
            step = np.linalg.solve(J, F[..., None])[..., 0]
            X = X - np.where(ok[..., None] & np.isfinite(step), step, 0.0)
        F = fk.residual(X, L2)
    conv = np.all(np.abs(F) < 1e-8, axis=-1) & np.all(np.isfinite(X), axis=-1)
    return X, conv


def distinct(fk, X, conv, tol=1e-6):
    """Number of distinct converged roots (q and -q are one rotation)."""
    pts = X[conv]
    if fk.kind != "planar-3rpr":
        p = fk.n_pos
        pts = pts.copy()
        pts[:, p:] *= np.where(pts[:, p:p + 1] < 0, -1.0, 1.0)
    roots = []
    for x in pts:
        if not any(np.max(np.abs(x - r)) < tol for r in roots):
            roots.append(x)
    return len(roots)


def newton_multistart(fk, lengths, starts, rng):
    L = np.asarray([float(Fraction(v)) for v in lengths])
    lo, hi = fk.domain(L)
    X0 = fk.random_starts(lo, hi, starts, rng)
    X, conv = newton(fk, X0, L ** 2)
    return distinct(fk, X, conv)


def newton_multistart_batch(fk, L, starts, rng):
    """L (M, legs) floats: all instances x starts in one array; returns distinct roots per instance."""
    M = len(L)
    X0 = np.empty((M, starts, fk.n))
    for i in range(M):
        lo, hi = fk.domain(L[i])
        X0[i] = fk.random_starts(lo, hi, starts, rng)
    X, conv = newton(fk, X0, (L ** 2)[:, None, :])
    return [distinct(fk, X[i], conv[i]) for i in range(M)]


# ----- codac ----------------------------------------------------------------------------------
def codac_available():
    try:
        import codac  # noqa: F401
        return True
    except ImportError:
        return False


def _codac_const(text):
    import codac
    f = Fraction(str(text))
    return codac.Interval(f.numerator) / codac.Interval(f.denominator)   # outward rounded


def codac_contractor(robot):
    """CtcInverse of the FK system (legs without rho^2) onto y = (rho_1^2, ..., 0)."""
    import codac
    fk = FloatFK(robot)
    n, dim = robot.n_legs, robot.dim
    texts = robot.geometry_texts()
    a = [[_codac_const(t) for t in texts[i * dim:(i + 1) * dim]] for i in range(n)]
    b = [[_codac_const(t) for t in texts[n * dim + i * dim:n * dim + (i + 1) * dim]] for i in range(n)]
    X = codac.VectorVar(fk.n)
    p = fk.n_pos
    if robot.kind == "planar-3rpr":
        c, s = X[2], X[3]
        R = [[c, -s], [s, c]]
        rot = [c, s]
    else:
        q0, q1, q2, q3 = (X[p + k] for k in range(4))
        R = [[1 - 2 * (codac.sqr(q2) + codac.sqr(q3)), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
             [2 * (q1 * q2 + q0 * q3), 1 - 2 * (codac.sqr(q1) + codac.sqr(q3)), 2 * (q2 * q3 - q0 * q1)],
             [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (codac.sqr(q1) + codac.sqr(q2))]]
        rot = [q0, q1, q2, q3]
    eqs = []
    for i in range(n):
        total = None
        for k in range(dim):
            e = R[k][0] * b[i][0]
            for j in range(1, dim):
                e = e + R[k][j] * b[i][j]
            e = e - a[i][k]
            if p:
                e = e + X[k]
            total = codac.sqr(e) if total is None else total + codac.sqr(e)
        eqs.append(total)
    norm = codac.sqr(rot[0])
    for r in rot[1:]:
        norm = norm + codac.sqr(r)
    eqs.append(norm)
    f = codac.AnalyticFunction([X], codac.vec(*eqs))
    return f, fk


def codac_pave(robot, lengths, eps, cap):
    """(seconds, boxes, connected subsets, finished) of pave with CtcInverse on the FK system."""
    import codac
    f, fk = codac_contractor(robot)
    y = [codac.sqr(_codac_const(v)) for v in lengths] + [codac.Interval(1)]
    ctc = codac.CtcInverse(f, codac.IntervalVector(y))
    L = np.array([float(Fraction(str(v))) for v in lengths])
    lo, hi = fk.domain(L)
    lo[:fk.n_pos] -= 1e-9   # float reach: widen a little so that the box surely holds certkin's domain
    hi[:fk.n_pos] += 1e-9
    x0 = codac.IntervalVector([[float(l), float(h)] for l, h in zip(lo, hi)])
    t = time.perf_counter()
    paving = codac.pave(x0, ctc, eps, cap)
    dt = time.perf_counter() - t
    boxes = len(paving.boxes(codac.PavingOut.outer))
    subsets = len(paving.connected_subsets())
    return dt, boxes, subsets, dt < 0.98 * cap


def _codac_child(queue, robot_dict, lengths, eps, cap):
    robot = load_robot(robot_dict) if isinstance(robot_dict, (str, Path)) else robot_from_dict(robot_dict)
    queue.put(codac_pave(robot, lengths, eps, cap))


def codac_pave_capped(robot_spec, lengths, eps, cap):
    """codac_pave in a child process killed after cap + 10 s (pave's own time limit is honoured
    by codac only between bisections); returns None when it did not return in time."""
    ctx = mp.get_context("fork")
    queue = ctx.Queue()
    proc = ctx.Process(target=_codac_child, args=(queue, robot_spec, lengths, eps, cap))
    t = time.perf_counter()
    proc.start()
    try:
        out = queue.get(timeout=cap + 10)
    except Exception:
        out = None
    proc.join(timeout=1)
    if proc.is_alive():
        proc.kill()
        proc.join()
    return out, time.perf_counter() - t


# ----- Gough poses (as tests/test_fk.py) -------------------------------------------------------
def table_vi2():
    rows = []
    for line in TABLE_VI2.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        v = [Fraction(t) for t in line.split()[1:]]
        rows.append(np.array([[float(v[3 * k + j]) for j in range(3)] for k in range(6)]))
    return rows


def pose_from_points(robot, P):
    """(x, y, z, psi, theta, phi) of the rigid motion taking the platform points to P (least squares)."""
    b = np.array([[float(Fraction(c)) for c in p] for p in robot.platform])
    bc, pc = b.mean(0), P.mean(0)
    U, _, Vt = np.linalg.svd((P - pc).T @ (b - bc))
    Rm = U @ np.diag([1, 1, np.linalg.det(U @ Vt)]) @ Vt
    C = pc - Rm @ bc
    theta = np.arccos(np.clip(Rm[2, 2], -1, 1))
    return [*C, np.arctan2(Rm[0, 2], -Rm[1, 2]), theta, np.arctan2(Rm[2, 0], Rm[2, 1])]


def quaternion_of_pose(pose):
    """Unit quaternion (q0 >= 0) of R = Rz(psi) Rx(theta) Rz(phi) (floats)."""
    def qz(t):
        return np.array([np.cos(t / 2), 0, 0, np.sin(t / 2)])

    def qx(t):
        return np.array([np.cos(t / 2), np.sin(t / 2), 0, 0])

    def mul(p, q):
        return np.array([p[0] * q[0] - p[1:] @ q[1:], *(p[0] * q[1:] + q[0] * p[1:] + np.cross(p[1:], q[1:]))])
    q = mul(mul(qz(pose[3]), qx(pose[4])), qz(pose[5]))
    return q if q[0] >= 0 else -q


# ----- the table --------------------------------------------------------------------------------
class Table:
    def __init__(self):
        self.rows = []
        self.cpu = None     # certkin CPU seconds of the workload being added

    def add(self, workload, certkin_s, peer, peer_s, target_s, note="", cpu=None):
        self.rows.append((workload, certkin_s, self.cpu if cpu is None else cpu, peer, peer_s, target_s, note))

    def print(self):
        def ms(v):
            if v is None:
                return "-"
            if isinstance(v, str):
                return v
            return f"{v * 1e3:.2f} ms" if v < 1 else f"{v:.1f} s"
        head = (f"{'workload':42s} {'certkin':>11s} {'(cpu)':>11s} {'peer':44s} {'peer':>11s} {'ratio':>7s} "
                f"{'target':>9s} {'met?':>5s}  note")
        print(head)
        print("-" * len(head))
        for workload, c, cpu, peer, p, target, note in self.rows:
            ratio = f"{c / p:.2f}" if isinstance(c, float) and isinstance(p, float) and p > 0 else "-"
            met = "-" if target is None else ("yes" if isinstance(c, float) and c <= target else "no")
            print(f"{workload:42s} {ms(c):>11s} {ms(cpu):>11s} {peer:44s} {ms(p):>11s} {ratio:>7s} {ms(target):>9s} {met:>5s}  {note}")


# ----- tracking ----------------------------------------------------------------------------------
def planar_motion(planar, steps):
    """Poses along a smooth closed motion from mode 1 of the 6-mode instance (x ± 0.5, y up to +0.6,
    phi ± 0.05 rad: steps of up to 0.03 in x for 100 steps; the robot is ~35 across)."""
    res = forward_kinematics(planar, PLANAR_LENGTHS)
    home = np.array([float(0.5 * (v.lo + v.hi)) for v in res.solutions[0]["pose"].values()])
    t = 2 * np.pi * np.linspace(0.0, 1.0, steps + 1)[:, None]
    return home + np.array([0.5, 0.3, 0.05]) * np.hstack([np.sin(t), 1 - np.cos(t), np.sin(t)])


def gough_motion(gough, steps):
    """Poses from posture 1 of Table VI.2 out and back along a smooth motion (up to 2 cm, 0.6 deg)."""
    pose = np.array(pose_from_points(gough, table_vi2()[0]))
    t = np.linspace(0.0, 1.0, steps + 1)[:, None]
    return pose + np.sin(np.pi * t) * np.array([0.02, -0.01, 0.015, 0.01, 0.005, -0.01])


def float_unknowns(fk, pose):
    """The FK unknowns of a pose (planar: x, y, cos phi, sin phi; Gough: position and quaternion)."""
    if fk.kind == "planar-3rpr":
        return np.array([pose[0], pose[1], np.cos(pose[2]), np.sin(pose[2])])
    return np.concatenate([pose[:3], quaternion_of_pose(pose)])


def newton_steps(fk, x0, L2rows, iters=8):
    """The peer of a tracked sequence: float Newton step after step from the last root (uncertified)."""
    x, ok = x0[None, :], True
    for L2 in L2rows:
        x, conv = newton(fk, x, L2, iters=iters)
        ok &= bool(conv[0])
    return x, ok


def tracking_rows(table, args):
    """Tracking: Gough (one call; a sequence) and planar (one call; a sequence of ``--steps``)."""
    from certkin.fk import track_sequence
    text = lambda pose: ",".join(repr(float(v)) for v in pose)  # noqa: E731
    # (c) Gough tracking, one call: the pose fitted to posture 1 of Table VI.2 and its own lengths
    gough = load_robot(GOUGH_FILE)
    pose = pose_from_points(gough, table_vi2()[0])
    pose_text = text(pose)
    forward_kinematics(gough, GOUGH_LENGTHS, track=pose_text)
    t_g, res_g = timed(lambda: forward_kinematics(gough, GOUGH_LENGTHS, track=pose_text), args.repeat)
    table.cpu = timed.cpu
    assert res_g.tracked and len(res_g.solutions) == 1
    gfk = FloatFK(gough)
    Lg = np.array([float(v) for v in GOUGH_LENGTHS.split(",")])
    x0 = np.concatenate([pose[:3], quaternion_of_pose(pose)])[None, :]
    t_gn, (xg, conv) = timed(lambda: newton(gfk, x0, Lg ** 2, iters=8), args.repeat)
    w = "Gough 24-solution robot, tracking 1 pose"
    table.add(w, t_g, "numpy Newton from the pose (uncertified)", t_gn, 0.010,
              f"certkin proved unique; Newton converged: {bool(conv[0])}")
    sys.stdout.flush()

    # (c'') Gough tracking, a sequence of steps
    n = args.steps
    poses = gough_motion(gough, n)
    L = gough.leg_lengths_float(poses[1:])
    track_sequence(gough, L[:2], text(poses[0]), fallback=False)
    t_s, out = timed(lambda: track_sequence(gough, L, text(poses[0]), fallback=False), args.repeat)
    cpu = timed.cpu / n
    t_p, (_, ok) = timed(lambda: newton_steps(gfk, float_unknowns(gfk, poses[0]), L ** 2), args.repeat)
    table.add(f"Gough tracking, sequence of {n}, per step", t_s / n, "numpy Newton step after step", t_p / n, 0.010,
              f"certkin: {sum(r.tracked for r in out)}/{n} steps proved unique; Newton converged: {ok}", cpu=cpu)
    sys.stdout.flush()

    # (d) planar tracking: one call per step, then the whole sequence
    planar = robot_from_dict(PLANAR)
    pfk = FloatFK(planar)
    poses = planar_motion(planar, n)
    L = planar.leg_lengths_float(poses[1:])
    rows = [[repr(float(v)) for v in row] for row in L]
    starts = [text(p) for p in poses[:-1]]
    forward_kinematics(planar, rows[0], track=starts[0])
    wall, cpu, tracked = [], [], 0
    for _ in range(args.repeat):
        for k in range(n):
            t, c = time.perf_counter(), time.process_time()
            r = forward_kinematics(planar, rows[k], track=starts[k])
            wall.append(time.perf_counter() - t)
            cpu.append(time.process_time() - c)
            tracked += r.tracked
    peer = []
    for _ in range(args.repeat):
        for k in range(n):
            x = float_unknowns(pfk, poses[k])[None, :]
            t = time.perf_counter()
            newton(pfk, x, L[k] ** 2, iters=8)
            peer.append(time.perf_counter() - t)
    table.add("planar 6-mode, tracking 1 step (one call)", statistics.median(wall), "numpy Newton from the pose",
              statistics.median(peer), 0.001, f"median over {n} steps x {args.repeat}; "
              f"certkin {tracked}/{n * args.repeat} proved unique", cpu=statistics.median(cpu))
    track_sequence(planar, L[:2], starts[0], fallback=False)
    t_s, out = timed(lambda: track_sequence(planar, L, starts[0], fallback=False), args.repeat)
    cpu = timed.cpu / n
    t_p, (_, ok) = timed(lambda: newton_steps(pfk, float_unknowns(pfk, poses[0]), L ** 2), args.repeat)
    table.add(f"planar tracking, sequence of {n}, per step", t_s / n, "numpy Newton step after step", t_p / n, 0.001,
              f"certkin: {sum(r.tracked for r in out)}/{n} steps proved unique; Newton converged: {ok}", cpu=cpu)
    sys.stdout.flush()


def search_rows(table, args, rng, has_codac):
    """The full-search workloads: planar one instance and batch, spherical one instance."""
    # (a) planar, one instance ----------------------------------------------------------------
    planar = robot_from_dict(PLANAR)
    forward_kinematics(planar, PLANAR_LENGTHS)   # compile once (excluded)
    t_c, res = timed(lambda: forward_kinematics(planar, PLANAR_LENGTHS), args.repeat)
    table.cpu = timed.cpu
    assert res.complete and len(res.solutions) == 6, (res.complete, len(res.solutions))
    ffk = FloatFK(planar)
    t_n, found = timed(lambda: newton_multistart(ffk, PLANAR_LENGTHS, args.starts, rng), args.repeat)
    w = "planar 6-mode, one instance"
    table.add(w, t_c, f"numpy Newton x{args.starts} starts (uncertified)", t_n, 0.020,
              f"certkin 6 proved unique, complete ({res.boxes} boxes); Newton found {found}")
    if has_codac:
        out, wall = codac_pave_capped(PLANAR, PLANAR_LENGTHS, args.codac_eps, args.codac_cap)
        if out is None:
            table.add(w, t_c, "codac CtcInverse+pave", f"> {args.codac_cap:.0f} s", 0.020,
                      f"codac did not finish in {args.codac_cap:.0f} s")
        else:
            times = [out[0]] + [codac_pave(planar, PLANAR_LENGTHS, args.codac_eps, args.codac_cap)[0]
                                for _ in range(args.repeat - 1)]
            table.add(w, t_c, f"codac CtcInverse+pave eps={args.codac_eps:g}", statistics.median(times), 0.020,
                      f"codac {out[2]} connected subsets, {out[1]} boxes, none proved"
                      + ("" if out[3] else f"; did not finish in {args.codac_cap:.0f} s"))
    sys.stdout.flush()

    # (a') planar batch ----------------------------------------------------------------------------
    home = np.array([float(0.5 * (v.lo + v.hi)) for v in res.solutions[0]["pose"].values()])
    poses = home + rng.uniform(-1, 1, (args.batch, 3)) * np.array([1.0, 1.0, 0.1])
    L = planar.leg_lengths_float(poses)
    forward_kinematics(planar, L[:4])
    t_b, out = timed(lambda: forward_kinematics(planar, L), args.batch_repeat)
    table.cpu = timed.cpu / args.batch
    assert all(r.complete for r in out)
    counts = np.bincount([len(r.solutions) for r in out], minlength=7)
    per = t_b / args.batch
    w = f"planar batch of {args.batch}, per instance"
    t_nb, found_b = timed(lambda: newton_multistart_batch(ffk, L, args.starts // 4, rng), args.repeat)
    missed = sum(f < len(r.solutions) for f, r in zip(found_b, out))
    table.add(w, per, f"numpy Newton x{args.starts // 4} starts, batched", t_nb / args.batch, 0.005,
              f"certkin: all complete, modes {dict((k, int(v)) for k, v in enumerate(counts) if v)}; "
              f"Newton missed roots on {missed} instances")
    if has_codac:
        k = min(args.codac_sample, args.batch)
        times = []
        for row in L[:k]:
            o = codac_pave(planar, [repr(float(v)) for v in row], args.codac_eps, args.codac_cap)
            times.append(o[0])
        table.add(w, per, f"codac CtcInverse+pave, {k} of them", statistics.mean(times), 0.005,
                  "codac: mean per instance over the sample, none proved")
    sys.stdout.flush()

    # (b) spherical, one instance ---------------------------------------------------------------
    sph = robot_from_dict(SPHERICAL)
    forward_kinematics(sph, SPHERICAL_LENGTHS)
    t_s, res_s = timed(lambda: forward_kinematics(sph, SPHERICAL_LENGTHS), args.repeat)
    table.cpu = timed.cpu
    assert res_s.complete and len(res_s.solutions) == 8, (res_s.complete, len(res_s.solutions))
    sfk = FloatFK(sph)
    t_sn, found_s = timed(lambda: newton_multistart(sfk, SPHERICAL_LENGTHS, args.starts, rng), args.repeat)
    w = "spherical 8-mode, one instance"
    table.add(w, t_s, f"numpy Newton x{args.starts} starts (uncertified)", t_sn, None,
              f"certkin 8 proved unique, complete ({res_s.boxes} boxes); Newton found {found_s}")
    if has_codac:
        out, wall = codac_pave_capped(SPHERICAL, SPHERICAL_LENGTHS, args.codac_eps, args.codac_cap)
        if out is None:
            table.add(w, t_s, "codac CtcInverse+pave", f"> {args.codac_cap:.0f} s", None,
                      f"codac did not finish in {args.codac_cap:.0f} s")
        else:
            times = [out[0]] + [codac_pave(sph, SPHERICAL_LENGTHS, args.codac_eps, args.codac_cap)[0]
                                for _ in range(args.repeat - 1)]
            table.add(w, t_s, f"codac CtcInverse+pave eps={args.codac_eps:g}", statistics.median(times), None,
                      f"codac {out[2]} connected subsets, {out[1]} boxes, none proved"
                      + ("" if out[3] else f"; did not finish in {args.codac_cap:.0f} s"))
    sys.stdout.flush()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="repeats per measurement (median)")
    ap.add_argument("--batch", type=int, default=1000, help="planar leg-length sets in the batch")
    ap.add_argument("--batch-repeat", type=int, default=5, help="repeats of the batch (it takes ~15 s)")
    ap.add_argument("--starts", type=int, default=256, help="Newton starts per instance (numpy peer)")
    ap.add_argument("--codac-cap", type=float, default=60.0, help="seconds allowed to each codac pave")
    ap.add_argument("--codac-eps", type=float, default=1e-9, help="codac pave resolution (issue #4: 1e-9)")
    ap.add_argument("--codac-sample", type=int, default=20, help="batch instances run through codac (extrapolated)")
    ap.add_argument("--gough-repeat", type=int, default=3, help="repeats of the Gough full-domain search (median)")
    ap.add_argument("--gough-full", type=float, default=0.0, metavar="SECONDS",
                    help="also run the Gough full-domain search (all 24 postures) with this time budget; 0: skip")
    ap.add_argument("--only", choices=("all", "tracking"), default="all",
                    help="'tracking': only the tracking rows (Gough and planar, one call and a sequence)")
    ap.add_argument("--steps", type=int, default=100, help="steps of the tracked sequences")
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    has_codac = codac_available()
    table = Table()
    if has_codac:
        from importlib.metadata import version
        codac_text = f"codac {version('codac')}"
    else:
        codac_text = "codac not installed (pip install 'certkin[bench]'): codac rows skipped"
    print(f"# FK benchmark; {describe()}; {codac_text}")
    sys.stdout.flush()

    if args.only == "all":
        search_rows(table, args, rng, has_codac)
    tracking_rows(table, args)
    gough = load_robot(GOUGH_FILE)
    gfk = FloatFK(gough)

    # (c') Gough full domain (optional) ------------------------------------------------------------
    if args.gough_full > 0 and args.only == "all":
        w = "Gough 24-solution robot, full domain"
        budget = Budget(max_boxes=10 ** 9, max_seconds=args.gough_full, min_width=1e-10)
        t_full, r = timed(lambda: forward_kinematics(gough, GOUGH_LENGTHS, budget=budget), args.gough_repeat)
        table.cpu = timed.cpu
        import resource
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        fresh = fresh_process_seconds()
        note = (f"certkin: {len(r.solutions)} proved unique, {len(r.unresolved)} unresolved clusters, "
                f"complete={r.complete}, {r.boxes} boxes, peak RSS {peak:.0f} MiB; median of "
                f"{args.gough_repeat}; in a fresh process (imports, robot file, search; kernels cached), median of 3: "
                f"{fresh:.2f} s")
        t_fn, found_g = timed(lambda: newton_multistart(gfk, GOUGH_LENGTHS.split(","), 20_000, rng), 1)
        table.add(w, t_full if r.complete else f">{t_full:.0f} s", "numpy Newton x20000 starts (uncertified)",
                  t_fn, 5.0, note + f"; Newton found {found_g} (one run)")
        if has_codac:
            out, wall = codac_pave_capped(str(GOUGH_FILE), GOUGH_LENGTHS.split(","), args.codac_eps, args.codac_cap)
            if out is None or not out[3]:
                table.add(w, t_full if r.complete else f">{t_full:.0f} s", "codac CtcInverse+pave",
                          f"> {args.codac_cap:.0f} s", 5.0, f"codac did not finish in {args.codac_cap:.0f} s")
            else:
                table.add(w, t_full if r.complete else f">{t_full:.0f} s",
                          f"codac CtcInverse+pave eps={args.codac_eps:g}", out[0], 5.0,
                          f"codac {out[2]} connected subsets, none proved (one run)")
    print()
    table.print()
    print("certkin: median wall time (cpu: median CPU time of the process; they differ when the core is shared). "
          "ratio = certkin wall / peer wall (below 1: certkin faster).\nPeers prove nothing: Newton may miss roots, "
          "codac's boxes enclose the solutions without proving existence or uniqueness.")


if __name__ == "__main__":
    main()
