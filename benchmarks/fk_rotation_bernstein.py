"""Rotation-only branch-and-bound by Bernstein expansion of the 15 Cayley-Menger polynomials (issue 16).

For any 4 legs of a 6-6 Gough-Stewart robot, the sphere centres c_m = a_m − R b_m and the platform
origin p are 5 points of 3-space, so their Cayley-Menger (CM) determinant vanishes; its entries are
ρ_m² and d_mn² = |c_m − c_n|², linear in R.  That gives 15 equations in the rotation alone
(`benchmarks/fk_cayley_menger.py` measured them with interval and Taylor enclosures).  Here they are
enclosed by their Bernstein coefficients on boxes of a rotation chart, and a search over the rotation
alone is measured.

Charts: unit quaternions up to sign are covered by 4 charts, chart k sets q_k = 1 and leaves the
other three components (x, y, z) in [−1, 1] (chart k holds the rotations whose |q_k| is the largest
component).  With R̃(q) = |q|² R(q), homogeneous quadratic in q, d²_mn·|q|² and ρ²·|q|² are
quadratics in (x, y, z), and CM·|q|^8 is a polynomial of total degree 8 in (x, y, z) (CM is homogeneous
of degree 4 in the squared distances).  Its coefficients are derived exactly (sympy ring over QQ, the
robot file's decimals read as exact rationals), checked to vanish at the proved postures of
`certkin.fk.forward_kinematics`, mapped to the tensor Bernstein basis of degree (8, 8, 8) on the chart
[−1, 1]³ exactly, and rounded to float once.

Search, per chart (depth first, compiled with numba): a box is excluded when one of the 15
polynomials has all its Bernstein coefficients of one strict sign; otherwise, while its widest side is
above ``w_min``, it is bisected along that side and the children's coefficients come from the parent's
by de Casteljau at 1/2 (15 × 81 lines of 9 coefficients); boxes whose widest side is at most ``w_min``
and still not excluded are "left".  Printed per robot and w_min: boxes visited, excluded, left, CPU
time (after a warm-up compilation), time per visited box, the left boxes' clusters (touching boxes,
joined across charts when two clusters' rotations come within the box width), which clusters hold the
proved postures' rotations, and that every posture's rotation lies in a left box of every chart that
holds it (otherwise the study has a bug: it stops with an error).

``--rounded`` also runs the search with an error bound carried per polynomial: the exact Bernstein
coefficients rounded to float (bound u·|b|), then each de Casteljau split adds at most
8·u·max|b|·(1 + 16u) (each level of averaging is one rounded addition and an exact halving; averages of
errors never grow them); a box is excluded only when all coefficients of one polynomial are above the
bound (or all below its negative).  That is the price of a version with directed-rounding guarantees,
measured; it is still not a certificate (no checker reads it).

Stage 2 (unless ``--no-stage2``): what is left is handed to certkin's own 6-D search
(``certkin.fk.search.search_instances``, one engine batch, each domain searched as if alone): one domain
per cluster of touching left boxes of a chart (``--per-box``: per left box), its rotation the hull of
the unit quaternions of that chart box (q0 ≥ 0, certkin's half; split at q0 = 0 when it meets both
signs) widened by 2 % + 1e-6, its position certkin's full position domain.  Printed: domains, boxes,
CPU seconds, how many of the proved postures it proves again, and the same robot's 6-D search alone
(``forward_kinematics``, in the same process, the postures' source).

THIS IS A FLOAT STUDY, NOT CERTIFIED: nothing in certkin uses it.

    python benchmarks/fk_rotation_bernstein.py [--robot seed002 dietmaier] [--wmin 1e-2 1e-3 1e-4]
                                               [--rounded] [--no-stage2] [--per-box]

Run time on one core: about 4 min with ``--rounded`` (about 1 min of it certkin's FK searches for the
postures, 2 × 11 s the exact coefficients in sympy, ~15 s numba compilation the first time, 2 min
stage 2 on Dietmaier, the rotation searches 12 s, 11 s more with ``--rounded``); seed002 alone about
35 s.  ``--per-box`` makes Dietmaier's stage 2 at w_min 1e-3 take about 45 s by itself.
"""
from __future__ import annotations

