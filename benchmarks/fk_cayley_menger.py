"""Cayley-Menger exclusion on the rotation: would it exclude the FK search's excluded leaves when wider?

For any 4 legs m < n < o < s of a 6-6 Gough-Stewart robot, the points c_i = a_i − R b_i of those legs
and the platform origin p are 5 points of 3-space, so their Cayley-Menger (CM) determinant
vanishes.  Its entries are D_ij = |c_i − c_j|² (functions of the rotation R alone) and
|p − c_i|² = ρ_i², so each of the 15 quadruples gives an equation in the rotation alone: a
quaternion box on which one of the 15 CM polynomials keeps one sign holds no posture.

The script runs certkin's FK search with ``record="whole"`` on one robot, checks that the 15 CM
values vanish at the proved postures, draws a random sample of the excluded leaves, widens each
leaf's quaternion box 1x, 2x, 4x, 8x about its centre and prints, per width, the fraction of the
sampled leaves excluded by

- exact CM (sampled): ``--points`` unit quaternions drawn in the box; excluded when one
  quadruple's CM has the same sign at all of them, |CM| > 1e-6 × that quadruple's typical size
  (what the best possible enclosure could do, up to sampling);
- exact pairs (sampled): one pair's triangle inequality |ρ_i − ρ_j| ≤ |c_i − c_j| ≤ ρ_i + ρ_j fails
  at all of them (the test on two legs, for comparison);
- naive: natural interval evaluation (entries of R, then the D_ij, then the expanded polynomial);
- centred: mean-value form in q, the gradient enclosed over the box;
- Taylor (c): Taylor form in q about the box centre: exact value and gradient, the quadratic part
  of D(q) through the gradient, the higher orders of CM in D bounded by magnitudes;
- Taylor-2 (c'): as (c), with the second order of CM in D taken through q as one 4x4 quadratic form.

Leaves whose widened box holds no sampled unit quaternion are left out of the sampled columns
(their share is the "unsampled" column).  With ``--replay`` every split node of the recorded tree is
tested by (c) and (c'); a passing node would have been an excluded leaf (the rest of the tree is
unchanged: same bisection), so every decided box (root or child of a split) below it is saved.  The
replay prints the decided boxes before -> after, and the split nodes holding a proved posture that
pass (must be 0) and proved leaves lost (must be 0).  Times are numpy (one process, vectorised
over boxes) for all 15 quadruples of a box.

The enclosures here are float studies WITHOUT outward rounding: NOT certified, and nothing in
certkin uses them.

    python benchmarks/fk_cayley_menger.py [--robot seed002|dietmaier] [--sample 3000] [--points 300] [--seed 0] [--replay]

``--seed 1`` draws the leaf sample of the original study (and reproduces its table).  seed002 takes
~1.5 min, ~3 min with ``--replay``, on one core (plus ~35 s for certkin's numba kernels the first
time); Dietmaier's search alone takes ~60 s and its tree is 12 times larger.
"""
from __future__ import annotations

import argparse
import itertools
import time
from math import comb
from pathlib import Path

import numpy as np
import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "robots"
ROBOTS = {   # name: (robot file, leg lengths)
    "seed002": (EXAMPLES / "seed002-general-6-6-24-solutions.toml", "1.093,2.280,2.031,2.524,3.136,1.845"),
    "dietmaier": (EXAMPLES / "dietmaier-6-6-40.toml", "1,0.645275,1.086284,1.503439,1.281933,0.771071"),
}
QUADS = list(itertools.combinations(range(6), 4))     # the 15 quadruples of legs
PAIRS = list(itertools.combinations(range(6), 2))     # the 15 pairs of legs
WIDTHS = (1, 2, 4, 8)
MARGIN = 1e-6      # sampled CM test: |CM| above this times the quadruple's typical |CM|


# ---------------------------------------------------------------- rotation and its derivatives

