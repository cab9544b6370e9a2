"""``interference``: the distance between the leg axes (segments [A_i, B_i]) at least r_i + r_j;
margin d_ij − r_i − r_j (length unit).

The segment-to-segment distance is exact (seed 000 digest, E9/E10/E12): the distance between the
lines bounds it from below; when the feet of the common perpendicular are proved inside both
segments it is the distance, when they are proved outside the minimum over the square of
segment parameters is on its boundary, where the four end-point terms give it
(docs/soundness.md, segment distance).  The distance from the points of one segment to the line
of the other bounds it from below too, and stays well defined for parallel legs (seed 000 digest,
E11), where the line distance is 0/0.
"""
from __future__ import annotations

from fractions import Fraction
import itertools

import numpy as np

from intervals import Interval, sqr, sqrt
from intervals.polynomial import Poly, padded
from intervals.rounding import down, up

from ..crossings import derivative, float_mul, midpoint
from ..pose import PathPose, broadcast, columns, cross, dot, enclose_all, stacked, sub
from .base import Family, Instance, states


class Interference(Family):
    constraint = "interference"
    key = "pair_lines"          # per pair: E, Δ and the feet numerators of the common perpendicular
    end_key = "pair_ends"       # per pair and end point: the point-to-segment terms

    @classmethod
    def build(cls, robot, base):
        return cls(robot, base)

    def __init__(self, robot, base):
        """``base``: the base points A_i as three (n,) enclosures (x, y, z; z = 0 for a planar robot)."""
        n = robot.n_legs
        self.pair_list = list(itertools.combinations(range(n), 2))
        radius = [Fraction(r) for r in robot.limits["leg_radius"]]
        self.r = enclose_all([Interval(radius[i] + radius[j]) for i, j in self.pair_list])
        self.r2 = sqr(self.r)
        I = np.array([i for i, _ in self.pair_list])
        J = np.array([j for _, j in self.pair_list])
        self.I, self.J = I, J
        self.w0 = [base[k][I] - base[k][J] for k in range(3)]        # A_i − A_j, (P,)
        self.instances = [Instance("interference", (i + 1, j + 1)) for i, j in self.pair_list]
        self._w0_poly = None

    @staticmethod
    def missing(robot):
        return None if "leg_radius" in robot.limits else "no [limits] leg_radius in the robot file"

    @property
    def n_pairs(self) -> int:
        return len(self.pair_list)

    def functions(self, pose: PathPose):
        """Per pair: line distance² − r² numerator E, Δ = |u×v|² and the feet numerators
        s, s − Δ, t, t − Δ of the common perpendicular (docs/soundness.md)."""
        L = pose.legs
        if isinstance(L[0], Poly):
            return self._line_polynomials(pose.vector())
        u = [columns(L[k], self.I) for k in range(3)]
        v = [columns(L[k], self.J) for k in range(3)]
        w0 = self.w0
        a, b, c = dot(u, u), dot(u, v), dot(v, v)
        d, e = dot(u, w0), dot(v, w0)
        uxv = cross(u, v)
        delta = dot(uxv, uxv)
        wc = dot(w0, uxv)
        s_num, t_num = b * e - c * d, a * e - b * d
        return [wc * wc - self.r2 * delta, delta, s_num, s_num - delta, t_num, t_num - delta]

    def _line_polynomials(self, vec: Poly):
        """``functions`` for polynomial legs ``vec`` (S, n, 3): the same formulas, with
        the products of one stage stacked into one outward-rounded product."""
        u, v = vec[:, self.I], vec[:, self.J]                                   # (S, P, 3)
        W = self._w0_vector()                                                   # (P, 3), degree 0
        _, first, second = slice(None), [1, 2, 0], [2, 0, 1]
        abc = (stacked([u, u, v], 2) * stacked([u, v, v], 2)).sum(axis=-1)    # a, b, c: (S, P, 3)
        de = (stacked([u, v], 2) * W[:, None]).sum(axis=-1)                    # d, e: (S, P, 2)
        pq = stacked([u[_, _, first], u[_, _, second]], 2) * stacked([v[_, _, second], v[_, _, first]], 2)
        uxv = pq[_, _, 0] - pq[_, _, 1]                                         # u × v: (S, P, 3)
        delta = (uxv * uxv).sum(axis=-1)
        wc = (uxv * W).sum(axis=-1)
        a, b, c, d, e = abc[_, _, 0], abc[_, _, 1], abc[_, _, 2], de[_, _, 0], de[_, _, 1]
        prod = stacked([b, c, a, b, wc], 2) * stacked([e, d, e, d, wc], 2)    # be, cd, ae, bd, wc²
        s_num, t_num = prod[_, _, 0] - prod[_, _, 1], prod[_, _, 2] - prod[_, _, 3]
        return [prod[_, _, 4] - self.r2 * delta, delta, s_num, s_num - delta, t_num, t_num - delta]

    def _w0_vector(self) -> Poly:
        if self._w0_poly is None:
            self._w0_poly = stacked([Poly.from_coefficients([x]) for x in self.w0], 1)
        return self._w0_poly

    def end_functions(self, pose: PathPose):
        """Per end point (A_i, B_i vs segment j; A_j, B_j vs segment i): τ numerator, τ − 1
        numerator, point-line numerator, |P − X|² − r², |P − Y|² − r², |Y − X|² (docs/soundness.md)."""
        L = pose.legs
        if isinstance(L[0], Poly):
            vec = pose.vector()
            return self._end_polynomials(vec[:, self.I], vec[:, self.J], self._w0_vector(), self.r2)
        u = [columns(L[k], self.I) for k in range(3)]
        v = [columns(L[k], self.J) for k in range(3)]
        w0, r2 = self.w0, self.r2
        a, c = dot(u, u), dot(v, v)
        ends = []
        neg_w0 = [-x for x in w0]
        for q, seg, seg2 in ((w0, v, c), ([w0[k] + u[k] for k in range(3)], v, c),
                             (neg_w0, u, a), ([neg_w0[k] + v[k] for k in range(3)], u, a)):
            q = [broadcast(x, seg[0]) if isinstance(x, Interval) and x.ndim == 1 else x for x in q]
            tau = dot(q, seg)
            qc = cross(q, seg)
            qe = sub(q, seg)
            ends += [tau, tau - seg2, dot(qc, qc) - r2 * seg2, dot(q, q) - r2, dot(qe, qe) - r2, seg2]
        return ends

    def _end_polynomials(self, u: Poly, v: Poly, W: Poly, r2: Interval):
        """``end_functions`` for polynomial legs u, v (batch shape (..., 3)), the constant
        A_i − A_j ``W`` (degree 0, broadcast to u) and r² (batch shape (...)): the four end points'
        terms stacked on one axis, each stage one outward-rounded product."""
        _, first, second = slice(None), [1, 2, 0], [2, 0, 1]
        pre = (_,) * (u.ndim - 1)
        W = Poly(np.broadcast_to(padded(W.lo, u.degree), u.lo.shape), np.broadcast_to(padded(W.hi, u.degree), u.hi.shape))
        axis = u.ndim - 1
        q = stacked([W, W + u, -W, v - W], axis)                               # the end points − X: (..., 4, 3)
        seg = stacked([v, v, u, u], axis)                                      # the other segment
        ac = (stacked([u, v], axis) * stacked([u, v], axis)).sum(axis=-1)     # |u|², |v|²: (..., 2)
        seg2 = ac[pre + ([1, 1, 0, 0],)]
        tau = (q * seg).sum(axis=-1)
        pq = stacked([q[pre + (_, first)], q[pre + (_, second)]], axis) * \
            stacked([seg[pre + (_, second)], seg[pre + (_, first)]], axis)
        qc = pq[pre + (0,)] - pq[pre + (1,)]                                    # q × seg: (..., 4, 3)
        qc2 = (qc * qc).sum(axis=-1)
        qe = q - seg
        sq = (stacked([q, qe], axis) * stacked([q, qe], axis)).sum(axis=-1)   # |q|², |q − seg|²: (..., 2, 4)
        r2 = r2[..., None]
        terms = [tau, tau - seg2, qc2 - r2 * seg2, sq[pre + (0,)] - r2, sq[pre + (1,)] - r2, seg2]
        return [t[pre + (e,)] for e in range(4) for t in terms]

    def end_items(self, vec: Poly, rows, pairs):
        """The 24 end-point polynomials (items,) of the (row, pair) items of the polynomial legs ``vec``."""
        u = Poly(vec.lo[rows, self.I[pairs]], vec.hi[rows, self.I[pairs]])
        v = Poly(vec.lo[rows, self.J[pairs]], vec.hi[rows, self.J[pairs]])
        W = self._w0_vector()
        return self._end_polynomials(u, v, Poly(W.lo[pairs], W.hi[pairs]), self.r2[pairs])

    def margins(self, path, rho, upper_wanted=True):
        """Enclosures of d_ij − (r_i + r_j) per pair (docs/soundness.md, segment distance).
        The end-point terms are bounded only for the (interval, pair) items where the line
        distance does not settle the bound (and, with ``upper_wanted``, where the feet of the
        common perpendicular are not proved inside the segments)."""
        P = len(self.pair_list)
        llo, lhi = path.range(self.key, self.functions)
        iv = lambda k: Interval.from_bounds(llo[:, k * P:(k + 1) * P], lhi[:, k * P:(k + 1) * P])  # noqa: E731
        delta = iv(1)
        s0, s1, t0, t1 = iv(2), iv(3), iv(4), iv(5)
        feet_in = (s0.lo >= 0) & (s1.hi <= 0) & (t0.lo >= 0) & (t1.hi <= 0) & (delta.lo > 0)
        feet_out = (s0.hi < 0) | (s1.lo > 0) | (t0.hi < 0) | (t1.lo > 0)
        line = path.ratio(self.key, self.functions, 0, 1, P)  # E / Δ: line distance² − r²
        lower = np.where(np.isnan(line.lo), -np.inf, line.lo)
        upper = np.where(feet_in & ~np.isnan(line.hi), line.hi, np.inf)
        need = ~feet_in & ((lower < 0) | upper_wanted)
        if need.any():
            rows, pairs = np.nonzero(need)
            (elo, ehi), pl = path.pair_ends(self, rows, pairs)   # (items, 4, 6), (items, 4)
            tau0, tau1, F0, F1 = (Interval.from_bounds(elo[..., k], ehi[..., k]) for k in (0, 1, 3, 4))
            before, after = tau0.hi <= 0, tau1.lo >= 0
            inside = (tau0.lo >= 0) & (tau1.hi <= 0)
            plo = np.where(np.isnan(pl.lo), -np.inf, pl.lo)
            clo = np.where(before, F0.lo, np.where(after, F1.lo, plo))       # point-segment distance² − r², lower
            chi = np.minimum(np.minimum(F0.hi, F1.hi), np.where(inside & ~np.isnan(pl.hi), pl.hi, np.inf))
            end_lower = clo.min(axis=1)
            end_upper = chi.min(axis=1)
            lower[rows, pairs] = np.maximum(lower[rows, pairs], _point_line_lower(elo, ehi, delta.hi[rows, pairs]))
            # the line distance is always a lower bound; when the feet of the common perpendicular
            # are outside [0, 1]², the minimum over the square is on its boundary: the end-point terms
            lower[rows, pairs] = np.where(feet_out[rows, pairs], np.maximum(lower[rows, pairs], end_lower),
                                          lower[rows, pairs])
            upper[rows, pairs] = np.minimum(upper[rows, pairs], end_upper)
        d2 = Interval.from_bounds(np.maximum(down(lower + self.r2.lo), 0.0), np.maximum(up(upper + self.r2.hi), 0.0))
        m = sqrt(d2) - self.r
        return m.lo, m.hi, states(m.lo, m.hi)

    def crossings(self, polys, put):
        E, delta = polys[self.key][:2]
        e, d = midpoint(E), midpoint(delta)
        stationary = float_mul(derivative(e), d) - float_mul(e, derivative(d))     # (E/Δ)' Δ²
        put(self.columns, 0, E)                                       # (S, pairs), one column per pair
        put(self.columns, 2, stationary)


