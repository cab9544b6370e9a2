"""Forward-kinematics claims (``"problem": "forward-kinematics"``, docs/certificates.md).

The equations are rebuilt here from the exact geometry and leg lengths
stated in the certificate (models ``planar-3rpr-fk/1``,
``spherical-3dof-fk/1``, ``gough-stewart-fk/1``):

- unknowns: the platform origin p (planar x, y; Gough x, y, z; none for
  the spherical robot) and the rotation, (c, s) in the plane or a
  quaternion (q0, q1, q2, q3) in space, with
  R(q) = [[1 − 2(q2² + q3²), 2(q1 q2 − q0 q3), 2(q1 q3 + q0 q2)],
          [2(q1 q2 + q0 q3), 1 − 2(q1² + q3²), 2(q2 q3 − q0 q1)],
          [2(q1 q3 − q0 q2), 2(q2 q3 + q0 q1), 1 − 2(q1² + q2²)]],
  R = [[c, −s], [s, c]] in the plane;
- equations: leg i, Σ_k (p_k + (R b_i)_k − a_ik)² − ρ_i² (i = 1..legs; a length given as a
  range "lo:hi" makes ρ_i an interval: every step then holds for every length in the ranges,
  a Krawczyk box holds exactly one root for each length vector),
  then c² + s² − 1 or |q|² − 1;
- position system (for ``position`` contractions): D p = g with, for i ≥ 2,
  D_i = 2((R b_i − R b_1) − (a_i − a_1)),
  g_i = 2(a_i·R b_i − a_1·R b_1) − (|a_i|² + |b_i|²) + (|a_1|² + |b_1|²) + ρ_i² − ρ_1².

A claim lists ``solutions`` (boxes R_j of unknowns, each with a float
matrix C_j such that the Krawczyk image K(R_j) lies in the interior of R_j:
exactly one root in R_j), pairwise disjoint, inside the ``domain``; and a
``tree`` covering the domain whose leaves are excluded (``equation``,
``krawczyk-empty``, ``slope-empty``, ``slope-gs-empty``, ``position-empty``, ``hc4-empty``), left in
a listed cluster region (``cluster``: nothing is proved about the leaf; the claim's ``clusters`` are
regions that may hold any number of postures), or proved
(``krawczyk-unique``:
K(X*) ⊂ int X* for X* ⊇ leaf, and the solution it names lies in X*, so the
leaf's only possible root is that solution — or, with ``twin``, the
solution with q negated, the same posture; or ``outside``: a box proved to
hold X*'s root misses the leaf, which then holds no root).  Solutions are
distinct postures: their boxes, and (spatial robots) their boxes with the
quaternion negated, are pairwise disjoint.  Contractions (``krawczyk``:
K(X) ∩ X, ``slope``: the same with slope matrices in place of the Jacobian
(``System.slope``), ``slope-gs``: one Gauss-Seidel sweep of (C S) (x − c) = −C f(c) with those
slope matrices (``System.slope_gauss_seidel``), ``position``: one Gauss-Seidel sweep of
(P D) p = P g, ``hc4``:
one forward-backward pass, ``System.hc4``, then the sweep if P is given) must
land inside the child box.  With ``complete`` true, no leaf is undecided, so every root in the
domain lies in a solution box (exactly one root each) or in a cluster box; with ``covers`` =
``all-postures`` the domain is checked to hold every real posture.  The
Krawczyk midpoint c is the float fl(0.5 lo + 0.5 hi) of each box.
"""
from __future__ import annotations

from mpmath import iv

from . import ad, tree
from .numbers import enclose, exact, real
from .report import Rejected
from .singularity import read_box

MODELS = {"planar-3rpr-fk/1": ("planar-3rpr", ("x", "y", "c", "s"), 3, 2, 2),
          "spherical-3dof-fk/1": ("spherical-3dof", ("q0", "q1", "q2", "q3"), 3, 3, 0),
          "gough-stewart-fk/1": ("gough-stewart", ("x", "y", "z", "q0", "q1", "q2", "q3"), 6, 3, 3)}


def _sqr(x):
    if isinstance(x, ad.Dual):
        return ad.Dual(x.v ** 2, {k: 2 * x.v * g for k, g in x.d.items()})
    return x ** 2


