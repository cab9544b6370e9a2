"""The forward-kinematics equations over batches of boxes, and the operators that prove things about them.

The equations (leg equations, norm equation, position system D p = g), the Krawczyk operator K(X), the slope matrices
S(X, c), the Gauss-Seidel sweep and the HC4 pass (in its fixed order) are those of docs/certificates.md
"Forward-kinematics claims", rebuilt from the exact geometry and leg lengths; docs/soundness.md §8 argues their
soundness.  R b_i over a box is the natural enclosure intersected, for a quaternion, with the centred form around the
float midpoint (exact: R b_i is quadratic in q)."""
from __future__ import annotations

import numpy as np

from .arith import Iv, pmatmul, pmatvec, stack
from .models import points
from .numbers import exact

MODELS = {"planar-3rpr-fk/1": ("planar-3rpr", ("x", "y", "c", "s"), 3, 2, 2),
          "spherical-3dof-fk/1": ("spherical-3dof", ("q0", "q1", "q2", "q3"), 3, 3, 0),
          "gough-stewart-fk/1": ("gough-stewart", ("x", "y", "z", "q0", "q1", "q2", "q3"), 6, 3, 3)}
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
PAIR_ROUNDS = 2     # HC4 step 3, Gough-Stewart: rounds of the leg pairs


