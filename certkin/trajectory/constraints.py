"""The constraints of a trajectory, as functions of the pose, bounded over sub-intervals of t.

Seed 000 §1.3 lists the constraints; the digest's corrections are applied (E4: ρ² is convex, so
ρ can have an interior minimum; E9/E10: the corrected line-distance polynomial; E12: the exact
segment-to-segment distance).  Each kind is a *family* with its own module, behind one protocol
(``trajectory.families.base``): ``leg-length``, ``joints``, ``interference``, ``singularity``.
``Constraints`` selects the families a robot file allows, gives each its columns (one per
instance, in this order) and evaluates them all on batches of t-intervals.

Every quantity is a polynomial (or, for the determinant, a Laplace expansion) in the pose,
written once with sympy and compiled by ``intervals.compiler``.  Along a segment pose(t) = P + t D,
so on a t-interval T each is enclosed by a path evaluator (``trajectory.evaluate``): mean-value
forms with the t-derivative, or Bernstein bounds of its polynomial in t.
``docs/soundness.md`` gives the argument for the segment distance.
"""
from __future__ import annotations

from math import factorial

import numpy as np

from intervals import Interval, sqrt
from intervals.interval import mul
from intervals.polynomial import Poly, degree_limit, padded
from intervals.rounding import down_sum, sum_bounds, up_sum

from ..errors import InputError, shown
from .crossings import midpoint
from .evaluate import PathPoints, PolyPath
from .families import FAMILIES
from .families.base import Instance, cached
from .pose import LENGTHS, PathPose, enclose_all, legs_squared, stacked

KINDS = tuple(f.constraint for f in FAMILIES)
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


def constraint_names(kinds):
    """None (every constraint), or the list of names of ``kinds`` (a list or a comma-separated
    text); an empty list, an empty name or a name given twice raise ``InputError``."""
    if kinds is None:
        return None
    if not isinstance(kinds, (str, list, tuple)):
        raise InputError("constraints", "", f"expected names (a text or a list), got {type(kinds).__name__}")
    names = [k.strip() for k in kinds.split(",")] if isinstance(kinds, str) else list(kinds)
    if not names or names == [""]:
        raise InputError("constraints", "", "empty list (leave it out to check every constraint)")
    for k in names:
        if not isinstance(k, str) or not k:
            raise InputError("constraints", "", f"expected constraint names, got {shown(k)}")
        if names.count(k) > 1:
            raise InputError("constraints", k, "given twice")
    return names


