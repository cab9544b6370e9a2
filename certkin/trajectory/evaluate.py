"""Path evaluators: enclosures over batches of t-intervals of the functions of the pose.

A constraint family (``trajectory.families``) asks an evaluator for the range of its functions of
the pose over each t-interval T of a segment (``range``, ``ratio``, ``range_det``,
``pair_ends``); the evaluator decides how:

- ``PathPoints``: the natural enclosure on pose(T) with the t-derivative (``autodiff.Dual``) and
  the values at the ends and the midpoint m of T: the range is hull(g(lo), g(hi)) when dg/dt has
  one sign on T, otherwise the mean-value form g(m) + g'(T)(T − m) ∩ g(T) (the mean-value theorem,
  exact: no truncated Taylor expansion);
- ``PolyPath``: the functions as polynomials in t, built once per search
  (``Constraints.polynomials``), bounded on each T by Bernstein coefficients
  (``intervals.polynomial``).
"""
from __future__ import annotations

import numpy as np

from intervals import Interval
from intervals.autodiff import Dual
from intervals.polynomial import Poly, bernstein_weights, degree_limit, padded, ratio_range

from .pose import PathPose


class PathPoints:
    """pose(T) with its t-derivative, and the thin poses at the ends and midpoints of T."""

    def __init__(self, constraints, P0: Interval, D: Interval, tlo, thi, linear=None):
        self.c = constraints
        self.P0, self.D, self.linear = P0, D, linear
        self.tlo, self.thi = np.asarray(tlo, dtype=np.float64), np.asarray(thi, dtype=np.float64)
        self.tm = 0.5 * (self.tlo + self.thi)
        self.N = N = len(self.tlo)
        self.T = T = Interval.from_bounds(self.tlo, self.thi)
        self._memo = {}
        d = P0.shape[-1]
        t3 = np.concatenate([self.tlo, self.tm, self.thi])
        self.t3 = Interval.from_bounds(t3, t3)
        tile = lambda x: Interval.from_bounds(np.tile(x.lo, (3, 1)), np.tile(x.hi, (3, 1)))  # noqa: E731
        n, with_R = constraints.n, constraints.with_R
        if linear is not None:            # constant orientation: legs linear in t, no trigonometry
            V, w, R = linear["V"], linear["w"], linear["R"]
            V3 = [Interval.from_bounds(np.tile(v.lo, (3, 1)), np.tile(v.hi, (3, 1))) for v in V]
            w3 = [Interval.from_bounds(np.tile(x.lo, 3), np.tile(x.hi, 3)) for x in w]
            R3 = None if R is None else [Interval.from_bounds(np.tile(x.lo, 3), np.tile(x.hi, 3)) for x in R]
            self.pose_dual = PathPose.linear(V, w, R, T, dual=True)
            self.pose_points = PathPose.linear(V3, w3, R3, self.t3, dual=False)
            self.duals = self.points = None
        else:
            self.duals = [Dual(P0[:, k] + T * D[:, k], Interval.from_bounds(D.lo[:, k, None], D.hi[:, k, None]))
                          for k in range(d)]
            P3 = tile(P0) + self.t3[:, None] * tile(D)
            self.points = [P3[:, k] for k in range(d)]
            params = constraints.robot.parameters
            self.pose_dual = PathPose(constraints.vectors.evaluate(self.duals, params), n, N, with_R)
            self.pose_points = PathPose(constraints.vectors.evaluate(self.points, params), n, 3 * N, with_R)

    def centre(self):
        """The platform origin C over T (Gough-Stewart: the first three pose coordinates)."""
        return [self.P0[:, k] + self.T * self.D[:, k] for k in range(3)]

    def range(self, key, fn):
        """(lo, hi) arrays (N, m): enclosures over T of the values ``fn(pose)`` (flattened), computed
        once per ``key``."""
        if key not in self._memo:
            self._memo[key] = self._combine(fn(self.pose_dual), fn(self.pose_points))
        return self._memo[key]

    def range_det(self, det):
        """(lo, hi) (N,): enclosures of det(A) over T (``det``: the determinant family)."""
        if det.laplace:                   # Gough-Stewart: natural LU-preconditioned enclosure over T
            legs = [x.value if isinstance(x, Dual) else x for x in self.pose_dual.legs]
            D = det.natural(legs, self.centre())
            return D.lo, D.hi
        duals, points = self.duals, self.points
        if duals is None:
            duals = [Dual(self.P0[:, k] + self.T * self.D[:, k], Interval.from_bounds(self.D.lo[:, k, None], self.D.hi[:, k, None]))
                     for k in range(self.P0.shape[-1])]
            tile = lambda x: Interval.from_bounds(np.tile(x.lo, (3, 1)), np.tile(x.hi, (3, 1)))  # noqa: E731
            P3 = tile(self.P0) + self.t3[:, None] * tile(self.D)
            points = [P3[:, k] for k in range(self.P0.shape[-1])]
        lo, hi = self._combine([det(duals)], [det(points)])
        return lo[:, 0], hi[:, 0]

    def ratio(self, key, fn, i, j, width):
        """Enclosure (N, width) of block i / block j of the flattened values of ``fn``."""
        lo, hi = self.range(key, fn)
        cols = lambda k: Interval.from_bounds(lo[:, k * width:(k + 1) * width], hi[:, k * width:(k + 1) * width])  # noqa: E731
        return cols(i) / cols(j)

    def pair_ends(self, family, rows, pairs):
        """End-point terms (items, 4, 6) of the (interval, pair) items ``rows``, ``pairs``, and
        the point-line distance² − r² (items, 4) (their third term over their sixth); ``family``:
        the interference family (``end_functions``, ``n_pairs``)."""
        P = family.n_pairs
        elo, ehi = self._combine(family.end_functions(self.pose_dual), family.end_functions(self.pose_points))
        elo = elo.reshape(self.N, 4, 6, P)[rows, :, :, pairs]
        ehi = ehi.reshape(self.N, 4, 6, P)[rows, :, :, pairs]
        pl = Interval.from_bounds(elo[..., 2], ehi[..., 2]) / Interval.from_bounds(np.maximum(elo[..., 5], 0.0), ehi[..., 5])
        return (elo, ehi), pl

    def _combine(self, duals, pts):
        N = self.N
        los, his = [], []
        for g, p in zip(duals, pts):
            p = p if isinstance(p, Interval) else Interval(p)
            if p.ndim == 0 or p.shape[0] != 3 * N:
                p = Interval.from_bounds(np.broadcast_to(p.lo, (3 * N,) + p.shape[-1:] if p.ndim else (3 * N,)),
                                  np.broadcast_to(p.hi, (3 * N,) + p.shape[-1:] if p.ndim else (3 * N,)))
            a = Interval.from_bounds(p.lo[:N], p.hi[:N])
            m = Interval.from_bounds(p.lo[N:2 * N], p.hi[N:2 * N])
            b = Interval.from_bounds(p.lo[2 * N:], p.hi[2 * N:])
            if not isinstance(g, Dual):           # constant along the path
                lo, hi = a.lo, a.hi
            else:
                nat = g.value
                der = Interval.from_bounds(g.grad.lo[..., 0], g.grad.hi[..., 0])
                Tm = self.T - Interval.from_bounds(self.tm, self.tm)
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