import argparse
import itertools
import os
import time
import tomllib
from fractions import Fraction
from math import comb
from pathlib import Path

import numba
import numpy as np
import sympy as sp
from sympy import QQ
from sympy.polys.rings import ring

from fk_cayley_menger import D_SYMBOLS, QUADS, R_SYMBOLS, ROBOTS, cayley_menger_symbolic   # (that study's robots, quadruples, determinant)

DEG = 8                                               # degree of CM·|q|^8 in each chart variable
N1 = DEG + 1
U = 2.0 ** -53                                        # unit roundoff


# ---------------------------------------------------------------- exact CM polynomials per chart

def cayley_menger_terms():
    """Expanded CM determinant of 4 points and p: [(integer coefficient, exponents of D01..D23, r0..r3)]."""
    poly = sp.Poly(cayley_menger_symbolic(), *D_SYMBOLS, *R_SYMBOLS)
    return [(int(c), e) for e, c in poly.terms()]


def read_robot(name):
    """a, b (6×3) and ρ (6) of a robot as exact rationals (the file's decimals)."""
    path, lengths = ROBOTS[name]
    data = tomllib.loads(Path(path).read_text())
    a = [[Fraction(repr(float(v))) for v in row] for row in data["base"]]
    b = [[Fraction(repr(float(v))) for v in row] for row in data["platform"]]
    rho = [Fraction(t) for t in lengths.split(",")]
    return a, b, rho