def rotation(q):
    """R(q) of certkin's unknowns (non-homogeneous form): q (..., 4) -> (..., 3, 3)."""
    q0, q1, q2, q3 = np.moveaxis(q, -1, 0)
    return np.stack([np.stack([1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)], -1),
                     np.stack([2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)], -1),
                     np.stack([2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)], -1)],
                    -2)


def rotation_derivatives(q):
    """dR/dq_k, (..., 4, 3, 3); linear in q."""
    q0, q1, q2, q3 = np.moveaxis(q, -1, 0)
    z = 0 * q0
    d0 = [[z, -2 * q3, 2 * q2], [2 * q3, z, -2 * q1], [-2 * q2, 2 * q1, z]]
    d1 = [[z, 2 * q2, 2 * q3], [2 * q2, -4 * q1, -2 * q0], [2 * q3, 2 * q0, -4 * q1]]
    d2 = [[-4 * q2, 2 * q1, 2 * q0], [2 * q1, z, 2 * q3], [-2 * q0, 2 * q3, -4 * q2]]
    d3 = [[-4 * q3, -2 * q0, 2 * q1], [2 * q0, -4 * q3, 2 * q2], [2 * q1, 2 * q2, z]]
    return np.stack([np.stack([np.stack(row, -1) for row in d], -2) for d in (d0, d1, d2, d3)], -3)


# ---------------------------------------------------------------- the CM polynomials of a robot

D_SYMBOLS = sp.symbols("D01 D02 D03 D12 D13 D23")    # squared distances of the 4 centres
R_SYMBOLS = sp.symbols("r0 r1 r2 r3")                # squared leg lengths


def cayley_menger_symbolic():
    """Expanded CM determinant of 4 centres and p, in D_SYMBOLS and R_SYMBOLS."""
    M = sp.zeros(6, 6)
    for i in range(1, 6):
        M[0, i] = M[i, 0] = 1
    for (m, n), s in zip(itertools.combinations(range(4), 2), D_SYMBOLS):
        M[1 + m, 1 + n] = M[1 + n, 1 + m] = s
    for m in range(4):
        M[1 + m, 5] = M[5, 1 + m] = R_SYMBOLS[m]
    return sp.expand(M.det())


class Geometry:
    """A robot's legs (a, b, ρ) and its 15 CM polynomials, each in the 6 D_ij of its quadruple.

    D_ij = |c_i − c_j|² = c0_ij − 2 W_ij : R with W_ij = (a_i − a_j)(b_i − b_j)ᵀ, linear in R.
    ``polys[k]``: (coefficients (T,), exponents (T, 6)) of quadruple k; ``qpairs[k]``: the indices
    (in PAIRS) of its 6 D's, in the order of D_SYMBOLS.
    """

    def __init__(self, a, b, rho):
        self.a, self.b, self.rho = (np.asarray(x, float) for x in (a, b, rho))
        da = np.array([self.a[m] - self.a[n] for m, n in PAIRS])
        db = np.array([self.b[m] - self.b[n] for m, n in PAIRS])
        self.c0 = np.sum(da ** 2, 1) + np.sum(db ** 2, 1)
        self.W = np.einsum("pi,pj->pij", da, db)
        pair_index = {p: k for k, p in enumerate(PAIRS)}
        cm = cayley_menger_symbolic()
        self.polys, qpairs = [], []
        for quad in QUADS:
            poly = sp.Poly(cm.subs({s: float(self.rho[quad[k]] ** 2) for k, s in enumerate(R_SYMBOLS)}), *D_SYMBOLS)
            terms = poly.terms()
            self.polys.append((np.array([float(c) for _, c in terms]), np.array([e for e, _ in terms], int)))
            qpairs.append([pair_index[(quad[m], quad[n])] for m, n in itertools.combinations(range(4), 2)])
        self.qpairs = np.array(qpairs)

    def squared_distances(self, q):
        """D_ij (..., 15 pairs) at quaternions q (..., 4)."""
        return self.c0 - 2 * np.einsum("pij,...ij->...p", self.W, rotation(q))

    def cm_determinant(self, q):
        """The 15 CM values (..., 15) as float 6x6 determinants (independent of the expansion)."""
        D = self.squared_distances(q)
        M = np.zeros(D.shape[:-1] + (15, 6, 6))
        M[..., 0, 1:] = M[..., 1:, 0] = 1
        for k, quad in enumerate(QUADS):
            for (m, n), p in zip(itertools.combinations(range(4), 2), self.qpairs[k]):
                M[..., k, 1 + m, 1 + n] = M[..., k, 1 + n, 1 + m] = D[..., p]
            for m in range(4):
                M[..., k, 1 + m, 5] = M[..., k, 5, 1 + m] = self.rho[quad[m]] ** 2
        return np.linalg.det(M)

    def cm_polynomial(self, D):
        """The 15 CM values (..., 15) from the expanded polynomials at D (..., 15 pairs)."""
        out = []
        for (c, e), idx in zip(self.polys, self.qpairs):
            out.append(np.sum(c * np.prod(D[..., None, idx] ** e, -1), -1))
        return np.stack(out, -1)

    def pair_bounds(self):
        """(ρ_i − ρ_j)², (ρ_i + ρ_j)² per pair: D_ij must lie between them."""
        rm, rn = self.rho[[m for m, _ in PAIRS]], self.rho[[n for _, n in PAIRS]]
        return (rm - rn) ** 2, (rm + rn) ** 2