class Constraints:
    """The selected constraints of a robot, evaluated on batches of t-intervals."""

    def __init__(self, robot, kinds=None):
        self.robot = robot
        kinds = list(KINDS if kinds is None else kinds)
        for k in kinds:
            if k not in KINDS:
                raise InputError("constraints", k, f"unknown constraint (known: {', '.join(KINDS)})")
        self.n = robot.n_legs
        self.skipped = {}           # families asked for that the robot file gives no limits for: why
        self.not_asked = []         # families the robot file allows that the selection leaves out
        self.partial = {}           # families checked in part only: what is not checked
        self.instances: list[Instance] = []
        self.families = []
        self.vectors = robot.compiled("leg_vectors")
        self.with_R = "R" in robot.model_parts()
        self.base = cached(robot, "base", lambda: [enclose_all([Interval(p[k]) if k < robot.dim else Interval(0)
                                                                   for p in robot.base]) for k in range(3)])
        self.platform = cached(robot, "platform", lambda: [enclose_all([Interval(p[k]) for p in robot.platform])
                                                           for k in range(robot.dim)])
        for family in FAMILIES:
            why = family.missing(robot)
            if family.constraint not in kinds:
                if why is None:
                    self.not_asked.append(family.constraint)
                continue
            if why is not None:
                self.skipped[family.constraint] = why
            else:
                self._add(family.build(robot, self.base))
                if (part := family.partial(robot)) is not None:
                    self.partial[family.constraint] = part
        self.det = next((f for f in self.families if f.sign_only), None)
        self.uses_lengths = any(f.uses_lengths for f in self.families)
        self.function_keys = [LENGTHS] + [f.key for f in self.families if f.key is not None]
        self.K = len(self.instances)

    @classmethod
    def of(cls, robot, kinds=None) -> "Constraints":
        """The constraints ``kinds`` of ``robot`` (None: all; names as a list or one text
        ``"leg-length,joints"``), built once per robot, selection and limits."""
        kinds = constraint_names(kinds)
        key = ("constraints", None if kinds is None else tuple(kinds))
        return cached(robot, key, lambda: cls(robot, kinds))

    def _add(self, family):
        start = len(self.instances)
        self.instances.extend(family.instances)
        family.columns = slice(start, len(self.instances))
        self.families.append(family)

    def unchecked(self) -> list[tuple[str, str]]:
        """(family, why) of every constraint family not checked, or checked in part only."""
        return ([(k, why) for k, why in self.skipped.items()] + [(k, "not asked: --constraints") for k in self.not_asked]
                + [(f"{k} (in part)", why) for k, why in self.partial.items()])

    def family(self, constraint: str):
        """The family of one constraint kind, or None when it is not selected or not checkable."""
        return next((f for f in self.families if f.constraint == constraint), None)

    def linear_data(self, P0: Interval, D: Interval):
        """Per segment, when no pose angle moves: V (leg vectors at t = 0), w (the velocity of
        the platform origin) and R, so that l_i(t) = V_i + t w exactly.  None otherwise."""
        robot = self.robot
        angles = [k for k, name in enumerate(robot.pose_names) if name in robot.angle_names]
        if np.any(D.lo[:, angles] != 0) or np.any(D.hi[:, angles] != 0):
            return None
        S = P0.shape[0]
        position = [k for k, name in enumerate(robot.pose_names) if name not in robot.angle_names]
        zero = Interval.from_bounds(np.zeros(S), np.zeros(S))
        w = [D[:, position[k]] if k < len(position) else zero for k in range(3)]
        variables = [P0[:, k] for k in range(P0.shape[1])]
        if robot.rigid_legs():        # l_i = C + R b_i − a_i: R once, then one product for every leg
            R = robot.compiled("R").evaluate(variables, robot.parameters)
            R = [r if isinstance(r, Interval) else Interval(r) for r in R]
            R = [Interval.from_bounds(np.broadcast_to(r.lo, (S,)), np.broadcast_to(r.hi, (S,))) for r in R]
            C = [P0[:, position[k]] if k < len(position) else zero for k in range(3)]
            Rm = Interval.from_bounds(np.stack([r.lo for r in R], -1).reshape(S, 3, 3, 1),
                               np.stack([r.hi for r in R], -1).reshape(S, 3, 3, 1))
            plat, base = self._stacked_points()
            Rb = mul(Rm, plat)                                                    # R_kj b_ij: (S, 3, 3, n)
            lo, hi = sum_bounds(Rb.lo, Rb.hi, axis=2)                              # (R b_i)_k: (S, 3, n)
            Clo = np.stack([c.lo for c in C], -1)[:, :, None]
            Chi = np.stack([c.hi for c in C], -1)[:, :, None]
            lo, hi = down_sum(down_sum(lo + Clo) - base.hi), up_sum(up_sum(hi + Chi) - base.lo)
            V = [Interval.from_bounds(lo[:, k], hi[:, k]) for k in range(3)]
            return {"V": V, "w": w, "R": R if self.with_R else None}
        out = PathPose(self.vectors.evaluate(variables, robot.parameters), self.n, S, self.with_R)
        return {"V": out.legs, "w": w, "R": out.R}

    def _stacked_points(self):
        """The platform points as a (3, n) Interval and the base points as (3, n), built once."""
        if getattr(self, "_points", None) is None:
            self._points = tuple(Interval.from_bounds(np.stack([p[k].lo for k in range(3)]), np.stack([p[k].hi for k in range(3)]))
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
        return self.det.columns.start if self.det is not None else None

    def refinable(self):
        """Columns whose margin is refined to the requested tolerance (all but the sign of det A)."""
        mask = np.ones(self.K, dtype=bool)
        for f in self.families:
            if f.sign_only:
                mask[f.columns] = False
        return mask

    # ----- evaluation -------------------------------------------------------------------
    def polynomials(self, linear, P0: Interval) -> dict:
        """Constant orientation: every constraint function as a polynomial in t, per segment
        (``linear_data``; built once per search, bounded per t-interval by ``PolyPath``)."""
        return self._functions(PathPose.polynomial(linear["V"], linear["w"], linear["R"]), linear=linear, P0=P0)

    def piece_polynomials(self, P0: Interval, D: Interval, a, h, degree: int, stop=None) -> dict | None:
        """Any path: per piece t ∈ [a, a + h] of a segment (rows of P0, D, a, h), the constraint
        functions as polynomials in the local τ ∈ [0, 1], t = a + h τ (``intervals.polynomial``:
        sin/cos by Taylor expansions with Lagrange remainders, products truncated to ``degree``
        with remainders; valid for τ ∈ [0, 1]).  None when the model uses a function the
        polynomials do not support.  Rows are expanded ``PIECE_ROWS`` at a time and joined (the
        products hold about 1 MiB a row while they run: a polyline of 60 segments took 0.4 GiB).
        ``stop()``, asked after each chunk: when true, only the rows built so far are returned (the
        first rows, a multiple of ``PIECE_ROWS``: the time budget ran out)."""
        shape = (P0.shape[0],)
        a, h = np.broadcast_to(np.asarray(a, float), shape), np.broadcast_to(np.asarray(h, float), shape)
        parts = []
        for k in range(0, P0.shape[0], PIECE_ROWS):
            if parts and stop is not None and stop():
                break
            rows = slice(k, k + PIECE_ROWS)
            part = self._piece_polynomials(P0[rows], D[rows], a[rows], h[rows], degree)
            if part is None:
                return None
            parts.append(part)
        return parts[0] if len(parts) == 1 else _joined(parts)

    def _piece_polynomials(self, P0: Interval, D: Interval, a, h, degree: int) -> dict | None:
        robot = self.robot
        S, d = P0.shape
        A, H = Interval.from_bounds(np.asarray(a, float), np.asarray(a, float)), Interval.from_bounds(np.asarray(h, float), np.asarray(h, float))
        var = [Poly.from_coefficients([P0[:, k] + A * D[:, k], H * D[:, k]]) for k in range(d)]
        try:
            with degree_limit(degree):
                if robot.rigid_legs():       # l_i = C + R b_i − a_i: R, then one stacked product
                    pose = self._rigid_pose(var, S)
                else:
                    pose = PathPose.from_polys(self.vectors.evaluate(var, robot.parameters), self.n, S, self.with_R)
                out = self._functions(pose, var=var)
                out["degree_limit"] = degree   # the pair end-point terms, built when needed, too
        except NotImplementedError:
            return None
        return out

    def _rigid_pose(self, var, S) -> PathPose:
        """Leg vectors C + R b_i − a_i (and R) from the polynomial pose coordinates ``var`` of a
        robot with rigid legs (``Robot.rigid_legs``): R from the compiled model, then R b_i for
        every leg in one product (inside the caller's degree limit)."""
        robot = self.robot
        R = [r if isinstance(r, Poly) else Poly.from_coefficients([r if isinstance(r, Interval) else Interval(r)])
             for r in robot.compiled("R").evaluate(var, robot.parameters)]
        d = max(r.degree for r in R)
        Rm = Poly(np.stack([np.broadcast_to(padded(r.lo, d), (S, d + 1)) for r in R], 1).reshape(S, 3, 3, d + 1),
                  np.stack([np.broadcast_to(padded(r.hi, d), (S, d + 1)) for r in R], 1).reshape(S, 3, 3, d + 1))
        plat, base = self._stacked_points()                                  # (3, n): [coordinate, leg]
        Rb = (Rm[:, :, :, None] * plat).sum(axis=2)                           # (R b_i)_k: (S, 3, n)
        position = [k for k, name in enumerate(robot.pose_names) if name not in robot.angle_names]
        if position:                                                          # C (S, 3, 1); spherical: none
            zero = Poly(np.zeros((S, 1)), np.zeros((S, 1)))
            Rb = Rb + stacked([var[position[k]] if k < len(position) else zero for k in range(3)], 1)[:, :, None]
        legs = Rb - base
        out = PathPose.__new__(PathPose)
        out.legs = [legs[:, k] for k in range(3)]
        out.R = [Rm[:, k // 3, k % 3] for k in range(9)] if self.with_R else None
        return out

    def _functions(self, pose, linear=None, P0=None, var=None) -> dict:
        """The pose and every family's functions as polynomials in t (``Family.polynomials``), with
        the squared leg lengths when a family uses them."""
        out = {"pose": pose}
        if self.uses_lengths:
            out[LENGTHS] = legs_squared(pose)
        for f in self.families:
            polys = f.polynomials(pose, linear=linear, P0=P0, var=var)
            if polys is not None:
                out[f.key] = polys
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

        def put(col, cand, p):
            c = midpoint(p) if isinstance(p, Poly) else p
            out[:, col, cand, :c.shape[-1]] = c
            out[:, col, cand, c.shape[-1]:] = 0.0
            if isinstance(p, Poly):
                rad[:, col, cand, :c.shape[-1]] = 0.5 * (p.hi - p.lo)
        for f in self.families:
            f.crossings(polys, put)
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
            path = PolyPath(self, polys, rows, P0, D, tlo, thi)
        else:
            path = PathPoints(self, P0, D, tlo, thi, linear)
        rho = None
        if self.uses_lengths:
            rlo, rhi = path.range(LENGTHS, legs_squared)
            rho = sqrt(Interval.from_bounds(np.maximum(rlo, 0.0), np.maximum(rhi, 0.0)))
        for f in self.families:
            mlo[:, f.columns], mhi[:, f.columns], state[:, f.columns] = f.margins(path, rho, upper)
        return state, mlo, mhi


PIECE_ROWS = 128        # rows of ``piece_polynomials`` expanded at once


def _joined(parts: list):
    """The values computed for consecutive row chunks, joined along the rows: polynomials and intervals
    stacked (shorter polynomials padded with exact zero coefficients), lists, tables and path poses
    entry by entry; anything else (a degree limit, None) is the same in every chunk."""
    first = parts[0]
    if isinstance(first, Poly):
        n = max(p.lo.shape[-1] for p in parts)
        return Poly(np.concatenate([padded(p.lo, n - 1) for p in parts]),
                    np.concatenate([padded(p.hi, n - 1) for p in parts]))
    if isinstance(first, Interval):
        return Interval.from_bounds(np.concatenate([p.lo for p in parts]), np.concatenate([p.hi for p in parts]))
    if isinstance(first, (list, tuple)):
        return type(first)(_joined([p[i] for p in parts]) for i in range(len(first)))
    if isinstance(first, dict):
        return {k: _joined([p[k] for p in parts]) for k in first}
    if isinstance(first, PathPose):
        out = PathPose.__new__(PathPose)
        for name, value in vars(first).items():
            setattr(out, name, _joined([getattr(p, name) for p in parts]))
        return out
    if isinstance(first, np.ndarray):
        return np.concatenate(parts)
    if any(p != first for p in parts):
        raise ValueError(f"chunks of piece_polynomials disagree: {parts!r:.200}")
    return first
