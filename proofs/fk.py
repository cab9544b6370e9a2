"""Forward-kinematics claims (``"problem": "forward-kinematics"``, docs/certificates.md).

The equations are rebuilt from the exact geometry and leg lengths (models
``planar-3rpr-fk/1``, ``spherical-3dof-fk/1``, ``gough-stewart-fk/1``):

- unknowns: the platform origin p (planar x, y; Gough x, y, z; none for
  the spherical robot) and the rotation, (c, s) in the plane or a
  quaternion (q0, q1, q2, q3) in space, with
  R(q) = [[1 − 2(q2² + q3²), 2(q1 q2 − q0 q3), 2(q1 q3 + q0 q2)],
          [2(q1 q2 + q0 q3), 1 − 2(q1² + q3²), 2(q2 q3 − q0 q1)],
          [2(q1 q3 − q0 q2), 2(q2 q3 + q0 q1), 1 − 2(q1² + q2²)]],
  R = [[c, −s], [s, c]] in the plane;
- equations: leg i, Σ_k e_ik² − ρ_i² with e_i = p + R b_i − a_i (i = 1..legs),
  then c² + s² − 1 or |q|² − 1 (ρ_i² an interval for length ranges);
- position system: D p = g with, for i ≥ 2, D_i = 2((R b_i − R b_1) − (a_i − a_1)),
  g_i = 2(a_i·R b_i − a_1·R b_1) − ((|a_i|² + |b_i|²) − (|a_1|² + |b_1|²)) + (ρ_i² − ρ_1²).

R b_i over a box is the natural enclosure intersected, for a quaternion,
with the centred form R b_i(c) + Σ_r ∂(R b_i)/∂q_r(Y)(q_r − c_r), c the float
midpoint, Y ∋ (x + c)/2 (exact: R b_i is quadratic in q; docs/soundness.md §8).
K(X) = c − C f(c) + (I − C J(X))(X − c) with c = fl(0.5 lo + 0.5 hi) (Krawczyk);
slope matrices S(X, c), row i = Σ_k (e_ik(X) + e_ik(c)) [∂e_ik/∂p, ∂(R b_i)_k/∂r(Y)],
norm row (r(X) + r(c)) (f(x) − f(c) = S (x − c)), give K_S and the
Hansen-Sengupta sweep on (C S) y = −C f(c).  HC4 is the seven-step pass of
docs/soundness.md §8 in its fixed order.  The rules of the tree (leaf and
contraction codes) and of the regions are listed in docs/certificates.md.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from . import tree
from .arith import Iv, pmatmul, pmatvec, stack
from .models import points
from .numbers import exact, real
from .report import Rejected

MODELS = {"planar-3rpr-fk/1": ("planar-3rpr", ("x", "y", "c", "s"), 3, 2, 2),
          "spherical-3dof-fk/1": ("spherical-3dof", ("q0", "q1", "q2", "q3"), 3, 3, 0),
          "gough-stewart-fk/1": ("gough-stewart", ("x", "y", "z", "q0", "q1", "q2", "q3"), 6, 3, 3)}
LEAVES = {0: ("equation", {"tree.index": 1}), 1: ("hc4-empty", {}), 2: ("position-empty", {"tree.P": 1}),
          3: ("krawczyk-empty", {"tree.C": 1}), 4: ("slope-empty", {"tree.C": 1}),
          5: ("slope-gs-empty", {"tree.C": 1}), 6: ("krawczyk-unique", {"tree.star": 1, "tree.C": 1, "tree.index": 2}),
          7: ("krawczyk-outside", {"tree.star": 1, "tree.C": 2, "tree.rootbox": 1}),
          8: ("in-region", {"tree.index": 1}), 9: ("in-cluster", {"tree.index": 1}), 10: ("undecided", {})}
CONTRACTIONS = {0: ("hc4", {}), 1: ("hc4-position", {"tree.P": 1}), 2: ("position", {"tree.P": 1}),
                3: ("krawczyk", {"tree.C": 1}), 4: ("slope", {"tree.C": 1}), 5: ("slope-gs", {"tree.C": 1})}
# ∂(R b)_k/∂q_r = Σ (coefficient · b_j · q_s) over the terms (coefficient, j, s)
DROT = {(0, 0): ((-2, 1, 3), (2, 2, 2)), (0, 1): ((2, 1, 2), (2, 2, 3)), (0, 2): ((-4, 0, 2), (2, 1, 1), (2, 2, 0)),
        (0, 3): ((-4, 0, 3), (-2, 1, 0), (2, 2, 1)), (1, 0): ((2, 0, 3), (-2, 2, 1)),
        (1, 1): ((2, 0, 2), (-4, 1, 1), (-2, 2, 0)), (1, 2): ((2, 0, 1), (2, 2, 3)),
        (1, 3): ((2, 0, 0), (-4, 1, 3), (2, 2, 2)), (2, 0): ((-2, 0, 2), (2, 1, 1)),
        (2, 1): ((2, 0, 3), (2, 1, 0), (-4, 2, 1)), (2, 2): ((-2, 0, 0), (2, 1, 3), (-4, 2, 2)),
        (2, 3): ((2, 0, 1), (2, 1, 2))}
# R_kj = 2(q_a q_b + σ q_c q_d): ((k, j), (a, b), (c, d), σ); R_kk = 1 − 2(q_a² + q_b²): (k, a, b)
HC4_OFF_DIAGONAL = (((0, 1), (1, 2), (0, 3), -1), ((1, 0), (1, 2), (0, 3), 1), ((0, 2), (1, 3), (0, 2), 1),
                    ((2, 0), (1, 3), (0, 2), -1), ((1, 2), (2, 3), (0, 1), -1), ((2, 1), (2, 3), (0, 1), 1))
HC4_DIAGONAL = ((0, 2, 3), (1, 1, 3), (2, 1, 2))


def _mid(lo, hi):
    return np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)


def _sum(parts):
    out = parts[0]
    for p in parts[1:]:
        out = out + p
    return out


class System:
    """The equations of one robot over batches of boxes; ``L`` (N, legs): squared leg lengths per box."""

    def __init__(self, model: str, robot: dict):
        kind, self.names, self.legs, self.dim, self.p = MODELS[model]
        self.n, self.planar = len(self.names), self.dim == 2
        a, b = points(robot, "base", self.legs, self.dim), points(robot, "platform", self.legs, self.dim)
        self.a = [stack([pt[k] for pt in a]) for k in range(self.dim)]       # a[k]: (legs,)
        self.b = [stack([pt[k] for pt in b]) for k in range(self.dim)]
        self.na2 = _sum([v.sqr() for v in self.a])
        self.nb2 = _sum([v.sqr() for v in self.b])
        if self.planar:          # d(R b)_k/d(c, s): constants
            self.dconst = {(0, 0): self.b[0], (0, 1): -self.b[1], (1, 0): self.b[1], (1, 1): self.b[0]}

    # ----- R b_i -------------------------------------------------------------------
    def rotated_natural(self, z):
        """[(R b_i)_k over the boxes, k < dim], each (N, legs); z: the unknowns as Iv (N,)."""
        col = lambda v: Iv(v.lo[:, None], v.hi[:, None])  # noqa: E731
        if self.planar:
            c, s = col(z[2]), col(z[3])
            return [c * self.b[0] - s * self.b[1], s * self.b[0] + c * self.b[1]]
        q0, q1, q2, q3 = [col(v) for v in z[self.p:]]
        s1, s2, s3 = q1.sqr(), q2.sqr(), q3.sqr()
        R = [[1.0 - (s2 + s3) * 2.0, (q1 * q2 - q0 * q3) * 2.0, (q1 * q3 + q0 * q2) * 2.0],
             [(q1 * q2 + q0 * q3) * 2.0, 1.0 - (s1 + s3) * 2.0, (q2 * q3 - q0 * q1) * 2.0],
             [(q1 * q3 - q0 * q2) * 2.0, (q2 * q3 + q0 * q1) * 2.0, 1.0 - (s1 + s2) * 2.0]]
        return [(R[k][0] * self.b[0] + R[k][1] * self.b[1]) + R[k][2] * self.b[2] for k in range(3)]

    def drot(self, y):
        """{(k, r): ∂(R b_i)_k/∂r over the boxes y} (rotation unknown r counted from 0), each (N, legs)."""
        if self.planar:
            return self.dconst
        col = [Iv(v.lo[:, None], v.hi[:, None]) for v in y[self.p:]]
        return {kr: _sum([(self.b[j] * float(c)) * col[s] for c, j, s in terms]) for kr, terms in DROT.items()}

    def rotated(self, z, centre=None):
        """R b_i over the boxes: natural ∩ centred form around the float midpoint c of ``centre``
        (default: of z) with Y ∋ (x + c)/2 over z (a quaternion only; points stay natural)."""
        rb = self.rotated_natural(z)
        if self.planar:
            return rb
        src = z if centre is None else centre
        c = [_mid(v.lo, v.hi) for v in src]
        rbc = self.rotated_natural([Iv(x) for x in c])
        D = self.drot([(v + x) * 0.5 for v, x in zip(z, c)])
        out = []
        for k in range(3):
            acc = rbc[k]
            for r in range(4):
                d = z[self.p + r] - c[self.p + r]
                acc = acc + D[k, r] * Iv(d.lo[:, None], d.hi[:, None])
            out.append(rb[k].meet(acc))
        return out

    # ----- equations, Jacobian, slopes ------------------------------------------------
    def e(self, z, rb):
        """e_ik = (R b_i − a_i)_k + p_k, each (N, legs)."""
        col = lambda v: Iv(v.lo[:, None], v.hi[:, None])  # noqa: E731
        return [(rb[k] - self.a[k]) + col(z[k]) if self.p else rb[k] - self.a[k] for k in range(self.dim)]

    def equations(self, z, L, rb=None):
        """(leg equations (N, legs), norm equation (N,))."""
        e = self.e(z, self.rotated(z) if rb is None else rb)
        return _sum([v.sqr() for v in e]) - L, _sum([v.sqr() for v in z[self.p:]]) - 1.0

    def values(self, z, L):
        f, norm = self.equations(z, L)
        return Iv(np.concatenate([f.lo, norm.lo[:, None]], 1), np.concatenate([f.hi, norm.hi[:, None]], 1))

    def _matrix(self, s, D, last):
        """Rows [s_ik for k < p] + [Σ_k s_ik D_kr], then the norm row ``last`` (over the rotation)."""
        N = s[0].shape[0]
        zero = Iv(np.zeros((N, self.legs)))
        cols = [s[k] if k < self.p else zero for k in range(self.p)]
        cols += [_sum([s[k] * D[k, r] for k in range(self.dim)]) for r in range(self.n - self.p)]
        M = stack(cols, -1)                                               # (N, legs, n)
        norm = stack([Iv(np.zeros(N))] * self.p + last, -1)[:, None, :]  # (N, 1, n)
        return Iv(np.concatenate([M.lo, norm.lo], 1), np.concatenate([M.hi, norm.hi], 1))

    def jacobian(self, z):
        e = self.e(z, self.rotated(z))
        return self._matrix([v * 2.0 for v in e], self.drot(z), [v * 2.0 for v in z[self.p:]])

    def slope(self, z, c):
        """Slope matrices at the points c (N, n) over the boxes z: f(x) − f(c) = S (x − c) for each x."""
        zc = [Iv(c[:, k]) for k in range(self.n)]
        ex, ec = self.e(z, self.rotated(z)), self.e(zc, self.rotated_natural(zc))
        D = self.drot([(v + x) * 0.5 for v, x in zip(z, zc)])
        return self._matrix([u + v for u, v in zip(ex, ec)], D, [v + x for v, x in zip(z[self.p:], zc[self.p:])])

    # ----- operators ---------------------------------------------------------------------
    def _at_mid(self, lo, hi, L):
        c = _mid(lo, hi)
        return c, self.values([Iv(c[:, k]) for k in range(self.n)], L)

    def krawczyk(self, lo, hi, C, L, slope=False) -> Iv:
        """K(X) (or K_S with slope matrices: no uniqueness) for the boxes [lo, hi] (N, n), C (N, n, n)."""
        z = [Iv(lo[:, k], hi[:, k]) for k in range(self.n)]
        c, fc = self._at_mid(lo, hi, L)
        J = self.slope(z, c) if slope else self.jacobian(z)
        M = Iv(np.eye(self.n)) - pmatmul(C, J)
        dx = Iv(lo, hi) - c
        return (Iv(c) - pmatvec(C, fc)) + (M * Iv(dx.lo[:, None, :], dx.hi[:, None, :])).sum(-1)

    def slope_gauss_seidel(self, lo, hi, C, L):
        """The Hansen-Sengupta sweep with slopes: ((c + y) ∩ X as Iv (N, n), empty mask)."""
        z = [Iv(lo[:, k], hi[:, k]) for k in range(self.n)]
        c, fc = self._at_mid(lo, hi, L)
        G = pmatmul(C, self.slope(z, c))
        y, empty = _sweep(G, -pmatvec(C, fc), Iv(lo, hi) - c)
        return (y + c).meet(Iv(lo, hi)), empty

    def gauss_seidel(self, z, P, L):
        """One sweep on (P D) p = P g over the boxes z (list of Iv): (new position Iv (N, p), empty)."""
        rb = self.rotated(z)
        a = self.a
        arb = _sum([a[k] * rb[k] for k in range(self.dim)])
        D = stack([((rb[k][:, 1:] - rb[k][:, :1]) - (a[k][1:] - a[k][:1])) * 2.0 for k in range(self.p)], -1)
        g = ((arb[:, 1:] - arb[:, :1]) * 2.0 - ((self.na2[1:] + self.nb2[1:]) - (self.na2[:1] + self.nb2[:1]))) \
            + (L[:, 1:] - L[:, :1])
        x = stack(z[:self.p], -1)
        return _sweep(pmatmul(P, D), pmatvec(P, g), x)

    def hc4(self, lo, hi, L):
        """One forward-backward pass (docs/soundness.md §8, in its order): (box Iv (N, n), empty)."""
        N, p, n, dim = len(lo), self.p, self.n, self.dim
        z = [Iv(lo[:, k], hi[:, k]) for k in range(n)]
        empty = np.zeros(N, dtype=bool)
        for k in range(p, n):                                   # 1. the norm equation
            z[k] = _root(z[k], 1.0 - _sum([z[j].sqr() for j in range(p, n) if j != k]))
            empty |= z[k].empty()
        centre = [Iv(lo[:, k], hi[:, k]) for k in range(n)]     # 2. forward: R, u = R b_i, e
        u = self.rotated(z, centre)
        R = self._rotation_entries(z)
        e = self.e(z, u)
        for i in range(self.legs):                              # 3. backward through each leg
            s = [v[:, i].sqr() for v in e]
            for k in range(dim):
                col = _root(e[k][:, i], L[:, i] - _sum([s[j] for j in range(dim) if j != k]))
                empty |= col.empty()
                e[k][:, i] = col
                s[k] = col.sqr()
        for k in range(p):                                      # 4. the position
            for i in range(self.legs):
                z[k] = z[k].meet((e[k][:, i] - u[k][:, i]) + self.a[k][i])
                empty |= z[k].empty()
        for i in range(self.legs):                              # 5. u_ik from e_ik
            for k in range(dim):
                back = e[k][:, i] - z[k] if p else e[k][:, i]
                u[k][:, i] = u[k][:, i].meet(back + self.a[k][i])
                empty |= u[k][:, i].empty()
        newR = [row[:] for row in R]                            # 6. entries of R from u_i = R b_i
        for i in range(self.legs):
            for k in range(dim):
                T = [R[k][j] * self.b[j][i] for j in range(dim)]
                for j in range(dim):
                    bij = self.b[j][i]
                    if not (bij.pos() or bij.neg()):
                        continue
                    rest = _sum([T[jj] for jj in range(dim) if jj != j])
                    newR[k][j] = newR[k][j].meet((u[k][:, i] - rest) / bij)
                    empty |= newR[k][j].empty()
        R = newR
        if self.planar:                                         # 7. the rotation unknowns from R
            for k, parts in ((2, (R[0][0], R[1][1])), (3, (R[1][0], -R[0][1]))):
                for v in parts:
                    z[k] = z[k].meet(v)
                    empty |= z[k].empty()
            return stack(z, -1), empty
        q = z[p:]
        for k, ia, ib in HC4_DIAGONAL:
            t = (1.0 - R[k][k]) * 0.5
            for x, y in ((ia, ib), (ib, ia)):
                q[x] = _root(q[x], t - q[y].sqr())
                empty |= q[x].empty()
        for (k, j), (ia, ib), (ic, id_), sigma in HC4_OFF_DIAGONAL:
            h = R[k][j] * 0.5
            g = h - q[ic] * q[id_] if sigma > 0 else h + q[ic] * q[id_]
            for x, y in ((ia, ib), (ib, ia)):
                q[x] = _divide_by(q[x], g, q[y])
                empty |= q[x].empty()
            g2 = h - q[ia] * q[ib]
            g2 = -g2 if sigma < 0 else g2
            for x, y in ((ic, id_), (id_, ic)):
                q[x] = _divide_by(q[x], g2, q[y])
                empty |= q[x].empty()
        return stack(z[:p] + q, -1), empty

    def _rotation_entries(self, z):
        """The entries R_kj over the boxes (Iv (N,)), as in ``rotated_natural``."""
        if self.planar:
            return [[z[2], -z[3]], [z[3], z[2]]]
        q0, q1, q2, q3 = z[self.p:]
        s1, s2, s3 = q1.sqr(), q2.sqr(), q3.sqr()
        return [[1.0 - (s2 + s3) * 2.0, (q1 * q2 - q0 * q3) * 2.0, (q1 * q3 + q0 * q2) * 2.0],
                [(q1 * q2 + q0 * q3) * 2.0, 1.0 - (s1 + s3) * 2.0, (q2 * q3 - q0 * q1) * 2.0],
                [(q1 * q3 - q0 * q2) * 2.0, (q2 * q3 + q0 * q1) * 2.0, 1.0 - (s1 + s2) * 2.0]]


def _root(x, t):
    """hull(x ∩ {y : y² ∈ t}): the pieces x ∩ [−√t̄, −√t̲] and x ∩ [√t̲, √t̄] (empty if t̄ < 0)."""
    r = Iv(np.maximum(t.lo, 0.0), t.hi).sqrt()
    neg, pos = x.meet(-r), x.meet(r)
    ne, pe = neg.empty() | (t.hi < 0), pos.empty() | (t.hi < 0)
    lo = np.where(ne, pos.lo, neg.lo)
    hi = np.where(pe, neg.hi, pos.hi)
    both = ne & pe
    return Iv(np.where(both, np.inf, lo), np.where(both, -np.inf, hi))


def _divide_by(x, num, den):
    """x ∩ num/den where 0 ∉ den; x itself elsewhere."""
    ok = den.pos() | den.neg()
    m = x.meet(num / den)
    return Iv(np.where(ok, m.lo, x.lo), np.where(ok, m.hi, x.hi))


def _divide_into(num, den, x):
    """x ∩ {t : d t = v, d ∈ den, v ∈ num} (its hull; Hansen & Sengupta 1981), empty when lo > hi."""
    plain = den.pos() | den.neg()
    q = x.meet(num / den)
    with np.errstate(all="ignore"):
        npos, nneg = num.pos(), num.neg()
        dl, dh, nl, nh = den.lo, den.hi, num.lo, num.hi
        # pieces: for num > 0, [nl/dh, ∞) if dh > 0 and (−∞, nl/dl] if dl < 0; for num < 0, (−∞, nh/dh]
        # if dh > 0 and [nh/dl, ∞) if dl < 0
        r_lo = np.where(npos, (Iv(nl) / Iv(dh)).lo, (Iv(nh) / Iv(dl)).lo)      # the piece [r_lo, ∞)
        l_hi = np.where(npos, (Iv(nl) / Iv(dl)).hi, (Iv(nh) / Iv(dh)).hi)      # the piece (−∞, l_hi]
        has_r = np.where(npos, dh > 0, dl < 0) & (npos | nneg)
        has_l = np.where(npos, dl < 0, dh > 0) & (npos | nneg)
    rl, rh = np.maximum(x.lo, r_lo), x.hi
    ll, lh = x.lo, np.minimum(x.hi, l_hi)
    r_ok, l_ok = has_r & (rl <= rh), has_l & (ll <= lh)
    ext_lo = np.where(l_ok, ll, np.where(r_ok, rl, np.inf))
    ext_hi = np.where(r_ok, rh, np.where(l_ok, lh, -np.inf))
    keep = ~plain & ~(npos | nneg)                       # 0 in both: every t qualifies
    lo = np.where(plain, q.lo, np.where(keep, x.lo, ext_lo))
    hi = np.where(plain, q.hi, np.where(keep, x.hi, ext_hi))
    return Iv(lo, hi)


def _sweep(A: Iv, b: Iv, x: Iv):
    """One interval Gauss-Seidel sweep on A x = b from x (N, m): (new x, empty mask)."""
    x = x.copy()
    empty = np.zeros(x.lo.shape[0], dtype=bool)
    m = x.lo.shape[1]
    for i in range(m):
        num = b[:, i]
        for j in range(m):
            if j != i:
                num = num - A[:, i, j] * x[:, j]
        x[:, i] = _divide_into(num, A[:, i, i], x[:, i])
        empty |= x[:, i].empty()
    return x, empty


# ----------------------------------------------------------------------------- claims
class _Claim:
    """One set of leg lengths: its squared lengths, domain, regions (X*, R, C*, C_R) and clusters."""

    EXCLUDED = ("equation", "hc4-empty", "position-empty", "krawczyk-empty", "slope-empty", "slope-gs-empty",
                "krawczyk-outside")

    def figures(self):
        return {"solutions": self.solutions, "regions": len(self.regions[0]), "leaves": self.rules}

    def summary(self):
        if self.domain is None:
            return f"{self.text}: no posture at all (the leg-length balls do not meet)"
        excluded = sum(v for k, v in self.rules.items() if k in self.EXCLUDED)
        text = f"{self.text}: {self.solutions} unique postures in the domain, {excluded} boxes excluded"
        if self.clusters.size:
            text += f", {len(self.clusters)} unresolved clusters"
        return text + (", complete: proved" if self.complete else ", complete: not claimed")


def check(cert, report) -> None:
    h = cert.header
    model = h.get("model")
    if not isinstance(model, str) or model not in MODELS:
        raise Rejected(f"model: unknown model {model!r:.60} (known: {', '.join(MODELS)})")
    if h["robot"].get("kind") != MODELS[model][0]:
        raise Rejected(f"robot.kind: {h['robot'].get('kind')!r:.60} does not fit model {model}")
    if h.get("unknowns") != list(MODELS[model][1]):
        raise Rejected(f"unknowns: expected {list(MODELS[model][1])} for model {model}")
    system = System(model, h["robot"])
    n, counts = system.n, report.checked
    if cert.version == 1:
        cert._arrays.update(_from_v1(system, h["claims"]))
    claims = [_read_claim(system, cert, c, f"claims[{k}]") for k, c in enumerate(h["claims"])]
    for k, cl in enumerate(claims):
        _regions(system, cl, f"claims[{k}]")
        counts["solutions"] = counts.get("solutions", 0) + cl.solutions
    roots = [cl for cl in claims if cl.tree]
    dims = {"tree.C": ((n, n), ("<f4", "<f8")), "tree.P": ((system.p, system.legs - 1), ("<f4", "<f8")),
            "tree.index": ((), ("<i4",)), "tree.star": ((n, 2), ("<f8",)), "tree.rootbox": ((n, 2), ("<f8",))}
    forest = tree.Forest(cert, [c.domain[0] for c in roots], [c.domain[1] for c in roots], LEAVES, CONTRACTIONS, dims)
    L = Iv(np.array([c.L.lo for c in roots] or np.zeros((0, system.legs))),
           np.array([c.L.hi for c in roots] or np.zeros((0, system.legs))))
    rules = np.zeros((len(roots), len(LEAVES)), dtype=np.int64)

    def visit(kind, code, ids, lo, hi, root, child):
        at = lambda i, what: (  # noqa: E731
            f"claims[{roots[root[i]].index}].tree: node {ids[i]} ({(LEAVES if kind == tree.LEAF else CONTRACTIONS)[code][0]}): {what}")
        if kind == tree.CONTRACT:
            _contraction(system, forest, code, ids, lo, hi, child, L[root], at)
            counts["contractions"] = counts.get("contractions", 0) + len(ids)
        else:
            _leaf(system, forest, code, ids, lo, hi, L[root], [roots[r] for r in root], at)
            np.add.at(rules[:, code], root, 1)
            counts["leaves"] += len(ids)

    forest.walk(visit, report.progress)
    for j, cl in enumerate(roots):
        cl.rules = {LEAVES[c][0]: int(v) for c, v in enumerate(rules[j]) if v}
        if "figures" in cl.raw and cl.raw["figures"] != cl.figures():
            raise Rejected(f"claims[{cl.index}].figures: stated {cl.raw['figures']}, found {cl.figures()}")
    report.about["question"] = (f"every assembly mode for {len(claims)} set(s) of leg lengths; first: {claims[0].text}, "
                                f"domain: {h['claims'][0].get('covers', 'empty')}")
    for cl in claims[:5]:
        report.proved.append(cl.summary())
    if len(claims) > 5:
        report.proved.append(f"... and {len(claims) - 5} more leg-length sets, "
                             f"{sum(c.solutions for c in claims[5:])} unique postures in all")


def _read_claim(system, cert, raw, where):
    if not isinstance(raw, dict):
        raise Rejected(f"{where}: expected an object")
    cl = _Claim()
    cl.raw, cl.index, cl.rules = raw, int(where[7:-1]), {}
    if "length_ranges" in raw:
        rng = raw["length_ranges"]
        if not isinstance(rng, list) or len(rng) != system.legs or not all(isinstance(r, list) and len(r) == 2 for r in rng):
            raise Rejected(f"{where}.length_ranges: expected {system.legs} [lo, hi] exact decimals")
        qs = [(exact(a, f"{where}.length_ranges"), exact(b, f"{where}.length_ranges")) for a, b in rng]
        cl.text = "lengths in " + ", ".join(f"[{a}, {b}]" for a, b in rng)
    else:
        ls = raw.get("lengths")
        if not isinstance(ls, list) or len(ls) != system.legs:
            raise Rejected(f"{where}.lengths: expected {system.legs} exact decimals")
        qs = [(exact(v, f"{where}.lengths[{i}]"),) * 2 for i, v in enumerate(ls)]
        cl.text = "lengths " + ", ".join(map(str, ls))
    if any(not 0 <= a <= b for a, b in qs):
        raise Rejected(f"{where}: leg lengths must satisfy 0 <= lo <= hi")
    cl.L = Iv([Iv.const(a * a).lo for a, _ in qs], [Iv.const(b * b).hi for _, b in qs])
    cl.rho_hi = Iv([Iv.const(b).hi for _, b in qs])
    cl.complete = raw.get("complete")
    if cl.complete not in (True, False):
        raise Rejected(f"{where}.complete: expected true or false")
    cl.regions = (np.zeros((0, system.n, 2)),) * 2 + (np.zeros((0, system.n, system.n)),) * 2
    cl.clusters, cl.solutions, cl.tree = np.zeros((0, system.n, 2)), 0, False
    if raw.get("domain") == "empty":
        _no_position(system, cl, f"{where}.domain")
        if raw.get("solutions") != [] or cl.complete is not True:
            raise Rejected(f"{where}: an empty domain has no solutions and is complete")
        cl.domain = None
        return cl
    lo, hi = _box(raw.get("domain"), system.n, f"{where}.domain")
    cl.domain = (lo, hi)
    if raw.get("covers") == "all-postures":
        _covers_all(system, cl, f"{where}.domain")
    elif raw.get("covers") != "box":
        raise Rejected(f"{where}.covers: expected 'all-postures' or 'box'")
    reg = raw.get("regions", [0, 0])
    if not (isinstance(reg, list) and len(reg) == 2 and all(type(v) is int and v >= 0 for v in reg)):
        raise Rejected(f"{where}.regions: expected [first, count]")
    names = ("fk.region.star", "fk.region.box", "fk.region.star_C", "fk.region.box_C")
    if reg[1]:
        arrs = [cert.array(nm, *(((("<f8",), (system.n, 2))) if "C" not in nm else (("<f4", "<f8"), (system.n, system.n))))
                for nm in names]
        if any(len(a) < reg[0] + reg[1] for a in arrs):
            raise Rejected(f"{where}.regions: rows {reg[0]}..{reg[0] + reg[1] - 1} are not all in the body")
        cl.regions = tuple(a[reg[0]:reg[0] + reg[1]].astype(np.float64) for a in arrs)
    clusters = raw.get("clusters", [])
    if not isinstance(clusters, list):
        raise Rejected(f"{where}.clusters: expected a list of boxes")
    cl.clusters = np.array([np.stack(_box(c, system.n, f"{where}.clusters[{j}]"), -1) for j, c in enumerate(clusters)]
                           or np.zeros((0, system.n, 2)))
    cl.tree = raw.get("tree") is not None
    if cert.version == 2 and raw.get("tree") not in (True, None):
        raise Rejected(f"{where}.tree: expected true (the tree is in the body) or null")
    return cl


def _box(value, n, where):
    b = np.array(tree._box(value, n, where))
    return b[:, 0], b[:, 1]


def _reach(system, cl, k):
    """Bounds (lows, highs) per leg of a_ik ∓ (ρ_i + |b_i|): every posture has max(lows) <= p_k <= min(highs)."""
    reach = cl.rho_hi + system.nb2.sqrt()
    return (system.a[k] - reach).lo, (system.a[k] + reach).hi


def _covers_all(system, cl, where):
    lo, hi = cl.domain
    for k in range(system.p, system.n):
        need = 0.0 if (not system.planar and k == system.p) else -1.0
        if not (lo[k] <= need and hi[k] >= 1.0):
            raise Rejected(f"{where}: {system.names[k]} does not cover [{need}, 1]")
    for k in range(system.p):
        lows, highs = _reach(system, cl, k)
        if not (lo[k] <= np.max(lows) and hi[k] >= np.min(highs)):
            raise Rejected(f"{where}: {system.names[k]} does not cover the reachable positions")


def _no_position(system, cl, where):
    for k in range(system.p):
        lows, highs = _reach(system, cl, k)
        if np.max(lows) > np.min(highs):
            return
    raise Rejected(f"{where}: 'empty' is not proved: the leg-length balls may meet")


def _unique(system, lo, hi, C, L):
    """K(X) ⊂ int X, per box (exactly one root in X)."""
    K = system.krawczyk(lo, hi, C, L)
    return np.all((K.lo > lo) & (K.hi < hi), axis=1)


def _negated(system, lo, hi):
    p = system.p
    if system.planar:
        return lo, hi
    return np.concatenate([lo[..., :p], -hi[..., p:]], -1), np.concatenate([hi[..., :p], -lo[..., p:]], -1)


def _disjoint(alo, ahi, blo, bhi):
    return np.any((ahi < blo) | (bhi < alo), axis=-1)


def _inside(alo, ahi, blo, bhi):
    return np.all((blo <= alo) & (ahi <= bhi), axis=-1)


def _regions(system, cl, where):
    """Each region: K(X*) ⊂ int X* (one root), R ⊆ X*, K(R) ⊂ int R (that root is in R); the R pairwise
    disjoint (and from the negated quaternions); classified against the domain."""
    star, box, Cs, Cb = cl.regions
    K = len(star)
    if not K:
        return
    L = Iv(np.broadcast_to(cl.L.lo, (K, system.legs)), np.broadcast_to(cl.L.hi, (K, system.legs)))
    slo, shi, blo, bhi = star[..., 0], star[..., 1], box[..., 0], box[..., 1]
    bad = np.nonzero(~(slo <= shi).all(1) | ~(blo <= bhi).all(1) | ~_inside(blo, bhi, slo, shi)
                     | ~_unique(system, slo, shi, Cs, L) | ~_unique(system, blo, bhi, Cb, L))[0]
    if len(bad):
        raise Rejected(f"{where}.regions[{bad[0]}]: K(X*) ⊂ int X*, R ⊆ X* and K(R) ⊂ int R not all proved")
    nlo, nhi = _negated(system, blo, bhi)
    meet = ~_disjoint(blo[:, None], bhi[:, None], blo[None], bhi[None])
    if not system.planar:
        meet |= ~_disjoint(blo[:, None], bhi[:, None], nlo[None], nhi[None])
    np.fill_diagonal(meet, False)
    if meet.any():
        i, j = np.argwhere(meet)[0]
        raise Rejected(f"{where}.regions[{i}]: meets regions[{j}] (or its negated quaternion): "
                       "the postures are not proved distinct")
    if cl.domain is None:
        raise Rejected(f"{where}: an empty domain has no regions")
    dlo, dhi = cl.domain
    inside = _inside(blo, bhi, dlo, dhi)
    outside = _disjoint(blo, bhi, dlo, dhi)
    if cl.complete and not np.all(inside | outside):
        raise Rejected(f"{where}: complete, but regions[{np.nonzero(~(inside | outside))[0][0]}] straddles the domain")
    cl.solutions = int(inside.sum())
    sols = cl.raw.get("solutions")
    if cl.raw.get("_v1"):
        if not inside.all():
            raise Rejected(f"{where}.solutions[{np.nonzero(~inside)[0][0]}]: box not inside the domain")
        return
    if not isinstance(sols, list) or [s.get("region") if isinstance(s, dict) else None for s in sols] \
            != np.nonzero(inside)[0].tolist():
        raise Rejected(f"{where}.solutions: must list, in order, the regions whose box lies in the domain")
    for j, s in enumerate(sols):
        dec = s.get("box")
        if not isinstance(dec, list) or len(dec) != system.n or not all(isinstance(v, list) and len(v) == 2 for v in dec):
            raise Rejected(f"{where}.solutions[{j}].box: expected {system.n} [lo, hi] decimal strings")
        r = s["region"]
        for k, (a, b) in enumerate(dec):
            if not (exact(a, where) <= Fraction(blo[r, k]) and Fraction(bhi[r, k]) <= exact(b, where)):
                raise Rejected(f"{where}.solutions[{j}].box: [{a}, {b}] does not enclose {system.names[k]} of region {r}")


def _contraction(system, forest, code, ids, lo, hi, child, L, at):
    clo, chi = child
    n, p = system.n, system.p
    if code in (0, 1):                   # hc4 (then, with P, one sweep on the position)
        z, empty = system.hc4(lo, hi, L)
        if code == 1 and p:
            x, e2 = system.gauss_seidel([z[:, k] for k in range(n)], forest.rows("tree.P", ids).astype(float), L)
            empty |= e2
            z = Iv(np.concatenate([x.lo, z.lo[:, p:]], 1), np.concatenate([x.hi, z.hi[:, p:]], 1))
        elif code == 1:
            raise Rejected(at(0, "a position step needs a position"))
    elif code == 2:                      # position: one sweep; the rotation is unchanged
        if not p:
            raise Rejected(at(0, "a position step needs a position"))
        x, empty = system.gauss_seidel([Iv(lo[:, k], hi[:, k]) for k in range(n)],
                                       forest.rows("tree.P", ids).astype(float), L)
        z = Iv(np.concatenate([x.lo, lo[:, p:]], 1), np.concatenate([x.hi, hi[:, p:]], 1))
        moved = np.any((clo[:, p:] != lo[:, p:]) | (chi[:, p:] != hi[:, p:]), axis=1)
        if moved.any():
            raise Rejected(at(np.nonzero(moved)[0][0], "a position step changes only the position"))
    elif code in (3, 4):                 # K(X) ∩ X (slope: K_S)
        K = system.krawczyk(lo, hi, forest.rows("tree.C", ids).astype(float), L, slope=code == 4)
        z = K.meet(Iv(lo, hi))
        empty = np.any(z.empty(), axis=1)
    else:                                # slope-gs
        z, empty = system.slope_gauss_seidel(lo, hi, forest.rows("tree.C", ids).astype(float), L)
    bad = ~empty & ~np.all((z.lo >= clo) & (z.hi <= chi), axis=1)
    if bad.any():
        i = np.nonzero(bad)[0][0]
        k = np.nonzero(~((z.lo[i] >= clo[i]) & (z.hi[i] <= chi[i])))[0][0]
        raise Rejected(at(i, f"the checker's result is not inside the child box on {system.names[k]}"))


def _leaf(system, forest, code, ids, lo, hi, L, claims, at):
    n = system.n
    fail = lambda mask, what: (_ for _ in ()).throw(Rejected(at(np.nonzero(mask)[0][0], what))) if mask.any() else None  # noqa: E731
    if code == 10:
        fail(np.array([c.complete for c in claims]), "undecided leaf in a claim that says complete")
    elif code == 0:
        k = forest.rows("tree.index", ids)
        fail((k < 0) | (k > system.legs), f"the equation index must be below {n}")
        v = system.values([Iv(lo[:, j], hi[:, j]) for j in range(n)], L)[np.arange(len(ids)), np.clip(k, 0, n - 1)]
        fail(~(v.pos() | v.neg()), "the equation may vanish on the box")
    elif code == 1:
        fail(~system.hc4(lo, hi, L)[1], "the forward-backward pass does not empty the box")
    elif code == 2:
        if not system.p:
            raise Rejected(at(0, "needs a position"))
        _, empty = system.gauss_seidel([Iv(lo[:, j], hi[:, j]) for j in range(n)], forest.rows("tree.P", ids).astype(float), L)
        fail(~empty, "Gauss-Seidel on the position does not empty the box")
    elif code in (3, 4):
        K = system.krawczyk(lo, hi, forest.rows("tree.C", ids).astype(float), L, slope=code == 4)
        fail(~np.any((K.hi < lo) | (K.lo > hi), axis=1), "the image meets the box: emptiness not proved")
    elif code == 5:
        fail(~system.slope_gauss_seidel(lo, hi, forest.rows("tree.C", ids).astype(float), L)[1],
             "the slope Gauss-Seidel sweep does not empty the box")
    elif code in (6, 7):
        star = forest.rows("tree.star", ids)
        slo, shi = star[..., 0], star[..., 1]
        fail(~_inside(lo, hi, slo, shi), "the leaf is not inside its uniqueness box X*")
        fail(~_unique(system, slo, shi, forest.rows("tree.C", ids).astype(float), L), "K(X*) ⊂ int X* not proved")
        if code == 7:               # X*'s root lies in a proved box that misses the leaf
            rb = forest.rows("tree.rootbox", ids)
            rlo, rhi = rb[..., 0], rb[..., 1]
            fail(~_inside(rlo, rhi, slo, shi) | ~_disjoint(rlo, rhi, lo, hi), "the root box must lie in X* and miss the leaf")
            fail(~_unique(system, rlo, rhi, forest.rows("tree.C", ids, 1).astype(float), L), "K(R) ⊂ int R not proved")
            return
        j, twin = forest.rows("tree.index", ids), forest.rows("tree.index", ids, 1)
        count = np.array([len(c.regions[1]) for c in claims])
        fail((j < 0) | (j >= count) | ((twin != 0) & (twin != 1)), "names no region of its claim")
        box = np.array([c.regions[1][i] for c, i in zip(claims, j)])
        blo, bhi = box[..., 0], box[..., 1]
        nlo, nhi = _negated(system, blo, bhi)
        blo, bhi = np.where(twin[:, None] == 1, nlo, blo), np.where(twin[:, None] == 1, nhi, bhi)
        fail(~_inside(blo, bhi, slo, shi), "its region's root box is not inside X*: the leaf's root is not that one")
    else:                            # 8 in-region, 9 in-cluster: the leaf lies in the named box
        j = forest.rows("tree.index", ids)
        tables = [c.regions[0] if code == 8 else c.clusters for c in claims]
        fail((j < 0) | (j >= np.array([len(t) for t in tables])), "names no region or cluster of its claim")
        box = np.array([t[i] for t, i in zip(tables, j)])
        fail(~_inside(lo, hi, box[..., 0], box[..., 1]), "the leaf is not inside the named box")


def _from_v1(system, claims):
    """Version 1 claims → the arrays of version 2 (solutions become regions with X* = R)."""
    n, p, legs = system.n, system.p, system.legs
    regions, roots = [], []
    for k, c in enumerate(claims):
        if not isinstance(c, dict):
            continue
        sols = c.get("solutions")
        if not isinstance(sols, list):
            raise Rejected(f"claims[{k}].solutions: expected a list")
        first = len(regions)
        for j, sol in enumerate(sols):
            w = f"claims[{k}].solutions[{j}]"
            if not isinstance(sol, dict):
                raise Rejected(f"{w}: expected an object")
            regions.append((np.stack(_box(sol.get("box"), n, f"{w}.box"), -1), _matrix(sol.get("C"), n, n, f"{w}.C")))
        c["regions"], c["_v1"] = [first, len(sols)], True
        if c.get("domain") != "empty":
            roots.append((k, c.get("tree")))

    def leaf(node, at, root):
        rule = node.get("leaf")
        C = lambda key="C", d=node: [_matrix(d.get(key), n, n, f"{at}: {key}")]  # noqa: E731
        if rule == "equation":
            k = node.get("equation")
            if type(k) is not int or not 0 <= k < n:
                raise Rejected(f"{at}: 'equation' must be an index below {n}")
            return 0, {"tree.index": [k]}
        if rule in ("hc4-empty", "undecided"):
            return (1 if rule == "hc4-empty" else 10), {}
        if rule == "position-empty":
            return 2, {"tree.P": [_matrix(node.get("P"), p, legs - 1, f"{at}: P")]}
        if rule in ("krawczyk-empty", "slope-empty", "slope-gs-empty"):
            return {"krawczyk-empty": 3, "slope-empty": 4, "slope-gs-empty": 5}[rule], {"tree.C": C()}
        if rule != "krawczyk-unique":
            raise Rejected(f"{at}: unknown rule {rule!r:.60}")
        star = [np.stack(_box(node.get("star", node.get("box")), n, f"{at}: star"), -1)]
        if "outside" in node:
            out = node["outside"] if isinstance(node["outside"], dict) else {}
            return 7, {"tree.star": star, "tree.C": C() + C("C", out),
                       "tree.rootbox": [np.stack(_box(out.get("box"), n, f"{at}: outside.box"), -1)]}
        j = node.get("solution")
        if type(j) is not int:
            raise Rejected(f"{at}: 'solution' must name one of the solutions")
        return 6, {"tree.star": star, "tree.C": C(), "tree.index": [j, int(node.get("twin") is True)]}

    def contraction(node, at):
        rule = node.get("contract")
        if rule == "hc4":
            if "P" in node:
                return 1, {"tree.P": [_matrix(node.get("P"), p, legs - 1, f"{at}: P")]}
            return 0, {}
        if rule == "position":
            return 2, {"tree.P": [_matrix(node.get("P"), p, legs - 1, f"{at}: P")]}
        if rule in ("krawczyk", "slope", "slope-gs"):
            return {"krawczyk": 3, "slope": 4, "slope-gs": 5}[rule], {"tree.C": [_matrix(node.get("C"), n, n, f"{at}: C")]}
        raise Rejected(f"{at}: unknown contraction {rule!r:.60}")

    out = tree.flatten(roots, n, leaf, contraction, {"tree.index": np.int32})
    shapes = {"tree.C": (n, n), "tree.P": (p, legs - 1), "tree.star": (n, 2), "tree.rootbox": (n, 2), "tree.index": ()}
    for name, tail in shapes.items():
        arr = out.get(name, np.zeros(0))
        out[name] = arr.reshape((-1,) + tail) if arr.size else np.zeros((0,) + tail, np.int32 if tail == () else float)
    reg = [r[0] for r in regions]
    Cs = np.array([r[1] for r in regions]).reshape(-1, n, n)
    out.update({"fk.region.star": np.array(reg).reshape(-1, n, 2), "fk.region.box": np.array(reg).reshape(-1, n, 2),
                "fk.region.star_C": Cs, "fk.region.box_C": Cs})
    return out


def _matrix(value, rows, cols, where):
    if not isinstance(value, list) or len(value) != rows or any(not isinstance(r, list) or len(r) != cols for r in value):
        raise Rejected(f"{where}: expected a {rows}x{cols} matrix of numbers")
    return [[real(v, where) for v in r] for r in value]