# ---------------------------------------------------------------- float interval arithmetic (no outward rounding)

def imul(al, ah, bl, bh):
    """[al, ah] · [bl, bh]."""
    p = np.stack([al * bl, al * bh, ah * bl, ah * bh])
    return p.min(0), p.max(0)


def ipow(lo, hi, e):
    """[lo, hi]^e, e a natural number."""
    if e == 0:
        return np.ones_like(lo), np.ones_like(hi)
    if e == 1:
        return lo, hi
    a, b = lo ** e, hi ** e
    if e % 2:
        return a, b
    return np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(a, b)), np.maximum(a, b)


def rotation_interval(ql, qh, clip=True):
    """Range of each entry of R over the quaternion box (exact: each q_k occurs once per term sum),
    clipped to [−1, 1] (true on the unit sphere) unless ``clip`` is False: (..., 3, 3) lo, hi."""
    sq = [ipow(ql[..., k], qh[..., k], 2) for k in range(4)]

    def prod(i, j):
        return imul(ql[..., i], qh[..., i], ql[..., j], qh[..., j])

    def diagonal(i, j):          # 1 − 2 (q_i² + q_j²)
        return 1 - 2 * (sq[i][1] + sq[j][1]), 1 - 2 * (sq[i][0] + sq[j][0])

    def off(x, y, sign):         # 2 (x ± y)
        if sign > 0:
            return 2 * (x[0] + y[0]), 2 * (x[1] + y[1])
        return 2 * (x[0] - y[1]), 2 * (x[1] - y[0])

    E = [[diagonal(2, 3), off(prod(1, 2), prod(0, 3), -1), off(prod(1, 3), prod(0, 2), 1)],
         [off(prod(1, 2), prod(0, 3), 1), diagonal(1, 3), off(prod(2, 3), prod(0, 1), -1)],
         [off(prod(1, 3), prod(0, 2), -1), off(prod(2, 3), prod(0, 1), 1), diagonal(1, 2)]]
    lo = np.stack([np.stack([E[i][j][0] for j in range(3)], -1) for i in range(3)], -2)
    hi = np.stack([np.stack([E[i][j][1] for j in range(3)], -1) for i in range(3)], -2)
    return (np.clip(lo, -1, 1), np.clip(hi, -1, 1)) if clip else (lo, hi)


def distance_interval(G, Rl, Rh):
    """Exact range of D = c0 − 2 W : R over the box of R entries: (..., 15) lo, hi."""
    mid = G.c0 - 2 * np.einsum("pij,...ij->...p", G.W, (Rl + Rh) / 2)
    rad = 2 * np.einsum("pij,...ij->...p", np.abs(G.W), (Rh - Rl) / 2)
    return mid - rad, mid + rad