class System:
    """The FK equations of one robot and one set of leg lengths, over ``iv`` boxes."""

    def __init__(self, model: str, robot: dict, lengths):
        kind, names, legs, dim, n_pos = MODELS[model]
        self.names, self.legs, self.dim, self.n_pos = names, legs, dim, n_pos
        self.n = len(names)
        self.planar = dim == 2
        self.a = _points(robot, "base", legs, dim)
        self.b = _points(robot, "platform", legs, dim)
        if not isinstance(lengths, list) or len(lengths) != legs:
            raise Rejected(f"lengths: expected {legs} exact decimals")
        self.rho = [_length(v, f"lengths[{i}]") for i, v in enumerate(lengths)]
        rho = self.rho
        self.L = [r ** 2 for r in rho]
        self.norm_a2 = [sum((c ** 2 for c in p), iv.mpf(0)) for p in self.a]
        self.norm_b2 = [sum((c ** 2 for c in p), iv.mpf(0)) for p in self.b]
        self._lift = ([[ad.lift(c) for c in p] for p in self.a], [[ad.lift(c) for c in p] for p in self.b])

    # ----- the formulas (same code for iv numbers and ad.Dual numbers) --------
    def rotation(self, z):
        p = self.n_pos
        if self.planar:
            c, s = z[2], z[3]
            return [[c, -s], [s, c]]
        q0, q1, q2, q3 = z[p:p + 4]
        return [[1 - 2 * (_sqr(q2) + _sqr(q3)), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                [2 * (q1 * q2 + q0 * q3), 1 - 2 * (_sqr(q1) + _sqr(q3)), 2 * (q2 * q3 - q0 * q1)],
                [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (_sqr(q1) + _sqr(q2))]]

    def rotated(self, R, b):
        """R b_i for every leg (b: the platform points, plain or lifted)."""
        out = []
        for bi in b:
            out.append([sum((R[k][j] * bi[j] for j in range(1, self.dim)), R[k][0] * bi[0]) for k in range(self.dim)])
        return out

    def rotated_box(self, z, centre=None):
        """R b_i over the box z: the natural enclosure intersected, for a quaternion, with the centred
        form R b_i(c) + Σ_r ∂(R b_i)/∂q_r(y) (z_r − c_r), c the float midpoint of the box (of ``centre``,
        a box given as (lo, hi) pairs or intervals, if given) and y ∋ (x + c)/2: exact since R b_i is
        quadratic in q, so every value of R b_i over the box lies in both."""
        rb = self.rotated(self.rotation(z), self.b)
        if self.planar or all((v.a == v.b) is True for v in z):
            return rb
        p = self.n_pos
        c = []
        for v in (z if centre is None else _intervals(centre)):
            lo, hi = float(v.a), float(v.b)
            c.append(min(max(0.5 * lo + 0.5 * hi, lo), hi))
        zc = [iv.mpf(x) for x in c]
        acc = self.rotated(self.rotation(zc), self.b)
        rby = self.rotated(self.rotation(ad.variables([(v + x) / 2 for v, x in zip(z, zc)])), self._lift[1])
        grads = [[ad.gradient(rby[i][k], self.n)[1] for k in range(self.dim)] for i in range(self.legs)]
        for r in range(p, self.n):                  # in the solver's order (FKSystem.rotated_centred)
            d = z[r] - zc[r]
            for i in range(self.legs):
                for k in range(self.dim):
                    acc[i][k] = acc[i][k] + grads[i][k][r] * d
        return [[iv.mpf([max(u.a, v.a), min(u.b, v.b)]) for u, v in zip(ru, rv)] for ru, rv in zip(rb, acc)]

    def equations(self, z, dual=False):
        a, b = self._lift if dual else (self.a, self.b)
        rb = self.rotated(self.rotation(z), b) if dual else self.rotated_box(z)
        out = []
        for i in range(self.legs):
            total = None
            for k in range(self.dim):
                ell = rb[i][k] - a[i][k]
                if self.n_pos:
                    ell = z[k] + ell
                total = _sqr(ell) if total is None else total + _sqr(ell)
            out.append(total - self.L[i])
        norm = _sqr(z[self.n_pos])
        for k in range(self.n_pos + 1, self.n):
            norm = norm + _sqr(z[k])
        out.append(norm - 1)
        return out

    def values(self, box):
        return self.equations([iv.mpf([lo, hi]) for lo, hi in box])

    def jacobian(self, box):
        zs = ad.variables([iv.mpf([lo, hi]) for lo, hi in box])
        rows = []
        for f in self.equations(zs, dual=True):
            _, grad = ad.gradient(f, self.n)
            rows.append(grad)
        return rows

    def position_system(self, box):
        z = _intervals(box)
        rb = self.rotated_box(z)
        a = self.a
        arb = [sum((a[i][k] * rb[i][k] for k in range(1, self.dim)), a[i][0] * rb[i][0]) for i in range(self.legs)]
        D, g = [], []
        for i in range(1, self.legs):
            D.append([2 * ((rb[i][k] - rb[0][k]) - (a[i][k] - a[0][k])) for k in range(self.n_pos)])
            g.append(2 * (arb[i] - arb[0]) - ((self.norm_a2[i] + self.norm_b2[i]) - (self.norm_a2[0] + self.norm_b2[0]))
                     + (self.L[i] - self.L[0]))
        return D, g

    def slope(self, box, c):
        """Slope matrices at the point c over the box: for every x in the box, some S in the
        result has f(x) − f(c) = S (x − c).  R b_i is quadratic in the rotation unknowns, so
        R b_i(x) − R b_i(c) = ∇(R b_i)((x + c)/2) (x − c) exactly, and with ell = p + R b_i − a_i,
        ell_k(x)² − ell_k(c)² = (ell_k(x) + ell_k(c)) (ell_k(x) − ell_k(c)); the norm equation
        gives |r(x)|² − |r(c)|² = (r(x) + r(c))·(r(x) − r(c))."""
        z = _intervals(box)
        zc = [iv.mpf(x) for x in c]
        y = [(zi + ci) / 2 for zi, ci in zip(z, zc)]              # holds (x + c)/2 for every x in the box
        p, n, dim = self.n_pos, self.n, self.dim
        rb = self.rotated_box(z)
        rbc = self.rotated(self.rotation(zc), self.b)
        rby = self.rotated(self.rotation(ad.variables(y)), self._lift[1])   # Duals: ∇(R b_i) over y
        rows = []
        for i in range(self.legs):
            s = []
            for k in range(dim):
                ell, ellc = rb[i][k] - self.a[i][k], rbc[i][k] - self.a[i][k]
                if p:
                    ell, ellc = ell + z[k], ellc + zc[k]
                s.append(ell + ellc)
            row = [s[k] if k < p else iv.mpf(0) for k in range(n)]
            grads = [ad.gradient(rby[i][k], n)[1] for k in range(dim)]
            for r in range(p, n):
                total = s[0] * grads[0][r]
                for k in range(1, dim):
                    total = total + s[k] * grads[k][r]
                row[r] = total
            rows.append(row)
        rows.append([iv.mpf(0) if k < p else z[k] + zc[k] for k in range(n)])
        return rows

    # ----- the tests ---------------------------------------------------------------
    def krawczyk(self, box, C, slope=False):
        """The Krawczyk image K = c − C f(c) + (I − C J(box))(box − c), c the float midpoint
        (``slope``: with the slope matrices of ``slope`` in place of J: every root in the box lies
        in K, but K inside the box proves no uniqueness)."""
        c = [min(max(0.5 * lo + 0.5 * hi, lo), hi) for lo, hi in box]
        fc = self.values([(x, x) for x in c])
        J = self.slope(box, c) if slope else self.jacobian(box)
        n = self.n
        K = []
        for i in range(n):
            acc = iv.mpf(c[i])
            for k in range(n):
                acc = acc - iv.mpf(C[i][k]) * fc[k]
            for j in range(n):
                r = iv.mpf(1 if i == j else 0)
                for k in range(n):
                    r = r - iv.mpf(C[i][k]) * J[k][j]
                acc = acc + r * (iv.mpf([box[j][0], box[j][1]]) - iv.mpf(c[j]))
            K.append(acc)
        return K

    def slope_gauss_seidel(self, box, C):
        """The Hansen-Sengupta step with slope matrices: one Gauss-Seidel sweep on
        (C S) y = −C f(c), y = x − c, c the float midpoint, S = ``slope(box, c)``, from y = box − c.
        Every root x in the box has f(c) + S (x − c) = 0 for some S in the slope enclosure, so
        y = x − c solves the preconditioned system and stays in each update.  Returns the intervals
        c + y (a box holding every root of the box), or None when the sweep empties the box."""
        c = [min(max(0.5 * lo + 0.5 * hi, lo), hi) for lo, hi in box]
        fc = self.values([(x, x) for x in c])
        S = self.slope(box, c)
        n = self.n
        Cm = [[iv.mpf(C[i][k]) for k in range(n)] for i in range(n)]
        G = [[sum((Cm[i][k] * S[k][j] for k in range(1, n)), Cm[i][0] * S[0][j]) for j in range(n)]
             for i in range(n)]
        r = [-sum((Cm[i][k] * fc[k] for k in range(1, n)), Cm[i][0] * fc[0]) for i in range(n)]
        y = _sweep(G, r, [iv.mpf([lo, hi]) - iv.mpf(x) for (lo, hi), x in zip(box, c)])
        return None if y is None else [yi + iv.mpf(x) for yi, x in zip(y, c)]

    def gauss_seidel(self, box, P):
        """One Gauss-Seidel sweep on (P D) p = P g; returns the new position intervals or None (empty).

        ``box``: (lo, hi) pairs of floats, or ``iv`` intervals (the result of ``hc4``)."""
        D, g = self.position_system(box)
        m = len(D)
        A = [[sum((iv.mpf(P[i][r]) * D[r][j] for r in range(1, m)), iv.mpf(P[i][0]) * D[0][j])
              for j in range(self.n_pos)] for i in range(self.n_pos)]
        rhs = [sum((iv.mpf(P[i][r]) * g[r] for r in range(1, m)), iv.mpf(P[i][0]) * g[0]) for i in range(self.n_pos)]
        return _sweep(A, rhs, _intervals(box)[:self.n_pos])

    def hc4(self, box):
        """One forward-backward (HC4-revise) pass over the box; the contracted box, or None when the
        box holds no root.  The same operations, in the same order, as certkin/fk_hc4.py (its
        docstring lists them; docs/soundness.md §8 proves that each keeps every root)."""
        z = _intervals(box)
        p, n, dim, legs = self.n_pos, self.n, self.dim, self.legs
        # 1. the norm equation
        for k in range(p, n):
            others = None
            for j in range(p, n):
                if j != k:
                    others = _sqr(z[j]) if others is None else others + _sqr(z[j])
            z[k] = _root(z[k], 1 - others)
            if z[k] is None:
                return None
        # 2. forward: R, u_i = R b_i (natural ∩ centred around the float midpoint of the given box),
        #    e_i = (u_i − a_i) + p
        R = self.rotation(z)
        u = self.rotated_box(z, centre=box)
        a, b = self.a, self.b
        e = [[(u[i][k] - a[i][k]) + z[k] if p else u[i][k] - a[i][k] for k in range(dim)] for i in range(legs)]
        # 3. backward through each leg equation
        for i in range(legs):
            s = [_sqr(v) for v in e[i]]
            for k in range(dim):
                others = None
                for kk in range(dim):
                    if kk != k:
                        others = s[kk] if others is None else others + s[kk]
                e[i][k] = _root(e[i][k], self.L[i] - others)
                if e[i][k] is None:
                    return None
                s[k] = _sqr(e[i][k])
        # 4. the position
        for k in range(p):
            for i in range(legs):
                z[k] = _meet(z[k], (e[i][k] - u[i][k]) + a[i][k])
                if z[k] is None:
                    return None
        # 5. u_ik from e_ik
        for i in range(legs):
            for k in range(dim):
                back = e[i][k] - z[k] if p else e[i][k]
                u[i][k] = _meet(u[i][k], back + a[i][k])
                if u[i][k] is None:
                    return None
        # 6. entries of R from u_i = R b_i (all candidates from the R of step 2)
        newR = [row[:] for row in R]
        for i in range(legs):
            for k in range(dim):
                T = [R[k][j] * b[i][j] for j in range(dim)]
                for j in range(dim):
                    if not ((b[i][j] > 0) is True or (b[i][j] < 0) is True):
                        continue
                    rest = None
                    for jj in range(dim):
                        if jj != j:
                            rest = T[jj] if rest is None else rest + T[jj]
                    newR[k][j] = _meet(newR[k][j], (u[i][k] - rest) / b[i][j])
                    if newR[k][j] is None:
                        return None
        R = newR
        # 7. the rotation unknowns from R
        if self.planar:
            for k, parts in ((2, (R[0][0], R[1][1])), (3, (R[1][0], -R[0][1]))):
                for v in parts:
                    z[k] = _meet(z[k], v)
                    if z[k] is None:
                        return None
            return z
        q = z[p:]
        for k, ia, ib in HC4_DIAGONAL:
            t = (1 - R[k][k]) * 0.5
            for x, y in ((ia, ib), (ib, ia)):
                q[x] = _root(q[x], t - _sqr(q[y]))
                if q[x] is None:
                    return None
        for (k, j), (ia, ib), (ic, id_), sigma in HC4_OFF_DIAGONAL:
            h = R[k][j] * 0.5
            g = h - q[ic] * q[id_] if sigma > 0 else h + q[ic] * q[id_]
            for x, y in ((ia, ib), (ib, ia)):
                q[x] = _divide_by(q[x], g, q[y])
                if q[x] is None:
                    return None
            g2 = h - q[ia] * q[ib]
            if sigma < 0:
                g2 = -g2
            for x, y in ((ic, id_), (id_, ic)):
                q[x] = _divide_by(q[x], g2, q[y])
                if q[x] is None:
                    return None
        return z[:p] + q


# R_kj = 2(q_a q_b + σ q_c q_d): ((k, j), (a, b), (c, d), σ); R_kk = 1 − 2(q_a² + q_b²): (k, a, b)
HC4_OFF_DIAGONAL = (((0, 1), (1, 2), (0, 3), -1), ((1, 0), (1, 2), (0, 3), 1),
                    ((0, 2), (1, 3), (0, 2), 1), ((2, 0), (1, 3), (0, 2), -1),
                    ((1, 2), (2, 3), (0, 1), -1), ((2, 1), (2, 3), (0, 1), 1))
HC4_DIAGONAL = ((0, 2, 3), (1, 1, 3), (2, 1, 2))


def _intervals(box):
    """``iv`` intervals from (lo, hi) float pairs (``iv`` intervals are kept)."""
    return [v if isinstance(v, iv.mpf) else iv.mpf([v[0], v[1]]) for v in box]


def _root(x, t):
    """hull(x ∩ {y : y² ∈ t}), or None when empty: the pieces x ∩ [−√t̄, −√t̲] and x ∩ [√t̲, √t̄]."""
    if (t.b < 0) is True:
        return None
    rhi = iv.sqrt(t.b).b
    rlo = iv.sqrt(t.a).a if (t.a > 0) is True else iv.mpf(0)
    neg = _meet(x, iv.mpf([-rhi, -rlo]))
    pos = _meet(x, iv.mpf([rlo, rhi]))
    if neg is None or pos is None:
        return neg if pos is None else pos
    return iv.mpf([neg.a, pos.b])


def _divide_by(x, num, den):
    """x ∩ num / den when 0 ∉ den (None if empty); x itself otherwise."""
    if (den > 0) is True or (den < 0) is True:
        return _meet(x, num / den)
    return x


def _sweep(A, b, x):
    """One interval Gauss-Seidel sweep on A x = b from the intervals x: x_i ∩ (b_i − Σ_{j≠i} A_ij x_j) / A_ii
    in turn (``_divide_into``); the new intervals, or None when one is empty (no solution in x)."""
    x = list(x)
    for i in range(len(x)):
        num = b[i]
        for j in range(len(x)):
            if j != i:
                num = num - A[i][j] * x[j]
        new = _divide_into(num, A[i][i], x[i])
        if new is None:
            return None
        x[i] = new
    return x


def _divide_into(num, den, x):
    """x ∩ {t : d t = v, d ∈ den, v ∈ num} (its hull), or None when empty.

    With 0 in den and not in num the set is one or two half-lines (Hansen &
    Sengupta 1981): for num > 0, [nl/dh, ∞) if dh > 0 and (−∞, nl/dl] if
    dl < 0; for num < 0, (−∞, nh/dh] if dh > 0 and [nh/dl, ∞) if dl < 0.
    """
    if (den > 0) is True or (den < 0) is True:
        return _meet(x, num / den)
    if (num > 0) is not True and (num < 0) is not True:
        return x  # 0 in both: every t qualifies
    dl, dh = den.a, den.b
    inf = iv.mpf("inf")
    pieces = []
    if (num > 0) is True:
        if (dh > 0) is True:
            pieces.append(iv.mpf([(num.a / dh).a, inf]))
        if (dl < 0) is True:
            pieces.append(iv.mpf([-inf, (num.a / dl).b]))
    else:
        if (dh > 0) is True:
            pieces.append(iv.mpf([-inf, (num.b / dh).b]))
        if (dl < 0) is True:
            pieces.append(iv.mpf([(num.b / dl).a, inf]))
    parts = [m for m in (_meet(x, piece) for piece in pieces) if m is not None]
    if not parts:
        return None
    return iv.mpf([min((m.a for m in parts), key=float), max((m.b for m in parts), key=float)])


def _meet(x, y):
    lo, hi = max(x.a, y.a), min(x.b, y.b)
    if (lo > hi) is True:
        return None
    return iv.mpf([lo, hi])


def _length(value, where):
    """A leg length: an exact decimal, or a range "lo:hi" of exact decimals (0 <= lo <= hi), enclosed
    outward; every claim about the range holds for every length in it."""
    parts = value.split(":") if isinstance(value, str) else [value]
    if len(parts) > 2:
        raise Rejected(f"{where}: expected a decimal or 'lo:hi'")
    lo, hi = parts[0], parts[-1]
    if exact(lo, where) < 0 or exact(lo, where) > exact(hi, where):
        raise Rejected(f"{where}: a leg length (range) must satisfy 0 <= lo <= hi")
    return iv.mpf([enclose(lo, where).a, enclose(hi, where).b])


def _points(robot, key, count, dim):
    pts = robot.get(key)
    if not isinstance(pts, list) or len(pts) != count:
        raise Rejected(f"robot.{key}: expected {count} points")
    out = []
    for i, p in enumerate(pts):
        if not isinstance(p, list) or len(p) != dim:
            raise Rejected(f"robot.{key}[{i}]: expected {dim} coordinates")
        out.append([enclose(c, f"robot.{key}[{i}][{j}]") for j, c in enumerate(p)])
    return out


# ----------------------------------------------------------------------------- claims
def check_claims(model, robot, claims, counts):
    if model not in MODELS:
        raise Rejected(f"model: unknown model {model!r} (known: {', '.join(MODELS)})")
    if robot.get("kind") != MODELS[model][0]:
        raise Rejected(f"robot.kind: {robot.get('kind')!r} does not fit model {model}")
    for k, claim in enumerate(claims):
        if not isinstance(claim, dict):
            raise Rejected(f"claims[{k}]: expected an object")
        _claim(model, robot, claim, f"claims[{k}]", counts)


def _matrix(value, n, m, where):
    if not isinstance(value, list) or len(value) != n or any(not isinstance(r, list) or len(r) != m for r in value):
        raise Rejected(f"{where}: expected a {n}x{m} matrix of numbers")
    return [[real(v, where) for v in r] for r in value]


def _claim(model, robot, claim, where, counts):
    system = System(model, robot, claim.get("lengths"))
    n = system.n
    if claim.get("domain") == "empty":
        _no_position(system, f"{where}.domain")
        if claim.get("solutions") != [] or claim.get("complete") is not True:
            raise Rejected(f"{where}: an empty domain has no solutions and is complete")
        return
    domain = read_box(claim.get("domain"), n, f"{where}.domain")
    complete = claim.get("complete")
    if complete not in (True, False):
        raise Rejected(f"{where}.complete: expected true or false")
    if claim.get("covers") == "all-postures":
        _covers_all(system, domain, f"{where}.domain")
    elif claim.get("covers") != "box":
        raise Rejected(f"{where}.covers: expected 'all-postures' or 'box'")
    sols = claim.get("solutions")
    if not isinstance(sols, list):
        raise Rejected(f"{where}.solutions: expected a list")
    boxes = []
    for j, s in enumerate(sols):
        w = f"{where}.solutions[{j}]"
        if not isinstance(s, dict):
            raise Rejected(f"{w}: expected an object")
        box = read_box(s.get("box"), n, f"{w}.box")
        C = _matrix(s.get("C"), n, n, f"{w}.C")
        if not _inside(box, domain):
            raise Rejected(f"{w}: box not inside the domain")
        if not _interior(system.krawczyk(box, C), box):
            raise Rejected(f"{w}: Krawczyk image not inside the box: uniqueness not proved")
        for i, other in enumerate(boxes):
            if not _disjoint(box, other) or (not system.planar and not _disjoint(box, _negated(system, other))):
                raise Rejected(f"{w}: box meets solutions[{i}] (or its negated quaternion): "
                               "the postures are not proved distinct")
        boxes.append(box)
        counts["solutions"] = counts.get("solutions", 0) + 1
    clusters = claim.get("clusters", [])
    if not isinstance(clusters, list):
        raise Rejected(f"{where}.clusters: expected a list of boxes")
    clusters = [read_box(c, n, f"{where}.clusters[{j}]") for j, c in enumerate(clusters)]
    _tree(system, claim.get("tree"), domain, boxes, complete, f"{where}.tree", counts, clusters)


def _covers_all(system, domain, where):
    """The domain holds every real posture: rotation unknowns cover the circle/hemisphere, and
    |p − a_i| ≤ ρ_i + |b_i| bounds the origin."""
    p = system.n_pos
    for k in range(p, system.n):
        need_lo = 0.0 if (not system.planar and k == p) else -1.0
        if not (domain[k][0] <= need_lo and domain[k][1] >= 1.0):
            raise Rejected(f"{where}: {system.names[k]} does not cover [{need_lo}, 1]")
    for k in range(p):
        lows, highs = _reach(system, k)
        if not ((iv.mpf(domain[k][0]) <= max(lows)) is True and (iv.mpf(domain[k][1]) >= min(highs)) is True):
            raise Rejected(f"{where}: {system.names[k]} does not cover the reachable positions")


def _reach(system, k):
    """Rigorous bounds (lows, highs) of a_ik ∓ (ρ_i + |b_i|) per leg: every posture's origin p
    satisfies max(lows) <= p_k <= min(highs)."""
    lows, highs = [], []
    for i in range(system.legs):
        reach = system.rho[i] + iv.sqrt(system.norm_b2[i])
        lows.append((system.a[i][k] - reach).a)
        highs.append((system.a[i][k] + reach).b)
    return lows, highs


def _no_position(system, where):
    """Some coordinate of the origin has no admissible value: no posture at all."""
    for k in range(system.n_pos):
        lows, highs = _reach(system, k)
        if (max(lows) > min(highs)) is True:
            return
    raise Rejected(f"{where}: 'empty' is not proved: the leg-length balls may meet")


def _inside(inner, outer):
    return all(a >= c and b <= d for (a, b), (c, d) in zip(inner, outer))


def _disjoint(x, y):
    return any(b < c or d < a for (a, b), (c, d) in zip(x, y))


def _interior(K, box):
    return all((k > lo) is True and (k < hi) is True for k, (lo, hi) in zip(K, box))


def _negated(system, box):
    """The box with the quaternion negated (the same rotation)."""
    p = system.n_pos
    return [b if k < p else (-b[1], -b[0]) for k, b in enumerate(box)]


def _tree(system, root, domain, solutions, complete, where, counts, clusters=()):
    n = system.n
    stack = [(root, domain, ())]
    while stack:
        node, box, path = stack.pop()
        at = tree.label(where, node, path)
        if "split" in node:
            (c0, lower), (c1, upper) = tree.split(node, box, at)
            stack.append((c1, upper, path + (1,)))
            stack.append((c0, lower, path + (0,)))
        elif "contract" in node:
            child_box = read_box(node.get("box"), n, f"{at}: box")
            if not _inside(child_box, box):
                raise Rejected(f"{at}: contracted box not inside its parent")
            _contraction(system, node, box, child_box, at)
            counts["contractions"] = counts.get("contractions", 0) + 1
            stack.append((node.get("child"), child_box, path + ("c",)))
        elif "leaf" in node:
            if read_box(node.get("box"), n, f"{at}: box") != box:
                raise Rejected(f"{at}: box does not match the derived box")
            _leaf(system, node, box, solutions, complete, at, clusters, counts)
            counts["leaves"] += 1
        else:
            raise Rejected(f"{at}: neither a split, a contraction nor a leaf")


def _contraction(system, node, box, child, at):
    rule = node.get("contract")
    if rule in ("krawczyk", "slope"):
        K = system.krawczyk(box, _matrix(node.get("C"), system.n, system.n, f"{at}: C"), slope=rule == "slope")
        for k, ((lo, hi), (clo, chi)) in enumerate(zip(box, child)):
            kk = K[k]
            low = max(kk.a, iv.mpf(lo))   # K ∩ X along coordinate k
            high = min(kk.b, iv.mpf(hi))
            if (low > high) is True:
                continue  # K ∩ X is empty: no root in X at all
            if not ((low >= clo) is True and (high <= chi) is True):
                raise Rejected(f"{at}: {rule} contraction: K ∩ X not inside the child box on dim {k}")
    elif rule == "slope-gs":
        z = system.slope_gauss_seidel(box, _matrix(node.get("C"), system.n, system.n, f"{at}: C"))
        if z is None:
            return  # no root in X at all
        for k in range(system.n):
            if not ((z[k].a >= child[k][0]) is True and (z[k].b <= child[k][1]) is True):
                raise Rejected(f"{at}: slope-gs contraction: Gauss-Seidel result not inside the child box on dim {k}")
    elif rule == "hc4":
        z = system.hc4(box)
        if z is not None and "P" in node:  # then one Gauss-Seidel sweep on the position
            if not system.n_pos:
                raise Rejected(f"{at}: a position contraction needs a position")
            x = system.gauss_seidel(z, _matrix(node.get("P"), system.n_pos, system.legs - 1, f"{at}: P"))
            z = None if x is None else x + z[system.n_pos:]
        if z is None:
            return  # no root in X at all
        for k in range(system.n):
            if not ((z[k].a >= child[k][0]) is True and (z[k].b <= child[k][1]) is True):
                raise Rejected(f"{at}: hc4 contraction: result not inside the child box on dim {k}")
    elif rule == "position":
        if not system.n_pos:
            raise Rejected(f"{at}: a position contraction needs a position")
        P = _matrix(node.get("P"), system.n_pos, system.legs - 1, f"{at}: P")
        x = system.gauss_seidel(box, P)
        if x is None:
            return  # no root in X at all
        for k in range(system.n_pos):
            if not ((x[k] >= child[k][0]) is True and (x[k] <= child[k][1]) is True):
                raise Rejected(f"{at}: position contraction: Gauss-Seidel result not inside the child box on dim {k}")
        for k in range(system.n_pos, system.n):
            if child[k] != box[k]:
                raise Rejected(f"{at}: a position contraction changes only the position")
    else:
        raise Rejected(f"{at}: unknown contraction {rule!r} (known: krawczyk, slope, slope-gs, position, hc4)")


def _leaf(system, node, box, solutions, complete, at, clusters=(), counts=None):
    rule = node.get("leaf")
    n = system.n
    if rule == "undecided":
        if complete:
            raise Rejected(f"{at}: undecided leaf in a claim that says complete")
        return
    if rule == "cluster":   # nothing proved about the leaf: it lies in a region the claim lists as a cluster
        j = node.get("cluster")
        if isinstance(j, bool) or not isinstance(j, int) or not 0 <= j < len(clusters):
            raise Rejected(f"{at}: 'cluster' must name one of the {len(clusters)} clusters")
        if not _inside(box, clusters[j]):
            raise Rejected(f"{at}: box not inside clusters[{j}]")
        if counts is not None:
            counts["clusters"] = counts.get("clusters", 0) + 1
        return
    if rule == "equation":
        k = node.get("equation")
        if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < n:
            raise Rejected(f"{at}: 'equation' must be an index below {n}")
        v = system.values(box)[k]
        if (v > 0) is not True and (v < 0) is not True:
            raise Rejected(f"{at}: equation {k} may vanish on the box")
        return
    if rule in ("krawczyk-empty", "slope-empty"):
        K = system.krawczyk(box, _matrix(node.get("C"), n, n, f"{at}: C"), slope=rule == "slope-empty")
        if not any((K[k] < lo) is True or (K[k] > hi) is True for k, (lo, hi) in enumerate(box)):
            raise Rejected(f"{at}: {'slope' if rule == 'slope-empty' else 'Krawczyk'} image meets the box: "
                           "emptiness not proved")
        return
    if rule == "slope-gs-empty":
        if system.slope_gauss_seidel(box, _matrix(node.get("C"), n, n, f"{at}: C")) is not None:
            raise Rejected(f"{at}: slope Gauss-Seidel sweep does not empty the box: emptiness not proved")
        return
    if rule == "hc4-empty":
        if system.hc4(box) is not None:
            raise Rejected(f"{at}: forward-backward contraction does not prove the box empty")
        return
    if rule == "position-empty":
        if not system.n_pos:
            raise Rejected(f"{at}: position-empty needs a position")
        if system.gauss_seidel(box, _matrix(node.get("P"), system.n_pos, system.legs - 1, f"{at}: P")) is not None:
            raise Rejected(f"{at}: Gauss-Seidel on the position does not prove the box empty")
        return
    if rule == "krawczyk-unique":
        star = read_box(node["star"], n, f"{at}: star") if "star" in node else box
        if not _inside(box, star):
            raise Rejected(f"{at}: box not inside its uniqueness box 'star'")
        if not _interior(system.krawczyk(star, _matrix(node.get("C"), n, n, f"{at}: C")), star):
            raise Rejected(f"{at}: Krawczyk image not inside 'star': uniqueness not proved")
        if "outside" in node:  # the star's root lies in a box that misses the leaf: no root in the leaf
            out = node["outside"]
            if not isinstance(out, dict):
                raise Rejected(f"{at}: 'outside' must be {{'box': ..., 'C': ...}}")
            root = read_box(out.get("box"), n, f"{at}: outside.box")
            if not _inside(root, star) or not _disjoint(root, box):
                raise Rejected(f"{at}: 'outside' box must lie in 'star' and miss the leaf")
            if not _interior(system.krawczyk(root, _matrix(out.get("C"), n, n, f"{at}: outside.C")), root):
                raise Rejected(f"{at}: Krawczyk image not inside 'outside.box': its root is not proved")
            return
        j = node.get("solution")
        if isinstance(j, bool) or not isinstance(j, int) or not 0 <= j < len(solutions):
            raise Rejected(f"{at}: 'solution' must name one of the {len(solutions)} solutions")
        sol = _negated(system, solutions[j]) if node.get("twin") is True else solutions[j]
        if not _inside(sol, star):
            raise Rejected(f"{at}: solutions[{j}] is not inside 'star': the leaf's root is not that solution")
        return
    raise Rejected(f"{at}: unknown rule {rule!r}")