def mid(lo, hi):
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
        self.a_q, self.b_q = [[[exact(v, key) for v in p] for p in robot[key]] for key in ("base", "platform")]
        self.a = [stack([pt[k] for pt in a]) for k in range(self.dim)]       # a[k]: (legs,)
        self.b = [stack([pt[k] for pt in b]) for k in range(self.dim)]
        self.na2, self.nb2 = (_sum([v.sqr() for v in pts]) for pts in (self.a, self.b))
        self.db, self.da = ([v[:, None] - v[None, :] for v in pts] for pts in (self.b, self.a))   # (legs, legs)
        if self.planar:          # d(R b)_k/d(c, s): constants
            self.dconst = {(0, 0): self.b[0], (0, 1): -self.b[1], (1, 0): self.b[1], (1, 1): self.b[0]}

    def rotation(self, z):
        """The entries R_kj over the boxes (lists of Iv), z: the unknowns (Iv of any one shape)."""
        if self.planar:
            return [[z[2], -z[3]], [z[3], z[2]]]
        q0, q1, q2, q3 = z[self.p:]
        s1, s2, s3 = q1.sqr(), q2.sqr(), q3.sqr()
        return [[1.0 - (s2 + s3) * 2.0, (q1 * q2 - q0 * q3) * 2.0, (q1 * q3 + q0 * q2) * 2.0],
                [(q1 * q2 + q0 * q3) * 2.0, 1.0 - (s1 + s3) * 2.0, (q2 * q3 - q0 * q1) * 2.0],
                [(q1 * q3 - q0 * q2) * 2.0, (q2 * q3 + q0 * q1) * 2.0, 1.0 - (s1 + s2) * 2.0]]

    def rotated_natural(self, z):
        """[(R b_i)_k over the boxes, k < dim], each (N, legs); z: the unknowns as Iv (N,)."""
        R = self.rotation([Iv(v.lo[:, None], v.hi[:, None]) for v in z])
        return [_sum([R[k][j] * self.b[j] for j in range(self.dim)]) for k in range(self.dim)]

    def drot(self, y):
        """{(k, r): ∂(R b_i)_k/∂r over the boxes y} (rotation unknown r counted from 0), each (N, legs)."""
        if self.planar:
            return self.dconst
        col = [Iv(v.lo[:, None], v.hi[:, None]) for v in y[self.p:]]
        return {kr: _sum([(self.b[j] * float(c)) * col[s] for c, j, s in terms]) for kr, terms in DROT.items()}

    def rotated(self, z, centre=None, parts=False):
        """R b_i over the boxes: natural ∩ centred form around the float midpoint c of ``centre``
        (default: of z) with Y ∋ (x + c)/2 over z (a quaternion only; points stay natural); ``parts``:
        also R b_i(c), the derivatives D over Y and the unknowns minus c."""
        rb = self.rotated_natural(z)
        if self.planar:
            return rb
        src = z if centre is None else centre
        c = [mid(v.lo, v.hi) for v in src]
        rbc = self.rotated_natural([Iv(x) for x in c])
        D = self.drot([(v + x) * 0.5 for v, x in zip(z, c)])
        d = [z[self.p + r] - c[self.p + r] for r in range(4)]
        out = [rb[k].meet(_sum([rbc[k]] + [D[k, r] * d[r][:, None] for r in range(4)])) for k in range(3)]
        return (out, rbc, D, d) if parts else out

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

    def _at_mid(self, lo, hi, C, L, slope):
        """(c, f(c), J(X) or S(X, c), C or, when None, the float inverse of the midpoint of that matrix)."""
        c, z = mid(lo, hi), [Iv(lo[:, k], hi[:, k]) for k in range(self.n)]
        fc = self.values([Iv(c[:, k]) for k in range(self.n)], L)
        J = self.slope(z, c) if slope else self.jacobian(z)
        return c, fc, J, float_inverse(J) if C is None else C

    def krawczyk(self, lo, hi, C, L, slope=False) -> Iv:
        """K(X) (or K_S with slope matrices: no uniqueness) for the boxes [lo, hi] (N, n), C (N, n, n)
        (None: the float32 inverse of the midpoint of J or S, ``float_inverse``)."""
        c, fc, J, C = self._at_mid(lo, hi, C, L, slope)
        M = Iv(np.eye(self.n)) - pmatmul(C, J)
        dx = Iv(lo, hi) - c
        return (Iv(c) - pmatvec(C, fc)) + (M * Iv(dx.lo[:, None, :], dx.hi[:, None, :])).sum(-1)

    def slope_gauss_seidel(self, lo, hi, C, L):
        """The Hansen-Sengupta sweep with slopes: ((c + y) ∩ X as Iv (N, n), empty mask)."""
        c, fc, S, C = self._at_mid(lo, hi, C, L, slope=True)
        G = pmatmul(C, S)
        y, empty = _sweep(G, -pmatvec(C, fc), Iv(lo, hi) - c)
        return (y + c).meet(Iv(lo, hi)), empty

    def gauss_seidel(self, z, P, L):
        """One sweep on (P D) p = P g over the boxes z (list of Iv): (new position Iv (N, p), empty); P None:
        the float32 rounding of the pseudo-inverse of the midpoint of D."""
        rb = self.rotated(z)
        a = self.a
        arb = _sum([a[k] * rb[k] for k in range(self.dim)])
        D = stack([((rb[k][:, 1:] - rb[k][:, :1]) - (a[k][1:] - a[k][:1])) * 2.0 for k in range(self.p)], -1)
        g = ((arb[:, 1:] - arb[:, :1]) * 2.0 - ((self.na2[1:] + self.nb2[1:]) - (self.na2[:1] + self.nb2[:1]))) \
            + (L[:, 1:] - L[:, :1])
        P = float_inverse(D, pseudo=True) if P is None else P
        return _sweep(pmatmul(P, D), pmatvec(P, g), stack(z[:self.p], -1))

    def hc4(self, lo, hi, L):
        """One forward-backward pass (docs/soundness.md §8, in its order): (box Iv (N, n), empty)."""
        N, p, n, dim = len(lo), self.p, self.n, self.dim
        z = [Iv(lo[:, k], hi[:, k]) for k in range(n)]
        empty = np.zeros(N, dtype=bool)
        for k in range(p, n):                                   # 1. the norm equation
            z[k] = _root(z[k], 1.0 - _sum([z[j].sqr() for j in range(p, n) if j != k]))
            empty |= z[k].empty()
        centre = [Iv(lo[:, k], hi[:, k]) for k in range(n)]     # 2. forward: R, u = R b_i, e
        u, rbc, D, dq = self.rotated(z, centre, parts=True) if p and not self.planar else (self.rotated(z, centre),) * 4
        R = self.rotation(z)
        e = self.e(z, u)

        def legs(empty, i=slice(None)):                         # 3. backward through each leg (or leg i)
            s = [v[:, i].sqr() for v in e]
            for k in range(dim):
                e[k][:, i] = _root(e[k][:, i], L[:, i] - _sum([s[j] for j in range(dim) if j != k]))
                s[k], empty = e[k][:, i].sqr(), empty | e[k][:, i].empty().any(1)
            return empty
        empty = legs(empty)
        rounds = PAIR_ROUNDS if p and not self.planar else 0     # leg pairs: d_ij = R (b_i − b_j) − (a_i − a_j),
        d = [(_sum([R[k][m][:, None, None] * self.db[m] for m in range(dim)]).meet(_sum(    # natural ∩ centred
            [rbc[k][:, :, None] - rbc[k][:, None, :]] + [(D[k, r][:, :, None] - D[k, r][:, None, :]) * dq[r][:, None, None]
                                                         for r in range(4)])) - self.da[k]) for k in range(dim)] if rounds else []
        for i in list(range(self.legs)) * rounds:               # leg after leg: e_i ∩ (e_j + d_ij), then its roots
            for k in range(dim):
                c = e[k] + d[k][:, i]
                e[k][:, i] = e[k][:, i].meet(Iv(c.lo.max(1), c.hi.min(1)))
            empty = legs(empty, slice(i, i + 1))
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


def float_inverse(M: Iv, pseudo=False):
    """The float32 rounding of the inverse (``pseudo``: the pseudo-inverse) of the midpoint matrices of M
    (a preconditioner: any float matrix is sound; the pseudo-inverse where a midpoint is singular)."""
    m = 0.5 * M.lo + 0.5 * M.hi
    m = np.where(np.isfinite(m), m, 0.0)
    with np.errstate(all="ignore"):
        try:
            C = np.linalg.pinv(m) if pseudo else np.linalg.inv(m)
        except np.linalg.LinAlgError:
            C = np.linalg.pinv(m)
    return np.where(np.isfinite(C), C, 0.0).astype(np.float32).astype(np.float64)


def _root(x, t):
    """hull(x ∩ {y : y² ∈ t}): the pieces x ∩ [−√t̄, −√t̲] and x ∩ [√t̲, √t̄] (empty if t̄ < 0)."""
    r = Iv(np.maximum(t.lo, 0.0), t.hi).sqrt()
    neg, pos = x.meet(-r), x.meet(r)
    ne, pe = neg.empty() | (t.hi < 0), pos.empty() | (t.hi < 0)
    lo, hi = np.where(ne, pos.lo, neg.lo), np.where(pe, neg.hi, pos.hi)
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
