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
``q0 ∈ [−δ, 1 + ε]`` (δ = ε = 2⁻¹⁰) holds a representative of every rotation
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

from intervals import Interval, atan2, pi, sqr, sqrt

from ..robots.spherical import rotation_float
from .rotation import DQ_INDEX, RotatedPoints, from_midrad

DELTA = 2.0 ** -10      # q0 >= -DELTA: the hemisphere with a margin (see the module docstring)
BEYOND = 2.0 ** -10     # the domain reaches this far beyond the unit circle/sphere and the position bounds


def _cat(parts, axis=-1):
    return Interval.from_bounds(np.stack([p.lo for p in parts], axis=axis), np.stack([p.hi for p in parts], axis=axis))


def angle(y: Interval, x: Interval) -> Interval:
    """The angles of the points of the boxes Y × X, modulo 2π: ``atan2`` in (−π, π], except for a
    box crossing the cut (x < 0 and 0 in Y, where atan2 gives [−π, π]): there atan2(−y, −x) + π, an
    enclosure in [π/2, 3π/2] (the angle of (−t, −s) is that of (t, s) minus π)."""
    a = atan2(y, x)
    cut = (x.hi < 0) & (y.lo < 0) & (y.hi >= 0)
    if not np.any(cut):
        return a
    b = atan2(-y, -x) + pi
    return Interval.from_bounds(np.where(cut, b.lo, a.lo), np.where(cut, b.hi, a.hi))