def polynomial_interval(c, e, Dl, Dh):
    """Natural interval evaluation of Σ_t c_t Π_v D_v^e_tv over D in [Dl, Dh] (..., 6)."""
    total_lo, total_hi = np.zeros(Dl.shape[:-1]), np.zeros(Dl.shape[:-1])
    powers = {}
    for ct, et in zip(c, e):
        tl, th = np.full(Dl.shape[:-1], ct), np.full(Dl.shape[:-1], ct)
        for v in np.nonzero(et)[0]:
            key = (v, et[v])
            if key not in powers:
                powers[key] = ipow(Dl[..., v], Dh[..., v], et[v])
            tl, th = imul(tl, th, *powers[key])
        total_lo += tl
        total_hi += th
    return total_lo, total_hi


def polynomial_gradient(c, e):
    """The 6 partial derivatives of Σ c_t Π D^e_t, each as (coefficients, exponents)."""
    out = []
    for v in range(6):
        has = e[:, v] > 0
        ev = e[has].copy()
        ev[:, v] -= 1
        out.append((c[has] * e[has, v], ev))
    return out


# ---------------------------------------------------------------- the enclosures of the 15 CM values over q-boxes

def excludes(lo, hi):
    """(N,) True where one of the 15 enclosures (N, 15) misses 0."""
    return ((lo > 0) | (hi < 0)).any(1)


def enclose_naive(G, ql, qh):
    """Natural interval CM over the boxes: R entries -> D_ij -> expanded polynomial."""
    Dl, Dh = distance_interval(G, *rotation_interval(ql, qh))
    out = [polynomial_interval(c, e, Dl[..., idx], Dh[..., idx]) for (c, e), idx in zip(G.polys, G.qpairs)]
    return np.stack([o[0] for o in out], -1), np.stack([o[1] for o in out], -1)


class CentredCM:
    """Mean-value form in q: CM(centre) + Σ_k [dCM/dq_k over the box] · [−r_k, r_k].

    dCM/dq_k = Σ_v dP/dD_v · dD_v/dq_k, dP/dD_v by natural interval evaluation over the D box (R not
    clipped: the segment from the centre leaves the sphere), dD/dq_k linear in q (exact range).
    """

    def __init__(self, G):
        self.G = G
        self.gradients = [polynomial_gradient(c, e) for c, e in G.polys]
        self.dD_coef = -2 * np.einsum("pij,lkij->lkp", G.W, rotation_derivatives(np.eye(4)))   # (l, k, 15)

    def enclose(self, ql, qh):
        """Enclosures lo, hi (..., 15) of the 15 CM values over the boxes [ql, qh] (..., 4)."""
        G = self.G
        qm, qr = (ql + qh) / 2, (qh - ql) / 2
        Dl, Dh = distance_interval(G, *rotation_interval(ql, qh, clip=False))
        value = G.cm_polynomial(G.squared_distances(qm))
        dD_mid = -2 * np.einsum("pij,...kij->...kp", G.W, rotation_derivatives(qm))           # (..., 4, 15)
        dD_rad = np.einsum("lkp,...l->...kp", np.abs(self.dD_coef), qr)
        lo, hi = [], []
        for k, idx in enumerate(G.qpairs):
            Sl = Sh = 0.0
            for v in range(6):
                gl, gh = polynomial_interval(*self.gradients[k][v], Dl[..., idx], Dh[..., idx])
                dmid, drad = dD_mid[..., :, idx[v]], dD_rad[..., :, idx[v]]
                sl, sh = imul(gl[..., None], gh[..., None], dmid - drad, dmid + drad)
                Sl, Sh = Sl + sl, Sh + sh
            rad = np.sum(np.maximum(np.abs(Sl), np.abs(Sh)) * qr, -1)
            lo.append(value[..., k] - rad)
            hi.append(value[..., k] + rad)
        return np.stack(lo, -1), np.stack(hi, -1)