def _point_line_lower(elo, ehi, delta_hi):
    """A lower bound of d² − r² per item from the points of each segment to the other's line.

    For X(s) = A_i + s u, s in [0, 1], and the line of leg j (direction v):
    dist(X(s), line)² |v|² = |c0 + s c1|² with c0 = (A_i − A_j) × v, c1 = u × v, and
    |c0 + s c1|² ≥ |c0|² + 2 s c0·c1 ≥ min(|c0|², |c0 + c1|² − |c1|²) on [0, 1] (linear in s);
    |c1|² = Δ.  The end-point terms hold |c0|² − r²|v|² (end 0, term 2), |c0 + c1|² − r²|v|²
    (end 1) and |v|² (term 5); ends 2 and 3 give the same for the points of leg j and the line of
    leg i.  The segment distance is at least the distance to the line, so d² − r² ≥ N / |v|² with
    N = min(term₀, term₁ − Δ).  For parallel legs (Δ = 0) this is the distance between them."""
    best = np.full(elo.shape[0], -np.inf)
    for first in (0, 2):
        n_lo = np.minimum(elo[:, first, 2], down(elo[:, first + 1, 2] - delta_hi))
        v2lo, v2hi = elo[:, first, 5], ehi[:, first, 5]
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = np.where(n_lo >= 0, down(n_lo / v2hi), np.where(v2lo > 0, down(n_lo / np.where(v2lo > 0, v2lo, 1.0)),
                                                                    -np.inf))
        best = np.maximum(best, np.where(np.isnan(bound), -np.inf, bound))
    return best

