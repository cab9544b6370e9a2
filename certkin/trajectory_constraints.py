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

import numpy as np

from intervals import Interval, cos, sqr, sqrt, stack
from intervals.autodiff import Dual
from intervals.linalg import laplace_det
from intervals.rounding import down, up

from .errors import InputError
from .robots.base import parse_number

KINDS = ("leg-length", "joints", "interference", "singularity")
SATISFIED, VIOLATED, UNKNOWN = 1, -1, 0


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
    """Per-robot data derived from its limits, built once."""
    cache = robot.__dict__.setdefault("_trajectory_cache", {})
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
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


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

    def rotate(self, v):
        """R v for constant vectors v (3 arrays of shape (n,)) -> 3 x (M, n)."""
        R = self.R
        return [_stack_rows(R[3 * r], v[0]) + _stack_rows(R[3 * r + 1], v[1]) + _stack_rows(R[3 * r + 2], v[2])
                for r in range(3)]


def _stack_rows(x, v: Interval):
    """x (M,) times v (n,) -> (M, n)."""
    n = v.shape[0]
    if isinstance(x, Dual):
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
        out = _Pose(self.vectors.evaluate([P0[:, k] for k in range(P0.shape[1])], robot.parameters), self.n, S, self.with_R)
        position = [k for k, name in enumerate(robot.pose_names) if name not in robot.angle_names]
        zero = Interval._raw(np.zeros(S), np.zeros(S))
        w = [D[:, position[k]] if k < len(position) else zero for k in range(3)]
        return {"V": out.legs, "w": w, "R": out.R}

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

    def _pair_functions(self, pose: _Pose):
        """Per pair: line distance² − r² numerator E, Δ = |u×v|², feet numerators; per end point
        (A_i, B_i vs segment j; A_j, B_j vs segment i): τ numerator, τ − 1 numerator,
        point-line numerator, |P − X|² − r², |P − Y|² − r² (docs/soundness.md)."""
        L = pose.legs
        u = [_cols(L[k], self.I) for k in range(3)]
        v = [_cols(L[k], self.J) for k in range(3)]
        w0 = self.w0
        r2 = self.r2
        a, b, c = _dot(u, u), _dot(u, v), _dot(v, v)
        d, e = _dot(u, w0), _dot(v, w0)
        cross = _cross(u, v)
        delta = _dot(cross, cross)
        wc = _dot(w0, cross)
        s_num, t_num = b * e - c * d, a * e - b * d
        line = [wc * wc - r2 * delta, delta, s_num, s_num - delta, t_num, t_num - delta]
        ends = []
        neg_w0 = [-x for x in w0]
        for q, seg, seg2 in ((w0, v, c), ([w0[k] + u[k] for k in range(3)], v, c),
                             (neg_w0, u, a), ([neg_w0[k] + v[k] for k in range(3)], u, a)):
            q = [_bcast(x, seg[0]) if isinstance(x, Interval) and x.ndim == 1 else x for x in q]
            tau = _dot(q, seg)
            qc = _cross(q, seg)
            qe = _sub(q, seg)
            ends += [tau, tau - seg2, _dot(qc, qc) - r2 * seg2, _dot(q, q) - r2, _dot(qe, qe) - r2]
        return line, ends

    # ----- evaluation -------------------------------------------------------------------
    def evaluate(self, P0: Interval, D: Interval, tlo, thi, linear=None):
        """States (N, K) in {SATISFIED, VIOLATED, UNKNOWN} and margin enclosures (N, K) (lo, hi)
        over the t-intervals [tlo, thi] of the segments pose(t) = P0 + t D (rows of P0, D)."""
        N = len(tlo)
        state = np.zeros((N, self.K), dtype=np.int8)
        mlo = np.full((N, self.K), -np.inf)
        mhi = np.full((N, self.K), np.inf)
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
            mlo[:, sl], mhi[:, sl] = self._pair_margins(path)
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

    def _pair_margins(self, path):
        """Enclosures of d_ij − (r_i + r_j) per pair (docs/soundness.md, segment distance)."""
        P = len(self.pair_list)
        (llo, lhi), rows, (elo, ehi) = path.pair_ranges(self._pair_functions)
        iv = lambda k: Interval._raw(llo[:, k * P:(k + 1) * P], lhi[:, k * P:(k + 1) * P])  # noqa: E731
        E, delta = iv(0), iv(1)
        s0, s1, t0, t1 = iv(2), iv(3), iv(4), iv(5)
        feet_in = (s0.lo >= 0) & (s1.hi <= 0) & (t0.lo >= 0) & (t1.hi <= 0) & (delta.lo > 0)
        feet_out = (s0.hi < 0) | (s1.lo > 0) | (t0.hi < 0) | (t1.lo > 0)
        line = E / delta                                        # line distance² − r²
        lower = np.where(np.isnan(line.lo), -np.inf, line.lo)
        upper = np.where(feet_in & ~np.isnan(line.hi), line.hi, np.inf)
        if rows is not None and len(rows):
            tau0, tau1, Eps, F0, F1 = (Interval._raw(elo[..., k], ehi[..., k]) for k in range(5))
            seg2 = tau0 - tau1                                  # |Y − X|², enclosed again
            pl = Eps / Interval._raw(np.maximum(seg2.lo, 0.0), seg2.hi)
            before, after = tau0.hi <= 0, tau1.lo >= 0
            inside = (tau0.lo >= 0) & (tau1.hi <= 0)
            plo = np.where(np.isnan(pl.lo), -np.inf, pl.lo)
            clo = np.where(before, F0.lo, np.where(after, F1.lo, plo))       # point-segment distance² − r², lower
            chi = np.minimum(np.minimum(F0.hi, F1.hi), np.where(inside & ~np.isnan(pl.hi), pl.hi, np.inf))
            end_lower = clo.min(axis=2)
            end_upper = chi.min(axis=2)
            # the line distance is always a lower bound; when the feet of the common perpendicular
            # are outside [0, 1]², the minimum over the square is on its boundary: the end-point terms
            lower[rows] = np.where(feet_out[rows], np.maximum(lower[rows], end_lower), lower[rows])
            upper[rows] = np.minimum(upper[rows], end_upper)
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
        return self._combine(fn(self.pose_dual), fn(self.pose_points))

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

    def pair_ranges(self, fn):
        """Line terms for every box; end-point terms (N', P, 4, 5) only where some pair needs them."""
        line_d, ends_d = fn(self.pose_dual)
        line_p, ends_p = fn(self.pose_points)
        line = self._combine(line_d, line_p)
        P = len(self.c.pair_list)
        rows = np.arange(self.N)
        elo, ehi = self._combine(ends_d, ends_p)
        elo = elo[rows].reshape(len(rows), 4, 5, P).transpose(0, 3, 1, 2)
        ehi = ehi[rows].reshape(len(rows), 4, 5, P).transpose(0, 3, 1, 2)
        return line, rows, (elo, ehi)

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