class TaylorCM:
    """(c) Taylor form of CM in q about the box centre m, radius r.

    D(q) is quadratic in q: D(m + δ) = D(m) + J δ + ½ δᵀ Hq δ exactly, |J δ + ½ δᵀ Hq δ| ≤ e.
    CM(D(m) + ε) = Σ_β C_β ε^β (C_β: Taylor coefficients of the polynomial at D(m)).  The order 0
    and 1 terms are taken through q exactly (value, gradient g·J, quadratic ½ Σ_v g_v Hq_v), the
    orders ≥ 2 bounded by |C_β| e^β.
    """

    first_bounded_order = 2

    def __init__(self, G):
        self.G = G
        self.shift = [self._shift_table(c, e) for c, e in G.polys]
        A = rotation_derivatives(np.eye(4))                   # dR/dq_k = Σ_l A_lk q_l
        self.Hq = -2 * np.einsum("pij,lkij->pkl", G.W, A)     # Hessian of D_p in q (constant), (15, 4, 4)

    @staticmethod
    def _shift_table(c, e):
        """Rows of the expansion of Σ c Π (Dm + ε)^e in ε: factor, power of Dm, index of ε^β; the βs."""
        rows = []
        for ct, et in zip(c, e):
            for beta in itertools.product(*[range(x + 1) for x in et]):
                factor = ct * np.prod([comb(int(et[v]), beta[v]) for v in range(6)])
                rows.append((beta, factor, et - np.array(beta)))
        betas = sorted(set(r[0] for r in rows))
        where = {b: i for i, b in enumerate(betas)}
        return (np.array([r[1] for r in rows]), np.array([r[2] for r in rows]),
                np.array([where[r[0]] for r in rows]), np.array(betas))

    def _centre(self, ql, qh):
        """Centre, radius, D at the centre, J = dD/dq there (N, 4, 15), bounds on |J δ| and |½ δᵀ Hq δ|."""
        m, r = (ql + qh) / 2, (qh - ql) / 2
        J = -2 * np.einsum("pij,nkij->nkp", self.G.W, rotation_derivatives(m))
        linear = np.einsum("nkp,nk->np", np.abs(J), r)
        quadratic = 0.5 * np.einsum("pkl,nk,nl->np", np.abs(self.Hq), r, r)
        return m, r, self.G.squared_distances(m), J, linear, quadratic

    def _coefficients(self, k, Dm):
        """Taylor coefficients C (N, B) of quadruple k's polynomial at Dm, the βs, their orders, and
        the value and gradient (N, 6) at Dm."""
        factor, power, index, betas = self.shift[k]
        terms = factor * np.prod(Dm[:, None, self.G.qpairs[k]] ** power[None], -1)
        C = np.zeros((len(Dm), len(betas)))
        np.add.at(C.T, index, terms.T)
        order = betas.sum(1)
        first = np.nonzero(order == 1)[0]
        gradient = np.zeros((len(Dm), 6))
        gradient[:, np.argmax(betas[first], 1)] = C[:, first]
        return C, betas, order, C[:, order == 0][:, 0], gradient

    def _tail(self, C, betas, order, e):
        """Σ |C_β| e^β over the orders bounded by magnitudes."""
        high = order >= self.first_bounded_order
        return np.sum(np.abs(C[:, high]) * np.prod(e[:, None, :] ** betas[high][None], -1), 1)

    def _quadratic_form(self, k, J, gradient, C, betas, order, r, linear, quadratic):
        """4x4 quadratic part in q, and its extra remainder (none for (c))."""
        return 0.5 * np.einsum("nv,vkl->nkl", gradient, self.Hq[self.G.qpairs[k]]), 0.0

    def enclose(self, ql, qh):
        """Enclosures lo, hi (N, 15) of the 15 CM values over the boxes [ql, qh] (N, 4)."""
        m, r, Dm, J, linear, quadratic = self._centre(ql, qh)
        e = linear + quadratic
        lo, hi = [], []
        for k, idx in enumerate(self.G.qpairs):
            C, betas, order, value, gradient = self._coefficients(k, Dm)
            Q, extra = self._quadratic_form(k, J[:, :, idx], gradient, C, betas, order, r,
                                            linear[:, idx], quadratic[:, idx])
            Gq = np.einsum("nv,nkv->nk", gradient, J[:, :, idx])       # exact gradient in q at the centre
            rad = np.sum(np.abs(Gq) * r, 1) + np.einsum("nkl,nk,nl->n", np.abs(Q), r, r) + extra
            rad = rad + self._tail(C, betas, order, e[:, idx])
            lo.append(value - rad)
            hi.append(value + rad)
        return np.stack(lo, 1), np.stack(hi, 1)


