"""The exact boundary of a section: certified arcs, area and perimeter.

Circle-circle intersection points are enclosed in closed form and verified (Krawczyk), arcs are
kept by certified midpoint tests, and area and perimeter are intervals (Green's formula, arc =
chord triangle + circular segment).  Any undecided sign (tangency, three circles through a
point) gives ``Boundary(reason=...)`` with ``area`` None, never a guess (docs/soundness.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
import math

import numpy as np

from intervals import Interval, sqr
from intervals.elementary import atan2, cos, sin, sqrt
from intervals.elementary import pi as PI

from .annuli import Legs, intersections, pairs


def _iv(lo, hi=None) -> Interval:
    lo = np.asarray(lo, dtype=np.float64)
    return Interval.from_bounds(lo, lo.copy() if hi is None else np.asarray(hi, dtype=np.float64))


_TWO_PI = Interval(2) * PI


def _x_minus_sin(D: Interval) -> Interval:
    """Enclosure of f(Δ) = Δ − sin Δ for Δ ≥ 0 (f increases; for Δ ≤ 1/4 the alternating
    series Δ³/3! − Δ⁵/5! + … − Δ¹³/13!, whose partial sums bracket f, avoids the cancellation)."""
    lo_pt, hi_pt = _iv(D.lo), _iv(D.hi)
    direct = Interval.from_bounds((lo_pt - sin(lo_pt)).lo, (hi_pt - sin(hi_pt)).hi)
    x2 = sqr(D)
    term, S = D * x2 * Interval(Fraction(1, 6)), Interval(np.zeros(D.shape))
    for k in range(1, 6):                                # t1 .. t5 with signs + − + − +
        S = S + term if k % 2 else S - term
        term = term * x2 * Interval(Fraction(1, (2 * k + 2) * (2 * k + 3)))
    series = Interval.from_bounds((S - term).lo, S.hi)          # S5 − t6 ≤ f ≤ S5
    small = D.hi <= 0.25
    out = Interval.from_bounds(np.where(small, series.lo, direct.lo), np.where(small, series.hi, direct.hi))
    return Interval.from_bounds(np.maximum(out.lo, 0.0), out.hi)


def _krawczyk(px, py, ax, ay, r2a, bx, by, r2b):
    """Krawczyk test of g = (|p − a|² − r2a, |p − b|² − r2b) = 0 on a box around each (px, py).

    Returns (ok (K,), x, y): where ok, K(X) ⊂ int X proves that X holds exactly one
    common point of the two circles (for every value of the centres and radii in
    their enclosures); x, y are then K(X) ∩ P (both hold the root).
    """
    mx, my = px.mid(), py.mid()
    e = 2.0 * np.maximum(px.rad(), py.rad()) + 2.0 ** -44 * (np.abs(mx) + np.abs(my) + np.abs(ax.mid()) + np.abs(ay.mid())
                                                            + np.sqrt(np.maximum(r2a.mid(), 0.0)))
    X, Y = Interval.from_bounds(mx - e, mx + e), Interval.from_bounds(my - e, my + e)
    M, N = _iv(mx), _iv(my)
    g1 = sqr(M - ax) + sqr(N - ay) - r2a
    g2 = sqr(M - bx) + sqr(N - by) - r2b
    j11, j12 = 2 * (mx - ax.mid()), 2 * (my - ay.mid())
    j21, j22 = 2 * (mx - bx.mid()), 2 * (my - by.mid())
    with np.errstate(divide="ignore", invalid="ignore"):
        det = j11 * j22 - j12 * j21
        c11, c12, c21, c22 = j22 / det, -j12 / det, -j21 / det, j11 / det
    c11, c12, c21, c22 = (_iv(np.where(np.isfinite(c), c, 0.0)) for c in (c11, c12, c21, c22))
    two = Interval(2)
    J11, J12, J21, J22 = two * (X - ax), two * (Y - ay), two * (X - bx), two * (Y - by)
    one = Interval(1)
    A11 = one - (c11 * J11 + c12 * J21)
    A12 = Interval(0) - (c11 * J12 + c12 * J22)
    A21 = Interval(0) - (c21 * J11 + c22 * J21)
    A22 = one - (c21 * J12 + c22 * J22)
    dX, dY = X - M, Y - N
    Kx = M - (c11 * g1 + c12 * g2) + (A11 * dX + A12 * dY)
    Ky = N - (c21 * g1 + c22 * g2) + (A21 * dX + A22 * dY)
    ok = (Kx.lo > X.lo) & (Kx.hi < X.hi) & (Ky.lo > Y.lo) & (Ky.hi < Y.hi) & np.isfinite(det) & (det != 0)
    return ok, Kx.intersect(px), Ky.intersect(py)


@dataclass
class Boundary:
    """The exact boundary of a section: ``area`` and ``perimeter`` (Interval) or None with ``reason``."""

    area: Interval | None = None
    perimeter: Interval | None = None
    arcs: list = field(default_factory=list)
    loops: int | None = None
    reason: str = ""

    @property
    def decided(self) -> bool:
        return self.area is not None


class _Undecided(Exception):
    """An exact answer cannot be given: ``boundary`` says why (or gives what is known)."""

    def __init__(self, boundary: Boundary):
        super().__init__(boundary.reason)
        self.boundary = boundary


def exact_boundary(legs: Legs, Z: Interval, origin=(0.0, 0.0)) -> Boundary:
    """Certified arcs, area and perimeter of the section at ``Z`` (a 0-d or 1-element Interval).

    Elements: the outer circle of every leg (keep the inside) and the inner
    circle where ρmin² − h² > 0 is proved (keep the outside).  Each circle is
    split at its intersection points with the circles of the other legs;
    a piece is kept when a point of its open arc strictly satisfies every
    other constraint, dropped when it strictly violates one; any other
    outcome makes the whole answer undecided.  Outer arcs run
    counter-clockwise, inner arcs clockwise, so Green's formula sums to the
    area: arc P0 → P1 of sweep Δ (signed) contributes
    ½ (P0 − o) × (P1 − o) + ½ r² (Δ − sin Δ), a full circle ±π r².
    """
    try:
        circles = _Circles(legs, Z.reshape(1))
        Px, Py, point_circles = _points(circles)
        pieces = _pieces(circles, Px, Py, point_circles)
        kept = _kept(circles, pieces)
        return _green(circles, pieces, kept, Px, Py, origin)
    except _Undecided as exc:
        return exc.boundary


class _Circles:
    """The circles of a section: the outer circle of every leg, then the inner ones that exist
    (``leg``, ``kind`` +1 outer / −1 inner, centres ``cx``, ``cy``, squared radii ``r2``)."""

    def __init__(self, legs: Legs, Z: Interval):
        r2in, r2out = legs.radii2(Z)
        r2in, r2out = r2in[0], r2out[0]
        n = legs.n
        if np.any(r2out.hi < 0):
            raise _Undecided(Boundary(Interval(0), Interval(0), [], 0))
        if np.any(r2out.lo <= 0):
            i = int(np.argmax(r2out.lo <= 0))
            raise _Undecided(Boundary(reason=f"the outer circle of leg {i + 1} may have radius 0 (the plane touches "
                                             "its sphere)"))
        if np.any(legs.equal):
            i = int(np.argmax(legs.equal))
            raise _Undecided(Boundary(Interval(0), None, [], None,
                                      reason=f"leg {i + 1} has rho_min = rho_max: the section lies on a circle (area 0)"))
        has_in = r2in.lo > 0
        no_in = (r2in.hi <= 0) | legs.zero_min
        if np.any(~has_in & ~no_in):
            i = int(np.argmax(~has_in & ~no_in))
            raise _Undecided(Boundary(reason=f"the inner circle of leg {i + 1} may have radius 0 (the plane touches "
                                             "its sphere)"))
        self.legs, self.r2in, self.r2out, self.has_in, self.no_in = legs, r2in, r2out, has_in, no_in
        self.leg = leg = np.concatenate([np.arange(n), np.nonzero(has_in)[0]])
        self.kind = kind = np.concatenate([np.ones(n, int), -np.ones(int(has_in.sum()), int)])
        self.count = len(leg)
        self.cx, self.cy = legs.ux[leg], legs.uy[leg]
        self.r2 = Interval.from_bounds(np.where(kind > 0, r2out.lo[leg], r2in.lo[leg]),
                                       np.where(kind > 0, r2out.hi[leg], r2in.hi[leg]))
        self.names = [f"{'outer' if kind[k] > 0 else 'inner'} circle of leg {leg[k] + 1}" for k in range(self.count)]


def _points(c: _Circles):
    """The intersection points of the circles of different legs, each proved (Krawczyk): their
    coordinates (2K,) (point 2p + s: pair p, sign s) and the two circles of each (2K, 2)."""
    a, b = pairs(c.count)
    keep = c.leg[a] != c.leg[b]
    a, b = a[keep], b[keep]
    ccx, ccy, cr2 = c.cx, c.cy, c.r2
    disc, D, plus, minus = intersections(ccx[a], ccy[a], cr2[a], ccx[b], ccy[b], cr2[b])
    same_centre = D.hi == 0
    coincident = same_centre & ~cr2[a].disjoint(cr2[b])
    doubtful = (~same_centre & (D.lo <= 0)) | (~same_centre & ~(disc.lo > 0) & ~(disc.hi < 0)) | coincident
    if doubtful.any():
        overlap = ~cr2[a].disjoint(cr2[b])          # (radii that may be equal: name such a pair first)
        alike = doubtful & (same_centre | (D.lo <= 0)) & overlap
        p = int(np.argmax(alike)) if alike.any() else int(np.argmax(doubtful))
        why = "may be tangent" if not (same_centre[p] or D.lo[p] <= 0) else "may coincide" if overlap[p] else \
            "may have the same centre (not resolved)"
        raise _Undecided(Boundary(reason=f"the {c.names[a[p]]} and the {c.names[b[p]]} {why}"))
    two = ~same_centre & (disc.lo > 0)
    a2, b2 = a[two], b[two]
    pts = []                                   # per sign: (x, y) enclosures of the points of the meeting pairs
    for P in (plus, minus):
        px, py = P[0][two], P[1][two]
        ok, x, y = _krawczyk(px, py, ccx[a2], ccy[a2], cr2[a2], ccx[b2], ccy[b2], cr2[b2])
        if not ok.all():
            p = int(np.argmax(~ok))
            raise _Undecided(Boundary(reason=f"the intersection of the {c.names[a2[p]]} and the {c.names[b2[p]]} "
                                             "could not be verified (Krawczyk)"))
        pts.append((x, y))
    Px = Interval.from_bounds(np.stack([pts[0][0].lo, pts[1][0].lo], 1).ravel(),
                              np.stack([pts[0][0].hi, pts[1][0].hi], 1).ravel())
    Py = Interval.from_bounds(np.stack([pts[0][1].lo, pts[1][1].lo], 1).ravel(),
                              np.stack([pts[0][1].hi, pts[1][1].hi], 1).ravel())
    return Px, Py, np.repeat(np.stack([a2, b2], 1), 2, axis=0)


def _pieces(c: _Circles, Px, Py, point_circles):
    """Every circle cut at its points, in angular order: (circle, start id or −1, end id or −1,
    θ_start, θ_end, φ_ref, test angle (relative to φ_ref), wrap) per piece."""
    pieces = []
    for k in range(c.count):
        ids = np.nonzero((point_circles == k).any(axis=1))[0]
        if not len(ids):
            pieces.append((k, -1, -1, None, None, 0.0, Interval(0), False))
            continue
        vx, vy = Px[ids] - c.cx[k], Py[ids] - c.cy[k]
        fa = np.sort(np.arctan2(vy.mid(), vx.mid()))
        gaps = np.diff(np.concatenate([fa, [fa[0] + 2 * np.pi]]))
        g = int(np.argmax(gaps))
        ref = float(math.remainder(fa[g] + gaps[g] / 2 + np.pi, 2 * np.pi))   # the cut lies opposite ref
        cr, sr = cos(Interval(ref)), sin(Interval(ref))
        theta = atan2(Interval(0) - vx * sr + vy * cr, vx * cr + vy * sr)     # angles relative to ref
        order = np.argsort(theta.mid())
        ids, theta = ids[order], theta[order]
        sep = np.all(theta.hi[:-1] < theta.lo[1:]) and theta.lo[0] > -float(PI.lo) and theta.hi[-1] < float(PI.lo)
        if not sep:
            raise _Undecided(Boundary(reason=f"the intersection points on the {c.names[k]} are not separated "
                                             "(three circles through one point, or a tangency)"))
        for i in range(len(ids) - 1):
            m = 0.5 * theta.hi[i] + 0.5 * theta.lo[i + 1]
            if not theta.hi[i] < m < theta.lo[i + 1]:
                raise _Undecided(Boundary(reason=f"two intersection points on the {c.names[k]} are too close to "
                                                 "separate"))
            pieces.append((k, ids[i], ids[i + 1], theta[i], theta[i + 1], ref, Interval(m), False))
        pieces.append((k, ids[-1], ids[0], theta[len(ids) - 1], theta[0], ref, PI, True))
    return pieces


def _kept(c: _Circles, pieces):
    """The midpoint test of every piece at once: kept (the midpoint strictly satisfies every other
    constraint) or dropped (it strictly violates one); anything else is undecided."""
    legs = c.legs
    pk = np.array([p[0] for p in pieces])
    alpha = Interval.from_bounds(np.array([float(p[6].lo) for p in pieces]), np.array([float(p[6].hi) for p in pieces])) \
        + _iv(np.array([p[5] for p in pieces]))
    rad = sqrt(c.r2[pk])
    Mx, My = c.cx[pk] + rad * cos(alpha), c.cy[pk] + rad * sin(alpha)
    d2 = sqr(Mx.reshape(-1, 1) - legs.ux) + sqr(My.reshape(-1, 1) - legs.uy)          # (P, n)
    out_ok, out_bad = d2.hi < c.r2out.lo, d2.lo > c.r2out.hi
    in_ok, in_bad = (d2.lo > c.r2in.hi) | c.no_in, (d2.hi < c.r2in.lo) & c.has_in
    rows = np.arange(len(pieces))
    own_leg, own_kind = c.leg[pk], c.kind[pk]
    out_ok[rows[own_kind > 0], own_leg[own_kind > 0]] = True
    out_bad[rows[own_kind > 0], own_leg[own_kind > 0]] = False
    in_ok[rows[own_kind < 0], own_leg[own_kind < 0]] = True
    in_bad[rows[own_kind < 0], own_leg[own_kind < 0]] = False
    drop = (out_bad | in_bad).any(axis=1)
    kept = ~drop & (out_ok & in_ok).all(axis=1)
    if np.any(~drop & ~kept):
        p = int(np.argmax(~drop & ~kept))
        raise _Undecided(Boundary(reason=f"the midpoint test of an arc of the {c.names[pieces[p][0]]} is undecided"))
    return kept


def _green(c: _Circles, pieces, kept, Px, Py, origin) -> Boundary:
    """Area and perimeter of the kept arcs (Green's formula around ``origin``), the arcs, and the
    number of closed loops they chain into."""
    ox, oy = _iv(origin[0]), _iv(origin[1])
    area, perim = Interval(0), Interval(0)
    arcs, links, full_circles = [], {}, 0
    half = Interval("0.5")
    for p in np.nonzero(kept)[0]:
        k, s, e, ts, te, ref, _, wrap = pieces[p]
        r2k, rk = c.r2[k], sqrt(c.r2[k])
        centre = [float(c.cx[k].mid()), float(c.cy[k].mid())]
        entry = {"leg": int(c.leg[k]) + 1, "circle": "outer" if c.kind[k] > 0 else "inner", "center": centre,
                 "radius": [float(rk.lo), float(rk.hi)]}
        if s < 0:                                            # a whole circle
            full_circles += 1
            area = area + (PI * r2k if c.kind[k] > 0 else Interval(0) - PI * r2k)
            perim = perim + _TWO_PI * rk
            start = [centre[0] + float(rk.mid()), centre[1]]
            sweep = _TWO_PI if c.kind[k] > 0 else Interval(0) - _TWO_PI
            entry.update({"from": start, "to": start, "sweep": [float(sweep.lo), float(sweep.hi)]})
            arcs.append(entry)
            continue
        ccw = te - ts + (_TWO_PI if wrap else Interval(0))    # > 0
        if c.kind[k] > 0:
            P0, P1, delta = s, e, ccw
        else:
            P0, P1, delta = e, s, Interval(0) - ccw
        f = _x_minus_sin(ccw)
        seg = half * r2k * (f if c.kind[k] > 0 else Interval(0) - f)
        x0, y0, x1, y1 = Px[P0] - ox, Py[P0] - oy, Px[P1] - ox, Py[P1] - oy
        area = area + half * (x0 * y1 - y0 * x1) + seg
        perim = perim + rk * ccw
        if P0 in links:
            return Boundary(reason="the kept arcs do not chain into closed loops")
        links[int(P0)] = int(P1)
        entry.update({"from": [float(Px[P0].mid()), float(Py[P0].mid())],
                      "to": [float(Px[P1].mid()), float(Py[P1].mid())],
                      "sweep": [float(delta.lo), float(delta.hi)]})
        arcs.append(entry)
    loops = full_circles
    if sorted(links) != sorted(links.values()):
        return Boundary(reason="the kept arcs do not chain into closed loops")
    seen = set()
    for start in links:
        if start in seen:
            continue
        loops += 1
        j = start
        while j not in seen:
            seen.add(j)
            j = links[j]
    return Boundary(area, perim, arcs, loops)