def homogeneous_cm(a, b, rho):
    """The 15 polynomials CM·|q|^8, homogeneous of degree 8 in q = (q0, q1, q2, q3), exact (sympy ring)."""
    Rg, q0, q1, q2, q3 = ring("q0,q1,q2,q3", QQ)
    n2 = q0 ** 2 + q1 ** 2 + q2 ** 2 + q3 ** 2
    Rt = [[q0 ** 2 + q1 ** 2 - q2 ** 2 - q3 ** 2, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
          [2 * (q1 * q2 + q0 * q3), q0 ** 2 - q1 ** 2 + q2 ** 2 - q3 ** 2, 2 * (q2 * q3 - q0 * q1)],
          [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0 ** 2 - q1 ** 2 - q2 ** 2 + q3 ** 2]]

    def d2(m, n):      # |c_m − c_n|²·|q|² with c = a − R b
        da = [QQ(x.numerator, x.denominator) for x in (a[m][i] - a[n][i] for i in range(3))]
        db = [QQ(x.numerator, x.denominator) for x in (b[m][i] - b[n][i] for i in range(3))]
        out = (sum(x * x for x in da) + sum(x * x for x in db)) * n2
        for i in range(3):
            for j in range(3):
                if da[i] and db[j]:
                    out -= 2 * da[i] * db[j] * Rt[i][j]
        return out

    terms = cayley_menger_terms()
    polys = []
    for quad in QUADS:
        entries = [d2(quad[m], quad[n]) for m, n in itertools.combinations(range(4), 2)]
        entries += [QQ(rho[m].numerator ** 2, rho[m].denominator ** 2) * n2 for m in quad]
        powers = {}

        def power(v, e):
            if (v, e) not in powers:
                powers[(v, e)] = entries[v] ** e
            return powers[(v, e)]

        total = Rg(0)
        for c, e in terms:
            t = Rg(c)
            for v, ev in enumerate(e):
                if ev:
                    t = t * power(v, ev)
            total += t
        polys.append(total)
    return polys


def chart_power(poly, k):
    """Dense power coefficients A[i, j, l] (exact Fractions) of poly with q_k = 1, (x, y, z) the others."""
    A = np.full((N1, N1, N1), Fraction(0), dtype=object)
    for mono, c in poly.terms():
        e = [mono[i] for i in range(4) if i != k]
        A[e[0], e[1], e[2]] += Fraction(int(c.numerator), int(c.denominator))
    return A


def bernstein_matrix():
    """M (exact) with b = M a per axis: power coefficients on x in [−1, 1] -> Bernstein on that interval."""
    T = [[Fraction(0)] * N1 for _ in range(N1)]        # x = 2u − 1: T[j][i] = coefficient of u^i in (2u − 1)^j
    for j in range(N1):
        for i in range(j + 1):
            T[j][i] = Fraction(comb(j, i) * 2 ** i * (-1) ** (j - i))
    M = [[Fraction(0)] * N1 for _ in range(N1)]        # b_i = Σ_{m ≤ i} C(i, m)/C(n, m) p_m, p = power in u
    for i in range(N1):
        for j in range(N1):
            M[i][j] = sum((Fraction(comb(i, m), comb(DEG, m)) * T[j][m] for m in range(i + 1)), Fraction(0))
    return np.array(M, dtype=object)


def to_bernstein(A, M):
    """Tensor Bernstein coefficients (exact) of dense power coefficients A on [−1, 1]³."""
    B = np.tensordot(M, A, axes=([1], [0]))                        # axis 0
    B = np.tensordot(M, B, axes=([1], [1])).transpose(1, 0, 2)     # axis 1
    B = np.tensordot(M, B, axes=([1], [2])).transpose(1, 2, 0)     # axis 2
    return B


def power_eval(A, x):
    """Float value of dense power coefficients A at points x (N, 3)."""
    Af = A.astype(float)
    P = [np.stack([x[:, v] ** i for i in range(N1)], 1) for v in range(3)]
    return np.einsum("ijl,ni,nj,nl->n", Af, *P)


def bernstein_eval(B, x, lo, hi):
    """Float value of tensor Bernstein coefficients B on the box [lo, hi] at points x (N, 3)."""
    t = (x - lo) / (hi - lo)
    P = [np.stack([comb(DEG, i) * t[:, v] ** i * (1 - t[:, v]) ** (DEG - i) for i in range(N1)], 1) for v in range(3)]
    return np.einsum("ijl,ni,nj,nl->n", B, *P)


# ---------------------------------------------------------------- the search (compiled)

@numba.njit(cache=True)
def _split(src, left, right, axis):
    """de Casteljau at 1/2 along axis of src (15, 9, 9, 9) into left and right."""
    w = np.empty(N1)
    P = src.shape[0]
    for p in range(P):
        for i in range(N1):
            for j in range(N1):
                for t in range(N1):
                    if axis == 0:
                        w[t] = src[p, t, i, j]
                    elif axis == 1:
                        w[t] = src[p, i, t, j]
                    else:
                        w[t] = src[p, i, j, t]
                lo0 = w[0]
                hiN = w[N1 - 1]
                if axis == 0:
                    left[p, 0, i, j] = lo0
                    right[p, N1 - 1, i, j] = hiN
                elif axis == 1:
                    left[p, i, 0, j] = lo0
                    right[p, i, N1 - 1, j] = hiN
                else:
                    left[p, i, j, 0] = lo0
                    right[p, i, j, N1 - 1] = hiN
                for r in range(1, N1):
                    for t in range(N1 - r):
                        w[t] = 0.5 * (w[t] + w[t + 1])
                    if axis == 0:
                        left[p, r, i, j] = w[0]
                        right[p, N1 - 1 - r, i, j] = w[N1 - 1 - r]
                    elif axis == 1:
                        left[p, i, r, j] = w[0]
                        right[p, i, N1 - 1 - r, j] = w[N1 - 1 - r]
                    else:
                        left[p, i, j, r] = w[0]
                        right[p, i, j, N1 - 1 - r] = w[N1 - 1 - r]


@numba.njit(cache=True)
def _excluded(c, err):
    """True when one polynomial's coefficients all exceed err[p] or all lie below −err[p]."""
    P = c.shape[0]
    for p in range(P):
        e = err[p]
        pos = c[p, 0, 0, 0] > e
        neg = c[p, 0, 0, 0] < -e
        if not (pos or neg):
            continue
        ok = True
        for i in range(N1):
            for j in range(N1):
                for t in range(N1):
                    v = c[p, i, j, t]
                    if pos:
                        if not (v > e):
                            ok = False
                            break
                    else:
                        if not (v < -e):
                            ok = False
                            break
                if not ok:
                    break
            if not ok:
                break
        if ok:
            return True
    return False


@numba.njit(cache=True)
def _maxabs(c, p):
    m = 0.0
    for i in range(N1):
        for j in range(N1):
            for t in range(N1):
                v = abs(c[p, i, j, t])
                if v > m:
                    m = v
    return m


@numba.njit(cache=True)
def search(root, err0, wmin, rounded, max_left):
    """Depth-first search on [−1, 1]³: (visited, excluded, left boxes lo/hi (n, 3), n)."""
    P = root.shape[0]
    depth = 3 * 64
    stack = np.empty((depth, P, N1, N1, N1))
    errs = np.zeros((depth, P))
    blo = np.empty((depth, 3))
    bhi = np.empty((depth, 3))
    left_lo = np.empty((max_left, 3))
    left_hi = np.empty((max_left, 3))
    stack[0] = root
    errs[0] = err0
    blo[0] = -1.0
    bhi[0] = 1.0
    top = 1
    visited = 0
    excluded = 0
    nleft = 0
    grow = 8.0 * 2.0 ** -53 * (1.0 + 16.0 * 2.0 ** -53)
    while top > 0:
        top -= 1
        visited += 1
        if _excluded(stack[top], errs[top]):
            excluded += 1
            continue
        axis = 0
        wmax = bhi[top, 0] - blo[top, 0]
        for v in range(1, 3):
            if bhi[top, v] - blo[top, v] > wmax:
                wmax = bhi[top, v] - blo[top, v]
                axis = v
        if wmax <= wmin:
            if nleft < max_left:
                left_lo[nleft] = blo[top]
                left_hi[nleft] = bhi[top]
            nleft += 1
            continue
        # children: right into top + 1, left into top (overwriting the parent after the split)
        if rounded:
            for p in range(P):
                e = errs[top, p] + grow * _maxabs(stack[top], p)
                errs[top, p] = e
                errs[top + 1, p] = e
        else:
            errs[top + 1] = errs[top]
        _split(stack[top], stack[top], stack[top + 1], axis)    # each line is read whole before it is written
        mid = 0.5 * (blo[top, axis] + bhi[top, axis])
        blo[top + 1] = blo[top]
        bhi[top + 1] = bhi[top]
        blo[top + 1, axis] = mid
        bhi[top, axis] = mid
        top += 2
    return visited, excluded, left_lo[:min(nleft, max_left)], left_hi[:min(nleft, max_left)], nleft


# ---------------------------------------------------------------- postures, clusters

def chart_coordinates(q, k):
    """Chart k coordinates of the unit quaternions q (N, 4) (q_k ≠ 0)."""
    others = [i for i in range(4) if i != k]
    return q[:, others] / q[:, k:k + 1]


def chart_to_quaternion(x, k):
    """Unit quaternions (sign fixed by q_k > 0) of chart k points x (N, 3)."""
    q = np.insert(x, k, 1.0, axis=1)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def components(lo, hi, tol):
    """Connected components of closed boxes (touching counts), by a grid hash: labels (n,)."""
    n = len(lo)
    parent = np.arange(n)

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if n == 0:
        return parent
    cell = float((hi - lo).max()) + 2 * tol
    keys = np.floor(lo / cell).astype(np.int64)
    grid = {}
    for i, key in enumerate(map(tuple, keys)):
        grid.setdefault(key, []).append(i)
    for i, key in enumerate(map(tuple, keys)):
        for d in itertools.product((-1, 0, 1), repeat=3):
            for j in grid.get((key[0] + d[0], key[1] + d[1], key[2] + d[2]), ()):
                if j <= i:
                    continue
                if np.all(lo[i] <= hi[j] + tol) and np.all(lo[j] <= hi[i] + tol):
                    ri, rj = find(i), find(j)
                    if ri != rj:
                        parent[ri] = rj
    return np.array([find(i) for i in range(n)])


def clusters_across_charts(lefts, wmin):
    """Clusters of the left boxes of the 4 charts: touching in a chart, joined across charts when the
    rotations of two clusters' box centres come within 2·w_min (up to sign).  [(chart, indices) lists]."""
    groups = []       # each: list of (chart, index array)
    for k, (lo, hi) in enumerate(lefts):
        lab = components(lo, hi, 1e-12)
        for r in np.unique(lab):
            groups.append([(k, np.nonzero(lab == r)[0])])
    # representative rotations: centres of the boxes of each group
    reps = []
    for g in groups:
        (k, idx), = g
        lo, hi = lefts[k]
        reps.append(chart_to_quaternion((lo[idx] + hi[idx]) / 2, k))
    parent = list(range(len(groups)))

    def find(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for i in range(len(groups)):
        for j in range(i + 1, len(groups)):
            if groups[i][0][0] == groups[j][0][0]:
                continue
            d = np.abs(reps[i] @ reps[j].T)          # |cos| of the half angle, up to sign
            if np.max(d) > 1 - 2 * (2 * wmin) ** 2:  # within ~2 w_min
                ri, rj = find(i), find(j)
                if ri != rj:
                    parent[ri] = rj
    merged = {}
    for i, g in enumerate(groups):
        merged.setdefault(find(i), []).extend(g)
    return list(merged.values())


# ---------------------------------------------------------------- stage 2: certkin's 6-D search on what is left

def quaternion_hull(lo, hi, k):
    """Hull of the unit quaternions (q0 ≥ 0 half, certkin's) of chart k box [lo, hi]: list of (qlo, qhi)
    (two when the box meets both signs of q0)."""
    if k != 0 and lo[0] < 0 < hi[0]:
        a_hi, b_lo = hi.copy(), lo.copy()
        a_hi[0], b_lo[0] = 0.0, 0.0
        return quaternion_hull(lo, a_hi, k) + quaternion_hull(b_lo, hi, k)
    sq_lo = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(lo * lo, hi * hi))
    sq_hi = np.maximum(lo * lo, hi * hi)
    qlo, qhi = np.empty(4), np.empty(4)
    qlo[k], qhi[k] = 1 / np.sqrt(1 + sq_hi.sum()), 1 / np.sqrt(1 + sq_lo.sum())
    for v, j in enumerate(i for i in range(4) if i != k):
        smin, smax = sq_lo.sum() - sq_lo[v], sq_hi.sum() - sq_hi[v]
        f = lambda x, s: x / np.sqrt(1 + x * x + s)
        qlo[j] = f(lo[v], smax if lo[v] >= 0 else smin)
        qhi[j] = f(hi[v], smin if hi[v] >= 0 else smax)
    if k != 0 and hi[0] <= 0:
        qlo, qhi = -qhi, -qlo
    return [(qlo, qhi)]


def stage2(name, lefts, p, q, per_box=False):
    """certkin's FK search (one engine batch, each domain searched as if alone) on the hulls of the left
    boxes' clusters of each chart (each left box with ``per_box``), widened by 2 % (+1e-6), the position
    in certkin's domain: domains, boxes, CPU s, postures proved, undecided leaves, boxes per domain."""
    from intervals import Interval, sqr
    from certkin import load_robot
    from certkin.engine import PROVED, UNDECIDED, budgets
    from certkin.engine.budgets import make_budget
    from certkin.fk.search import search_instances
    from certkin.fk.system import fk_system
    from certkin.robots.poses import length_enclosures
    path, lengths = ROBOTS[name]
    robot = load_robot(path)
    system = fk_system(robot)
    rho = length_enclosures(robot, lengths)[0]
    L = sqr(rho)
    dlo, dhi = system.domain(rho)
    rows_lo, rows_hi = [], []
    for k, (lo, hi) in enumerate(lefts):
        lab = np.arange(len(lo)) if per_box else components(lo, hi, 1e-12)
        for r in np.unique(lab):
            sel = lab == r
            for qlo, qhi in quaternion_hull(lo[sel].min(0), hi[sel].max(0), k):
                pad = 0.02 * (qhi - qlo) + 1e-6
                rlo, rhi = dlo[0].copy(), dhi[0].copy()
                rlo[3:] = np.maximum(qlo - pad, dlo[0, 3:])
                rhi[3:] = np.minimum(qhi + pad, dhi[0, 3:])
                rows_lo.append(rlo)
                rows_hi.append(rhi)
    lo, hi = np.array(rows_lo), np.array(rows_hi)
    M = len(lo)
    LM = Interval.from_bounds(np.repeat(L.lo, M, 0), np.repeat(L.hi, M, 0))
    budget = make_budget({**budgets.FORWARD_KINEMATICS, "max_boxes": 40_000_000})
    t0 = time.process_time()
    res = search_instances(system, LM, lo, hi, budget, independent=True)
    seconds = time.process_time() - t0
    tree = res.tree
    proved = tree.leaves(kind=PROVED)
    undecided = tree.leaves(kind=UNDECIDED)
    boxes = int(tree.nodes_per_root().sum())
    qs = np.where(q[:, :1] < 0, -q, q)
    x = np.concatenate([p, qs], 1)
    plo, phi = tree.lo[proved], tree.hi[proved]
    found = sum(bool(np.any(np.all((plo <= xi + 1e-9) & (xi <= phi + 1e-9), axis=1))) for xi in x)
    return M, boxes, seconds, found, len(undecided), tree.nodes_per_root()


# ---------------------------------------------------------------- driver

def postures_of(name):
    """(p, q) of the postures proved by certkin's FK search (q unit, q0 scalar), and its CPU seconds and boxes."""
    from certkin import load_robot
    from certkin.fk import forward_kinematics
    path, lengths = ROBOTS[name]
    t0 = time.process_time()
    res = forward_kinematics(load_robot(path), lengths)
    seconds = time.process_time() - t0
    P = np.array([(np.asarray(s["box"].lo, float) + np.asarray(s["box"].hi, float)) / 2 for s in res.solutions])
    q = P[:, 3:] / np.linalg.norm(P[:, 3:], axis=1, keepdims=True)
    return P[:, :3], q, res.complete, res.boxes, seconds


def prepare(name):
    """Exact chart polynomials -> float Bernstein coefficients (4 charts × (15, 9, 9, 9)), with checks."""
    t0 = time.process_time()
    a, b, rho = read_robot(name)
    hom = homogeneous_cm(a, b, rho)
    M = bernstein_matrix()
    powers, roots, errs = [], [], []
    for k in range(4):
        Ak = [chart_power(h, k) for h in hom]
        Bk = [to_bernstein(A, M) for A in Ak]
        powers.append(Ak)
        Bf = np.array([B.astype(float) for B in Bk])
        roots.append(np.ascontiguousarray(Bf))
        errs.append(U * np.abs(Bf).max(axis=(1, 2, 3)))     # rounding each exact coefficient once
    return hom, powers, roots, errs, time.process_time() - t0


def check_polynomials(name, hom, powers, roots, q):
    """Relative values of the 15 polynomials at the postures, and Bernstein vs power form at random points."""
    worst_posture, worst_form = 0.0, 0.0
    rng = np.random.default_rng(0)
    for k in range(4):
        x = rng.uniform(-1, 1, size=(2000, 3))
        inside = np.abs(q[:, k]) >= np.abs(q).max(1) - 1e-15
        xp = chart_coordinates(q[inside], k)
        for A, B in zip(powers[k], roots[k]):
            v = power_eval(A, x)
            scale = np.median(np.abs(v))
            vb = bernstein_eval(B, x, -1.0, 1.0)
            worst_form = max(worst_form, np.abs(v - vb).max() / scale)
            if len(xp):
                worst_posture = max(worst_posture, np.abs(power_eval(A, xp)).max() / scale)
    print(f"{name}: 15 CM·|q|^8 polynomials, total degree {max(h.degree() for h in hom[:1])} in q; "
          f"at the proved postures max |P|/median|P| = {worst_posture:.1e}; "
          f"Bernstein vs power form {worst_form:.1e}")
    assert worst_posture < 1e-8, "the CM polynomials do not vanish at the postures"


def run(name, wmins, rounded_too, stage_two=True, per_box=False, max_left=4_000_000):
    p, q, complete, boxes6, sec6 = postures_of(name)
    print(f"{name}: certkin FK (6-D search, in this process): {len(q)} postures, complete {complete}, "
          f"{boxes6} boxes, {sec6:.1f} s CPU")
    hom, powers, roots, errs, sec = prepare(name)
    print(f"{name}: exact coefficients, 4 charts × 15 polynomials × 729 Bernstein coefficients: {sec:.1f} s")
    check_polynomials(name, hom, powers, roots, q)
    search(roots[0], errs[0], 0.5, False, 10)        # compile / warm up
    search(roots[0], errs[0], 0.5, True, 10)
    rows = []
    for rounded in ((False, True) if rounded_too else (False,)):
        for wmin in wmins:
            t0 = time.process_time()
            out = [search(roots[k], errs[k] if rounded else np.zeros(15), wmin, rounded, max_left) for k in range(4)]
            seconds = time.process_time() - t0
            visited = sum(o[0] for o in out)
            excluded = sum(o[1] for o in out)
            nleft = sum(o[4] for o in out)
            assert all(o[4] <= max_left for o in out), "too many left boxes for max_left"
            lefts = [(o[2], o[3]) for o in out]
            # every posture inside a left box of every chart holding it
            missing, dmax = 0, 0.0
            for k in range(4):
                lo, hi = lefts[k]
                hold = np.abs(q[:, k]) >= np.abs(q).max(1) - 1e-12
                for x in chart_coordinates(q[hold], k):
                    ins = np.all((lo <= x + 1e-12) & (x <= hi + 1e-12), axis=1)
                    if not ins.any():
                        missing += 1
                        gap = np.maximum(np.maximum(lo - x, x - hi), 0).max(1).min() if len(lo) else np.inf
                        dmax = max(dmax, gap)
            assert missing == 0, f"{missing} posture rotations outside every left box (max gap {dmax:.1e})"
            groups = clusters_across_charts(lefts, wmin)
            holding = []
            for g in groups:
                lo = np.concatenate([lefts[k][0][idx] for k, idx in g])
                hi = np.concatenate([lefts[k][1][idx] for k, idx in g])
                n_in = 0
                for s in range(len(q)):      # postures whose rotation is within the cluster
                    for k, idx in g:
                        if abs(q[s, k]) < np.abs(q[s]).max() - 1e-12:
                            continue
                        x = chart_coordinates(q[s:s + 1], k)[0]
                        if np.any(np.all((lefts[k][0][idx] <= x + 1e-12) & (x <= lefts[k][1][idx] + 1e-12), axis=1)):
                            n_in += 1
                            break
                span = np.max(hi.max(0) - lo.min(0)) if len(g) == 1 else np.nan
                holding.append((n_in, sum(len(idx) for _, idx in g), span))
            centres = np.concatenate([chart_to_quaternion((lo + hi) / 2, k) for k, (lo, hi) in enumerate(lefts)])
            angle = 2 * np.arccos(np.clip(np.abs(centres @ q.T).max(1), 0, 1))      # to the nearest posture
            far = [int(np.sum(angle > f * wmin)) for f in (10, 100)]
            with_posture = sum(1 for h in holding if h[0] > 0)
            most = max((h[0] for h in holding), default=0)
            sizes = sorted(h[1] for h in holding)
            empty_boxes = sum(h[1] for h in holding if h[0] == 0)
            if stage_two and not rounded:
                M, boxes2, sec2, found, und, per = stage2(name, lefts, p, q, per_box)
                two = (M, boxes2, sec2, found, und, int(np.max(per)))
            else:
                two = None
            rows.append((name, "error bound" if rounded else "float", wmin, visited, excluded, nleft, seconds,
                         1e6 * seconds / visited, len(groups), with_posture, most, empty_boxes,
                         sizes[len(sizes) // 2] if sizes else 0, sizes[-1] if sizes else 0, far, two, sec6, boxes6))
            print(f"  {'error bound' if rounded else 'float'} w_min {wmin:g}: visited {visited}, excluded {excluded}, "
                  f"left {nleft}, {seconds:.2f} s CPU ({1e6 * seconds / visited:.1f} µs/box); "
                  f"{len(groups)} clusters, {with_posture} hold postures (at most {most} in one), "
                  f"{empty_boxes} left boxes in clusters without a posture; boxes per cluster median "
                  f"{rows[-1][12]}, max {rows[-1][13]}; all {len(q)} postures inside left boxes; left boxes whose "
                  f"rotation is > 10 w_min / > 100 w_min (angle) from every posture: {far[0]} / {far[1]}", flush=True)
            if two:
                print(f"    stage 2 ({'each left box' if per_box else 'hull of each cluster'} of a chart, certkin's "
                      f"6-D search): {two[0]} domains, {two[1]} boxes (at most {two[5]} in one), {two[2]:.2f} s CPU, "
                      f"{two[3]} of {len(q)} postures proved, {two[4]} undecided leaves", flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--robot", nargs="+", default=["seed002", "dietmaier"], choices=sorted(ROBOTS))
    ap.add_argument("--wmin", nargs="+", type=float, default=[1e-2, 1e-3, 1e-4])
    ap.add_argument("--rounded", action="store_true", help="also the search with error bounds")
    ap.add_argument("--no-stage2", action="store_true", help="skip certkin's 6-D search on the left boxes")
    ap.add_argument("--per-box", action="store_true", help="stage 2 on each left box instead of each cluster's hull")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}; "
          f"numba {numba.__version__}, numpy {np.__version__}")
    rows = []
    for name in args.robot:
        rows += run(name, args.wmin, args.rounded, not args.no_stage2, args.per_box)
    print("\n| robot | arithmetic | w_min | visited | excluded | left | CPU s | µs/box | clusters | "
          "with postures | most postures in one | left boxes without posture | boxes/cluster median | max | "
          "left > 10 w_min / > 100 w_min from postures |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]:g} | {r[3]:,} | {r[4]:,} | {r[5]:,} | {r[6]:.2f} | {r[7]:.1f} | {r[8]} | "
              f"{r[9]} | {r[10]} | {r[11]:,} | {r[12]} | {r[13]} | {r[14][0]:,} / {r[14][1]:,} |".replace(",", " "))
    print("\n| robot | w_min | rotation stage: boxes, CPU s | stage 2 domains | stage 2 boxes (most in one) | "
          "stage 2 CPU s | postures proved | both stages CPU s | 6-D search alone: boxes, CPU s |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---|")
    for r in rows:
        if r[15]:
            t = r[15]
            print(f"| {r[0]} | {r[2]:g} | {r[3]:,}, {r[6]:.2f} | {t[0]} | {t[1]:,} ({t[5]:,}) | {t[2]:.2f} | {t[3]} | "
                  f"{r[6] + t[2]:.2f} | {r[17]:,}, {r[16]:.2f} |".replace(",", " ").replace("  ", ", "))


if __name__ == "__main__":
    main()