class Taylor2CM(TaylorCM):
    """(c') as (c), with the second order of CM in D through q: ½ δᵀ (Jᵀ H J + Σ_v g_v Hq_v) δ bounded as
    one 4x4 quadratic form (H: Hessian of CM in D at the centre); the cross terms of H with the
    quadratic part of D bounded by magnitudes; orders ≥ 3 by |C_β| e^β."""

    first_bounded_order = 3

    def _quadratic_form(self, k, J, gradient, C, betas, order, r, linear, quadratic):
        """4x4 quadratic part in q with the Hessian H of CM in D, and the bound on H's cross terms
        with the quadratic part of D."""
        H = np.zeros((len(C), 6, 6))
        for b in np.nonzero(order == 2)[0]:
            v = np.nonzero(betas[b])[0]
            if len(v) == 1:
                H[:, v[0], v[0]] = 2 * C[:, b]
            else:
                H[:, v[0], v[1]] = H[:, v[1], v[0]] = C[:, b]
        Q = (0.5 * np.einsum("nv,vkl->nkl", gradient, self.Hq[self.G.qpairs[k]])
             + 0.5 * np.einsum("nkv,nvw,nlw->nkl", J, H, J))
        extra = (np.einsum("nv,nvw,nw->n", quadratic, np.abs(H), linear)
                 + 0.5 * np.einsum("nv,nvw,nw->n", quadratic, np.abs(H), quadratic))
        return Q, extra


# ---------------------------------------------------------------- the search and the check at its postures

def recorded_search(path, lengths):
    """certkin's FK search with the whole tree recorded: (result, the tree's columns lo, hi, kind,
    parent, the postures' box centres, CPU seconds of the search)."""
    from certkin.fk import forward_kinematics
    t0 = time.process_time()
    res = forward_kinematics(path, lengths, record="whole")
    seconds = time.process_time() - t0
    cols = {name: np.asarray(getattr(res.tree, name)) for name in ("lo", "hi", "kind", "parent")}
    assert np.all(cols["parent"] < np.arange(len(cols["parent"]))), "replay needs parents before children"
    postures = np.array([(np.asarray(s["box"].lo, float) + np.asarray(s["box"].hi, float)) / 2 for s in res.solutions])
    return res, cols, postures, seconds


def run_search(robot):
    """certkin's FK search with the whole tree recorded; the tree's columns, postures and geometry."""
    from certkin.fk.system import fk_system
    from certkin.robots import as_robot
    path, lengths = ROBOTS[robot]
    res, cols, postures, seconds = recorded_search(path, lengths)
    system = fk_system(as_robot(path))
    G = Geometry(system.a.mid(), system.b.mid(), [float(x) for x in lengths.split(",")])
    print(f"{robot}: {len(postures)} postures, complete {res.complete}, {res.boxes} boxes, {len(cols['kind'])} nodes, "
          f"search {seconds:.1f} s CPU")
    return cols, postures, G


