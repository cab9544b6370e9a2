"""Forward-kinematics equations: position and rotation unknowns for every robot kind.

The unknowns are the platform origin ``p`` (none for the spherical robot,
whose platform turns about O) and the rotation as a unit complex number
(planar: ``c = cos phi``, ``s = sin phi``) or a unit quaternion
``q = (q0, q1, q2, q3)`` (spatial robots), with the rotation matrix

    R(q) = [[1 − 2(q2² + q3²), 2(q1 q2 − q0 q3), 2(q1 q3 + q0 q2)],
            [2(q1 q2 + q0 q3), 1 − 2(q1² + q3²), 2(q2 q3 − q0 q1)],
            [2(q1 q3 − q0 q2), 2(q2 q3 + q0 q1), 1 − 2(q1² + q2²)]]

(a rotation whenever |q| = 1; every unknown occurs once in each entry, so
each entry's interval extension is exact).  The equations are

    leg i:  sum_k (p_k + (R b_i)_k − a_ik)² − ρ_i² = 0
    norm:   c² + s² − 1 = 0,   or   q0² + q1² + q2² + q3² − 1 = 0

a square system (3 + 1 planar, 3 + 1 spherical, 6 + 1 Gough).  The domain
``q0 ∈ [−δ, 1]`` (δ = 2⁻¹⁰) holds a representative of every rotation
(q and −q give the same one); rotations with |q0| ≤ δ may appear twice, as
q and −q, and the solver reports such twins once (``docs/soundness.md``).

For a given rotation the position enters the differences of leg equations
linearly (Merlet's observation used in ALIAS):

    2 p·(R(b_i − b_1) − a_i + a_1) − 2 a_i·R b_i + 2 a_1·R b_1
        + |a_i|² − |a_1|² + |b_i|² − |b_1|² − ρ_i² + ρ_1² = 0   (i ≥ 2)

(|R b| = |b| holds at every solution), which the solver uses to contract
the position by preconditioned interval Gauss-Seidel.  The independent
checker (``proofs/fk.py``) evaluates the same formulas.

All functions are batched: ``X`` (N, n) boxes of unknowns, ``L`` (N, legs)
enclosures of the squared leg lengths (one instance per box).
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, atan2, sqr, sqrt
from intervals.rounding import down, down_sum, up, up_sum

DELTA = 2.0 ** -10      # q0 >= -DELTA: the hemisphere with a margin (see the module docstring)


def _cat(parts, axis=-1):
    return Interval._raw(np.stack([p.lo for p in parts], axis=axis), np.stack([p.hi for p in parts], axis=axis))


class FKSystem:
    """The FK equations of one robot (see the module docstring)."""

    def __init__(self, robot):
        self.robot = robot
        self.kind = robot.kind
        n = robot.n_legs
        dim = robot.dim
        params = robot.parameters
        self.a = Interval._raw(np.array([float(v.lo) for v in params[:n * dim]]).reshape(n, dim),
                               np.array([float(v.hi) for v in params[:n * dim]]).reshape(n, dim))
        self.b = Interval._raw(np.array([float(v.lo) for v in params[n * dim:]]).reshape(n, dim),
                               np.array([float(v.hi) for v in params[n * dim:]]).reshape(n, dim))
        self.legs = n
        if self.kind == "planar-3rpr":
            self.unknowns = ("x", "y", "c", "s")
            self.n_pos = 2
        elif self.kind == "gough-stewart":
            self.unknowns = ("x", "y", "z", "q0", "q1", "q2", "q3")
            self.n_pos = 3
        else:
            self.unknowns = ("q0", "q1", "q2", "q3")
            self.n_pos = 0
        self.n = len(self.unknowns)
        self.model_name = f"{self.kind}-fk/1"
        # |a_i|², |b_i|² (enclosures), used by the difference equations and the domain
        total = _sum3 if dim == 3 else _sum2
        self.norm_a2 = total(sqr(self.a))
        self.norm_b2 = total(sqr(self.b))
        self.size = float(max(np.max(np.abs(self.a.hi)), np.max(np.abs(self.b.hi)), 1e-300))  # the robot's scale

    # ----- rotation -----------------------------------------------------------
    def rotation(self, X: Interval) -> Interval:
        """Enclosure of R over the boxes: (N, dim, dim)."""
        if self.kind == "planar-3rpr":
            c, s = X[:, 2], X[:, 3]
            return _cat([_cat([c, -s]), _cat([s, c])], axis=-2)
        p = self.n_pos
        q0, q1, q2, q3 = (X[:, p + k] for k in range(4))
        s1, s2, s3 = sqr(q1), sqr(q2), sqr(q3)
        rows = [[1.0 - 2.0 * (s2 + s3), 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2)],
                [2.0 * (q1 * q2 + q0 * q3), 1.0 - 2.0 * (s1 + s3), 2.0 * (q2 * q3 - q0 * q1)],
                [2.0 * (q1 * q3 - q0 * q2), 2.0 * (q2 * q3 + q0 * q1), 1.0 - 2.0 * (s1 + s2)]]
        return _cat([_cat(r) for r in rows], axis=-2)

    def rotation_at_points(self, c: np.ndarray):
        """Quaternion: (Rm, Rr), (N, 3, 3): R(c) at the float points c (N, n) lies in [Rm ± Rr].

        Each entry is a float dot product of length at most three with exact factors 2
        (1 − 2(q_a² + q_b²) or 2(q_a q_b ± q_c q_d)), so it is within γ_3 Σ|terms| ≤ 4u Σ|terms| of the
        exact value, plus 3·2⁻¹⁰²² for underflow (Higham 2002, eq. 3.5, any order of summation); the
        float Σ|terms| (non-negative, at most 4 roundings) is bounded by ``linalg._upper``
        (docs/soundness.md §8, "midpoint-radius R b_i")."""
        from intervals.linalg import _ETA, _U, _upper
        p = self.n_pos
        q = [c[:, p + k] for k in range(4)]
        with np.errstate(invalid="ignore", over="ignore"):
            Rm = self._rotation_float(c)                               # the float dot products
            mag = np.empty_like(Rm)                                    # Σ|terms| of each entry
            for k, a, b in DIAGONAL:                                   # 1 − 2(q_a² + q_b²)
                mag[:, k, k] = 1.0 + 2.0 * (q[a] * q[a] + q[b] * q[b])
            for (k, j), (a, b), (c_, d), _ in OFF_DIAGONAL:            # 2(q_a q_b + σ q_c q_d)
                mag[:, k, j] = 2.0 * (np.abs(q[a] * q[b]) + np.abs(q[c_] * q[d]))
            Rr = _upper(4.0 * _U * mag, 6) + 3 * _ETA
        return Rm, Rr

    def rotated_at_points(self, c: np.ndarray) -> Interval:
        """R b_i at the float points c (N, n): (N, legs, dim) (quaternion: from ``rotation_at_points``)."""
        if self.kind == "planar-3rpr":
            return self.rotated(self.rotation(Interval._raw(c, c.copy())))
        return _from_midrad(*self.rotated_midrad(self.rotation_at_points(c)))

    def rotated(self, R: Interval) -> Interval:
        """R b_i for every leg: (..., legs, dim) for R (..., dim, dim).

        Planar: interval products and sums.  Quaternion: midpoint-radius form (``rotated_midrad``),
        the same enclosure up to a few units in the last place, in about a third of the operations."""
        if self.kind != "planar-3rpr":
            m, r = self.rotated_midrad(R)
            return _from_midrad(m, r)
        b = self.b
        out = R[:, None, :, 0] * b[None, :, 0, None]
        for j in range(1, b.shape[1]):
            out = out + R[:, None, :, j] * b[None, :, j, None]
        return out

    def _b_midrad(self):
        """(bm, inner, outer), each (dim, (dim + 1) legs): b_ij in [bm ± br], inner = (n + 1) u |bm| + br,
        outer = |bm| + br (n = dim), the factors of ``rotated_midrad``: the first legs columns for
        R b_i, then, for each column j of R, the same with b_ij set to 0 (the sums that leave column j
        out).  Computed once."""
        t = self.__dict__.get("_b_midrad_")
        if t is None:
            from intervals.linalg import _U, midrad
            bm, br = midrad(self.b.lo, self.b.hi)
            dim = bm.shape[1]
            full = (bm.T, ((dim + 1) * _U * np.abs(bm) + br).T, (np.abs(bm) + br).T)   # (dim, legs)
            keep = np.concatenate([np.ones((1, dim)), 1.0 - np.eye(dim)])[:, :, None]   # (dim + 1, dim, 1)
            t = self._b_midrad_ = tuple(np.ascontiguousarray(np.moveaxis(keep * v[None], 0, 1).reshape(dim, -1))
                                        for v in full)
        return t

    def rotated_midrad(self, R: Interval, columns: bool = False):
        """(m, r): R b_i in [m ± r] for every R in the interval matrices (..., dim, dim) and every b_ij
        in its enclosure: (..., legs, dim) each.  With R_kj in [Rm ± Rr], b_ij in [bm ± br],
        |R_kj b_ij − Rm bm| ≤ |Rm| br + Rr (|bm| + br); the float sum of the dim products
        Rm_kj bm_ij (a float matrix product, any order) is within γ_dim Σ_j |Rm_kj||bm_ij| +
        dim·2⁻¹⁰²² of the exact one (Higham 2002, eq. 3.5, γ_n ≤ (n + 1) u), and the float radius is
        bounded by ``linalg._upper`` (docs/soundness.md §8, "midpoint-radius R b_i"): the bound of
        ``linalg.product_midrad``.  ``columns``: also, per column j, the same for the sums that leave
        column j out, Σ_{j'≠j} R_kj' b_ij' (b_ij set to 0): (..., legs, dim, dim) each, j last.
        ``R`` may also be given as (Rm, Rr), R in [Rm ± Rr] (``rotation_at_points``)."""
        from intervals.linalg import _ETA, _upper, midrad
        bm, inner, outer = self._b_midrad()
        dim = bm.shape[0]
        legs = self.legs
        if not columns:
            bm, inner, outer = bm[:, :legs], inner[:, :legs], outer[:, :legs]
        with np.errstate(invalid="ignore", over="ignore"):
            Rm, Rr = midrad(R.lo, R.hi) if isinstance(R, Interval) else R
            lead = Rm.shape[:-2]
            Rm, Rr = Rm.reshape(-1, dim), Rr.reshape(-1, dim)
            m = Rm @ bm
            r = _upper(np.abs(Rm) @ inner + Rr @ outer, 4 * dim + 4) + dim * _ETA
            bad = ~(np.isfinite(m) & np.isfinite(r))
            if bad.any():
                m, r = np.where(bad, 0.0, m), np.where(bad, np.inf, r)
        if not columns:
            return (np.swapaxes(m.reshape(lead + (dim, legs)), -1, -2),
                    np.swapaxes(r.reshape(lead + (dim, legs)), -1, -2))
        m = m.reshape(lead + (dim, dim + 1, legs))                # (..., k, block, i)
        r = r.reshape(lead + (dim, dim + 1, legs))
        full = (np.swapaxes(m[..., 0, :], -1, -2), np.swapaxes(r[..., 0, :], -1, -2))
        left_out = tuple(np.moveaxis(v[..., 1:, :], (-3, -2, -1), (-2, -1, -3)) for v in (m, r))   # (..., i, k, j)
        return full + left_out

    # ----- equations -----------------------------------------------------------
    def equations(self, X: Interval, L: Interval, R: Interval | None = None, rb: Interval | None = None) -> Interval:
        """Enclosures of the n equations over the boxes: (N, n) (``R``, ``rb``: R and R b_i if known)."""
        if rb is None:
            rb = self.rotated(self.rotation(X) if R is None else R)
        ell = rb - self.a[None, :, :]
        if self.n_pos:
            ell = ell + X[:, None, :self.n_pos]
        legs = sqr(ell[..., 0])
        for k in range(1, ell.shape[-1]):
            legs = legs + sqr(ell[..., k])
        legs = legs - L
        p = self.n_pos
        norm = sqr(X[:, p])
        for k in range(p + 1, self.n):
            norm = norm + sqr(X[:, k])
        norm = norm - 1.0
        return Interval._raw(np.concatenate([legs.lo, norm.lo[:, None]], axis=1),
                             np.concatenate([legs.hi, norm.hi[:, None]], axis=1))

    def jacobian(self, X: Interval, R: Interval | None = None, rb: Interval | None = None) -> Interval:
        """Enclosure of the Jacobian over the boxes: (N, n, n)."""
        N = X.shape[0]
        if rb is None:
            rb = self.rotated(self.rotation(X) if R is None else R)
        ell = rb - self.a[None, :, :]
        p = self.n_pos
        if p:
            ell = ell + X[:, None, :p]
        two_ell = 2.0 * ell                                   # (N, legs, dim)
        J = Interval._raw(np.zeros((N, self.n, self.n)), np.zeros((N, self.n, self.n)))
        legs = self.legs
        for k in range(p):
            J[:, :legs, k] = two_ell[..., k]
        # d/dr of sum_k (ell_k)^2 = sum_k 2 ell_k d(R b)_k/dr
        for r, dR in enumerate(self._rotation_derivatives(X)):
            drb = self.rotated(dR)                            # (N, legs, dim)
            col = two_ell[..., 0] * drb[..., 0]
            for k in range(1, drb.shape[-1]):
                col = col + two_ell[..., k] * drb[..., k]
            J[:, :legs, p + r] = col
        for k in range(p, self.n):
            J[:, legs, k] = 2.0 * X[:, k]
        return J

    def rotated_centred(self, X: Interval, c: np.ndarray | None = None, rb: Interval | None = None,
                        parts: bool = False, form: tuple | None = None):
        """R b_i over the boxes (N, legs, dim): the natural enclosure (``rotated``, or ``rb``) intersected,
        for a quaternion, with the centred form R b_i(c) + Σ_r ∂(R b_i)/∂q_r(Y) (X_r − c_r), c = X.mid()
        unless given (any float points) and Y ∋ (x + c)/2 — exact for R b_i, quadratic in q
        (docs/soundness.md §8).  ``parts`` (quaternion): also R b_i at c and the derivatives over Y
        (midpoints and radii, (N, 4, legs, dim) each), which ``slope`` at the same c reuses (they
        depend only on the rotation part of X and c).  ``form``: ``centred_form(X)``, if known
        (c = X.mid())."""
        if rb is None:
            rb = self.rotated(self.rotation(X))
        if self.kind == "planar-3rpr":
            return rb
        if c is None:
            lo, hi, cm, cr, Dm, Dr = self.centred_form(X) if form is None else form
        else:
            lo, hi, cm, cr, Dm, Dr = self._centred_form_at(X, c)
        with np.errstate(invalid="ignore"):
            out = Interval._raw(np.fmax(rb.lo, lo), np.fmin(rb.hi, hi))   # NaN (non-finite input): natural
        if not parts:
            return out
        return out, _from_midrad(cm, cr), (Dm, Dr)

    def centred_form(self, X: Interval):
        """Quaternion: (lo, hi, cm, cr, Dm, Dr): the centred form of R b_i over the boxes X around
        their midpoints c = X.mid(), [lo, hi] (N, legs, dim), with R b_i(c) in [cm ± cr] and the
        derivatives over Y ∋ (x + c)/2 in [Dm ± Dr] (N, 4, legs, dim) (``rotated_centred``)."""
        from intervals.linalg import _upper
        c = X.mid()
        p = self.n_pos
        cm, cr, Dm, Dr = self._centre_parts(X, c)
        with np.errstate(invalid="ignore", over="ignore"):
            # c = X.mid(): X_r − c_r ⊆ [−h_r, h_r], so Σ_r ∂(R b_i)/∂q_r(Y) (X_r − c_r) ⊆ ±Σ_r (|Dm_r| + Dr_r) h_r,
            # and R b_i(c) + that lies in [cm ± (cr + Σ_r (|Dm_r| + Dr_r) h_r)], whose float radius
            # (non-negative terms, at most 8 roundings) is bounded by ``_upper``
            h = np.maximum(up_sum(c[:, p:] - X.lo[:, p:]), up_sum(X.hi[:, p:] - c[:, p:]))      # (N, 4)
            rad = _upper(cr + np.add.reduce((np.abs(Dm) + Dr) * h[:, :, None, None], axis=1), 8)
            lo, hi = down(cm - rad), up(cm + rad)
        return lo, hi, cm, cr, Dm, Dr

    def _centre_parts(self, X: Interval, c: np.ndarray):
        """R b_i at the points c in midpoint-radius form [cm ± cr] (N, legs, dim) and its quaternion
        derivatives over Y ∋ (x + c)/2, x ∈ X, in [Dm ± Dr] (N, 4, legs, dim)."""
        cm, cr = self.rotated_midrad(self.rotation_at_points(c))
        with np.errstate(invalid="ignore", over="ignore"):
            Y = Interval._raw(down(0.5 * down_sum(X.lo + c)), up(0.5 * up_sum(X.hi + c)))
            Dm, Dr = self._rotated_derivatives_midrad(Y)
        return cm, cr, Dm, Dr

    def _centred_form_at(self, X: Interval, c: np.ndarray):
        """``centred_form`` around any float points c in the boxes."""
        from intervals.linalg import _ETA, _U, _upper, midrad
        p = self.n_pos
        cm, cr, Dm, Dr = self._centre_parts(X, c)
        with np.errstate(invalid="ignore", over="ignore"):
            # any c: X_r − c_r in [em ± er]; the five-term sum cm + Σ_r Dm_r em_r is within
            # γ_5 (|cm| + Σ_r |Dm_r em_r|) + 5·2⁻¹⁰²² of its float value (Higham 2002, eq. 3.5), the exact
            # radius cr + Σ_r |Dm_r| er_r + Dr_r (|em_r| + er_r) is evaluated in floats and bounded by
            # ``_upper`` (at most 40 roundings)
            em, er = midrad(down_sum(X.lo[:, p:] - c[:, p:]), up_sum(X.hi[:, p:] - c[:, p:]))
            em, er = em[:, :, None, None], er[:, :, None, None]
            t = Dm * em
            mid = cm + np.add.reduce(t, axis=1)
            rad = np.add.reduce(np.abs(Dm) * er + Dr * (np.abs(em) + er), axis=1)
            mag = np.abs(cm) + np.add.reduce(np.abs(t), axis=1)
            rad = _upper(cr + rad + 6.0 * _U * mag, 40) + 5 * _ETA
            lo, hi = down(mid - rad), up(mid + rad)
        return lo, hi, cm, cr, Dm, Dr

    def slope(self, X: Interval, c: np.ndarray, rb: Interval | None = None, rbc: Interval | None = None,
              drbs: list | None = None) -> Interval:
        """Enclosure of slope matrices of the equations at the points ``c`` (N, n) in the boxes X:
        (N, n, n) holding, for every x in X, a matrix S with f(x) − f(c) = S (x − c) (``rb``,
        ``rbc``, ``drbs``: R b_i over X, at c and its derivatives over Y below, if known).

        R b_i is quadratic in the rotation unknowns (linear in (c, s)), so R b_i(x) − R b_i(c) =
        ∇(R b_i)(y) (x − c) exactly at y = (x + c)/2; with ell = p + R b_i − a_i,
        ell_k(x)² − ell_k(c)² = (ell_k(x) + ell_k(c)) (ell_k(x) − ell_k(c)).  Hence row i is
        Σ_k (ell_ik(X) + ell_ik(c)) [e_k, ∇(R b_i)_k(Y)] with Y ∋ (x + c)/2, and the norm row is
        (X_r + c_r) over the rotation unknowns r: about half as wide as the Jacobian over X
        (docs/soundness.md §8, slopes).
        """
        N = X.shape[0]
        p = self.n_pos
        point = Interval._raw(c, c.copy())
        if rb is None:
            rb = self.rotated(self.rotation(X))
        if rbc is None:
            rbc = self.rotated_at_points(c)
        ell = rb - self.a[None, :, :]
        ellc = rbc - self.a[None, :, :]
        if p:
            ell = ell + X[:, None, :p]
            ellc = ellc + point[:, None, :p]
        s = ell + ellc                                        # (N, legs, dim)
        with np.errstate(invalid="ignore", over="ignore"):
            Y = Interval._raw(down(0.5 * down_sum(X.lo + c)), up(0.5 * up_sum(X.hi + c)))  # ∋ (x + c)/2
        S = Interval._raw(np.zeros((N, self.n, self.n)), np.zeros((N, self.n, self.n)))
        legs = self.legs
        for k in range(p):
            S[:, :legs, k] = s[..., k]
        if self.kind != "planar-3rpr":
            # quaternion: Σ_k s_k ∂(R b_i)_k/∂q_r(Y), interval products and sums, the 4 unknowns at once
            Dm, Dr = self._rotated_derivatives_midrad(Y) if drbs is None else drbs   # (N, 4, legs, dim)
            D = _from_midrad(Dm, Dr)
            s4 = Interval._raw(s.lo[:, None], s.hi[:, None])
            col = s4[..., 0] * D[..., 0]
            for k in range(1, D.shape[-1]):
                col = col + s4[..., k] * D[..., k]                                 # (N, 4, legs)
            S.lo[:, :legs, p:] = np.swapaxes(col.lo, 1, 2)
            S.hi[:, :legs, p:] = np.swapaxes(col.hi, 1, 2)
        else:
            if drbs is None:
                drbs = self._rotated_derivatives(Y)
            for r, drb in enumerate(drbs):                      # ∂(R b_i)_k / ∂r over Y: (N, legs, dim)
                col = s[..., 0] * drb[..., 0]
                for k in range(1, drb.shape[-1]):
                    col = col + s[..., k] * drb[..., k]
                S[:, :legs, p + r] = col
        for k in range(p, self.n):
            S[:, legs, k] = X[:, k] + point[:, k]
        return S

    def _rotated_derivatives(self, X: Interval):
        """∂(R b_i)/∂r over the boxes for each rotation unknown r: a list of (N, legs, dim).

        Quaternion: ∂(R b_i)_k/∂q_r = Σ_s G[s, r, i, k] q_s is linear in q, each q_s once
        (``_quaternion_tables``), so its range over the box is mid ± radius, enclosed in
        midpoint-radius arithmetic (``linalg.product_midrad``: one float matrix product and a
        proved rounding bound).  Planar: constant matrices, ``rotated`` of ``_rotation_derivatives``."""
        if self.kind == "planar-3rpr":
            return [self.rotated(dR) for dR in self._rotation_derivatives(X)]
        return self._derivatives_from_midrad(*self._rotated_derivatives_midrad(X))

    def _rotated_derivatives_midrad(self, X: Interval):
        """Quaternion: (m, r), (N, 4, legs, dim): ∂(R b_i)_k/∂q_r over the boxes lies in [m ± r]
        (``linalg.product_midrad``; rows with a non-finite input: m = 0, r = ∞)."""
        from intervals.linalg import midrad, product_midrad
        Gm, Gr = self._quaternion_tables()
        p = self.n_pos
        N = X.shape[0]
        with np.errstate(invalid="ignore", over="ignore"):
            qm, qr = midrad(X.lo[:, p:], X.hi[:, p:])
            m, r = product_midrad(qm, qr, Gm, Gr)                        # (N, 4 legs dim)
            bad = ~(np.isfinite(m) & np.isfinite(r))
        if bad.any():
            m, r = np.where(bad, 0.0, m), np.where(bad, np.inf, r)
        shape = (N, 4, self.legs, self.b.shape[1])
        return m.reshape(shape), r.reshape(shape)

    def _derivatives_from_midrad(self, m, r):
        """The list of the 4 derivative enclosures (N, legs, dim) from (m, r) (N, 4, legs, dim)."""
        D = _from_midrad(m, r)
        return [Interval._raw(D.lo[:, k], D.hi[:, k]) for k in range(4)]

    def _quaternion_tables(self):
        """(Gm, Gr), (4, 4 legs dim): ∂(R b_i)_k/∂q_r = Σ_s G[s, r, i, k] q_s with G in [Gm ± Gr].
        Each row of dR/dq_r (``_rotation_derivatives``) holds distinct unknowns, so each entry is
        c b_ij for one j, c in {±2, ±4}: a scaling by a power of two, exact on the enclosure of b_ij."""
        tables = self.__dict__.get("_quaternion_tables_")
        if tables is None:
            from intervals.linalg import midrad
            bm, br = midrad(self.b.lo, self.b.hi)                          # (legs, dim)
            legs, dim = bm.shape
            Gm, Gr = np.zeros((4, 4, legs, dim)), np.zeros((4, 4, legs, dim))
            coef = np.array([0.0, 2.0, 2.0, 2.0, 2.0, -2.0, -2.0, -2.0, -2.0, -4.0, -4.0, -4.0, -4.0])
            var = np.array([-1, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3])
            for r in range(4):
                for k in range(3):
                    for j in range(3):
                        t = _DQ_INDEX[r, k, j]
                        if t:
                            Gm[var[t], r, :, k] += coef[t] * bm[:, j]
                            Gr[var[t], r, :, k] += abs(coef[t]) * br[:, j]
            tables = self._quaternion_tables_ = (Gm.reshape(4, -1), Gr.reshape(4, -1))
        return tables

    def _rotation_derivatives(self, X: Interval):
        """dR/dr for each rotation unknown r (each (N, dim, dim); linear in the unknowns)."""
        N = X.shape[0]
        if self.kind == "planar-3rpr":
            one = Interval._raw(np.ones(N), np.ones(N))
            zero = Interval._raw(np.zeros(N), np.zeros(N))
            return [_cat([_cat([one, zero]), _cat([zero, one])], axis=-2),        # d/dc
                    _cat([_cat([zero, -one]), _cat([one, zero])], axis=-2)]       # d/ds
        p = self.n_pos
        q0, q1, q2, q3 = (2.0 * X[:, p + k] for k in range(4))  # 2 q_k (exact scaling)
        z = Interval._raw(np.zeros(N), np.zeros(N))
        m = lambda rows: _cat([_cat(r) for r in rows], axis=-2)  # noqa: E731
        return [m([[z, -q3, q2], [q3, z, -q1], [-q2, q1, z]]),
                m([[z, q2, q3], [q2, -2.0 * q1, -q0], [q3, q0, -2.0 * q1]]),
                m([[-2.0 * q2, q1, q0], [q1, z, q3], [-q0, q3, -2.0 * q2]]),
                m([[-2.0 * q3, -q0, q1], [q0, -2.0 * q3, q2], [q1, q2, z]])]

    # ----- the position is linear given the rotation ----------------------------
    def position_system(self, X: Interval, L: Interval, R: Interval | None = None, rb: Interval | None = None):
        """(D, g): the differences of leg equations, D p = g, D (N, legs−1, n_pos), g (N, legs−1)."""
        if rb is None:
            rb = self.rotated(self.rotation(X) if R is None else R)   # (N, legs, dim)
        a = self.a[None, :, :]
        D = 2.0 * ((rb[:, 1:, :] - rb[:, :1, :]) - (a[:, 1:, :] - a[:, :1, :]))
        arb = a * rb
        arb_sum = arb[..., 0]
        for k in range(1, arb.shape[-1]):
            arb_sum = arb_sum + arb[..., k]                   # a_i · R b_i  (N, legs)
        const = (self.norm_a2 + self.norm_b2)[None, :]        # |a_i|² + |b_i|²
        rhs = 2.0 * (arb_sum[:, 1:] - arb_sum[:, :1]) - (const[:, 1:] - const[:, :1]) + (L[:, 1:] - L[:, :1])
        return D, rhs

    # ----- the domain holding every real posture ---------------------------------
    def domain(self, lengths: Interval) -> tuple[np.ndarray, np.ndarray]:
        """Boxes of unknowns holding every real posture of each instance: (M, n) each.

        Rotation unknowns in [−1, 1] (q0 in [−δ, 1]); the origin satisfies
        |p − a_i| ≤ ρ_i + |b_i| for every leg, so it lies in the intersection of
        those boxes (outward rounded).  An empty intersection means no posture:
        the box is then returned with lo > hi in some coordinate.
        """
        M = lengths.shape[0]
        lo = np.empty((M, self.n))
        hi = np.empty((M, self.n))
        p = self.n_pos
        lo[:, p:], hi[:, p:] = -1.0, 1.0
        if self.kind != "planar-3rpr":
            lo[:, p] = -DELTA
        if p:
            reach = lengths + sqrt(self.norm_b2)[None, :]    # (M, legs)
            for k in range(p):
                a = self.a[:, k][None, :]
                lo[:, k] = np.max((a - reach).lo, axis=1)
                hi[:, k] = np.min((a + reach).hi, axis=1)
        return lo, hi

    # ----- poses and points -------------------------------------------------------
    def points(self, X: Interval) -> Interval:
        """World coordinates of the platform joints over the boxes: (N, legs, dim)."""
        rb = self.rotated(self.rotation(X))
        return rb + X[:, None, :self.n_pos] if self.n_pos else rb

    def pose(self, X: Interval) -> dict:
        """Enclosures of the pose variables (dict name -> (N,) Interval).

        Angles come from entries of R with a rigorous atan2; they are wide
        near a parametrisation singularity (theta = 0 for Gough, phi2 = 0 for
        spherical) where ``platform_points`` stay tight.
        """
        if self.kind == "planar-3rpr":
            return {"x": X[:, 0], "y": X[:, 1], "phi": atan2(X[:, 3], X[:, 2])}
        R = self.rotation(X)
        e = lambda i, j: R[:, i, j]  # noqa: E731
        out = {}
        if self.kind == "gough-stewart":
            # R = Rz(psi) Rx(theta) Rz(phi): R33 = cos theta, (R13, R23) = sin theta (sin psi, −cos psi),
            # (R31, R32) = sin theta (sin phi, cos phi)
            out.update({"x": X[:, 0], "y": X[:, 1], "z": X[:, 2]})
            out["psi"] = atan2(e(0, 2), -e(1, 2))
            out["theta"] = atan2(sqrt(sqr(e(0, 2)) + sqr(e(1, 2))), e(2, 2))
            out["phi"] = atan2(e(2, 0), e(2, 1))
        else:
            # Q = Rz(phi1) Ry(phi2) Rz(phi3): Q33 = cos phi2, (Q13, Q23) = sin phi2 (cos phi1, sin phi1),
            # (Q31, Q32) = sin phi2 (−cos phi3, sin phi3)
            out["phi1"] = atan2(e(1, 2), e(0, 2))
            out["phi2"] = atan2(sqrt(sqr(e(0, 2)) + sqr(e(1, 2))), e(2, 2))
            out["phi3"] = atan2(e(2, 1), -e(2, 0))
        return out

    def unknowns_of_pose(self, pose) -> np.ndarray:
        """Float unknowns of float poses (..., d) (not certified: for guesses and tests)."""
        pose = np.asarray(pose, dtype=np.float64)
        if self.kind == "planar-3rpr":
            return np.stack([pose[..., 0], pose[..., 1], np.cos(pose[..., 2]), np.sin(pose[..., 2])], -1)
        from .spherical import rotation_float
        q = quaternion_float(rotation_float(self.kind, pose))
        return np.concatenate([pose[..., :3], q], -1) if self.n_pos else q

    # ----- float evaluation (guesses only: Newton iterates and box sizes, never proofs) ----
    def float_geometry(self):
        """(a, b): float midpoints of the base and platform point enclosures, computed once."""
        geometry = self.__dict__.get("_float_geometry")
        if geometry is None:
            geometry = self._float_geometry = (self.a.mid(), self.b.mid())
        return geometry

    def _rotation_float(self, x) -> np.ndarray:
        """R at float unknowns ``x`` (..., n): (..., dim, dim) (no enclosure by itself; each quaternion
        entry is a float dot product of length at most three with exact factors 2, the form whose
        rounding error ``rotation_at_points`` bounds)."""
        x = np.asarray(x, dtype=np.float64)
        if self.kind == "planar-3rpr":
            c, s = x[..., 2], x[..., 3]
            return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
        q0, q1, q2, q3 = (x[..., self.n_pos + k] for k in range(4))
        rows = [[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
                [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]]
        return np.stack([np.stack(r, -1) for r in rows], -2)

    def _float_tables(self):
        """(c0, D0, H) with R(u) b_i = c0_i + D0_i u + ½ uᵀ H_i u for the rotation unknowns u
        (R is at most quadratic in u): d(R b_i)/du = D0_i + H_i u.  Float midpoints, computed once."""
        tables = self.__dict__.get("_float_tables_")
        if tables is None:
            a, b = self.float_geometry()
            r = self.n - self.n_pos
            x = np.zeros((r + 1, self.n))
            x[1:, self.n_pos:] = np.eye(r)                                  # u = 0, e_1, ..., e_r
            rb = b @ np.swapaxes(self._rotation_float(x[:1]), -1, -2)          # (1, legs, dim)
            d = np.moveaxis(b @ np.swapaxes(self._rotation_derivatives_float(x), -1, -2), 1, -1)  # (r+1, legs, dim, r)
            D0 = d[0]
            H = np.moveaxis(d[1:] - D0, 0, -1)                                 # (legs, dim, r, r)
            tables = self._float_tables_ = (rb[0], D0, H)
        return tables

    def float_system(self, x, L2):
        """(f, J): the n equations and their Jacobian at float unknowns ``x`` (..., n), squared leg
        lengths ``L2`` (..., legs) — floats, not certified (Newton guesses, box sizes)."""
        a, _ = self.float_geometry()
        c0, D0, H = self._float_tables()
        x = np.asarray(x, dtype=np.float64)
        p, legs, r = self.n_pos, self.legs, self.n - self.n_pos
        lead = x.shape[:-1]
        dim = c0.shape[-1]
        u = x[..., p:]
        uu = (u[..., :, None] * u[..., None, :]).reshape(lead + (r * r,))
        # plain 2-D matrix products (numpy's stacked products of tiny matrices are slow)
        ell = ((c0 - a).reshape(-1) + u @ D0.reshape(-1, r).T + uu @ (0.5 * H).reshape(-1, r * r).T
               ).reshape(lead + (legs, dim))                                 # p + R b_i − a_i, less p
        if p:
            ell = ell + x[..., None, :p]
        dRb = D0 + (u @ H.reshape(-1, r).T).reshape(lead + (legs, dim, r))    # d(R b_i)/du
        f = np.empty(x.shape)
        f[..., :legs] = np.add.reduce(ell * ell, -1) - L2
        f[..., legs] = np.add.reduce(u * u, -1) - 1.0
        J = np.zeros(lead + (self.n, self.n))
        J[..., :legs, :p] = 2.0 * ell[..., :p]
        J[..., :legs, p:] = np.add.reduce((2.0 * ell)[..., None] * dRb, -2)
        J[..., legs, p:] = 2.0 * u
        return f, J

    def _rotation_derivatives_float(self, x) -> np.ndarray:
        """dR/dr for each rotation unknown r at float unknowns: (..., r, dim, dim)."""
        if self.kind == "planar-3rpr":
            d = np.array([[[1.0, 0.0], [0.0, 1.0]], [[0.0, -1.0], [1.0, 0.0]]])
            return np.broadcast_to(d, x.shape[:-1] + d.shape)
        q = 2.0 * x[..., self.n_pos:]
        cand = np.concatenate([np.zeros(x.shape[:-1] + (1,)), q, -q, -2.0 * q], -1)
        return cand[..., _DQ_INDEX]


# dR/dq_r of the quaternion rotation (see FKSystem._rotation_derivatives) as indices into
# [0, 2q0..2q3, -2q0..-2q3, -4q0..-4q3]
_DQ_INDEX = np.array([[[0, 8, 3], [4, 0, 6], [7, 2, 0]],
                      [[0, 3, 4], [3, 10, 5], [4, 1, 10]],
                      [[11, 2, 1], [2, 0, 4], [5, 4, 11]],
                      [[12, 5, 2], [1, 12, 3], [2, 3, 0]]])


# the entries of the quaternion rotation R(q) (module docstring), quaternion indices 0..3:
# R_kj = 2(q_a q_b + σ q_c q_d) off the diagonal: ((k, j), (a, b), (c, d), σ)
OFF_DIAGONAL = (((0, 1), (1, 2), (0, 3), -1), ((1, 0), (1, 2), (0, 3), 1),
                ((0, 2), (1, 3), (0, 2), 1), ((2, 0), (1, 3), (0, 2), -1),
                ((1, 2), (2, 3), (0, 1), -1), ((2, 1), (2, 3), (0, 1), 1))
DIAGONAL = ((0, 2, 3), (1, 1, 3), (2, 1, 2))     # R_kk = 1 − 2(q_a² + q_b²): (k, a, b)


def _from_midrad(m, r) -> Interval:
    """[m ± r] outward rounded (an infinite r gives the entire line)."""
    with np.errstate(invalid="ignore", over="ignore"):
        lo, hi = down(m - r), up(m + r)
    bad = np.isnan(lo)
    if bad.any():
        lo = np.where(bad, -np.inf, lo)
    bad = np.isnan(hi)
    if bad.any():
        hi = np.where(bad, np.inf, hi)
    return Interval._raw(lo, hi)


def _sum2(v: Interval) -> Interval:
    return v[..., 0] + v[..., 1]


def _sum3(v: Interval) -> Interval:
    return v[..., 0] + v[..., 1] + v[..., 2]


def quaternion_float(R) -> np.ndarray:
    """Unit quaternions (q0 >= 0) of rotation matrices (..., 3, 3) (floats, not certified)."""
    R = np.asarray(R, dtype=np.float64)
    tr = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    cand = np.stack([1 + tr, 1 + R[..., 0, 0] - R[..., 1, 1] - R[..., 2, 2],
                     1 - R[..., 0, 0] + R[..., 1, 1] - R[..., 2, 2], 1 - R[..., 0, 0] - R[..., 1, 1] + R[..., 2, 2]], -1)
    k = np.argmax(cand, axis=-1)
    q = np.zeros(R.shape[:-2] + (4,))
    big = np.sqrt(np.take_along_axis(cand, k[..., None], -1)[..., 0]) / 2
    # off-diagonal combinations: 4 q_i q_j
    s01 = (R[..., 2, 1] - R[..., 1, 2]) / 4
    s02 = (R[..., 0, 2] - R[..., 2, 0]) / 4
    s03 = (R[..., 1, 0] - R[..., 0, 1]) / 4
    s12 = (R[..., 0, 1] + R[..., 1, 0]) / 4
    s13 = (R[..., 0, 2] + R[..., 2, 0]) / 4
    s23 = (R[..., 1, 2] + R[..., 2, 1]) / 4
    table = {0: (s01, s02, s03), 1: (s01, s12, s13), 2: (s02, s12, s23), 3: (s03, s13, s23)}
    for i in range(4):
        sel = k == i
        others = [j for j in range(4) if j != i]
        q[..., i] = np.where(sel, big, q[..., i])
        for j, sij in zip(others, table[i]):
            q[..., j] = np.where(sel, sij / np.where(big > 0, big, 1.0), q[..., j])
    q = np.where(q[..., :1] < 0, -q, q)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)
