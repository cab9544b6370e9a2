"""The Bernstein Cayley-Menger test as a node rule of certkin's 6-D FK search (issue 16), measured as a lead.

`benchmarks/fk_rotation_bernstein.py` searched the rotation alone with the 15 Cayley-Menger (CM)
polynomials in Bernstein form; its certificate would need a cover of the quaternion charts by trees.
Here the same test is measured as a rule applied inside certkin's existing 6-D search (unknowns p, q,
q a unit quaternion, q0 in [−2⁻¹⁰, 1 + 2⁻¹⁰]), box by box, with nothing carried from a parent:

- the 6-D box's quaternion part Q = [qlo, qhi]; the chart k is the component with the largest
  smallest |q_k| over Q (untested when every component's interval holds 0);
- the chart box: Q_i / Q_k for i ≠ k, interval division, widened by one ulp each side (the image of
  the unit quaternions of Q, overestimated: the division takes Q's corners, not the sphere);
- per polynomial (CM·|q|^8 with q_k = 1, total degree 8 in the chart's x, y, z, power coefficients
  exact by sympy and rounded to float once): its values at the chart box's 8 vertices (the corner
  Bernstein coefficients; a sign change there rules the polynomial out), then its tensor Bernstein
  coefficients of degree (8, 8, 8) on the box, from scratch: per axis one 9×9 matrix, the Bernstein
  coefficients on [lo, hi] of the monomials x^j (Taylor shift to lo, scaling by hi − lo, the
  power-to-Bernstein map, composed; shared by the 15 polynomials), applied to the 165 power
  coefficients axis by axis (the total degree keeps the first two axes triangular);
- the box is excluded when one polynomial has all 729 coefficients of one strict sign (stopping at
  the first such polynomial; in an order given as an argument).

Replay: certkin's FK search runs with ``record="whole"``; every split node (a box the present steps
leave open) gets the test; when it passes, the decided boxes below it (children of splits) are saved,
as in ``benchmarks/fk_cayley_menger.py --replay``.  Printed per robot: decided boxes before -> after,
split nodes holding a proved posture that pass (must be 0), proved leaves lost (must be 0), the pass
rate by the node's quaternion width (bins), and the same replay with the test gated to boxes whose
quaternion width is below w (0.1, 0.03, 0.01).

Cost: the test is one numba kernel for a box (all 15 polynomials, stopping at the first that
excludes); timed over a sample of the boxes each gate would test (CPU seconds of the batch divided by
the boxes, the median of 3 repetitions, after a warm-up), in two orders of the 15 polynomials (index
order; most frequent excluder first, by the replay's counts).  The search time is modelled as
boxes_after × (µs a box today: the recorded search's CPU seconds / its boxes) + tests × µs a test,
against the recorded search's CPU seconds.

THIS IS A FLOAT STUDY, NOT CERTIFIED: no outward rounding in the Bernstein arithmetic, and nothing in
certkin uses it.

    python benchmarks/fk_bernstein_node.py [--robot seed002 dietmaier] [--sample 20000] [--tree-cache DIR]

Run time on one core (shared machine, load about 2): about 3 min 10 s for both robots; seed002 about
40 s, Dietmaier about 2.5 min (its recorded search 53 s after seed002's as a warm-up, 3 s each for the
exact coefficients, all 15 polynomials at its 694 000 split nodes 38 s); numba compilation about 10 s
the first time.  ``--tree-cache DIR`` keeps the recorded trees and the chart polynomials in DIR and
reads them from there on the next run (for work on the test; the search times are then the cached
run's).

A float study, kept as it was measured: the solver's certified form of this test (a proved rounding
bound, the forms in midpoint-radius) is ``certkin/fk/cayley_menger.py``.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from math import comb
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fk_cayley_menger import ROBOTS, Geometry, holding_a_posture, pruned_below, recorded_search, sample_unit_quaternions  # noqa: E402
from fk_rotation_bernstein import bernstein_eval, chart_power, homogeneous_cm, read_robot   # noqa: E402

DEG = 8
N1 = DEG + 1
GATES = (None, 0.1, 0.03, 0.01)
BINS = (0.0, 0.003, 0.01, 0.03, 0.1, 0.3, np.inf)
COMB = np.array([[comb(j, m) for m in range(N1)] for j in range(N1)], float)            # C(j, m)
BERN = np.array([[comb(i, m) / comb(DEG, m) for m in range(N1)] for i in range(N1)])     # C(i, m) / C(8, m)


# ---------------------------------------------------------------- the from-scratch test of one box (compiled)

@numba.njit(cache=True)
def _axis_matrices(lo, hi, M):
    """M[v, i, j]: Bernstein coefficient i (degree 8, on [lo_v, hi_v]) of x^j."""
    for v in range(3):
        a = lo[v]
        w = hi[v] - lo[v]
        ap = np.empty(N1)
        wp = np.empty(N1)
        ap[0] = 1.0
        wp[0] = 1.0
        for e in range(1, N1):
            ap[e] = ap[e - 1] * a
            wp[e] = wp[e - 1] * w
        for i in range(N1):
            for j in range(N1):
                s = 0.0
                for m in range(min(i, j) + 1):
                    s += COMB[j, m] * ap[j - m] * wp[m] * BERN[i, m]
                M[v, i, j] = s



@numba.njit(cache=True)
def _vertex_value(A, p, M, s0, s1, s2):
    """Value of polynomial p at the vertex (rows s0, s1, s2 ∈ {0, 8} of the axis matrices)."""
    total = 0.0
    for l in range(N1):
        zl = M[2, s2, l]
        for j in range(N1 - l):
            yj = M[1, s1, j]
            s = 0.0
            for i in range(N1 - j - l):
                s += A[p, i, j, l] * M[0, s0, i]
            total += s * yj * zl
    return total


@numba.njit(cache=True)
def _sign_definite(A, p, M, T0, T1, sign):
    """True when all Bernstein coefficients of polynomial p on the box have the strict sign ``sign``."""
    # axis 0: T0[i', j, l] for j + l ≤ 8
    for j in range(N1):
        for l in range(N1 - j):
            top = N1 - j - l
            for ii in range(N1):
                s = 0.0
                for i in range(top):
                    s += M[0, ii, i] * A[p, i, j, l]
                T0[ii, j, l] = s
    # axis 1: T1[i', j', l], j ≤ 8 − l
    for ii in range(N1):
        for l in range(N1):
            top = N1 - l
            for jj in range(N1):
                s = 0.0
                for j in range(top):
                    s += M[1, jj, j] * T0[ii, j, l]
                T1[ii, jj, l] = s
    # axis 2, with the sign check
    for ii in range(N1):
        for jj in range(N1):
            for ll in range(N1):
                s = 0.0
                for l in range(N1):
                    s += M[2, ll, l] * T1[ii, jj, l]
                if s * sign <= 0.0:
                    return False
    return True


VERTICES = np.array([[0, 0, 0], [8, 8, 8], [8, 0, 0], [0, 8, 8], [0, 8, 0], [8, 0, 8], [0, 0, 8], [8, 8, 0]])


@numba.njit(cache=True)
def chart_box(qlo, qhi, lo, hi):
    """Chart k (largest smallest |q_k| over the box) and the chart box Q_i / Q_k into lo, hi; −1 if none."""
    best, k = 0.0, -1
    for c in range(4):
        if qlo[c] > 0.0:
            m = qlo[c]
        elif qhi[c] < 0.0:
            m = -qhi[c]
        else:
            m = 0.0
        if m > best:
            best, k = m, c
    if k < 0:
        return -1
    v = 0
    for c in range(4):
        if c == k:
            continue
        a, b, d0, d1 = qlo[c], qhi[c], qlo[k], qhi[k]
        r0, r1, r2, r3 = a / d0, a / d1, b / d0, b / d1
        lo[v] = np.nextafter(min(min(r0, r1), min(r2, r3)), -np.inf)
        hi[v] = np.nextafter(max(max(r0, r1), max(r2, r3)), np.inf)
        v += 1
    return k


@numba.njit(cache=True)
def node_test(A4, order, qlo, qhi, M, T0, T1, lo, hi, all_polys):
    """The test of one 6-D box's quaternion part: the first polynomial (in ``order``) that is
    sign-definite on the chart box, or −1 (−2: no chart); with ``all_polys`` a bit mask of all the
    excluding ones instead of the first."""
    k = chart_box(qlo, qhi, lo, hi)
    if k < 0:
        return -2
    return chart_test(A4[k], order, lo, hi, M, T0, T1, all_polys)


@numba.njit(cache=True)
def chart_test(A, order, lo, hi, M, T0, T1, all_polys):
    """node_test on a chart box [lo, hi] of the chart polynomials A (15, 9, 9, 9)."""
    _axis_matrices(lo, hi, M)
    mask = 0
    for idx in range(order.shape[0]):
        p = order[idx]
        v0 = _vertex_value(A, p, M, 0, 0, 0)
        if v0 == 0.0:
            continue
        sign = 1.0 if v0 > 0.0 else -1.0
        ok = True
        for t in range(1, 8):
            if _vertex_value(A, p, M, VERTICES[t, 0], VERTICES[t, 1], VERTICES[t, 2]) * sign <= 0.0:
                ok = False
                break
        if not ok:
            continue
        if _sign_definite(A, p, M, T0, T1, sign):
            if not all_polys:
                return p
            mask |= 1 << p
    return mask if all_polys and mask else -1


@numba.njit(cache=True)
def test_many(A4, order, qlo, qhi, all_polys):
    """node_test over boxes (N, 4): (N,) results."""
    n = qlo.shape[0]
    out = np.empty(n, np.int64)
    M = np.empty((3, N1, N1))
    T0 = np.zeros((N1, N1, N1))
    T1 = np.zeros((N1, N1, N1))
    lo = np.empty(3)
    hi = np.empty(3)
    for b in range(n):
        out[b] = node_test(A4, order, qlo[b], qhi[b], M, T0, T1, lo, hi, all_polys)
    return out


@numba.njit(cache=True)
def test_chart_boxes(A4, ks, lo, hi):
    """chart_test (all polynomials, bit masks) over chart boxes of charts ks."""
    out = np.empty(len(ks), np.int64)
    M = np.empty((3, N1, N1))
    T0 = np.zeros((N1, N1, N1))
    T1 = np.zeros((N1, N1, N1))
    order = np.arange(15)
    for b in range(len(ks)):
        out[b] = chart_test(A4[ks[b]], order, lo[b], hi[b], M, T0, T1, True)
    return out


def division_loss(A4, qlo, qhi, masks, rng, n=3000, points=200):
    """On n split nodes: the pass rate with the chart box of the division and with the hull of the chart
    coordinates of up to ``points`` unit quaternions drawn in the box (an inner estimate of the image of
    the box's unit quaternions, so an upper bound of what an exact image would give); by width bin."""
    pick = rng.choice(len(qlo), min(n, len(qlo)), replace=False)
    ks, los, his, keep = [], [], [], []
    for i in pick:
        m = np.where(qlo[i] > 0, qlo[i], np.where(qhi[i] < 0, -qhi[i], 0.0))
        k = int(np.argmax(m))
        if m[k] <= 0:
            continue
        x = sample_unit_quaternions(rng, qlo[i], qhi[i], points)
        if len(x) < 2:
            continue
        c = np.delete(x, k, axis=1) / x[:, k:k + 1]
        ks.append(k)
        los.append(c.min(0))
        his.append(c.max(0))
        keep.append(i)
    keep = np.array(keep)
    inner = test_chart_boxes(A4, np.array(ks), np.array(los), np.array(his)) > 0
    width = (qhi[keep] - qlo[keep]).max(1)
    rows = []
    for a, b in zip(BINS[:-1], BINS[1:]):
        sel = (width >= a) & (width < b)
        rows.append((a, b, int(sel.sum()), float((masks[keep][sel] > 0).mean()) if sel.any() else float("nan"),
                     float(inner[sel].mean()) if sel.any() else float("nan")))
    return len(pick), len(keep), float((masks[keep] > 0).mean()), float(inner.mean()), rows


# ---------------------------------------------------------------- the polynomials

def chart_polynomials(name):
    """Float power coefficients (4 charts, 15, 9, 9, 9) of CM·|q|^8 with q_k = 1 (exact, rounded once)."""
    hom = homogeneous_cm(*read_robot(name))
    return np.ascontiguousarray(np.array([[chart_power(h, k).astype(float) for h in hom] for k in range(4)]))


def check_kernel(A4, postures):
    """The vertex values against the power form at random boxes; the 15 values at the postures."""
    rng = np.random.default_rng(0)
    M = np.empty((3, N1, N1))
    worst = 0.0
    for _ in range(50):
        lo = rng.uniform(-1, 0.5, 3)
        hi = lo + rng.uniform(0.01, 0.5, 3)
        _axis_matrices(lo, hi, M)
        k, p = rng.integers(4), rng.integers(15)
        A = A4[k, p]
        scale = np.abs(A).sum()
        for s in VERTICES:
            x = np.where(s == 0, lo, hi)
            ref = sum(A[i, j, l] * x[0] ** i * x[1] ** j * x[2] ** l
                      for i in range(N1) for j in range(N1) for l in range(N1) if A[i, j, l])
            worst = max(worst, abs(_vertex_value(A4[k], p, M, *s) - ref) / scale)
    # the whole tensor (numpy, all 9 rows of the axis matrices) against the power form at random points,
    # and the kernel's sign-definiteness against that tensor's
    T0, T1 = np.zeros((N1, N1, N1)), np.zeros((N1, N1, N1))
    form, agree, definite = 0.0, 0, 0
    for _ in range(400):
        c = rng.uniform(-1, 1, 3)
        r = 10 ** rng.uniform(-3, -0.5, 3)
        lo, hi = c - r, c + r
        _axis_matrices(lo, hi, M)
        k, p = rng.integers(4), rng.integers(15)
        A = A4[k, p]
        B = np.einsum("ai,bj,cl,ijl->abc", M[0], M[1], M[2], A)
        x = rng.uniform(lo, hi, size=(20, 3))
        ref = np.einsum("ijl,ni,nj,nl->n", A, *[x[:, v:v + 1] ** np.arange(N1) for v in range(3)])
        form = max(form, np.abs(bernstein_eval(B, x, lo, hi) - ref).max() / np.abs(B).max())
        sign = 1.0 if B[0, 0, 0] > 0 else -1.0
        numpy_says = bool(np.all(B * sign > 0))
        definite += numpy_says
        agree += numpy_says == _sign_definite(A4[k], p, M, T0, T1, sign)
    q = postures[:, 3:] / np.linalg.norm(postures[:, 3:], axis=1, keepdims=True)
    rel = 0.0
    for s in range(len(q)):
        k = int(np.argmax(np.abs(q[s])))
        x = np.delete(q[s], k) / q[s, k]
        for p in range(15):
            A = A4[k, p]
            v = np.einsum("ijl,i,j,l->", A, x[0] ** np.arange(N1), x[1] ** np.arange(N1), x[2] ** np.arange(N1))
            rel = max(rel, abs(v) / np.abs(A).sum())
    print(f"  kernel check: vertex values vs power form {worst:.1e} (relative to Σ|a|); Bernstein form vs power "
          f"form at random points of 400 random boxes {form:.1e} (relative to max|b|), kernel's sign test agrees "
          f"{agree}/400 ({definite} sign-definite); "
          f"15 polynomials at the proved postures max |P|/Σ|a| {rel:.1e}")
    assert worst < 1e-12 and rel < 1e-9 and form < 1e-12 and agree == 400


# ---------------------------------------------------------------- the replay

def record(name, cache=None):
    """certkin's FK search with the whole tree recorded: columns, postures, CPU seconds, boxes (from
    ``cache``/name.npz when given and present, written there otherwise)."""
    if cache and (Path(cache) / f"{name}.npz").exists():
        z = np.load(Path(cache) / f"{name}.npz")
        cols = {c: z[c] for c in ("lo", "hi", "kind", "parent")}
        return cols, z["postures"], float(z["rec"][0]), int(z["rec"][1]), True
    from certkin.fk import forward_kinematics
    forward_kinematics(*ROBOTS["seed002"])          # load certkin's kernels first
    res, cols, postures, seconds = recorded_search(*ROBOTS[name])
    if cache:
        Path(cache).mkdir(parents=True, exist_ok=True)
        np.savez(Path(cache) / f"{name}.npz", **cols, postures=postures, rec=[seconds, res.boxes])
    return cols, postures, seconds, res.boxes, res.complete


def timed(A4, order, qlo, qhi, repeats=3):
    """µs a box of test_many (CPU time of the batch / boxes, median of ``repeats``)."""
    if len(qlo) == 0:
        return float("nan")
    runs = []
    for _ in range(repeats):
        t0 = time.process_time()
        test_many(A4, order, qlo, qhi, False)
        runs.append((time.process_time() - t0) / len(qlo))
    return 1e6 * float(np.median(runs))


def run(name, sample, cache=None):
    from certkin.engine import PROVED, SPLIT
    cols, postures, seconds, boxes, complete = record(name, cache)
    us_box = 1e6 * seconds / boxes
    print(f"{name}: recorded search {seconds:.1f} s CPU, {boxes} boxes ({us_box:.1f} µs a box), "
          f"{len(postures)} postures, complete {complete}, {len(cols['kind'])} nodes", flush=True)
    t0 = time.process_time()
    path = Path(cache) / f"{name}-charts.npy" if cache else None
    if path and path.exists():
        A4 = np.load(path)
    else:
        A4 = chart_polynomials(name)
        if path:
            np.save(path, A4)
    print(f"  exact chart polynomials: {time.process_time() - t0:.1f} s", flush=True)
    check_kernel(A4, postures)
    kind, parent = cols["kind"], cols["parent"]
    splits = np.nonzero(kind == SPLIT)[0]
    decided = (parent < 0) | (kind[np.maximum(parent, 0)] == SPLIT)
    held = holding_a_posture(cols)
    qlo = np.ascontiguousarray(cols["lo"][splits, 3:])
    qhi = np.ascontiguousarray(cols["hi"][splits, 3:])
    width = (qhi - qlo).max(1)

    index_order = np.arange(15)
    test_many(A4, index_order, qlo[:50], qhi[:50], True)            # compile / warm up
    t0 = time.process_time()
    masks = test_many(A4, index_order, qlo, qhi, True)             # every excluding polynomial, per split node
    t_all = time.process_time() - t0
    passing = masks > 0
    counts = np.array([np.sum((masks > 0) & ((masks >> p) & 1 == 1)) for p in range(15)])
    # greedy order: the polynomial excluding most of the boxes not yet excluded by the ones before it
    left, freq_order = passing.copy(), []
    for _ in range(15):
        gain = [np.sum(left & ((masks >> p) & 1 == 1)) if p not in freq_order else -1 for p in range(15)]
        p = int(np.argmax(gain))
        freq_order.append(p)
        left &= ~((masks >> p) & 1 == 1)
    freq_order = np.array(freq_order)
    print(f"  {len(splits)} split nodes ({np.sum(held[splits])} holding a posture), {decided.sum()} decided boxes; "
          f"all 15 polynomials at every split node: {t_all:.1f} s; pass {passing.mean():.3f}; "
          f"boxes excluded by each polynomial: {[int(c) for c in counts]}; greedy order {[int(p) for p in freq_order]}", flush=True)

    # independent check: unit quaternions drawn in passing boxes, the 6×6 CM determinant of an excluding
    # quadruple (float, from a, b, ρ) keeps one sign there
    from certkin.fk.system import fk_system
    from certkin.robots import as_robot
    path, lengths = ROBOTS[name]
    system = fk_system(as_robot(path))
    G = Geometry(system.a.mid(), system.b.mid(), [float(x) for x in lengths.split(",")])
    rng = np.random.default_rng(1)
    checked = points = 0
    for i in rng.choice(np.nonzero(passing)[0], min(300, int(passing.sum())), replace=False):
        x = sample_unit_quaternions(rng, qlo[i], qhi[i], 100)
        if len(x) == 0:
            continue
        p = int(np.log2(masks[i] & -masks[i]))
        v = G.cm_determinant(x)[:, p]
        assert np.all(v > 0) or np.all(v < 0), "a passing box holds both signs of its polynomial"
        checked += 1
        points += len(x)
    print(f"  sampled check: {checked} passing boxes, {points} unit quaternions in them: the excluding "
          f"quadruple's CM determinant keeps one sign in each", flush=True)
    rows = []
    for gate in GATES:
        g = passing & (True if gate is None else width < gate)
        cut = np.zeros(len(kind), bool)
        cut[splits] = g
        pruned = pruned_below(parent, cut)
        after = int(np.sum(decided & ~pruned))
        tested = ~pruned[splits] & (True if gate is None else width < gate)
        ids = np.nonzero(tested)[0]
        pick = np.sort(np.random.default_rng(0).choice(ids, min(sample, len(ids)), replace=False)) if len(ids) else ids
        us = {}
        for label, order in (("index", index_order), ("greedy", freq_order)):
            test_many(A4, order, qlo[pick[:10]], qhi[pick[:10]], False)
            us[label] = timed(A4, order, qlo[pick], qhi[pick])
        us_pass = timed(A4, freq_order, qlo[pick[passing[pick]]], qhi[pick[passing[pick]]])
        us_fail = timed(A4, freq_order, qlo[pick[~passing[pick]]], qhi[pick[~passing[pick]]])
        n_tests = int(tested.sum())
        best = min(us.values())
        model = (after * us_box + n_tests * best) / 1e6
        rows.append((name, gate, int(decided.sum()), after, int(np.sum(cut & held)), int(np.sum(pruned & (kind == PROVED))),
                     n_tests, int(g[tested].sum()), us["index"], us["greedy"], us_pass, us_fail, model, seconds))
        print(f"  gate {gate}: decided boxes {decided.sum()} -> {after} ({after / decided.sum():.3f}); tests {n_tests}, "
              f"passing {g[tested].sum()}; posture-holding passing {np.sum(cut & held)}, proved lost "
              f"{np.sum(pruned & (kind == PROVED))}; µs a test: index order {us['index']:.1f}, greedy {us['greedy']:.1f} "
              f"(passing {us_pass:.1f}, failing {us_fail:.1f}); model {model:.2f} s vs {seconds:.2f} s "
              f"({model / seconds:.2f})", flush=True)
        assert np.sum(cut & held) == 0 and np.sum(pruned & (kind == PROVED)) == 0
    bins = []
    for a, b in zip(BINS[:-1], BINS[1:]):
        sel = (width >= a) & (width < b)
        bins.append((a, b, int(sel.sum()), float(passing[sel].mean()) if sel.any() else float("nan"),
                     float((masks[sel] == -2).mean()) if sel.any() else float("nan")))
    t0 = time.process_time()
    loss = division_loss(A4, qlo, qhi, masks, np.random.default_rng(2))
    print(f"  division against the sampled image: {loss[1]} of {loss[0]} sampled split nodes with unit quaternions "
          f"drawn; pass {loss[2]:.3f} (division) vs {loss[3]:.3f} (hull of the drawn points' chart coordinates), "
          f"{time.process_time() - t0:.0f} s", flush=True)
    return rows, bins, loss


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", nargs="+", default=["seed002", "dietmaier"], choices=list(ROBOTS))
    ap.add_argument("--sample", type=int, default=20000, help="boxes timed per gate")
    ap.add_argument("--tree-cache", help="directory: read the recorded trees from NAME.npz there when present")
    args = ap.parse_args()
    t0 = time.perf_counter()
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}; numba {numba.__version__}, numpy {np.__version__}")
    results = [(name, *run(name, args.sample, args.tree_cache)) for name in args.robot]
    print("\n| robot | gate (quaternion width <) | decided boxes before -> after | tests | passing | "
          "posture-holding passing | proved lost | µs a test (index / greedy order) | passing / failing | "
          "modelled search s | recorded search s | ratio |")
    print("|---|---|---:|---:|---:|---:|---:|---|---|---:|---:|---:|")
    for name, rows, _, _ in results:
        for r in rows:
            print(f"| {r[0]} | {'none' if r[1] is None else r[1]} | {r[2]:,} -> {r[3]:,} ({r[3] / r[2]:.3f}) | {r[6]:,} | "
                  f"{r[7]:,} | {r[4]} | {r[5]} | {r[8]:.1f} / {r[9]:.1f} | {r[10]:.1f} / {r[11]:.1f} | {r[12]:.2f} | "
                  f"{r[13]:.2f} | {r[12] / r[13]:.2f} |".replace(",", " "))
    print("\n| robot | node quaternion width | split nodes | pass rate | no chart (a component's interval holds 0 in all 4) |")
    print("|---|---|---:|---:|---:|")
    for name, _, bins, _ in results:
        for a, b, n, rate, none in bins:
            print(f"| {name} | {a:g} to {b:g} | {n:,} | {rate:.3f} | {none:.3f} |".replace(",", " "))
    print("\n| robot | node quaternion width | sampled split nodes | pass rate, chart box by division | "
          "pass rate, hull of drawn unit quaternions' chart coordinates |")
    print("|---|---|---:|---:|---:|")
    for name, _, _, loss in results:
        for a, b, n, rate, inner in loss[4]:
            print(f"| {name} | {a:g} to {b:g} | {n:,} | {rate:.3f} | {inner:.3f} |".replace(",", " "))
        print(f"| {name} | all | {loss[1]:,} | {loss[2]:.3f} | {loss[3]:.3f} |".replace(",", " "))
    print(f"\ntotal {time.perf_counter() - t0:.0f} s wall")


if __name__ == "__main__":
    main()