class FKSystem(RotatedPoints):
    """The FK equations of one robot (see the module docstring)."""

    def __init__(self, robot):
        self.robot = robot
        self.kind = robot.kind
        n = robot.n_legs
        dim = robot.dim
        params = robot.parameters
        self.a = Interval.from_bounds(np.array([float(v.lo) for v in params[:n * dim]]).reshape(n, dim),
                               np.array([float(v.hi) for v in params[:n * dim]]).reshape(n, dim))
        self.b = Interval.from_bounds(np.array([float(v.lo) for v in params[n * dim:]]).reshape(n, dim),
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
        self.norm_ab2 = self.norm_a2 + self.norm_b2
        self._memo = {}     # values derived from the geometry by the steps that use them (``memo``)
        self.size = float(max(np.max(np.abs(self.a.hi)), np.max(np.abs(self.b.hi)), 1e-300))  # the robot's scale

    def memo(self, name: str, build):
        """``build()``, computed once per system and geometry: a value derived from the geometry by
        a step that uses this system (shared with the system's stacked twin, ``fk.stacked``)."""
        value = self._memo.get(name)
        if value is None:
            value = self._memo[name] = build()
        return value

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

    def rotated(self, R: Interval) -> Interval:
        """R b_i for every leg: (..., legs, dim) for R (..., dim, dim).

        Planar: interval products and sums.  Quaternion: midpoint-radius form (``rotated_midrad``),
        the same enclosure up to a few units in the last place, in about a third of the operations."""
        if self.kind != "planar-3rpr":
            m, r = self.rotated_midrad(R)
            return from_midrad(m, r)
        b = self.b
        out = R[:, None, :, 0] * b[None, :, 0, None]
        for j in range(1, b.shape[1]):
            out = out + R[:, None, :, j] * b[None, :, j, None]
        return out

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
        return Interval.from_bounds(np.concatenate([legs.lo, norm.lo[:, None]], axis=1),
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
        J = Interval.from_bounds(np.zeros((N, self.n, self.n)), np.zeros((N, self.n, self.n)))
        legs = self.legs
        for k in range(p):
            J[:, :legs, k] = two_ell[..., k]
        # d/dr of sum_k (ell_k)^2 = sum_k 2 ell_k d(R b)_k/dr
        for r, dR in enumerate(self.rotation_derivatives(X)):
            drb = self.rotated(dR)                            # (N, legs, dim)
            col = two_ell[..., 0] * drb[..., 0]
            for k in range(1, drb.shape[-1]):
                col = col + two_ell[..., k] * drb[..., k]
            J[:, :legs, p + r] = col
        for k in range(p, self.n):
            J[:, legs, k] = 2.0 * X[:, k]
        return J

    def rotation_derivatives(self, X: Interval):
        """dR/dr for each rotation unknown r (each (N, dim, dim); linear in the unknowns)."""
        N = X.shape[0]
        if self.kind == "planar-3rpr":
            one = Interval.from_bounds(np.ones(N), np.ones(N))
            zero = Interval.from_bounds(np.zeros(N), np.zeros(N))
            return [_cat([_cat([one, zero]), _cat([zero, one])], axis=-2),        # d/dc
                    _cat([_cat([zero, -one]), _cat([one, zero])], axis=-2)]       # d/ds
        p = self.n_pos
        q0, q1, q2, q3 = (2.0 * X[:, p + k] for k in range(4))  # 2 q_k (exact scaling)
        z = Interval.from_bounds(np.zeros(N), np.zeros(N))
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

        Rotation unknowns in [−1 − ε, 1 + ε] (q0 in [−δ, 1 + ε]), ε = ``BEYOND``; the origin
        satisfies |p − a_i| ≤ ρ_i + |b_i| for every leg, so it lies in the intersection of those
        boxes (outward rounded), widened by ε of its width.  The margin keeps every root off the
        faces: the norm equation holds the rotation unknowns on the unit circle/sphere, whose points
        c = 1 (phi = 0) and q = (1, 0, 0, 0) (the identity, the home pose of most robots) would
        otherwise lie on a face, where no root box fits inside the domain.  An empty intersection
        means no posture: the box is then returned with lo > hi in some coordinate (the widening
        keeps it empty).
        """
        M = lengths.shape[0]
        lo = np.empty((M, self.n))
        hi = np.empty((M, self.n))
        p = self.n_pos
        lo[:, p:], hi[:, p:] = -1.0 - BEYOND, 1.0 + BEYOND
        if self.kind != "planar-3rpr":
            lo[:, p] = -DELTA
        if p:
            reach = lengths + sqrt(self.norm_b2)[None, :]    # (M, legs)
            for k in range(p):
                a = self.a[:, k][None, :]
                lo[:, k] = np.max((a - reach).lo, axis=1)
                hi[:, k] = np.min((a + reach).hi, axis=1)
            w = np.maximum(hi[:, :p] - lo[:, :p], 0.0) * BEYOND     # (lo − w, hi + w rounded: still outside)
            lo[:, :p] -= w
            hi[:, :p] += w
        return lo, hi

    # ----- poses and points -------------------------------------------------------
    def points(self, X: Interval) -> Interval:
        """World coordinates of the platform joints over the boxes: (N, legs, dim)."""
        rb = self.rotated(self.rotation(X))
        return rb + X[:, None, :self.n_pos] if self.n_pos else rb

    def pose(self, X: Interval) -> dict:
        """Enclosures of the pose variables (dict name -> (N,) Interval).

        Angles come from entries of R with a rigorous atan2 (``angle``: an angle
        near ±pi is enclosed near pi, never as [-pi, pi]); they are wide near a
        parametrisation singularity (theta = 0 for Gough, phi2 = 0 for
        spherical) where ``platform_points`` stay tight.
        """
        if self.kind == "planar-3rpr":
            return {"x": X[:, 0], "y": X[:, 1], "phi": angle(X[:, 3], X[:, 2])}
        R = self.rotation(X)
        e = lambda i, j: R[:, i, j]  # noqa: E731
        out = {}
        if self.kind == "gough-stewart":
            # R = Rz(psi) Rx(theta) Rz(phi): R33 = cos theta, (R13, R23) = sin theta (sin psi, −cos psi),
            # (R31, R32) = sin theta (sin phi, cos phi)
            out.update({"x": X[:, 0], "y": X[:, 1], "z": X[:, 2]})
            out["psi"] = angle(e(0, 2), -e(1, 2))
            out["theta"] = angle(sqrt(sqr(e(0, 2)) + sqr(e(1, 2))), e(2, 2))
            out["phi"] = angle(e(2, 0), e(2, 1))
        else:
            # Q = Rz(phi1) Ry(phi2) Rz(phi3): Q33 = cos phi2, (Q13, Q23) = sin phi2 (cos phi1, sin phi1),
            # (Q31, Q32) = sin phi2 (−cos phi3, sin phi3)
            out["phi1"] = angle(e(1, 2), e(0, 2))
            out["phi2"] = angle(sqrt(sqr(e(0, 2)) + sqr(e(1, 2))), e(2, 2))
            out["phi3"] = angle(e(2, 1), -e(2, 0))
        return out

    def unknowns_of_pose(self, pose) -> np.ndarray:
        """Float unknowns of float poses (..., d) (not certified: for guesses and tests)."""
        pose = np.asarray(pose, dtype=np.float64)
        if self.kind == "planar-3rpr":
            return np.stack([pose[..., 0], pose[..., 1], np.cos(pose[..., 2]), np.sin(pose[..., 2])], -1)
        q = quaternion_float(rotation_float(self.kind, pose))
        return np.concatenate([pose[..., :3], q], -1) if self.n_pos else q

    # ----- float evaluation (guesses only: Newton iterates and box sizes, never proofs) ----
    def float_geometry(self):
        """(a, b): float midpoints of the base and platform point enclosures, computed once."""
        geometry = self.__dict__.get("_float_geometry")
        if geometry is None:
            geometry = self._float_geometry = (self.a.mid(), self.b.mid())
        return geometry

    def float_rotation(self, x) -> np.ndarray:
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
            rb = b @ np.swapaxes(self.float_rotation(x[:1]), -1, -2)          # (1, legs, dim)
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
        return cand[..., DQ_INDEX]


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


def fk_system(robot):
    """The ``FKSystem`` of a robot, built once per geometry and kept on the robot object.

    The cache is keyed by the robot's kind and exact geometry texts (compared on every call), so a
    robot whose ``base`` or ``platform`` was changed gets a new system built from its current
    geometry (its cached parameter enclosures are dropped first), never a stale one.
    """
    key = (robot.kind, tuple(map(tuple, robot.base)), tuple(map(tuple, robot.platform)))
    cached = robot.__dict__.get("_fk_system")
    if cached is not None and cached[0] == key:
        return cached[1]
    robot.__dict__.pop("parameters", None)      # re-enclose the current geometry texts
    system = FKSystem(robot)
    robot.__dict__["_fk_system"] = (key, system)
    return system