def cm_scale(G, n=20000):
    """Typical |CM| per quadruple: the median over random unit quaternions (fixed generator)."""
    q = np.random.default_rng(0).normal(size=(n, 4))
    return np.median(np.abs(G.cm_determinant(q / np.linalg.norm(q, axis=1, keepdims=True))), 0)


def check_postures(G, postures, scale):
    """The CM values (relative to their scale) at the proved postures, and the leg residuals."""
    p, q = postures[:, :3], postures[:, 3:] / np.linalg.norm(postures[:, 3:], axis=1, keepdims=True)
    legs = np.linalg.norm(p[:, None, :] + np.einsum("sij,mj->smi", rotation(q), G.b) - G.a[None], axis=2)
    cm = G.cm_determinant(q) / scale
    poly = G.cm_polynomial(G.squared_distances(q)) / scale
    print(f"check at the proved postures: max leg residual {np.abs(legs - G.rho).max():.1e}; "
          f"15 CM values: max |CM|/scale {np.abs(cm).max():.1e} (determinant), {np.abs(poly).max():.1e} (polynomial)")


# ---------------------------------------------------------------- the leaf study

def sample_unit_quaternions(rng, lo, hi, n, rounds=40):
    """Up to n unit quaternions in the box: uniform points of the box, normalised, kept when inside."""
    got, count = [], 0
    for _ in range(rounds):
        x = rng.uniform(lo, hi, size=(max(4 * n, 2000), 4))
        x /= np.linalg.norm(x, axis=1, keepdims=True)
        x = x[np.all((x >= lo) & (x <= hi), 1)]
        got.append(x)
        count += len(x)
        if count >= n:
            break
    return np.concatenate(got)[:n]


def sampled_exclusion(G, lo, hi, rng, points, margin):
    """Per box: (no unit quaternion found, exact CM excludes, exact pair test excludes), sampled."""
    pair_lo, pair_hi = G.pair_bounds()
    empty, by_cm, by_pair = (np.zeros(len(lo), bool) for _ in range(3))
    for i in range(len(lo)):
        s = sample_unit_quaternions(rng, lo[i], hi[i], points)
        if len(s) == 0:
            empty[i] = True
            continue
        v = G.cm_determinant(s)
        one_sign = np.all(v > 0, 0) | np.all(v < 0, 0)
        by_cm[i] = (one_sign & (np.abs(v).min(0) > margin)).any()
        D = G.squared_distances(s)
        by_pair[i] = ((D < pair_lo) | (D > pair_hi)).all(0).any()
    return empty, by_cm, by_pair


def widened(qlo, qhi, factor):
    """The boxes widened ``factor`` times about their centres, clipped to [−1, 1]."""
    c, r = (qlo + qhi) / 2, factor * (qhi - qlo) / 2
    return np.clip(c - r, -1, 1), np.clip(c + r, -1, 1)


def leaf_study(G, cols, scale, args):
    """The table: fraction of sampled excluded leaves excluded at each width, per test."""
    from certkin.engine import EXCLUDED
    rng = np.random.default_rng(args.seed)
    excluded = np.nonzero(cols["kind"] == EXCLUDED)[0]
    pick = np.sort(rng.choice(excluded, min(args.sample, len(excluded)), replace=False))
    qlo, qhi = cols["lo"][pick, 3:], cols["hi"][pick, 3:]
    print(f"\n{len(excluded)} excluded leaves, sample {len(pick)} (seed {args.seed}), {args.points} points per box; "
          f"leaf q-width 10/50/90 %: {np.round(np.quantile((qhi - qlo).max(1), [.1, .5, .9]), 4)}\n")
    methods = {"naive": None, "centred": CentredCM(G), "Taylor (c)": TaylorCM(G), "Taylor-2 (c')": Taylor2CM(G)}
    seconds = dict.fromkeys(methods, 0.0)
    print("| width | unsampled | exact CM (sampled) | exact pairs (sampled) | " + " | ".join(methods) + " |")
    print("|---|" + "---:|" * (3 + len(methods)))
    for factor in WIDTHS:
        lo, hi = widened(qlo, qhi, factor)
        empty, by_cm, by_pair = sampled_exclusion(G, lo, hi, rng, args.points, MARGIN * scale)
        row = [empty.mean(), by_cm[~empty].mean(), by_pair[~empty].mean()]
        for name, method in methods.items():
            t0 = time.perf_counter()
            row.append(excludes(*(enclose_naive(G, lo, hi) if method is None else method.enclose(lo, hi))).mean())
            seconds[name] += time.perf_counter() - t0
        print(f"| {factor}x | " + " | ".join(f"{x:.3f}" for x in row) + " |", flush=True)
    per_box = ", ".join(f"{name} {1e6 * s / (len(pick) * len(WIDTHS)):.0f} us" for name, s in seconds.items())
    print(f"\nnumpy time per box (15 quadruples, batches of {len(pick)}): {per_box}")


