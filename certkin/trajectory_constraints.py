"""The constraints of a trajectory, as functions of the pose, bounded over sub-intervals of t.

Seed 000 §1.3 lists the constraints; the digest's corrections are applied
(E4: ρ² is convex, so ρ can have an interior minimum; E9/E10: the corrected
line-distance polynomial; E12: the exact segment-to-segment distance):

- ``leg-length``: ρ_min ≤ ρ_i ≤ ρ_max; margin min(ρ_i − ρ_min, ρ_max − ρ_i) (length unit);
- ``joints``: the leg direction inside each passive joint's pyramid (n·u ≥ 0 for every
  facet normal n) or cone (angle(u, axis) ≤ half-angle); base joints use u = B_i − A_i in
  the base frame, platform joints u = Rᵀ(A_i − B_i) in the platform frame; margin n̂·û
  (pyramid facet) or cos(angle(u, axis)) − cos(half-angle) (cone), dimensionless;
- ``interference``: the distance between the leg axes (segments [A_i, B_i]) at least
  r_i + r_j; margin d_ij − r_i − r_j (length unit);
- ``singularity``: det(A) ≠ 0 (its sign is decided box by box; the path is free of
  singularities when every box has the same sign).

Every quantity is a polynomial (or, for the determinant, a Laplace expansion) in the
pose, written once with sympy and compiled by ``intervals.compiler``.  Along a segment
pose(t) = P + t D, so on a t-interval T each quantity g is enclosed from

- its natural enclosure on pose(T) with its derivative dg/dt (``autodiff.Dual``),
- its values at the end points and the midpoint m of T (thin pose intervals):

the range is hull(g(lo), g(hi)) when dg/dt has one sign on T, otherwise the mean-value
form g(m) + g'(T)(T − m) ∩ g(T) (the mean-value theorem, exact: no truncated Taylor
expansion).  ``docs/soundness.md`` gives the argument for the segment distance.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
import itertools
from math import factorial

import numpy as np

from intervals import Interval, cos, sqr, sqrt, stack
from intervals.autodiff import Dual
from intervals.linalg import laplace_det
from intervals.polynomial import Poly, bernstein_weights, degree_limit, padded, ratio_range
from intervals.interval import mul
from intervals.rounding import down, down_sum, sum_bounds, up, up_sum

from .errors import InputError
from .robots.base import parse_number

KINDS = ("leg-length", "joints", "interference", "singularity")
SATISFIED, VIOLATED, UNKNOWN = 1, -1, 0
PIECE_DEGREES = (6, 8)   # degrees tried for the per-piece polynomials of a moving orientation (products truncated)
PIECE_TRUNCATION = 2.0 ** -40   # wanted size of a truncated term, relative: (angle change per piece)^(d+1)/(d+1)!


def piece_plan(angle_step: float, least: int = 4, most: int = 64) -> tuple[int, int]:
    """(pieces per segment, degree) for a moving orientation whose angles change by at most
    ``angle_step`` (radians) along a segment: the cheapest (pieces · (degree + 1)²) power-of-two
    count of pieces in [least, most] with (angle_step / pieces)^(degree+1)/(degree+1)! below
    ``PIECE_TRUNCATION``, so that the terms the truncation folds away stay negligible.  Any plan
    is sound (the folded terms are enclosed); this one keeps the enclosures tight."""
    plans = []
    for d in PIECE_DEGREES:
        reach = (PIECE_TRUNCATION * factorial(d + 1)) ** (1.0 / (d + 1))      # angle change per piece allowed
        pieces = least
        while pieces < most and angle_step / pieces > reach:
            pieces *= 2
        plans.append((pieces * (d + 1) ** 2, pieces, d))
    _, pieces, d = min(plans)
    return pieces, d


@dataclass(frozen=True)
class Instance:
    """One scalar constraint: its kind, the legs it concerns and a short detail."""

    constraint: str
    legs: tuple
    detail: str = ""

    def to_json(self) -> dict:
        d = {"constraint": self.constraint, "legs": list(self.legs)}
        if self.detail:
            d["detail"] = self.detail
        return d


def _cached(robot, key, build):
    """Per-robot data derived from its geometry and limits, built once per value of the limits
    (the geometry does not change after loading; the limits are a plain dict a caller may edit)."""
    cache = robot.__dict__.setdefault("_trajectory_cache", {})
    key = (key, repr(robot.limits))
    if key not in cache:
        cache[key] = build()
    return cache[key]


def _enclose_all(values) -> Interval:
    return Interval._raw(np.array([float(v.lo) for v in values]), np.array([float(v.hi) for v in values]))


def _cols(x, idx):
    """Columns ``idx`` of an (M, n) Interval or Dual."""
    if isinstance(x, Dual):
        return Dual(x.value[:, idx], x.grad[:, idx, :])
    return x[:, idx]


def _stack(items):
    """(M,) values -> (M, n)."""
    if isinstance(items[0], Dual):
        return Dual(stack([i.value for i in items], axis=-1), stack([i.grad for i in items], axis=-2))
    return stack(items, axis=-1)


def _dot(a, b):
    """a · b for 3-vectors given as component lists (Poly components: one stacked product)."""
    if isinstance(a[0], Poly) and all(isinstance(x, (Poly, Interval)) for x in (*a, *b)):
        return (_vector(a) * _vector(b)).sum(axis=-1)
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    """a × b for 3-vectors given as component lists (Poly components: two stacked products)."""
    if isinstance(a[0], Poly) and all(isinstance(x, (Poly, Interval)) for x in (*a, *b)):
        A, B = _vector(a), _vector(b)
        first, second = [1, 2, 0], [2, 0, 1]
        c = A[(slice(None),) * (A.ndim - 1) + (first,)] * B[(slice(None),) * (B.ndim - 1) + (second,)] \
            - A[(slice(None),) * (A.ndim - 1) + (second,)] * B[(slice(None),) * (B.ndim - 1) + (first,)]
        return [c[(slice(None),) * (c.ndim - 1) + (k,)] for k in range(3)]
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _vector(components) -> Poly:
    """Three Poly (or Interval) components stacked on a last batch axis, one common degree."""
    polys = [x if isinstance(x, Poly) else Poly.from_coefficients([x]) for x in components]
    n = max(p.degree for p in polys)
    shape = np.broadcast_shapes(*(p.shape for p in polys))
    lo = np.stack([np.broadcast_to(padded(p.lo, n), shape + (n + 1,)) for p in polys], -2)
    hi = np.stack([np.broadcast_to(padded(p.hi, n), shape + (n + 1,)) for p in polys], -2)
    return Poly(lo, hi)


def _stacked(polys, axis) -> Poly:
    """Polynomials of one batch shape stacked on a new batch ``axis``, padded to one degree."""
    n = max(p.degree for p in polys)
    axis = axis if axis >= 0 else axis - 1
    return Poly(np.stack([padded(p.lo, n) for p in polys], axis), np.stack([padded(p.hi, n) for p in polys], axis))


def _sub(a, b):
    return [x - y for x, y in zip(a, b)]


class _Pose:
    """Leg vectors (and R) along the path, as (M, n) components: Duals over T or thin intervals."""

    def __init__(self, outputs, n, M, with_R):
        like = next((o for o in outputs if isinstance(o, Dual)), None)
        fixed = []
        for o in outputs:
            if like is not None and not isinstance(o, Dual):
                o = like._lift(o if isinstance(o, Interval) else Interval(o))
            if isinstance(o, Dual):
                shape = (M,)
                o = Dual(Interval._raw(np.broadcast_to(o.value.lo, shape), np.broadcast_to(o.value.hi, shape)),
                         Interval._raw(np.broadcast_to(o.grad.lo, shape + (1,)), np.broadcast_to(o.grad.hi, shape + (1,))))
            else:
                o = o if isinstance(o, Interval) else Interval(o)
                o = Interval._raw(np.broadcast_to(o.lo, (M,)), np.broadcast_to(o.hi, (M,)))
            fixed.append(o)
        self.legs = [_stack([fixed[3 * i + k] for i in range(n)]) for k in range(3)]   # 3 x (M, n)
        self.R = [fixed[3 * n + k] for k in range(9)] if with_R else None             # row-major, (M,)

    @classmethod
    def from_polys(cls, outputs, n, S, with_R):
        """Leg vectors (and R) from polynomial outputs of the compiled model (constants allowed)."""
        polys = [o if isinstance(o, Poly) else Poly.from_coefficients([o]) for o in outputs]
        deg = max(p.degree for p in polys)
        fixed = []
        for p in polys:
            fixed.append(Poly(np.broadcast_to(padded(p.lo, deg), (S, deg + 1)), np.broadcast_to(padded(p.hi, deg), (S, deg + 1))))
        self = cls.__new__(cls)
        self.legs = [Poly(np.stack([fixed[3 * i + k].lo for i in range(n)], 1), np.stack([fixed[3 * i + k].hi for i in range(n)], 1))
                     for k in range(3)]
        self.R = [fixed[3 * n + k] for k in range(9)] if with_R else None
        return self

    @classmethod
    def linear(cls, V, w, R, t: Interval, dual: bool):
        """Constant orientation: l_i(t) = V_i + t w exactly (V (M, n) and w (M,) enclosed per
        row), at the t-intervals ``t`` (M,), as Duals (derivative w) or as intervals."""
        self = cls.__new__(cls)
        self.legs = []
        tc = t[:, None]
        for k in range(3):
            wk = w[k][:, None]
            value = V[k] + tc * wk
            if dual:
                shape = value.shape + (1,)
                g = Interval._raw(np.broadcast_to(wk.lo[..., None], shape), np.broadcast_to(wk.hi[..., None], shape))
                value = Dual(value, g)
            self.legs.append(value)
        self.R = R
        return self

    @classmethod
    def polynomial(cls, V, w, R):
        """Constant orientation: l_i(t) = V_i + t w as polynomials in t (one row per segment)."""
        self = cls.__new__(cls)
        self.legs = []
        for k in range(3):
            shape = V[k].shape
            self.legs.append(Poly(np.stack([V[k].lo, np.broadcast_to(w[k].lo[:, None], shape)], -1),
                                  np.stack([V[k].hi, np.broadcast_to(w[k].hi[:, None], shape)], -1)))
        self.R = R
        return self

    def vector(self) -> Poly:
        """Polynomial legs as one (S, n, 3) Poly (built once)."""
        if getattr(self, "_vector", None) is None:
            self._vector = _stacked(self.legs, 2)
        return self._vector

    def rows(self, idx):
        """The same pose data restricted to the batch rows ``idx``."""
        out = _Pose.__new__(_Pose)
        out.legs = [x[idx] for x in self.legs]
        out.R = None if self.R is None else [r[idx] for r in self.R]
        return out

    def rotate(self, v):
        """R v for constant vectors v (3 arrays of shape (n,)) -> 3 x (M, n)."""
        R = self.R
        return [_stack_rows(R[3 * r], v[0]) + _stack_rows(R[3 * r + 1], v[1]) + _stack_rows(R[3 * r + 2], v[2])
                for r in range(3)]


def _stack_rows(x, v: Interval):
    """x (M,) times v (n,) -> (M, n)."""
    n = v.shape[0]
    if isinstance(x, Poly):
        xv = Poly(np.repeat(x.lo[:, None], n, 1), np.repeat(x.hi[:, None], n, 1))
    elif isinstance(x, Dual):
        xv = Dual(Interval._raw(np.repeat(x.value.lo[:, None], n, 1), np.repeat(x.value.hi[:, None], n, 1)),
                  Interval._raw(np.repeat(x.grad.lo[:, None, :], n, 1), np.repeat(x.grad.hi[:, None, :], n, 1)))
    else:
        xv = Interval._raw(np.repeat(x.lo[:, None], n, 1), np.repeat(x.hi[:, None], n, 1))
    return xv * v


def _gough_det(legs, base, C):
    """det(A) with rows [l_i, (A_i − C) × l_i] (= (R b_i) × l_i, as l_i × l_i = 0), natural
    enclosure by ``intervals.linalg.det`` (LU-preconditioned) over (M,) boxes."""
    from intervals.linalg import det
    arm = [base[k][None, :] - C[k][:, None] for k in range(3)]          # A_i − C, (M, n)
    mom = _cross(arm, legs)
    cols = legs + mom                                                     # 6 x (M, n)
    A = Interval._raw(np.stack([c.lo for c in cols], axis=-1), np.stack([c.hi for c in cols], axis=-1))
    return det(A)


_SUBSETS = np.array(list(itertools.combinations(range(6), 3)))
_COMPLEMENTS = np.array([[i for i in range(6) if i not in S] for S in _SUBSETS])
_SIGNS = np.where((_SUBSETS.sum(axis=1) + 3) % 2 == 0, 1.0, -1.0)


def _det3(X):
    """det of 3 x 3 matrices of polynomials, X indexed [..., row, col] over the batch axes:
    x00 (x11 x22 − x12 x21) − x01 (x10 x22 − x12 x20) + x02 (x10 x21 − x11 x20), the six
    products of the minors in one stacked product and the three of row 0 in another."""
    pre = (slice(None),) * (X.ndim - 2)
    p = X[pre + ([1] * 6, [1, 2, 0, 2, 0, 1])] * X[pre + ([2] * 6, [2, 1, 2, 0, 1, 0])]      # (..., 6)
    minors = p[pre + (slice(0, None, 2),)] - p[pre + (slice(1, None, 2),)]                 # (..., 3)
    t = X[pre + ([0, 0, 0], [0, 1, 2])] * minors
    return t[pre + (0,)] - t[pre + (1,)] + t[pre + (2,)]


def _gough_det_poly(V, w, base, C0):
    """Constant orientation: det(A) as a polynomial in t (degree ≤ 6) per segment.

    Rows [l_i, (A_i − C) × l_i] = [V_i + t w, (A_i − C_0 − t w) × R b_i] with
    R b_i = V_i + A_i − C_0 constant: both blocks are linear in t."""
    shape = V[0].shape
    st = lambda xs, end: np.stack([np.broadcast_to(getattr(x, end), shape) for x in xs], -1)  # noqa: E731
    arm0 = [base[k][None, :] - C0[k][:, None] for k in range(3)]                 # A_i − C_0: (M, 6)
    arm = Interval._raw(st(arm0, "lo"), st(arm0, "hi"))                         # (M, 6, 3)
    wb = Interval._raw(st([w[k][:, None] for k in range(3)], "lo"), st([w[k][:, None] for k in range(3)], "hi"))
    Vs = Interval._raw(st(V, "lo"), st(V, "hi"))
    Rb = Vs + arm                                                                # R b_i = V_i + A_i − C_0
    first, second = [1, 2, 0], [2, 0, 1]
    X = Interval._raw(np.stack([arm.lo, wb.lo]), np.stack([arm.hi, wb.hi]))    # (2, M, 6, 3): arm, w
    m = mul(X[..., first], Rb[..., second]) - mul(X[..., second], Rb[..., first])   # arm × R b_i, w × R b_i
    L = [Poly(np.stack([Vs.lo[..., k], wb.lo[..., k]], -1), np.stack([Vs.hi[..., k], wb.hi[..., k]], -1)) for k in range(3)]
    M = [Poly(np.stack([m.lo[0, ..., k], -m.hi[1, ..., k]], -1), np.stack([m.hi[0, ..., k], -m.lo[1, ..., k]], -1))
         for k in range(3)]
    return _block_det(L, M)


def _block_det(L, M):
    """det of the 6 × 6 matrices with rows [L_i, M_i] (3 + 3 polynomial columns, batch (S, 6)):
    generalised Laplace expansion along the first three columns, det A = Σ_S ε(S) det L[S]
    det M[S^c] over the 20 row triples S, ε(S) = (−1)^(Σ_{i∈S} (i+1) + 6)."""
    n = max(p.degree for p in L + M)
    pad = lambda p: padded(p, n)  # noqa: E731
    lo = np.stack([np.stack([pad(x.lo) for x in L], 2), np.stack([pad(x.lo) for x in M], 2)], 1)   # (S, 2, 6, 3, n+1)
    hi = np.stack([np.stack([pad(x.hi) for x in L], 2), np.stack([pad(x.hi) for x in M], 2)], 1)
    rows = np.stack([_SUBSETS, _COMPLEMENTS])                                             # (2, 20, 3)
    sel = np.arange(2)[:, None, None]
    X = Poly(lo[:, sel, rows], hi[:, sel, rows])                                          # (S, 2, 20, 3, 3)
    d = _det3(X)                                                                          # (S, 2, 20)
    terms = d[:, 0] * d[:, 1]                                                             # (S, 20)
    s = _SIGNS[:, None]
    tlo = np.where(s > 0, terms.lo, -terms.hi)
    thi = np.where(s > 0, terms.hi, -terms.lo)
    return Poly(tlo, thi).sum(axis=1)


class _DetFamily:
    """det(A): the robot's symbolic det, or a Laplace expansion of the compiled entries of A."""

    def __init__(self, robot):
        model = robot.symbolic_model()
        self.robot = robot
        self.laplace = "det" not in model
        self.compiled = robot._compiled("A" if self.laplace else "det")
        self.n, self.d = robot.n_legs, len(robot.pose_names)

    def __call__(self, variables):
        out = self.compiled.evaluate(variables, self.robot.parameters)
        if not self.laplace:
            return out[0]
        return laplace_det([[out[i * self.d + j] for j in range(self.d)] for i in range(self.n)])