class PolyPath:
    """Constant orientation: ranges over T of the constraint functions from their polynomials
    in t (``Constraints.polynomials``), by Bernstein bounds (``intervals.polynomial``)."""

    def __init__(self, constraints, polys, rows, P0: Interval, D: Interval, tlo, thi):
        self.c, self.polys, self.rows = constraints, polys, np.asarray(rows)
        self.P0, self.D = P0, D
        self.tlo, self.thi = np.asarray(tlo, dtype=np.float64), np.asarray(thi, dtype=np.float64)
        self.N = len(self.tlo)
        self._memo = {}

    def _stacked(self):
        """Every family's functions as one (S, m, n + 1) pair of coefficient arrays at the
        largest degree n (lower degrees padded with zero coefficients), with each family's
        column range; built once per search."""
        if "_stacked" not in self.polys:
            S = self.polys["pose"].legs[0].shape[0]
            items = [(key, p) for key in self.c.function_keys if key in self.polys for p in self.polys[key]]
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
        return Interval.from_bounds(b.lo[:, first:last], b.hi[:, first:last])

    def range(self, key, fn):
        b = self._bernstein(key)
        return b.lo.min(axis=-1), b.hi.max(axis=-1)

    def ratio(self, key, fn, i, j, width):
        """Enclosure (N, width) of block i / block j of the functions of ``fn`` (rational Bernstein bound)."""
        b = self._bernstein(key)
        cols = lambda k: Interval.from_bounds(b.lo[:, k * width:(k + 1) * width], b.hi[:, k * width:(k + 1) * width])  # noqa: E731
        return ratio_range(cols(i), cols(j))

    def range_det(self, det):
        if det.key in self.polys:
            b = self._bernstein(det.key)
            return b.lo[:, 0].min(axis=-1), b.hi[:, 0].max(axis=-1)
        return PathPoints(self.c, self.P0, self.D, self.tlo, self.thi).range_det(det)

    def pair_ends(self, family, rows, pairs):
        """End-point terms (items, 4, 6) of the (interval, pair) items ``rows``, ``pairs`` and the
        point-line distance² − r² (items, 4); their polynomials are built for a (row, pair) (row:
        segment or piece) when it first needs them, at the degree of the other families when not
        above it (one Bernstein map for all)."""
        key = family.end_key
        seg = self.rows[rows]
        P = family.n_pairs
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
                        for p in family.end_items(self.polys["pose"].vector(), todo[:, 0], todo[:, 1])]
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
        pl = ratio_range(Interval.from_bounds(blo[:, :, 2], bhi[:, :, 2]), Interval.from_bounds(blo[:, :, 5], bhi[:, :, 5]))
        return (blo.min(axis=-1), bhi.max(axis=-1)), pl