# ---------------------------------------------------------------- the tree replay

def holding_a_posture(cols):
    """Nodes with a proved leaf below them (or that are one)."""
    from certkin.engine import PROVED
    parent, held = cols["parent"], np.zeros(len(cols["kind"]), bool)
    for i in np.nonzero(cols["kind"] == PROVED)[0]:
        p = i
        while p >= 0 and not held[p]:
            held[p] = True
            p = parent[p]
    return held


def pruned_below(parent, cut):
    """Nodes below a node in ``cut`` (parents precede children in the tree)."""
    pruned = np.zeros(len(parent), bool)
    for i, p in enumerate(parent):
        if p >= 0 and (pruned[p] or cut[p]):
            pruned[i] = True
    return pruned


def replay(G, cols, batch=4096):
    """Test every split node by (c) and (c'); the decided boxes the search would have saved."""
    from certkin.engine import PROVED, SPLIT
    kind, parent = cols["kind"], cols["parent"]
    splits = np.nonzero(kind == SPLIT)[0]
    decided = (parent < 0) | (kind[np.maximum(parent, 0)] == SPLIT)
    held = holding_a_posture(cols)
    print(f"\ntree replay: {len(kind)} nodes, {len(splits)} split nodes ({np.sum(held[splits])} holding a posture), "
          f"{decided.sum()} decided boxes (roots + children of splits)\n")
    print("| test | split nodes passing | decided boxes before -> after | saved | posture-holding passing | "
          "proved leaves lost | numpy us/box |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, method in (("Taylor (c)", TaylorCM(G)), ("Taylor-2 (c')", Taylor2CM(G))):
        cut = np.zeros(len(kind), bool)
        t0 = time.perf_counter()
        for j in range(0, len(splits), batch):
            ids = splits[j:j + batch]
            cut[ids] = excludes(*method.enclose(cols["lo"][ids, 3:], cols["hi"][ids, 3:]))
        us = 1e6 * (time.perf_counter() - t0) / len(splits)
        pruned = pruned_below(parent, cut)
        after = np.sum(decided & ~pruned)
        print(f"| {name} | {cut[splits].mean():.3f} | {decided.sum()} -> {after} | {np.mean(pruned[decided]):.1%} | "
              f"{np.sum(cut & held)} | {np.sum(pruned & (kind == PROVED))} | {us:.0f} |", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", choices=list(ROBOTS), default="seed002")
    ap.add_argument("--sample", type=int, default=3000, help="excluded leaves sampled")
    ap.add_argument("--points", type=int, default=300, help="unit quaternions sampled per box (exact columns)")
    ap.add_argument("--seed", type=int, default=0, help="random seed of the leaf sample and the points")
    ap.add_argument("--replay", action="store_true", help="also replay the tree with (c) and (c')")
    args = ap.parse_args()
    t0 = time.perf_counter()
    cols, postures, G = run_search(args.robot)
    scale = cm_scale(G)
    check_postures(G, postures, scale)
    leaf_study(G, cols, scale, args)
    if args.replay:
        replay(G, cols)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s wall")


if __name__ == "__main__":
    main()