class Constraints:
    """The selected constraints of a robot, evaluated on batches of t-intervals."""

    def __init__(self, robot, kinds=None):
        self.robot = robot
        kinds = list(KINDS if kinds is None else kinds)
        for k in kinds:
            if k not in KINDS:
                raise InputError("--constraints", k, f"unknown constraint (known: {', '.join(KINDS)})")
        limits = robot.limits
        n = robot.n_legs
        self.n = n
        self.skipped = {}
        self.instances: list[Instance] = []
        self._cols = {}
        self.vectors = robot._compiled("leg_vectors")
        self.with_R = "R" in robot.symbolic_model()
        self.base = _cached(robot, "base", lambda: [_enclose_all([Interval(p[k]) if k < robot.dim else Interval(0)
                                                                    for p in robot.base]) for k in range(3)])
        self.platform = _cached(robot, "platform", lambda: [_enclose_all([Interval(p[k]) for p in robot.platform])
                                                            for k in range(robot.dim)])
        self.det = None
        if "leg-length" in kinds:
            if "leg_length" in limits:
                self.rho_min = _enclose_all([Interval(a) for a, _ in limits["leg_length"]])
                self.rho_max = _enclose_all([Interval(b) for _, b in limits["leg_length"]])
                self._add("legs", [Instance("leg-length", (i + 1,)) for i in range(n)])
            else:
                self.skipped["leg-length"] = "no [limits] leg_length in the robot file"
        if "joints" in kinds:
            if "base_joints" in limits or "platform_joints" in limits:
                self.facets = _cached(robot, "joints", lambda: _joint_data(robot))
                self._add("joints", [f["instance"] for f in self.facets])
            else:
                self.skipped["joints"] = "no [limits] base_joints or platform_joints in the robot file"
        if "interference" in kinds:
            if "leg_radius" in limits:
                self.pair_list = list(itertools.combinations(range(n), 2))
                radius = [Fraction(r) for r in limits["leg_radius"]]
                self.r = _enclose_all([Interval(radius[i] + radius[j]) for i, j in self.pair_list])
                self.r2 = sqr(self.r)
                I = np.array([i for i, _ in self.pair_list])
                J = np.array([j for _, j in self.pair_list])
                self.I, self.J = I, J
                self.w0 = [self.base[k][I] - self.base[k][J] for k in range(3)]        # A_i − A_j, (P,)
                self._add("pairs", [Instance("interference", (i + 1, j + 1)) for i, j in self.pair_list])
            else:
                self.skipped["interference"] = "no [limits] leg_radius in the robot file"
        if "singularity" in kinds:
            self.det = _cached(robot, "det", lambda: _DetFamily(robot))
            self._add("det", [Instance("singularity", tuple(range(1, n + 1)))])
        self.K = len(self.instances)

    @classmethod
    def of(cls, robot, kinds=None) -> "Constraints":
        """The constraints ``kinds`` of ``robot``, built once per robot, selection and limits."""
        key = ("constraints", None if kinds is None else tuple(kinds))
        return _cached(robot, key, lambda: cls(robot, kinds))

    def _add(self, name, instances):
        start = len(self.instances)
        self.instances.extend(instances)
        self._cols[name] = slice(start, len(self.instances))

    def linear_data(self, P0: Interval, D: Interval):
        """Per segment, when no pose angle moves: V (leg vectors at t = 0), w (the velocity of
        the platform origin) and R, so that l_i(t) = V_i + t w exactly.  None otherwise."""
        robot = self.robot
        angles = [k for k, name in enumerate(robot.pose_names) if name in robot.angle_names]
        if np.any(D.lo[:, angles] != 0) or np.any(D.hi[:, angles] != 0):
            return None
        S = P0.shape[0]
        position = [k for k, name in enumerate(robot.pose_names) if name not in robot.angle_names]
        zero = Interval._raw(np.zeros(S), np.zeros(S))
        w = [D[:, position[k]] if k < len(position) else zero for k in range(3)]
        variables = [P0[:, k] for k in range(P0.shape[1])]
        if robot.rigid_legs():        # l_i = C + R b_i − a_i: R once, then one product for every leg
            R = robot._compiled("R").evaluate(variables, robot.parameters)
            R = [r if isinstance(r, Interval) else Interval(r) for r in R]
            R = [Interval._raw(np.broadcast_to(r.lo, (S,)), np.broadcast_to(r.hi, (S,))) for r in R]
            C = [P0[:, position[k]] if k < len(position) else zero for k in range(3)]
            Rm = Interval._raw(np.stack([r.lo for r in R], -1).reshape(S, 3, 3, 1),
                               np.stack([r.hi for r in R], -1).reshape(S, 3, 3, 1))
            plat, base = self._stacked_points()
            Rb = mul(Rm, plat)                                                    # R_kj b_ij: (S, 3, 3, n)
            lo, hi = sum_bounds(Rb.lo, Rb.hi, axis=2)                              # (R b_i)_k: (S, 3, n)
            Clo = np.stack([c.lo for c in C], -1)[:, :, None]
            Chi = np.stack([c.hi for c in C], -1)[:, :, None]
            lo, hi = down_sum(down_sum(lo + Clo) - base.hi), up_sum(up_sum(hi + Chi) - base.lo)
            V = [Interval._raw(lo[:, k], hi[:, k]) for k in range(3)]
            return {"V": V, "w": w, "R": R if self.with_R else None}
        out = _Pose(self.vectors.evaluate(variables, robot.parameters), self.n, S, self.with_R)
        return {"V": out.legs, "w": w, "R": out.R}

    def _stacked_points(self):
        """The platform points as a (3, n) Interval and the base points as (3, n), built once."""
        if getattr(self, "_points", None) is None:
            self._points = tuple(Interval._raw(np.stack([p[k].lo for k in range(3)]), np.stack([p[k].hi for k in range(3)]))
                                 for p in (self.platform, self.base))
        return self._points

    @staticmethod
    def rows_of(linear, rows):
        if linear is None:
            return None
        take = lambda x: x[rows]  # noqa: E731
        return {"V": [take(v) for v in linear["V"]], "w": [take(v) for v in linear["w"]],
                "R": None if linear["R"] is None else [take(v) for v in linear["R"]]}

    @property
    def det_column(self):
        return self._cols["det"].start if "det" in self._cols else None

    def refinable(self):
        """Columns whose margin is refined to the requested tolerance (all but det)."""
        mask = np.ones(self.K, dtype=bool)
        if "det" in self._cols:
            mask[self._cols["det"]] = False
        return mask

    # ----- the functions of the pose (each returns a list of (M,) or (M, X) values) ------------
    def _legs_sq(self, pose: _Pose):
        L = pose.legs
        if isinstance(L[0], Poly):
            vec = pose.vector()
            return [(vec * vec).sum(axis=-1)]
        return [_dot(L, L)]

    def _joint_functions(self, pose: _Pose):
        """Per facet n·u (base) or −(R n)·l (platform); per cone a·u and (a·u)² − |a|²cos²α |u|²."""
        out = []
        L = [pose.legs[k] for k in range(3)]
        for f in self.facets:
            leg = f["leg"]
            l = [_cols(L[k], [leg]) for k in range(3)]
            vec = f["vector"]                      # 3 Intervals of shape (1,)
            if f["side"] == "platform":
                vec = pose.rotate(vec)
                g = -_dot(vec, l)
            else:
                g = _dot([_bcast(v, l[0]) for v in vec], l)
            out.append(g)
            if f["kind"] == "cone":
                out.append(g * g - f["c2"] * _dot(l, l))
        return out

    def _pair_line_functions(self, pose: _Pose):
        """Per pair: line distance² − r² numerator E, Δ = |u×v|² and the feet numerators
        s, s − Δ, t, t − Δ of the common perpendicular (docs/soundness.md)."""
        L = pose.legs
        if isinstance(L[0], Poly):
            return self._pair_line_polynomials(pose.vector())
        u = [_cols(L[k], self.I) for k in range(3)]
        v = [_cols(L[k], self.J) for k in range(3)]
        w0 = self.w0
        a, b, c = _dot(u, u), _dot(u, v), _dot(v, v)
        d, e = _dot(u, w0), _dot(v, w0)
        cross = _cross(u, v)
        delta = _dot(cross, cross)
        wc = _dot(w0, cross)
        s_num, t_num = b * e - c * d, a * e - b * d
        return [wc * wc - self.r2 * delta, delta, s_num, s_num - delta, t_num, t_num - delta]

    def _pair_line_polynomials(self, vec: Poly):
        """``_pair_line_functions`` for polynomial legs ``vec`` (S, n, 3): the same formulas, with
        the products of one stage stacked into one outward-rounded product."""
        u, v = vec[:, self.I], vec[:, self.J]                                   # (S, P, 3)
        W = self._w0_vector()                                                   # (P, 3), degree 0
        _, first, second = slice(None), [1, 2, 0], [2, 0, 1]
        abc = (_stacked([u, u, v], 2) * _stacked([u, v, v], 2)).sum(axis=-1)    # a, b, c: (S, P, 3)
        de = (_stacked([u, v], 2) * W[:, None]).sum(axis=-1)                    # d, e: (S, P, 2)
        pq = _stacked([u[_, _, first], u[_, _, second]], 2) * _stacked([v[_, _, second], v[_, _, first]], 2)
        cross = pq[_, _, 0] - pq[_, _, 1]                                       # u × v: (S, P, 3)
        delta = (cross * cross).sum(axis=-1)
        wc = (cross * W).sum(axis=-1)
        a, b, c, d, e = abc[_, _, 0], abc[_, _, 1], abc[_, _, 2], de[_, _, 0], de[_, _, 1]
        prod = _stacked([b, c, a, b, wc], 2) * _stacked([e, d, e, d, wc], 2)    # be, cd, ae, bd, wc²
        s_num, t_num = prod[_, _, 0] - prod[_, _, 1], prod[_, _, 2] - prod[_, _, 3]
        return [prod[_, _, 4] - self.r2 * delta, delta, s_num, s_num - delta, t_num, t_num - delta]

    def _w0_vector(self) -> Poly:
        if getattr(self, "_w0_poly", None) is None:
            self._w0_poly = _stacked([Poly.from_coefficients([x]) for x in self.w0], 1)
        return self._w0_poly

    def _pair_end_functions(self, pose: _Pose):
        """Per end point (A_i, B_i vs segment j; A_j, B_j vs segment i): τ numerator, τ − 1
        numerator, point-line numerator, |P − X|² − r², |P − Y|² − r², |Y − X|² (docs/soundness.md)."""
        L = pose.legs
        if isinstance(L[0], Poly):
            vec = pose.vector()
            return self._pair_end_polynomials(vec[:, self.I], vec[:, self.J], self._w0_vector(), self.r2)
        u = [_cols(L[k], self.I) for k in range(3)]
        v = [_cols(L[k], self.J) for k in range(3)]
        w0, r2 = self.w0, self.r2
        a, c = _dot(u, u), _dot(v, v)
        ends = []
        neg_w0 = [-x for x in w0]
        for q, seg, seg2 in ((w0, v, c), ([w0[k] + u[k] for k in range(3)], v, c),
                             (neg_w0, u, a), ([neg_w0[k] + v[k] for k in range(3)], u, a)):
            q = [_bcast(x, seg[0]) if isinstance(x, Interval) and x.ndim == 1 else x for x in q]
            tau = _dot(q, seg)
            qc = _cross(q, seg)
            qe = _sub(q, seg)
            ends += [tau, tau - seg2, _dot(qc, qc) - r2 * seg2, _dot(q, q) - r2, _dot(qe, qe) - r2, seg2]
        return ends

    def _pair_end_polynomials(self, u: Poly, v: Poly, W: Poly, r2: Interval):
        """``_pair_end_functions`` for polynomial legs u, v (batch shape (..., 3)), the constant
        A_i − A_j ``W`` (degree 0, broadcast to u) and r² (batch shape (...)): the four end points'
        terms stacked on one axis, each stage one outward-rounded product."""
        _, first, second = slice(None), [1, 2, 0], [2, 0, 1]
        pre = (_,) * (u.ndim - 1)
        W = Poly(np.broadcast_to(padded(W.lo, u.degree), u.lo.shape), np.broadcast_to(padded(W.hi, u.degree), u.hi.shape))
        axis = u.ndim - 1
        q = _stacked([W, W + u, -W, v - W], axis)                               # the end points − X: (..., 4, 3)
        seg = _stacked([v, v, u, u], axis)                                      # the other segment
        ac = (_stacked([u, v], axis) * _stacked([u, v], axis)).sum(axis=-1)     # |u|², |v|²: (..., 2)
        seg2 = ac[pre + ([1, 1, 0, 0],)]
        tau = (q * seg).sum(axis=-1)
        pq = _stacked([q[pre + (_, first)], q[pre + (_, second)]], axis) * \
            _stacked([seg[pre + (_, second)], seg[pre + (_, first)]], axis)
        qc = pq[pre + (0,)] - pq[pre + (1,)]                                    # q × seg: (..., 4, 3)
        qc2 = (qc * qc).sum(axis=-1)
        qe = q - seg
        sq = (_stacked([q, qe], axis) * _stacked([q, qe], axis)).sum(axis=-1)   # |q|², |q − seg|²: (..., 2, 4)
        r2 = r2[..., None]
        terms = [tau, tau - seg2, qc2 - r2 * seg2, sq[pre + (0,)] - r2, sq[pre + (1,)] - r2, seg2]
        return [t[pre + (e,)] for e in range(4) for t in terms]

    def pair_end_items(self, vec: Poly, rows, pairs):
        """The 24 end-point polynomials (items,) of the (row, pair) items of the polynomial legs ``vec``."""
        u = Poly(vec.lo[rows, self.I[pairs]], vec.hi[rows, self.I[pairs]])
        v = Poly(vec.lo[rows, self.J[pairs]], vec.hi[rows, self.J[pairs]])
        W = self._w0_vector()
        return self._pair_end_polynomials(u, v, Poly(W.lo[pairs], W.hi[pairs]), self.r2[pairs])

    # ----- evaluation -------------------------------------------------------------------
    def polynomials(self, linear, P0: Interval) -> dict:
        """Constant orientation: every constraint function as a polynomial in t, per segment
        (``linear_data``; built once per search, bounded per t-interval by ``_PolyPath``)."""
        out = self._families(_Pose.polynomial(linear["V"], linear["w"], linear["R"]))
        if self.det is not None and self.det.laplace:
            out["det"] = [_gough_det_poly(linear["V"], linear["w"], self.base, [P0[:, k] for k in range(3)])]
        return out

    def piece_polynomials(self, P0: Interval, D: Interval, a, h, degree: int) -> dict | None:
        """Any path: per piece t ∈ [a, a + h] of a segment (rows of P0, D, a, h), the constraint
        functions as polynomials in the local τ ∈ [0, 1], t = a + h τ (``intervals.polynomial``:
        sin/cos by Taylor expansions with Lagrange remainders, products truncated to ``degree``
        with remainders; valid for τ ∈ [0, 1]).  None when the model uses a function the
        polynomials do not support."""
        robot = self.robot
        S, d = P0.shape
        A, H = Interval._raw(np.asarray(a, float), np.asarray(a, float)), Interval._raw(np.asarray(h, float), np.asarray(h, float))
        var = [Poly.from_coefficients([P0[:, k] + A * D[:, k], H * D[:, k]]) for k in range(d)]
        try:
            with degree_limit(degree):
                if robot.rigid_legs():       # l_i = C + R b_i − a_i: R, then one stacked product
                    pose = self._rigid_pose(var, S)
                else:
                    pose = _Pose.from_polys(self.vectors.evaluate(var, robot.parameters), self.n, S, self.with_R)
                out = self._families(pose)
                if self.det is not None:
                    if self.det.laplace:
                        C = [var[k] for k in range(3)]
                        arm = [_bcast(self.base[k], pose.legs[0]) - Poly(np.repeat(C[k].lo[:, None], self.n, 1),
                                                                        np.repeat(C[k].hi[:, None], self.n, 1))
                               for k in range(3)]
                        out["det"] = [_block_det(pose.legs, _cross(arm, pose.legs))]
                    else:
                        out["det"] = [self.det(var)]
                out["degree_limit"] = degree   # the pair end-point terms, built when needed, too
        except NotImplementedError:
            return None
        return out

    def _rigid_pose(self, var, S) -> _Pose:
        """Leg vectors C + R b_i − a_i (and R) from the polynomial pose coordinates ``var`` of a
        robot with rigid legs (``Robot.rigid_legs``): R from the compiled model, then R b_i for
        every leg in one product (inside the caller's degree limit)."""
        robot = self.robot
        R = [r if isinstance(r, Poly) else Poly.from_coefficients([r if isinstance(r, Interval) else Interval(r)])
             for r in robot._compiled("R").evaluate(var, robot.parameters)]
        d = max(r.degree for r in R)
        Rm = Poly(np.stack([np.broadcast_to(padded(r.lo, d), (S, d + 1)) for r in R], 1).reshape(S, 3, 3, d + 1),
                  np.stack([np.broadcast_to(padded(r.hi, d), (S, d + 1)) for r in R], 1).reshape(S, 3, 3, d + 1))
        plat, base = self._stacked_points()                                  # (3, n): [coordinate, leg]
        Rb = (Rm[:, :, :, None] * plat).sum(axis=2)                           # (R b_i)_k: (S, 3, n)
        position = [k for k, name in enumerate(robot.pose_names) if name not in robot.angle_names]
        if position:                                                          # C (S, 3, 1); spherical: none
            zero = Poly(np.zeros((S, 1)), np.zeros((S, 1)))
            Rb = Rb + _stacked([var[position[k]] if k < len(position) else zero for k in range(3)], 1)[:, :, None]
        legs = Rb - base
        out = _Pose.__new__(_Pose)
        out.legs = [legs[:, k] for k in range(3)]
        out.R = [Rm[:, k // 3, k % 3] for k in range(9)] if self.with_R else None
        return out

    def _families(self, pose) -> dict:
        out = {"pose": pose}
        if "legs" in self._cols or "joints" in self._cols:
            out["_legs_sq"] = self._legs_sq(pose)
        if "joints" in self._cols:
            out["_joint_functions"] = self._joint_functions(pose)
        if "pairs" in self._cols:
            out["_pair_line_functions"] = self._pair_line_functions(pose)
        return out

    def crossing_polynomials(self, polys) -> tuple[np.ndarray, np.ndarray]:
        """(S, K, 3, 16) float coefficients (NaN where absent) and their radii: per segment and column, two
        polynomials in t whose sign changes mark where the column's state can change (ρ² − ρ_min²
        and ρ_max² − ρ², facet and cone functions, the line-distance numerator E, det A), and one
        whose sign changes mark an extremum of its margin ((ρ²)', E'Δ − EΔ').  Used to choose
        where to cut a t-interval, never as a proof."""
        S = polys["pose"].legs[0].shape[0]
        out = np.full((S, self.K, 3, 16), np.nan)
        rad = np.zeros((S, self.K, 3, 16))
        mid = lambda p: 0.5 * (p.lo + p.hi)  # noqa: E731

        def put(col, cand, p):
            c = mid(p) if isinstance(p, Poly) else p
            out[:, col, cand, :c.shape[-1]] = c
            out[:, col, cand, c.shape[-1]:] = 0.0
            if isinstance(p, Poly):
                rad[:, col, cand, :c.shape[-1]] = 0.5 * (p.hi - p.lo)
        if "legs" in self._cols:
            sq, cols = polys["_legs_sq"][0], self._cols["legs"]          # (S, n), one column per leg
            put(cols, 0, sq - sqr(self.rho_min))
            put(cols, 1, -sq + sqr(self.rho_max))
            put(cols, 2, _derivative(mid(sq)))
        if "joints" in self._cols:
            fns, k = polys["_joint_functions"], 0
            for col, f in zip(range(self._cols["joints"].start, self._cols["joints"].stop), self.facets):
                put(col, 0, fns[k][:, 0])
                if f["kind"] == "cone":
                    put(col, 1, fns[k + 1][:, 0])
                k += 1 if f["kind"] == "facet" else 2
        if "pairs" in self._cols:
            E, delta = polys["_pair_line_functions"][:2]
            e, d = mid(E), mid(delta)
            stationary = _float_mul(_derivative(e), d) - _float_mul(e, _derivative(d))     # (E/Δ)' Δ²
            put(self._cols["pairs"], 0, E)                                 # (S, pairs), one column per pair
            put(self._cols["pairs"], 2, stationary)
        if "det" in polys:
            put(self._cols["det"].start, 0, polys["det"][0])
        return out, rad

    def evaluate(self, P0: Interval, D: Interval, tlo, thi, linear=None, polys=None, rows=None, upper=True):
        """States (N, K) in {SATISFIED, VIOLATED, UNKNOWN} and margin enclosures (N, K) (lo, hi)
        over the t-intervals [tlo, thi] of the segments pose(t) = P0 + t D (rows of P0, D).
        ``polys`` (from ``polynomials``) with ``rows`` (the segment of each t-interval) selects
        the polynomial bounds; otherwise mean-value forms on ``linear`` data or on the pose.
        ``upper=False``: upper bounds of the pair margins only where they can decide a state."""
        N = len(tlo)
        state = np.zeros((N, self.K), dtype=np.int8)
        mlo = np.full((N, self.K), -np.inf)
        mhi = np.full((N, self.K), np.inf)
        if polys is not None:
            path = _PolyPath(self, polys, rows, P0, D, tlo, thi)
        else:
            path = _PathPoints(self, P0, D, tlo, thi, linear)
        if "legs" in self._cols or "joints" in self._cols:
            rlo, rhi = path.range(self._legs_sq)
            rho = sqrt(Interval._raw(np.maximum(rlo, 0.0), np.maximum(rhi, 0.0)))
        if "legs" in self._cols:
            sl = self._cols["legs"]
            a = rho - self.rho_min
            b = self.rho_max - rho
            mlo[:, sl], mhi[:, sl] = np.minimum(a.lo, b.lo), np.minimum(a.hi, b.hi)
            state[:, sl] = _states(mlo[:, sl], mhi[:, sl])
        if "joints" in self._cols:
            sl = self._cols["joints"]
            glo, ghi = path.range(self._joint_functions)
            mlo[:, sl], mhi[:, sl], state[:, sl] = self._joint_margins(rho, glo, ghi)
        if "pairs" in self._cols:
            sl = self._cols["pairs"]
            mlo[:, sl], mhi[:, sl] = self._pair_margins(path, upper)
            state[:, sl] = _states(mlo[:, sl], mhi[:, sl])
        if self.det is not None:
            k = self._cols["det"].start
            dlo, dhi = path.range_det(self.det)
            mlo[:, k], mhi[:, k] = dlo, dhi
            state[:, k] = np.where((dlo > 0) | (dhi < 0), SATISFIED, UNKNOWN)
        return state, mlo, mhi

    def _joint_margins(self, rho, glo, ghi):
        """Margins n̂·û (facets) or cos(angle(u, axis)) − cos α (cones) and the states."""
        los, his, states = [], [], []
        col = 0
        for f in self.facets:
            r = rho[:, f["leg"]]
            g = Interval._raw(glo[:, col], ghi[:, col])
            if f["kind"] == "facet":
                m = g / (f["norm"] * r)
                st = _states(g.lo, g.hi)
                col += 1
            else:
                h = Interval._raw(glo[:, col + 1], ghi[:, col + 1])
                m = g / (f["norm"] * r) - f["cos"]
                ok = (g.lo >= 0) & (h.lo >= 0)
                bad = (g.hi < 0) | (h.hi < 0)
                st = np.where(ok, SATISFIED, np.where(bad, VIOLATED, UNKNOWN))
                col += 2
            los.append(np.where(np.isnan(m.lo), -np.inf, m.lo))
            his.append(np.where(np.isnan(m.hi), np.inf, m.hi))
            states.append(st)
        return np.stack(los, 1), np.stack(his, 1), np.stack(states, 1).astype(np.int8)

    def _pair_margins(self, path, upper_wanted=True):
        """Enclosures of d_ij − (r_i + r_j) per pair (docs/soundness.md, segment distance).
        The end-point terms are bounded only for the (interval, pair) items where the line
        distance does not settle the bound (and, with ``upper_wanted``, where the feet of the
        common perpendicular are not proved inside the segments)."""
        P = len(self.pair_list)
        llo, lhi = path.range(self._pair_line_functions)
        iv = lambda k: Interval._raw(llo[:, k * P:(k + 1) * P], lhi[:, k * P:(k + 1) * P])  # noqa: E731
        delta = iv(1)
        s0, s1, t0, t1 = iv(2), iv(3), iv(4), iv(5)
        feet_in = (s0.lo >= 0) & (s1.hi <= 0) & (t0.lo >= 0) & (t1.hi <= 0) & (delta.lo > 0)
        feet_out = (s0.hi < 0) | (s1.lo > 0) | (t0.hi < 0) | (t1.lo > 0)
        line = path.ratio(self._pair_line_functions, 0, 1, P)  # E / Δ: line distance² − r²
        lower = np.where(np.isnan(line.lo), -np.inf, line.lo)
        upper = np.where(feet_in & ~np.isnan(line.hi), line.hi, np.inf)
        need = ~feet_in & ((lower < 0) | upper_wanted)
        if need.any():
            rows, pairs = np.nonzero(need)
            (elo, ehi), pl = path.pair_ends(self._pair_end_functions, rows, pairs)   # (items, 4, 6), (items, 4)
            tau0, tau1, F0, F1 = (Interval._raw(elo[..., k], ehi[..., k]) for k in (0, 1, 3, 4))
            before, after = tau0.hi <= 0, tau1.lo >= 0
            inside = (tau0.lo >= 0) & (tau1.hi <= 0)
            plo = np.where(np.isnan(pl.lo), -np.inf, pl.lo)
            clo = np.where(before, F0.lo, np.where(after, F1.lo, plo))       # point-segment distance² − r², lower
            chi = np.minimum(np.minimum(F0.hi, F1.hi), np.where(inside & ~np.isnan(pl.hi), pl.hi, np.inf))
            end_lower = clo.min(axis=1)
            end_upper = chi.min(axis=1)
            # the line distance is always a lower bound; when the feet of the common perpendicular
            # are outside [0, 1]², the minimum over the square is on its boundary: the end-point terms
            lower[rows, pairs] = np.where(feet_out[rows, pairs], np.maximum(lower[rows, pairs], end_lower),
                                          lower[rows, pairs])
            upper[rows, pairs] = np.minimum(upper[rows, pairs], end_upper)
        d2 = Interval._raw(np.maximum(down(lower + self.r2.lo), 0.0), np.maximum(up(upper + self.r2.hi), 0.0))
        m = sqrt(d2) - self.r
        return m.lo, m.hi


def _states(lo, hi):
    return np.where(lo >= 0, SATISFIED, np.where(hi < 0, VIOLATED, UNKNOWN)).astype(np.int8)


def _bcast(v: Interval, like):
    """A constant (n,) interval vector broadcast to the (M, n) shape of ``like`` (Interval or Dual)."""
    shape = like.value.shape if isinstance(like, Dual) else like.shape
    return Interval._raw(np.broadcast_to(v.lo, shape), np.broadcast_to(v.hi, shape))


def _joint_data(robot):
    """The facets and cones of the joint limits, enclosed from their exact decimals."""
    out = []
    for side in ("base_joints", "platform_joints"):
        for i, table in enumerate(robot.limits.get(side, [])):
            field = f"limits.{side}[{i}]"
            where = side[:-7]
            if where == "platform" and "R" not in robot.symbolic_model():
                raise InputError(robot.source, field, f"platform joint limits are not modelled for {robot.kind} robots")
            for k, normal in enumerate(table.get("normals", [])):
                vec = [parse_number(c, robot.source, f"{field}.normals[{k}]")[0] for c in normal]
                norm = sqrt(sqr(vec[0]) + sqr(vec[1]) + sqr(vec[2]))
                out.append({"instance": Instance("joints", (i + 1,), f"{where} facet {k + 1}"), "leg": i,
                            "side": where, "kind": "facet", "vector": [_enclose_all([v]) for v in vec], "norm": norm})
            if "axis" in table:
                axis = [parse_number(c, robot.source, field + ".axis")[0] for c in table["axis"]]
                alpha = parse_number(table["half_angle"], robot.source, field + ".half_angle", angle=True)[0]
                ca = cos(alpha)
                if ca.lo < 0:
                    raise InputError(robot.source, field + ".half_angle", "cones wider than 90deg are not supported")
                a2 = sqr(axis[0]) + sqr(axis[1]) + sqr(axis[2])
                out.append({"instance": Instance("joints", (i + 1,), f"{where} cone"), "leg": i, "side": where,
                            "kind": "cone", "vector": [_enclose_all([v]) for v in axis], "norm": sqrt(a2),
                            "cos": ca, "c2": a2 * sqr(ca)})
    return out


class _PathPoints:
    """pose(T) with its t-derivative, and the thin poses at the ends and midpoints of T."""

    def __init__(self, constraints, P0: Interval, D: Interval, tlo, thi, linear=None):
        self.c = constraints
        self.P0, self.D, self.linear = P0, D, linear
        self.tlo, self.thi = np.asarray(tlo, dtype=np.float64), np.asarray(thi, dtype=np.float64)
        self.tm = 0.5 * (self.tlo + self.thi)
        self.N = N = len(self.tlo)
        self.T = T = Interval._raw(self.tlo, self.thi)
        d = P0.shape[-1]
        t3 = np.concatenate([self.tlo, self.tm, self.thi])
        self.t3 = Interval._raw(t3, t3)
        tile = lambda x: Interval._raw(np.tile(x.lo, (3, 1)), np.tile(x.hi, (3, 1)))  # noqa: E731
        n, with_R = constraints.n, constraints.with_R
        if linear is not None:            # constant orientation: legs linear in t, no trigonometry
            V, w, R = linear["V"], linear["w"], linear["R"]
            V3 = [Interval._raw(np.tile(v.lo, (3, 1)), np.tile(v.hi, (3, 1))) for v in V]
            w3 = [Interval._raw(np.tile(x.lo, 3), np.tile(x.hi, 3)) for x in w]
            R3 = None if R is None else [Interval._raw(np.tile(x.lo, 3), np.tile(x.hi, 3)) for x in R]
            self.pose_dual = _Pose.linear(V, w, R, T, dual=True)
            self.pose_points = _Pose.linear(V3, w3, R3, self.t3, dual=False)
            self.duals = self.points = None
        else:
            self.duals = [Dual(P0[:, k] + T * D[:, k], Interval._raw(D.lo[:, k, None], D.hi[:, k, None]))
                          for k in range(d)]
            P3 = tile(P0) + self.t3[:, None] * tile(D)
            self.points = [P3[:, k] for k in range(d)]
            params = constraints.robot.parameters
            self.pose_dual = _Pose(constraints.vectors.evaluate(self.duals, params), n, N, with_R)
            self.pose_points = _Pose(constraints.vectors.evaluate(self.points, params), n, 3 * N, with_R)

    def centre(self):
        """The platform origin C over T (Gough-Stewart: the first three pose coordinates)."""
        return [self.P0[:, k] + self.T * self.D[:, k] for k in range(3)]

    def range(self, fn):
        """(lo, hi) arrays (N, m): enclosures over T of the values ``fn(pose)`` (flattened)."""
        memo = self.__dict__.setdefault("_memo", {})
        if fn.__name__ not in memo:
            memo[fn.__name__] = self._combine(fn(self.pose_dual), fn(self.pose_points))
        return memo[fn.__name__]

    def range_det(self, det):
        if det.laplace:                   # Gough-Stewart: natural LU-preconditioned enclosure over T
            legs = [x.value if isinstance(x, Dual) else x for x in self.pose_dual.legs]
            D = _gough_det(legs, self.c.base, self.centre())
            return D.lo, D.hi
        duals, points = self.duals, self.points
        if duals is None:
            duals = [Dual(self.P0[:, k] + self.T * self.D[:, k], Interval._raw(self.D.lo[:, k, None], self.D.hi[:, k, None]))
                     for k in range(self.P0.shape[-1])]
            tile = lambda x: Interval._raw(np.tile(x.lo, (3, 1)), np.tile(x.hi, (3, 1)))  # noqa: E731
            P3 = tile(self.P0) + self.t3[:, None] * tile(self.D)
            points = [P3[:, k] for k in range(self.P0.shape[-1])]
        lo, hi = self._combine([det(duals)], [det(points)])
        return lo[:, 0], hi[:, 0]

    def ratio(self, fn, i, j, width):
        """Enclosure (N, width) of block i / block j of the flattened values of ``fn``."""
        lo, hi = self.range(fn)
        cols = lambda k: Interval._raw(lo[:, k * width:(k + 1) * width], hi[:, k * width:(k + 1) * width])  # noqa: E731
        return cols(i) / cols(j)

    def pair_ends(self, fn, rows, pairs):
        """End-point terms (items, 4, 6) of the (interval, pair) items ``rows``, ``pairs``, and
        the point-line distance² − r² (items, 4) (their third term over their sixth)."""
        P = len(self.c.pair_list)
        elo, ehi = self._combine(fn(self.pose_dual), fn(self.pose_points))
        elo = elo.reshape(self.N, 4, 6, P)[rows, :, :, pairs]
        ehi = ehi.reshape(self.N, 4, 6, P)[rows, :, :, pairs]
        pl = Interval._raw(elo[..., 2], ehi[..., 2]) / Interval._raw(np.maximum(elo[..., 5], 0.0), ehi[..., 5])
        return (elo, ehi), pl

    def _combine(self, duals, pts):
        N = self.N
        los, his = [], []
        for g, p in zip(duals, pts):
            p = p if isinstance(p, Interval) else Interval(p)
            if p.ndim == 0 or p.shape[0] != 3 * N:
                p = Interval._raw(np.broadcast_to(p.lo, (3 * N,) + p.shape[-1:] if p.ndim else (3 * N,)),
                                  np.broadcast_to(p.hi, (3 * N,) + p.shape[-1:] if p.ndim else (3 * N,)))
            a = Interval._raw(p.lo[:N], p.hi[:N])
            m = Interval._raw(p.lo[N:2 * N], p.hi[N:2 * N])
            b = Interval._raw(p.lo[2 * N:], p.hi[2 * N:])
            if not isinstance(g, Dual):           # constant along the path
                lo, hi = a.lo, a.hi
            else:
                nat = g.value
                der = Interval._raw(g.grad.lo[..., 0], g.grad.hi[..., 0])
                Tm = self.T - Interval._raw(self.tm, self.tm)
                if der.ndim == 2:
                    Tm = Tm[:, None]
                cen = m + der * Tm
                up_ = der.lo >= 0
                down_ = der.hi <= 0
                lo = np.where(up_, a.lo, np.where(down_, b.lo, np.maximum(cen.lo, nat.lo)))
                hi = np.where(up_, b.hi, np.where(down_, a.hi, np.minimum(cen.hi, nat.hi)))
            lo = np.broadcast_to(lo, (N,) + np.shape(lo)[1:]).reshape(N, -1)
            hi = np.broadcast_to(hi, (N,) + np.shape(hi)[1:]).reshape(N, -1)
            los.append(lo)
            his.append(hi)
        return np.concatenate(los, axis=1), np.concatenate(his, axis=1)


class _PolyPath:
    """Constant orientation: ranges over T of the constraint functions from their polynomials
    in t (``Constraints.polynomials``), by Bernstein bounds (``intervals.polynomial``)."""

    def __init__(self, constraints, polys, rows, P0: Interval, D: Interval, tlo, thi):
        self.c, self.polys, self.rows = constraints, polys, np.asarray(rows)
        self.P0, self.D = P0, D
        self.tlo, self.thi = np.asarray(tlo, dtype=np.float64), np.asarray(thi, dtype=np.float64)
        self.N = len(self.tlo)
        self._memo = {}

    FAMILIES = ("_legs_sq", "_joint_functions", "_pair_line_functions", "det")

    def _stacked(self):
        """Every family's functions as one (S, m, n + 1) pair of coefficient arrays at the
        largest degree n (lower degrees padded with zero coefficients), with each family's
        column range; built once per search."""
        if "_stacked" not in self.polys:
            S = self.polys["pose"].legs[0].shape[0]
            items = [(key, p) for key in self.FAMILIES if key in self.polys for p in self.polys[key]]
            polys = [p if isinstance(p, Poly) else Poly.from_coefficients([p]) for _, p in items]
            n = max(p.degree for p in polys)
            blocks, spans, at = [], {}, 0
            for (key, _), p in zip(items, polys):
                width = int(np.prod(p.shape[1:])) if p.ndim and p.shape[0] == S else int(np.prod(p.shape))
                blocks.append((p, width))
                spans[key] = (spans.get(key, (at, at))[0], at + width)
                at += width
            lo, hi = np.zeros((S, at, n + 1)), np.zeros((S, at, n + 1))
            at = 0
            for p, width in blocks:      # a constant of the robot (no segment axis) is the same on every segment
                lo[:, at:at + width, :p.degree + 1] = p.lo.reshape(-1, width, p.degree + 1)
                hi[:, at:at + width, :p.degree + 1] = p.hi.reshape(-1, width, p.degree + 1)
                at += width
            self.polys["_stacked"] = (lo, hi, spans)
        return self.polys["_stacked"]

    def _weights(self, n):
        """The Bernstein maps of degree n on the rows' t-intervals (shared by every function)."""
        if ("W", n) not in self._memo:
            self._memo[("W", n)] = bernstein_weights(self.tlo[:, None], self.thi[:, None], n)
        return self._memo[("W", n)]

    def _bernstein(self, key):
        """Bernstein coefficients (N, m, n + 1) of the functions ``key`` on each row's t-interval
        (every family in one product, on first use)."""
        if "all" not in self._memo:
            lo, hi, _ = self._stacked()
            W = self._weights(lo.shape[-1] - 1)
            self._memo["all"] = Poly(lo[self.rows], hi[self.rows]).bernstein(self.tlo[:, None], self.thi[:, None], W)
        first, last = self._stacked()[2][key]
        b = self._memo["all"]
        return Interval._raw(b.lo[:, first:last], b.hi[:, first:last])

    def range(self, fn):
        b = self._bernstein(fn.__name__)
        return b.lo.min(axis=-1), b.hi.max(axis=-1)

    def ratio(self, fn, i, j, width):
        """Enclosure (N, width) of block i / block j of the functions of ``fn`` (rational Bernstein bound)."""
        b = self._bernstein(fn.__name__)
        cols = lambda k: Interval._raw(b.lo[:, k * width:(k + 1) * width], b.hi[:, k * width:(k + 1) * width])  # noqa: E731
        return ratio_range(cols(i), cols(j))

    def range_det(self, det):
        if "det" in self.polys:
            b = self._bernstein("det")
            return b.lo[:, 0].min(axis=-1), b.hi[:, 0].max(axis=-1)
        return _PathPoints(self.c, self.P0, self.D, self.tlo, self.thi).range_det(det)

    def pair_ends(self, fn, rows, pairs):
        """End-point terms (items, 4, 6) of the (interval, pair) items ``rows``, ``pairs`` and the
        point-line distance² − r² (items, 4); their polynomials are built for a (row, pair) (row:
        segment or piece) when it first needs them, at the degree of the other families when not
        above it (one Bernstein map for all)."""
        key = fn.__name__
        seg = self.rows[rows]
        P = len(self.c.pair_list)
        if key not in self.polys:
            S = self.polys["pose"].legs[0].shape[0]
            n = self._stacked()[0].shape[-1] - 1
            self.polys[key] = (np.zeros((S, 24 * P, n + 1)), np.zeros((S, 24 * P, n + 1)), np.zeros((S, P), dtype=bool))
        lo, hi, built = self.polys[key]
        need = ~built[seg, pairs]
        if need.any():                 # built for the (row, pair) items that need them, once
            todo = np.unique(np.stack([seg[need], pairs[need]], 1), axis=0)
            with degree_limit(self.polys.get("degree_limit")):
                ends = [p if isinstance(p, Poly) else Poly.from_coefficients([p])
                        for p in self.c.pair_end_items(self.polys["pose"].vector(), todo[:, 0], todo[:, 1])]
            m = max(p.degree for p in ends)
            if m + 1 > lo.shape[-1]:
                lo, hi = padded(lo, m), padded(hi, m)
            for k, p in enumerate(ends):                   # term-major: column k * P + pair
                lo[todo[:, 0], k * P + todo[:, 1], :p.degree + 1] = p.lo
                hi[todo[:, 0], k * P + todo[:, 1], :p.degree + 1] = p.hi
            built[todo[:, 0], todo[:, 1]] = True
            self.polys[key] = (lo, hi, built)
        cols = (np.arange(24)[None, :] * P + pairs[:, None])     # (items, 24)
        W = self._weights(lo.shape[-1] - 1)
        b = Poly(lo[seg[:, None], cols], hi[seg[:, None], cols]).bernstein(self.tlo[rows, None], self.thi[rows, None],
                                                                           (W[0][rows], W[1][rows]))
        blo, bhi = b.lo.reshape(len(rows), 4, 6, -1), b.hi.reshape(len(rows), 4, 6, -1)
        pl = ratio_range(Interval._raw(blo[:, :, 2], bhi[:, :, 2]), Interval._raw(blo[:, :, 5], bhi[:, :, 5]))
        return (blo.min(axis=-1), bhi.max(axis=-1)), pl


def _derivative(c):
    """Coefficients of p' (float, last axis), same length (last coefficient 0)."""
    return np.concatenate([c[..., 1:] * np.arange(1, c.shape[-1]), np.zeros(c.shape[:-1] + (1,))], -1)


def _float_mul(a, b):
    """Float product of coefficient arrays (last axis), at most 16 coefficients."""
    out = np.zeros(np.broadcast_shapes(a.shape[:-1], b.shape[:-1]) + (a.shape[-1] + b.shape[-1] - 1,))
    for i in range(a.shape[-1]):
        out[..., i:i + b.shape[-1]] += a[..., i:i + 1] * b
    if np.any(out[..., 16:] != 0):
        raise ValueError("polynomial of degree above 15")
    return out[..., :16]


def crossing_points(coefficients, tlo, thi, iterations: int = 60, radii=None):
    """Float estimates of a sign change of each polynomial (rows of ``coefficients``, (M, m),
    NaN rows allowed) inside [tlo, thi]: Newton in the bracket, regula falsi where a Newton step
    leaves it (until the steps stop moving, at most ``iterations``); NaN when the values at the
    two ends have the same sign.  With ``radii`` (the coefficients' uncertainty),
    also an estimate of the estimate's error, (Σ r_k |t|^k + 2⁻⁴⁸ Σ |c_k t^k|) / |p'(t)|.
    A heuristic for cutting boxes, not a proof."""
    coefficients = np.asarray(coefficients, dtype=np.float64)
    m, n = coefficients.shape
    c = np.where(np.isnan(coefficients), 0.0, coefficients)
    a = np.broadcast_to(np.asarray(tlo, dtype=np.float64), (m,))
    b = np.broadcast_to(np.asarray(thi, dtype=np.float64), (m,))
    k = np.arange(n, dtype=np.float64)
    dc = c[:, 1:] * k[1:]

    def powers(x):                      # x^0, ..., x^(n−1) by repeated products
        out = np.empty((len(x), n))
        out[:, 0] = 1.0
        if n > 1:
            out[:, 1:] = x[:, None]
            np.cumprod(out[:, 1:], axis=1, out=out[:, 1:])
        return out

    fa = np.einsum("ij,ij->i", powers(a), c)
    fb = np.einsum("ij,ij->i", powers(b), c)
    bracket = (np.sign(fa) * np.sign(fb) < 0) & ~np.isnan(coefficients[:, 0])
    rows = np.nonzero(bracket)[0]           # only the bracketed rows are iterated
    c, dc, a, b, fa, fb = c[rows], dc[rows], a[rows], b[rows], fa[rows], fb[rows]
    with np.errstate(all="ignore"):
        x = a - fa * (b - a) / (fb - fa)                                           # regula falsi start
    x = np.where((x > a) & (x < b), x, 0.5 * (a + b))
    for _ in range(iterations if len(rows) else 0):
        xp = powers(x)
        f = np.einsum("ij,ij->i", xp, c)
        df = np.einsum("ij,ij->i", xp[:, :-1], dc)
        same = np.sign(f) == np.sign(fa)
        a, fa = np.where(same, x, a), np.where(same, f, fa)
        b, fb = np.where(same, b, x), np.where(same, fb, f)
        with np.errstate(all="ignore"):
            newton = x - f / df
            secant = a - fa * (b - a) / (fb - fa)
        previous = x
        x = np.where((newton > a) & (newton < b), newton,
                     np.where((secant > a) & (secant < b), secant, 0.5 * (a + b)))
        x = np.where(f == 0, previous, x)
        if np.all(np.abs(x - previous) <= 2.0 ** -50 * np.abs(x)):
            break
    t = np.full(m, np.nan)
    t[rows] = x
    if radii is None:
        return t
    xp = np.abs(powers(x))
    err = np.full(m, np.nan)
    with np.errstate(all="ignore"):
        err[rows] = (np.einsum("ij,ij->i", xp, radii[rows]) + 2.0 ** -48 * np.einsum("ij,ij->i", xp, np.abs(c))) \
            / np.abs(np.einsum("ij,ij->i", xp[:, :-1], dc))
    return t, err
