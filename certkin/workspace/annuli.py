"""The annuli of a constant orientation (seed 004 §3.2, spec §6.2), and the domain of a section.

With the orientation R fixed, leg i of a Gough-Stewart platform keeps the platform point
C = (X, Y, z) in a spherical shell around u_i = A_i − R b_i (the position of C that would put B_i
on A_i):

    ρmin_i² ≤ (X − u_ix)² + (Y − u_iy)² + (z − u_iz)² ≤ ρmax_i²,

so the section z = const is the intersection of the annuli R_in,i² ≤ (X − u_ix)² + (Y − u_iy)² ≤
R_out,i² with R² = ρ² − (z − u_iz)².  A planar 3-RPR robot at a fixed angle phi is the same
problem with u_iz = z = 0.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
import math
import time

import numpy as np

from intervals import Interval, sqr
from intervals.elementary import cos, sin, sqrt

from ..errors import InputError

ORIENTATION = {"gough-stewart": ("psi", "theta", "phi"), "planar-3rpr": ("phi",)}     # the kinds that translate


def check_robot(robot):
    source = getattr(robot, "source", "") or getattr(robot, "name", "robot")
    if robot.kind not in ORIENTATION:
        raise InputError(source, "kind", f"the constant-orientation workspace needs a robot that translates "
                                         f"(gough-stewart or planar-3rpr), not {robot.kind}")
    if "leg_length" not in robot.limits:
        raise InputError(source, "limits.leg_length", "the workspace needs [min, max] leg-length limits for every leg")


# ---------------------------------------------------------------------------
# the annuli of one orientation
# ---------------------------------------------------------------------------
@dataclass
class Legs:
    """u_i = A_i − R b_i (enclosures, (n,) each) and the squared leg-length limits."""

    ux: Interval
    uy: Interval
    uz: Interval
    rmin2: Interval
    rmax2: Interval
    equal: np.ndarray          # (n,) bool: rho_min == rho_max exactly
    zero_min: np.ndarray       # (n,) bool: rho_min == 0 exactly (no inner constraint)

    @property
    def n(self) -> int:
        return self.ux.shape[0]

    def h2(self, Z: Interval) -> Interval:
        """(z − u_iz)² for each z-interval: Z (m,) -> (m, n)."""
        return sqr(Z.reshape(-1, 1) - self.uz)

    def radii2(self, Z: Interval):
        """(R_in², R_out²), each (m, n): ρ² − (z − u_iz)² over each z-interval of Z (m,)."""
        h2 = self.h2(Z)
        return self.rmin2 - h2, self.rmax2 - h2


def _rot(axis, c, s, v):
    x, y, z = v
    if axis == "z":
        return (c * x - s * y, s * x + c * y, z)
    return (x, c * y - s * z, s * y + c * z)


def leg_data(robot, angles) -> Legs:
    """The u_i and limits of ``robot`` at the orientation ``angles`` (enclosures from ``parse_orientation``)."""
    base = [[Interval(t) for t in p] for p in robot.base]
    plat = [[Interval(t) for t in p] for p in robot.platform]
    n = robot.n_legs
    if robot.kind == "gough-stewart":
        psi, theta, phi = angles
        cs = [(cos(a), sin(a)) for a in (psi, theta, phi)]
        u = []
        for a, b in zip(base, plat):
            v = _rot("z", *cs[2], b)
            v = _rot("x", *cs[1], v)
            v = _rot("z", *cs[0], v)
            u.append([a[k] - v[k] for k in range(3)])
    else:
        (phi,) = angles
        c, s = cos(phi), sin(phi)
        u = [[a[0] - (c * b[0] - s * b[1]), a[1] - (s * b[0] + c * b[1]), Interval(0)] for a, b in zip(base, plat)]
    comp = [Interval.from_bounds(np.array([float(u[i][k].lo) for i in range(n)]), np.array([float(u[i][k].hi) for i in range(n)]))
            for k in range(3)]
    limits = robot.limits["leg_length"]
    rmin = Interval(np.array([str(p[0]) for p in limits]))
    rmax = Interval(np.array([str(p[1]) for p in limits]))
    equal = np.array([Fraction(str(p[0])) == Fraction(str(p[1])) for p in limits])
    zero = np.array([Fraction(str(p[0])) == 0 for p in limits])
    rmin2 = sqr(rmin)
    rmin2.hi[zero] = 0.0                       # rho_min = 0: the inner constraint is vacuous, exactly
    return Legs(comp[0], comp[1], comp[2], rmin2, sqr(rmax), equal, zero)


# ---------------------------------------------------------------------------
# circle-circle intersections (closed form) and the domain
# ---------------------------------------------------------------------------
def pairs(n):
    a, b = np.triu_indices(n, 1)
    return a, b


def intersections(ax, ay, r2a, bx, by, r2b):
    """Enclosures of the intersection points of the circles (a, √r2a) and (b, √r2b).

    With d = b − a, Δ = |d|², s = Δ + r2a − r2b and disc = 4Δ·r2a − s²
    (16 × the squared area of the triangle of sides |d|, ra, rb): the circles
    meet iff disc ≥ 0, at a + (s/2Δ) d ± (√disc/2Δ) d⊥ with d⊥ = (−d_y, d_x).
    Returns (disc, Δ, (P+x, P+y), (P−x, P−y)); the negative part of disc is
    ignored by ``sqrt`` (a point that exists has disc ≥ 0), and Δ ∋ 0 gives
    unbounded enclosures.
    """
    dx, dy = bx - ax, by - ay
    D = sqr(dx) + sqr(dy)
    s = D + r2a - r2b
    disc = Interval(4) * D * r2a - sqr(s)
    twoD = Interval(2) * D
    t = s / twoD
    q = sqrt(disc) / twoD
    cx, cy = ax + t * dx, ay + t * dy
    plus = (cx - q * dy, cy + q * dx)
    minus = (cx + q * dy, cy - q * dx)
    return disc, D, plus, minus


def _finite(iv: Interval) -> Interval:
    """NaN endpoints (no information) become infinite ones."""
    return Interval.from_bounds(np.where(np.isnan(iv.lo), -np.inf, iv.lo), np.where(np.isnan(iv.hi), np.inf, iv.hi))


def section_domain(cx: Interval, cy: Interval, r2: Interval, deadline: float = math.inf):
    """Bounding boxes of the intersections of the disks (c_i, √r2_i), for each row of ``r2`` (m, n).

    Returns ``(lo (m, 2), hi (m, 2), empty (m,))``.  Two valid bounds per
    side, the smaller kept.  (1) The nearest side of one disk's own bounding
    box.  (2) The *candidates*: the maximum of x over a non-empty
    intersection K of disks is attained at a point p of K; if one circle is
    active at p, p is the rightmost point of that disk; if two or more are,
    p is an intersection point of two of the circles (or of coincident
    circles, back to the first case).  So every extreme of K is among the
    four extreme points of each disk and the pairwise intersection points,
    and it is not outside any disk: the bound is the extreme of the
    candidates not proved outside some disk, and no candidate left means K
    is empty.  (1) costs O(n) per row; (2), O(n³), is computed for rows in
    chunks until ``time.perf_counter()`` passes ``deadline`` (the rest keep
    (1): a wider box, as valid).  When the disks' boxes are disjoint under
    (1) alone, K is empty and lies in any box: the box between the two
    crossed sides is returned (the checker accepts it by the same rule).
    An interval radius (a z-slab) stands for its largest value.  The box is
    widened by a relative 2^-30 so that the checker's own enclosures fit in it.
    """
    r2 = Interval.from_bounds(np.atleast_2d(r2.lo), np.atleast_2d(r2.hi))
    m, n = r2.shape
    disk_empty = (r2.hi < 0).any(axis=1)
    r = sqrt(Interval.from_bounds(np.maximum(r2.lo, 0.0), np.maximum(r2.hi, 0.0)))       # (m, n)
    lo = np.stack([(cx - r).lo.max(axis=1), (cy - r).lo.max(axis=1)], 1)
    hi = np.stack([(cx + r).hi.min(axis=1), (cy + r).hi.min(axis=1)], 1)
    empty = disk_empty.copy()
    refined = np.zeros(m, bool)
    for start in range(0, m, CHUNK_ROWS):
        if time.perf_counter() > deadline:
            break
        rows = slice(start, min(m, start + CHUNK_ROWS))
        clo, chi, none = _candidate_bounds(cx, cy, r2[rows], r[rows])
        lo[rows], hi[rows] = np.maximum(lo[rows], clo), np.minimum(hi[rows], chi)
        empty[rows] |= none
        refined[rows] = True
    crossed = lo > hi
    empty |= refined & crossed.any(axis=1)
    lo, hi = np.where(crossed, hi, lo), np.where(crossed, lo, hi)     # disjoint disks (1): K is empty
    with np.errstate(invalid="ignore"):
        pad = 2.0 ** -30 * (hi - lo) + 2.0 ** -40 * np.maximum(np.abs(lo), np.abs(hi)) + 2.0 ** -1000
        lo, hi = lo - pad, hi + pad
    lo[empty], hi[empty] = 0.0, 0.0
    return lo, hi, empty


CHUNK_ROWS = 256        # rows of (2) between two looks at the clock: about 30 ms


def _candidate_bounds(cx: Interval, cy: Interval, r2: Interval, r: Interval):
    """Bound (2) of ``section_domain`` for rows ``r2`` (m, n): ``(lo (m, 2), hi (m, 2), empty (m,))``."""
    m, n = r2.shape
    X = [cx + r, cx - r, cx + Interval(np.zeros((m, n))), cx + Interval(np.zeros((m, n)))]
    Y = [cy + Interval(np.zeros((m, n))), cy + Interval(np.zeros((m, n))), cy + r, cy - r]
    dead = [np.zeros((m, n), bool)] * 4
    a, b = pairs(n)
    if len(a):
        disc, D, plus, minus = intersections(cx[a], cy[a], r2[:, a], cx[b], cy[b], r2[:, b])
        none = disc.hi < 0
        for P in (plus, minus):
            X.append(_finite(P[0] + Interval(np.zeros((m, len(a))))))
            Y.append(_finite(P[1] + Interval(np.zeros((m, len(a))))))
            dead.append(none)
    X = Interval.from_bounds(np.concatenate([x.lo for x in X], 1), np.concatenate([x.hi for x in X], 1))   # (m, C)
    Y = Interval.from_bounds(np.concatenate([y.lo for y in Y], 1), np.concatenate([y.hi for y in Y], 1))
    dead = np.concatenate(dead, 1) | (X.lo > X.hi) | (Y.lo > Y.hi)
    d2 = sqr(X.reshape(m, -1, 1) - cx) + sqr(Y.reshape(m, -1, 1) - cy)             # (m, C, n)
    dead |= (d2.lo > r2.hi[:, None, :]).any(axis=2)
    alive = ~dead
    with np.errstate(invalid="ignore"):
        lo = np.stack([np.where(alive, X.lo, np.inf).min(axis=1), np.where(alive, Y.lo, np.inf).min(axis=1)], 1)
        hi = np.stack([np.where(alive, X.hi, -np.inf).max(axis=1), np.where(alive, Y.hi, -np.inf).max(axis=1)], 1)
    return lo, hi, ~alive.any(axis=1)
