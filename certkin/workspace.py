"""Constant-orientation workspace (seed 004): certified sections and volumes.

With the orientation R fixed, leg i of a Gough-Stewart platform keeps the
platform point C = (X, Y, z) in a spherical shell around
u_i = A_i − R b_i (the position of C that would put B_i on A_i):

    ρmin_i² ≤ (X − u_ix)² + (Y − u_iy)² + (z − u_iz)² ≤ ρmax_i²,

so the section z = const is the intersection of the annuli
R_in,i² ≤ (X − u_ix)² + (Y − u_iy)² ≤ R_out,i² with R² = ρ² − (z − u_iz)²
(seed 004 §3.2, spec §6.2).  A planar 3-RPR robot at a fixed angle phi is
the same problem with u_iz = z = 0.  Only the leg-length limits are
constraints here: passive-joint limits and leg interference are *not*
taken into account (the results describe a superset of the workspace of a
robot that has such limits, and say so in ``ignored_limits``).

Three answers, each rigorous (outward-rounded ``intervals`` arithmetic):

* a **paving** of the section by the shared engine: a box is *inside* when
  for every leg the interval of ρ_i² over the box — the exact range up to
  rounding, every variable occurring once under ``sqr`` — lies in
  [ρmin², ρmax²]; *outside* when it is disjoint from it for one leg;
  otherwise it is bisected down to ``min_width`` (relative to the domain) and
  left as a *boundary* box.  area(inside) ≤ area(section) ≤
  area(inside ∪ boundary), whatever the budget.  The domain is the bounding
  box of the intersection of the outer disks (``section_domain``);
* the **exact boundary**: circle-circle intersection points enclosed in
  closed form and verified (Krawczyk), arcs kept by certified midpoint tests,
  area and perimeter as intervals (Green's formula, arc = chord triangle +
  circular segment).  Any undecided sign (tangency, three circles through a
  point) gives ``exact = None`` with the reason, never a guess;
* a **volume** bracket over z slabs, z kept as an interval per slab.

``workspace_section`` and ``workspace_volume`` return result objects with
``status``, ``to_json()``, ``certificate()`` (checked by ``proofs.workspace``)
and ``plot(path)``.  The soundness argument is in ``docs/soundness.md``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction
import json
import math
import sys
import time

import numpy as np

from intervals import Interval, sqr
from intervals.elementary import atan2, cos, sin, sqrt
from intervals.elementary import pi as PI
from intervals.rounding import down, down_sum, up, up_sum

from .engine.search import EXCLUDED, PROVED, UNDECIDED, Budget, search
from .errors import InputError
from .robots.base import parse_number
from .plots import _pyplot as pyplot

__all__ = ["workspace_section", "workspace_volume", "SectionResult", "VolumeResult", "section_domain",
           "exact_boundary", "parse_orientation", "describe", "add_arguments", "run"]

KINDS = {"gough-stewart": ("psi", "theta", "phi"), "planar-3rpr": ("phi",)}
MODEL = {"gough-stewart": "gough-stewart-workspace/1", "planar-3rpr": "planar-3rpr-workspace/1"}
DEFAULT_MIN_WIDTH = 1e-3          # paving resolution, relative to the domain
DEFAULT_MAX_BOXES = 1_000_000
DEFAULT_MAX_SECONDS = 60.0
DEFAULT_SLABS = 200
REASONS = ("inside: every leg length within its limits on the whole box",
           "outside: one leg length outside its limits on the whole box")


def _iv(lo, hi=None) -> Interval:
    lo = np.asarray(lo, dtype=np.float64)
    return Interval._raw(lo, lo.copy() if hi is None else np.asarray(hi, dtype=np.float64))


# ---------------------------------------------------------------------------
# input
# ---------------------------------------------------------------------------
def _exact_text(value) -> str:
    """A float becomes its exact decimal expansion (never the decimal it was printed from)."""
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value):
            return repr(float(value))
        return str(Decimal(float(value)))
    return value


def _number(value, option, name, angle):
    try:
        return parse_number(_exact_text(value), option, name, angle=angle)
    except InputError as exc:
        raise InputError(option, name, exc.problem) from None


def parse_orientation(robot, orientation, option="--orientation"):
    """([Interval] per angle, [exact text]) from ``"psi,theta,phi"`` (``deg`` allowed), a sequence or a mapping.

    ``None`` means every angle 0.  Planar robots take one angle, ``phi``.
    """
    names = KINDS[robot.kind]
    if orientation is None:
        parts = ["0"] * len(names)
    elif isinstance(orientation, str):
        parts = [p.strip() for p in orientation.split(",")]
    elif isinstance(orientation, dict):
        unknown = [k for k in orientation if k not in names]
        if unknown:
            raise InputError(option, str(unknown[0]), f"unknown angle (the angles are {','.join(names)})")
        parts = [orientation.get(n, "0") for n in names]
    else:
        try:
            parts = list(orientation)
        except TypeError:
            parts = [orientation]
    if len(parts) != len(names):
        raise InputError(option, "", f"expected {len(names)} comma-separated angles ({','.join(names)}), "
                                     f"got {len(parts)}")
    ivs, texts = [], []
    for name, p in zip(names, parts):
        if isinstance(p, str) and not p.strip():
            raise InputError(option, name, "missing value")
        iv, text = _number(p, option, name, True)
        ivs.append(iv)
        texts.append(str(text))
    return ivs, texts


def _parse_z(value, option="--z", name="z"):
    if value is None or (isinstance(value, str) and not value.strip()):
        raise InputError(option, name, "missing value")
    iv, text = _number(value.strip() if isinstance(value, str) else value, option, name, False)
    return iv, str(text)


def _parse_range(value, option="--z-range"):
    if isinstance(value, str):
        parts = value.split(":")
        if len(parts) != 2:
            raise InputError(option, "z", f"expected lo:hi, got {value!r}")
    else:
        parts = list(value)
        if len(parts) != 2:
            raise InputError(option, "z", "expected (lo, hi)")
    (a, ta), (b, tb) = _parse_z(parts[0], option, "z"), _parse_z(parts[1], option, "z")
    if not Fraction(ta) < Fraction(tb):
        raise InputError(option, "z", f"lower bound {ta} must be below upper bound {tb}")
    return (a, ta), (b, tb)


def _check_robot(robot):
    source = getattr(robot, "source", "") or getattr(robot, "name", "robot")
    if robot.kind not in KINDS:
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
    comp = [Interval._raw(np.array([float(u[i][k].lo) for i in range(n)]), np.array([float(u[i][k].hi) for i in range(n)]))
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
def _pairs(n):
    a, b = np.triu_indices(n, 1)
    return a, b


def _intersections(ax, ay, r2a, bx, by, r2b):
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
    return Interval._raw(np.where(np.isnan(iv.lo), -np.inf, iv.lo), np.where(np.isnan(iv.hi), np.inf, iv.hi))


def section_domain(cx: Interval, cy: Interval, r2: Interval):
    """Bounding boxes of the intersections of the disks (c_i, √r2_i), for each row of ``r2`` (m, n).

    Returns ``(lo (m, 2), hi (m, 2), empty (m,))``.  Argument: the maximum of x
    over a non-empty intersection K of disks is attained at a point p of K;
    if one circle is active at p, p is the rightmost point of that disk; if
    two or more are, p is an intersection point of two of the circles (or of
    coincident circles, back to the first case).  So every extreme of K is
    among the *candidates* (the four extreme points of each disk and the
    pairwise intersection points), and it is not outside any disk.  The
    bound on each side is the extreme of the candidates not proved outside
    some disk, and also (always valid) the nearest side of one disk's own
    bounding box: the smaller of the two is kept.  No candidate left means K
    is empty.  An interval radius (a z-slab) stands for its largest value.
    The box is widened by a relative 2^-30 so that the checker's own
    enclosures fit in it.
    """
    r2 = Interval._raw(np.atleast_2d(r2.lo), np.atleast_2d(r2.hi))
    m, n = r2.shape
    disk_empty = (r2.hi < 0).any(axis=1)
    r = sqrt(Interval._raw(np.maximum(r2.lo, 0.0), np.maximum(r2.hi, 0.0)))       # (m, n)
    X = [cx + r, cx - r, cx + Interval(np.zeros((m, n))), cx + Interval(np.zeros((m, n)))]
    Y = [cy + Interval(np.zeros((m, n))), cy + Interval(np.zeros((m, n))), cy + r, cy - r]
    dead = [np.zeros((m, n), bool)] * 4
    a, b = _pairs(n)
    if len(a):
        disc, D, plus, minus = _intersections(cx[a], cy[a], r2[:, a], cx[b], cy[b], r2[:, b])
        none = disc.hi < 0
        for P in (plus, minus):
            X.append(_finite(P[0] + Interval(np.zeros((m, len(a))))))
            Y.append(_finite(P[1] + Interval(np.zeros((m, len(a))))))
            dead.append(none)
    X = Interval._raw(np.concatenate([x.lo for x in X], 1), np.concatenate([x.hi for x in X], 1))   # (m, C)
    Y = Interval._raw(np.concatenate([y.lo for y in Y], 1), np.concatenate([y.hi for y in Y], 1))
    dead = np.concatenate(dead, 1) | (X.lo > X.hi) | (Y.lo > Y.hi)
    d2 = sqr(X.reshape(m, -1, 1) - cx) + sqr(Y.reshape(m, -1, 1) - cy)             # (m, C, n)
    dead |= (d2.lo > r2.hi[:, None, :]).any(axis=2)
    alive = ~dead
    with np.errstate(invalid="ignore"):
        xlo = np.where(alive, X.lo, np.inf).min(axis=1)
        xhi = np.where(alive, X.hi, -np.inf).max(axis=1)
        ylo = np.where(alive, Y.lo, np.inf).min(axis=1)
        yhi = np.where(alive, Y.hi, -np.inf).max(axis=1)
    xlo = np.maximum(xlo, (cx - r).lo.max(axis=1))
    xhi = np.minimum(xhi, (cx + r).hi.min(axis=1))
    ylo = np.maximum(ylo, (cy - r).lo.max(axis=1))
    yhi = np.minimum(yhi, (cy + r).hi.min(axis=1))
    empty = disk_empty | ~alive.any(axis=1) | (xlo > xhi) | (ylo > yhi)
    lo = np.stack([xlo, ylo], 1)
    hi = np.stack([xhi, yhi], 1)
    with np.errstate(invalid="ignore"):
        pad = 2.0 ** -30 * (hi - lo) + 2.0 ** -40 * np.maximum(np.abs(lo), np.abs(hi)) + 2.0 ** -1000
        lo, hi = lo - pad, hi + pad
    lo[empty], hi[empty] = 0.0, 0.0
    return lo, hi, empty


# ---------------------------------------------------------------------------
# the paving (one engine search; each root is one section or one z-slab)
# ---------------------------------------------------------------------------
class PavingProblem:
    """Decides batches of (X, Y) boxes; root k carries the z-interval Z[k]."""

    reasons = REASONS

    def __init__(self, legs: Legs, Z: Interval):
        self.legs = legs
        self.h2 = legs.h2(Z)                                   # (m, n)

    def rho2(self, lo, hi, roots) -> Interval:
        """Exact range (up to rounding) of ρ_i² over each box: (N, n)."""
        L = self.legs
        X = Interval._raw(lo[:, 0:1], hi[:, 0:1])
        Y = Interval._raw(lo[:, 1:2], hi[:, 1:2])
        return sqr(X - L.ux) + sqr(Y - L.uy) + self.h2[roots]

    def decide(self, lo, hi, roots):
        from .engine.search import OPEN, Decisions
        L = self.legs
        d2 = self.rho2(lo, hi, roots)
        inside = ((d2.lo >= L.rmin2.hi) & (d2.hi <= L.rmax2.lo)).all(axis=1)
        out = (d2.hi < L.rmin2.lo) | (d2.lo > L.rmax2.hi)
        excluded = out.any(axis=1) & ~inside
        leg = np.argmax(out, axis=1)
        status = np.where(inside, PROVED, np.where(excluded, EXCLUDED, OPEN)).astype(np.int8)
        reason = np.where(inside, 0, 1)
        return Decisions(status=status, reason=reason, evidence={"leg": (excluded, leg[excluded])})


@dataclass
class Paving:
    """The leaves of one root of the search: boxes (lo, hi) and kind, with the excluding leg."""

    tree: object
    root: int

    def leaves(self, kind):
        return self.tree.leaves(self.root, kind)

    def counts(self) -> dict:
        return {"inner_boxes": int(len(self.leaves(PROVED))), "boundary_boxes": int(len(self.leaves(UNDECIDED))),
                "outside_boxes": int(len(self.leaves(EXCLUDED)))}

    def _areas(self, ids):
        t = self.tree
        w = t.hi[ids] - t.lo[ids]
        wlo, whi = down_sum(w), up_sum(w)
        lo = np.maximum(down(wlo[:, 0] * wlo[:, 1]), 0.0)
        hi = up(whi[:, 0] * whi[:, 1])
        return lo, hi

    def inner_area(self) -> float:
        """A lower bound of the area of the inside boxes (rounded down)."""
        lo, _ = self._areas(self.leaves(PROVED))
        return float(np.nextafter(math.fsum(lo), -np.inf)) if len(lo) else 0.0

    def outer_area(self) -> float:
        """An upper bound of the area of the inside and boundary boxes (rounded up)."""
        ids = np.concatenate([self.leaves(PROVED), self.leaves(UNDECIDED)])
        _, hi = self._areas(ids)
        return float(np.nextafter(math.fsum(hi), np.inf)) if len(hi) else 0.0

    def boxes(self, kind) -> tuple[np.ndarray, np.ndarray]:
        ids = self.leaves(kind)
        return self.tree.lo[ids], self.tree.hi[ids]

    def certificate_tree(self, leg_names=None) -> dict:
        t = self.tree

        def leaf(i):
            box = [[float(t.lo[i, 0]), float(t.hi[i, 0])], [float(t.lo[i, 1]), float(t.hi[i, 1])]]
            if t.kind[i] == PROVED:
                return {"leaf": "inside", "box": box}
            if t.kind[i] == EXCLUDED:
                return {"leaf": "outside", "leg": int(t.evidence_of(i, ("leg",))["leg"]) + 1, "box": box}
            return {"leaf": "boundary", "box": box}

        return t.nested(self.root, leaf)


def _pave(legs, Z, lo, hi, budget, progress, floor=0.0):
    """Pave the domains [lo, hi] (k, 2) with z-intervals Z (k,) in one search.

    ``budget.min_width`` is relative to the extent of the set, not of the
    domain (the outer disks' box can be far larger than a section bounded by
    inner circles): a first search at resolution 1/64 gives the hull of the
    boxes not proved outside, whose widths become the scale.  The scale only
    decides when to stop splitting; the tree of the second search, rooted at
    the domain, is the answer.  ``floor``: an absolute side below which
    splitting is pointless (for z-slabs, how far the boundary moves across
    the slab).
    """
    problem = PavingProblem(legs, Z)
    width = np.max(hi - lo, axis=0)
    scale = np.where(width > 0, width, 1.0)
    t0 = time.perf_counter()
    first = search(problem, lo, hi, scale=scale, budget=Budget(budget.max_boxes, budget.max_seconds, 1.0 / 64))
    t = first.tree
    live = t.leaf_mask() & (t.kind != EXCLUDED)
    if live.any() and not first.exhausted:
        hull = np.max(t.hi[live], axis=0) - np.min(t.lo[live], axis=0)
        scale = np.where(hull > 0, np.minimum(hull, scale), scale)
    left = budget.max_seconds - (time.perf_counter() - t0)
    min_width = max(budget.min_width, min(float(np.max(floor / scale)), 1.0 / 64))
    budget = Budget(budget.max_boxes, max(left, 1e-3), min_width)
    return search(problem, lo, hi, scale=scale, budget=budget, progress=progress)


# ---------------------------------------------------------------------------
# the exact boundary
# ---------------------------------------------------------------------------
_TWO_PI = Interval(2) * PI


def _x_minus_sin(D: Interval) -> Interval:
    """Enclosure of f(Δ) = Δ − sin Δ for Δ ≥ 0 (f increases; for Δ ≤ 1/4 the alternating
    series Δ³/3! − Δ⁵/5! + … − Δ¹³/13!, whose partial sums bracket f, avoids the cancellation)."""
    lo_pt, hi_pt = _iv(D.lo), _iv(D.hi)
    direct = Interval._raw((lo_pt - sin(lo_pt)).lo, (hi_pt - sin(hi_pt)).hi)
    x2 = sqr(D)
    term, S = D * x2 * Interval(Fraction(1, 6)), Interval(np.zeros(D.shape))
    for k in range(1, 6):                                # t1 .. t5 with signs + − + − +
        S = S + term if k % 2 else S - term
        term = term * x2 * Interval(Fraction(1, (2 * k + 2) * (2 * k + 3)))
    series = Interval._raw((S - term).lo, S.hi)          # S5 − t6 ≤ f ≤ S5
    small = D.hi <= 0.25
    out = Interval._raw(np.where(small, series.lo, direct.lo), np.where(small, series.hi, direct.hi))
    return Interval._raw(np.maximum(out.lo, 0.0), out.hi)


def _krawczyk(px, py, ax, ay, r2a, bx, by, r2b):
    """Krawczyk test of g = (|p − a|² − r2a, |p − b|² − r2b) = 0 on a box around each (px, py).

    Returns (ok (K,), x, y): where ok, K(X) ⊂ int X proves that X holds exactly one
    common point of the two circles (for every value of the centres and radii in
    their enclosures); x, y are then K(X) ∩ P (both hold the root).
    """
    mx, my = px.mid(), py.mid()
    e = 2.0 * np.maximum(px.rad(), py.rad()) + 2.0 ** -44 * (np.abs(mx) + np.abs(my) + np.abs(ax.mid()) + np.abs(ay.mid())
                                                            + np.sqrt(np.maximum(r2a.mid(), 0.0)))
    X, Y = Interval._raw(mx - e, mx + e), Interval._raw(my - e, my + e)
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
    Z = Z.reshape(1)
    r2in, r2out = legs.radii2(Z)
    r2in, r2out = r2in[0], r2out[0]
    n = legs.n
    if np.any(r2out.hi < 0):
        return Boundary(Interval(0), Interval(0), [], 0)
    if np.any(r2out.lo <= 0):
        i = int(np.argmax(r2out.lo <= 0))
        return Boundary(reason=f"the outer circle of leg {i + 1} may have radius 0 (the plane touches its sphere)")
    if np.any(legs.equal):
        i = int(np.argmax(legs.equal))
        return Boundary(Interval(0), None, [], None,
                        reason=f"leg {i + 1} has rho_min = rho_max: the section lies on a circle (area 0)")
    has_in = r2in.lo > 0
    no_in = (r2in.hi <= 0) | legs.zero_min
    if np.any(~has_in & ~no_in):
        i = int(np.argmax(~has_in & ~no_in))
        return Boundary(reason=f"the inner circle of leg {i + 1} may have radius 0 (the plane touches its sphere)")
    # the circles: outer of every leg, then the existing inner ones
    leg = np.concatenate([np.arange(n), np.nonzero(has_in)[0]])
    kind = np.concatenate([np.ones(n, int), -np.ones(int(has_in.sum()), int)])
    C = len(leg)
    ccx, ccy = legs.ux[leg], legs.uy[leg]
    cr2 = Interval._raw(np.where(kind > 0, r2out.lo[leg], r2in.lo[leg]), np.where(kind > 0, r2out.hi[leg], r2in.hi[leg]))
    a, b = _pairs(C)
    keep = leg[a] != leg[b]
    a, b = a[keep], b[keep]
    names = [f"{'outer' if kind[k] > 0 else 'inner'} circle of leg {leg[k] + 1}" for k in range(C)]
    disc, D, plus, minus = _intersections(ccx[a], ccy[a], cr2[a], ccx[b], ccy[b], cr2[b])
    same_centre = D.hi == 0
    coincident = same_centre & ~cr2[a].disjoint(cr2[b])
    doubtful = (~same_centre & (D.lo <= 0)) | (~same_centre & ~(disc.lo > 0) & ~(disc.hi < 0)) | coincident
    if doubtful.any():
        p = int(np.argmax(doubtful))
        why = "may coincide" if same_centre[p] or D.lo[p] <= 0 else "may be tangent"
        return Boundary(reason=f"the {names[a[p]]} and the {names[b[p]]} {why}")
    two = ~same_centre & (disc.lo > 0)
    a2, b2 = a[two], b[two]
    pts = []                                   # per sign: (x, y) enclosures of the points of the meeting pairs
    for P in (plus, minus):
        px, py = P[0][two], P[1][two]
        ok, x, y = _krawczyk(px, py, ccx[a2], ccy[a2], cr2[a2], ccx[b2], ccy[b2], cr2[b2])
        if not ok.all():
            p = int(np.argmax(~ok))
            return Boundary(reason=f"the intersection of the {names[a2[p]]} and the {names[b2[p]]} "
                                   "could not be verified (Krawczyk)")
        pts.append((x, y))
    # point id 2p + s (pair p, sign s); coordinates as (2K,) intervals
    Px = Interval._raw(np.stack([pts[0][0].lo, pts[1][0].lo], 1).ravel(), np.stack([pts[0][0].hi, pts[1][0].hi], 1).ravel())
    Py = Interval._raw(np.stack([pts[0][1].lo, pts[1][1].lo], 1).ravel(), np.stack([pts[0][1].hi, pts[1][1].hi], 1).ravel())
    point_circles = np.repeat(np.stack([a2, b2], 1), 2, axis=0)       # (2K, 2)
    # pieces of every circle
    pieces = []      # (circle, start id or -1, end id or -1, θ_start, θ_end, φ_ref, test angle (rel.), wrap)
    for k in range(C):
        ids = np.nonzero((point_circles == k).any(axis=1))[0]
        if not len(ids):
            pieces.append((k, -1, -1, None, None, 0.0, Interval(0), False))
            continue
        vx, vy = Px[ids] - ccx[k], Py[ids] - ccy[k]
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
            return Boundary(reason=f"the intersection points on the {names[k]} are not separated "
                                   "(three circles through one point, or a tangency)")
        for i in range(len(ids) - 1):
            m = 0.5 * theta.hi[i] + 0.5 * theta.lo[i + 1]
            if not theta.hi[i] < m < theta.lo[i + 1]:
                return Boundary(reason=f"two intersection points on the {names[k]} are too close to separate")
            pieces.append((k, ids[i], ids[i + 1], theta[i], theta[i + 1], ref, Interval(m), False))
        pieces.append((k, ids[-1], ids[0], theta[len(ids) - 1], theta[0], ref, PI, True))
    # midpoint tests, all pieces at once
    pk = np.array([p[0] for p in pieces])
    alpha = Interval._raw(np.array([float(p[6].lo) for p in pieces]), np.array([float(p[6].hi) for p in pieces])) \
        + _iv(np.array([p[5] for p in pieces]))
    rad = sqrt(cr2[pk])
    Mx, My = ccx[pk] + rad * cos(alpha), ccy[pk] + rad * sin(alpha)
    d2 = sqr(Mx.reshape(-1, 1) - legs.ux) + sqr(My.reshape(-1, 1) - legs.uy)          # (P, n)
    out_ok, out_bad = d2.hi < r2out.lo, d2.lo > r2out.hi
    in_ok, in_bad = (d2.lo > r2in.hi) | no_in, (d2.hi < r2in.lo) & has_in
    rows = np.arange(len(pieces))
    own_leg, own_kind = leg[pk], kind[pk]
    out_ok[rows[own_kind > 0], own_leg[own_kind > 0]] = True
    out_bad[rows[own_kind > 0], own_leg[own_kind > 0]] = False
    in_ok[rows[own_kind < 0], own_leg[own_kind < 0]] = True
    in_bad[rows[own_kind < 0], own_leg[own_kind < 0]] = False
    drop = (out_bad | in_bad).any(axis=1)
    kept = ~drop & (out_ok & in_ok).all(axis=1)
    if np.any(~drop & ~kept):
        p = int(np.argmax(~drop & ~kept))
        return Boundary(reason=f"the midpoint test of an arc of the {names[pieces[p][0]]} is undecided")
    # area and perimeter of the kept arcs
    ox, oy = _iv(origin[0]), _iv(origin[1])
    area, perim = Interval(0), Interval(0)
    arcs, links, full_circles = [], {}, 0
    half = Interval("0.5")
    for p in np.nonzero(kept)[0]:
        k, s, e, ts, te, ref, _, wrap = pieces[p]
        r2k, rk = cr2[k], sqrt(cr2[k])
        centre = [float(ccx[k].mid()), float(ccy[k].mid())]
        entry = {"leg": int(leg[k]) + 1, "circle": "outer" if kind[k] > 0 else "inner", "center": centre,
                 "radius": [float(rk.lo), float(rk.hi)]}
        if s < 0:                                            # a whole circle
            full_circles += 1
            area = area + (PI * r2k if kind[k] > 0 else Interval(0) - PI * r2k)
            perim = perim + _TWO_PI * rk
            start = [centre[0] + float(rk.mid()), centre[1]]
            sweep = _TWO_PI if kind[k] > 0 else Interval(0) - _TWO_PI
            entry.update({"from": start, "to": start, "sweep": [float(sweep.lo), float(sweep.hi)]})
            arcs.append(entry)
            continue
        ccw = te - ts + (_TWO_PI if wrap else Interval(0))    # > 0
        if kind[k] > 0:
            P0, P1, delta = s, e, ccw
        else:
            P0, P1, delta = e, s, Interval(0) - ccw
        f = _x_minus_sin(ccw)
        seg = half * r2k * (f if kind[k] > 0 else Interval(0) - f)
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


# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------
def _header(robot, problem, orientation):
    from .certificates import FORMAT, VERSION
    return {"format": FORMAT, "version": VERSION, "problem": problem, "robot": robot.to_dict(),
            "model": MODEL[robot.kind], "orientation": dict(zip(KINDS[robot.kind], orientation))}


def _ignored(robot):
    return sorted(k for k in robot.limits if k != "leg_length")


def _pair(iv):
    return None if iv is None else [float(iv.lo), float(iv.hi)]


@dataclass
class SectionResult:
    """One certified section.  ``status``: ``non-empty`` (a box or the exact area proves it), ``empty``
    (every box of the domain is outside, or the domain is empty), ``undecided``."""

    robot: object
    orientation: list
    z: str | None
    legs: Legs
    domain: tuple | None                    # (lo (2,), hi (2,)) or None when proved empty
    paving: Paving | None
    boundary: Boundary
    stats: dict
    status: str = "undecided"

    @property
    def inner(self) -> float:
        return self.paving.inner_area() if self.paving else 0.0

    @property
    def outer(self) -> float:
        return self.paving.outer_area() if self.paving else 0.0

    @property
    def area(self) -> Interval | None:
        return self.boundary.area

    @property
    def perimeter(self) -> Interval | None:
        return self.boundary.perimeter

    def counts(self) -> dict:
        return self.paving.counts() if self.paving else {"inner_boxes": 0, "boundary_boxes": 0, "outside_boxes": 0}

    def to_json(self) -> dict:
        b = self.boundary
        doc = {"problem": "workspace-section", "robot": self.robot.name, "kind": self.robot.kind,
               "status": self.status, "orientation": dict(zip(KINDS[self.robot.kind], self.orientation)),
               "z": self.z,
               "constraints": ["leg_length"], "ignored_limits": _ignored(self.robot),
               "area": {"exact": _pair(b.area), "inner": self.inner, "outer": self.outer},
               "perimeter": _pair(b.perimeter),
               "arcs": b.arcs if b.decided else [],
               "loops": b.loops,
               "paving": self.counts(),
               "domain": None if self.domain is None else [[float(self.domain[0][k]), float(self.domain[1][k])]
                                                           for k in range(2)],
               "stats": dict(self.stats, bracket_width=self.outer - self.inner)}
        if not b.decided or b.reason:
            doc["exact_undecided"] = b.reason
        return doc

    def certificate(self) -> dict:
        cert = _header(self.robot, "workspace-section", self.orientation)
        claim = {} if self.z is None else {"z": self.z}
        if self.domain is None:
            claim.update({"domain": "empty", "tree": None, "area": {"inner": 0.0, "outer": 0.0}})
        else:
            claim.update({"domain": [[float(self.domain[0][k]), float(self.domain[1][k])] for k in range(2)],
                          "tree": self.paving.certificate_tree(),
                          "area": {"inner": self.inner, "outer": self.outer}})
        cert["claims"] = [claim]
        return cert

    def plot(self, path):
        plot_section(self, path)


def _z_interval(robot, z):
    if robot.kind == "planar-3rpr":
        if z is not None:
            raise InputError("--z", "z", "a planar robot has no z: leave it out")
        return Interval(0), None
    if z is None:
        raise InputError("--z", "z", "missing: give the height of the section")
    return _parse_z(z)


def workspace_section(robot, orientation=None, z=None, *, max_boxes=DEFAULT_MAX_BOXES, min_width=DEFAULT_MIN_WIDTH,
                      max_seconds=DEFAULT_MAX_SECONDS, progress=None, exact=True) -> SectionResult:
    """Certified section ``z = const`` of the constant-orientation workspace (leg-length limits).

    ``orientation``: ``"psi,theta,phi"`` (Gough) or ``"phi"`` (planar), a
    sequence or a mapping of exact decimals (``deg`` allowed); ``z``: an exact
    decimal (Gough only).  ``min_width`` is relative to the domain.  Raises
    ``InputError`` for bad input.
    """
    _check_robot(robot)
    angles, texts = parse_orientation(robot, orientation)
    Z, ztext = _z_interval(robot, z)
    _check_budget(max_boxes, min_width, max_seconds)
    t0 = time.perf_counter()
    legs = leg_data(robot, angles)
    Z1 = Z.reshape(1)
    r2in, r2out = legs.radii2(Z1)
    lo, hi, empty = section_domain(legs.ux, legs.uy, r2out)
    stats = {"boxes": 0, "seconds": 0.0, "exhausted": False, "min_width": min_width}
    if empty[0]:
        domain, paving = None, None
    else:
        domain = (lo[0], hi[0])
        res = _pave(legs, Z1, lo, hi, Budget(max_boxes, max_seconds, min_width), progress)
        paving = Paving(res.tree, 0)
        stats.update(boxes=res.boxes, exhausted=res.exhausted)
    stats["paving_seconds"] = time.perf_counter() - t0
    if exact:
        origin = (0.0, 0.0) if domain is None else tuple(0.5 * domain[0] + 0.5 * domain[1])
        boundary = exact_boundary(legs, Z1, origin)
    else:
        boundary = Boundary(reason="not computed (exact=False)")
    stats["seconds"] = time.perf_counter() - t0
    result = SectionResult(robot, texts, ztext, legs, domain, paving, boundary, stats)
    _consistent(result)
    counts = result.counts()
    if domain is None or (counts["inner_boxes"] == 0 and counts["boundary_boxes"] == 0):
        result.status = "empty"
    elif counts["inner_boxes"] > 0 or (boundary.decided and boundary.area.lo > 0):
        result.status = "non-empty"
    return result


def _consistent(r):
    """The exact area and the paving bracket are two proofs about one number: they must meet."""
    a = r.boundary.area
    if a is not None and (a.hi < r.inner or a.lo > r.outer):
        raise RuntimeError(f"internal error: exact area [{a.lo}, {a.hi}] outside the paving bracket "
                           f"[{r.inner}, {r.outer}]; please report this robot and section")


def _check_budget(max_boxes, min_width, max_seconds):
    if isinstance(max_boxes, bool) or not isinstance(max_boxes, (int, np.integer)) or max_boxes < 1:
        raise InputError("--max-boxes", "", f"expected a positive integer, got {max_boxes!r}")
    if not (isinstance(min_width, (int, float)) and math.isfinite(min_width) and min_width > 0):
        raise InputError("--min-width", "", f"expected a positive number, got {min_width!r}")
    if not (isinstance(max_seconds, (int, float)) and max_seconds > 0):
        raise InputError("--max-seconds", "", f"expected a positive number, got {max_seconds!r}")


@dataclass
class VolumeResult:
    """Certified volume bracket of the workspace part with z in the slabs [b_0, b_n]."""

    robot: object
    orientation: list
    z_range: tuple                      # exact texts
    bounds: np.ndarray                  # (n + 1,) floats b_0 < ... < b_n, b_0 <= z_lo, b_n >= z_hi
    domains: list                       # per slab (lo, hi) or None
    pavings: list                       # per slab Paving or None
    stats: dict
    status: str = "undecided"

    def areas(self):
        return [(p.inner_area(), p.outer_area()) if p else (0.0, 0.0) for p in self.pavings]

    def volume(self) -> tuple[float, float]:
        h = np.diff(self.bounds)
        hlo, hhi = down_sum(h), up_sum(h)
        ar = np.array(self.areas()).reshape(-1, 2)
        lo = np.maximum(down(hlo * ar[:, 0]), 0.0)
        hi = up(hhi * ar[:, 1])
        return float(np.nextafter(math.fsum(lo), -np.inf)), float(np.nextafter(math.fsum(hi), np.inf))

    def counts(self) -> dict:
        out = {"inner_boxes": 0, "boundary_boxes": 0, "outside_boxes": 0}
        for p in self.pavings:
            if p:
                for k, v in p.counts().items():
                    out[k] += v
        return out

    def to_json(self) -> dict:
        vin, vout = self.volume()
        return {"problem": "workspace-volume", "robot": self.robot.name, "kind": self.robot.kind,
                "status": self.status, "orientation": dict(zip(KINDS[self.robot.kind], self.orientation)),
                "z_range": list(self.z_range), "slabs": len(self.pavings),
                "slab_bounds": [float(v) for v in self.bounds],
                "constraints": ["leg_length"], "ignored_limits": _ignored(self.robot),
                "volume": {"inner": vin, "outer": vout},
                "sections": [{"z": [float(self.bounds[k]), float(self.bounds[k + 1])], "inner": a, "outer": b}
                             for k, (a, b) in enumerate(self.areas())],
                "paving": self.counts(), "stats": dict(self.stats, bracket_width=vout - vin)}

    def certificate(self) -> dict:
        cert = _header(self.robot, "workspace-volume", self.orientation)
        cert["requested"] = {"z": list(self.z_range)}
        claims = []
        for k, (dom, pav) in enumerate(zip(self.domains, self.pavings)):
            claim = {"slab": [float(self.bounds[k]), float(self.bounds[k + 1])]}
            if dom is None:
                claim.update({"domain": "empty", "tree": None, "area": {"inner": 0.0, "outer": 0.0}})
            else:
                claim.update({"domain": [[float(dom[0][j]), float(dom[1][j])] for j in range(2)],
                              "tree": pav.certificate_tree(),
                              "area": {"inner": pav.inner_area(), "outer": pav.outer_area()}})
            claims.append(claim)
        cert["claims"] = claims
        vin, vout = self.volume()
        cert["volume"] = {"inner": vin, "outer": vout}
        return cert

    def plot(self, path):
        plot_volume(self, path)


def workspace_volume(robot, orientation=None, z_range=None, slabs=DEFAULT_SLABS, *, max_boxes=DEFAULT_MAX_BOXES,
                     min_width=DEFAULT_MIN_WIDTH, max_seconds=DEFAULT_MAX_SECONDS, progress=None) -> VolumeResult:
    """Certified bracket of the volume of {C in the workspace : z_lo <= z <= z_hi} (Gough-Stewart).

    ``z_range``: ``"lo:hi"`` or a pair of exact decimals, cut into ``slabs``
    equal slabs (float bounds; the outer ones round outward).  Each slab's
    (X, Y) domain is paved with z kept as the slab's interval: a box inside
    for every z of the slab adds h·area to the inner volume, a box not proved
    outside adds it to the outer volume.  ``min_width`` is relative to the
    largest section; boxes are not split below twice the distance a section
    boundary moves across a slab (finer boxes would mostly stay boundary
    boxes: more slabs is the better way to narrow the bracket).
    """
    _check_robot(robot)
    if robot.kind != "gough-stewart":
        raise InputError("--z-range", "z", "only spatial (gough-stewart) robots have a volume")
    angles, texts = parse_orientation(robot, orientation)
    if z_range is None:
        raise InputError("--z-range", "z", "missing: give lo:hi")
    (zl, tl), (zh, th) = _parse_range(z_range)
    if isinstance(slabs, bool) or not isinstance(slabs, (int, np.integer)) or not 1 <= slabs <= 100_000:
        raise InputError("--slabs", "", f"expected an integer in [1, 100000], got {slabs!r}")
    _check_budget(max_boxes, min_width, max_seconds)
    t0 = time.perf_counter()
    ql, qh = Fraction(tl), Fraction(th)
    inner = [float(ql + (qh - ql) * k / slabs) for k in range(1, slabs)]
    bounds = np.array([float(zl.lo)] + inner + [float(zh.hi)])
    if np.any(np.diff(bounds) <= 0):
        raise InputError("--slabs", "", "too many slabs for this z range (slab bounds collide in float64)")
    legs = leg_data(robot, angles)
    Z = Interval._raw(bounds[:-1].copy(), bounds[1:].copy())
    _, r2out = legs.radii2(Z)
    lo, hi, empty = section_domain(legs.ux, legs.uy, r2out)
    live = np.nonzero(~empty)[0]
    domains = [None if empty[k] else (lo[k], hi[k]) for k in range(slabs)]
    pavings = [None] * slabs
    stats = {"boxes": 0, "seconds": 0.0, "exhausted": False, "min_width": min_width}
    if len(live):
        # how far a section boundary can move across a slab, |dR/dz| h = h |z - u_z| / R (a float
        # estimate: it only sets the resolution, below which boundary boxes stay boundary anyway)
        zmid = 0.5 * (bounds[:-1] + bounds[1:])[live]
        r2mid = 0.5 * (r2out.lo + r2out.hi)[live]
        with np.errstate(divide="ignore", invalid="ignore"):
            speed = np.abs(zmid[:, None] - legs.uz.mid()) / np.sqrt(np.maximum(r2mid, 0.0))
        speed = np.where(np.isfinite(speed), speed, 0.0)
        # one resolution for all slabs: the median (a few slabs near a tangency move fast)
        floor = 2.0 * float(np.median(np.diff(bounds)[live] * np.max(speed, axis=1)))
        res = _pave(legs, Z[live], lo[live], hi[live], Budget(max_boxes, max_seconds, min_width), progress, floor)
        for root, k in enumerate(live):
            pavings[k] = Paving(res.tree, root)
        stats.update(boxes=res.boxes, exhausted=res.exhausted)
    stats["seconds"] = time.perf_counter() - t0
    result = VolumeResult(robot, texts, (tl, th), bounds, domains, pavings, stats)
    counts = result.counts()
    if counts["inner_boxes"]:
        result.status = "non-empty"
    elif not counts["boundary_boxes"]:
        result.status = "empty"
    return result


# ---------------------------------------------------------------------------
# pictures
# ---------------------------------------------------------------------------
COLOURS = {"inside": "#55a868", "boundary": "#f2c14e", "outside": "#e6e6e6", "arc": "#1f3b73"}


def _rects(ax, lo, hi, colour, edge):
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle
    if not len(lo):
        return
    patches = [Rectangle((a[0], a[1]), b[0] - a[0], b[1] - a[1]) for a, b in zip(lo, hi)]
    ax.add_collection(PatchCollection(patches, facecolor=colour, edgecolor=edge, linewidth=0.2))


def plot_section(result: SectionResult, path):
    """The paving (inside green, boundary yellow, outside grey) and the exact arcs (dark blue)."""
    plt = pyplot()
    from matplotlib.patches import Patch
    fig, ax = plt.subplots(figsize=(6.4, 6.0))
    if result.paving is not None:
        for kind, name in ((EXCLUDED, "outside"), (UNDECIDED, "boundary"), (PROVED, "inside")):
            lo, hi = result.paving.boxes(kind)
            _rects(ax, lo, hi, COLOURS[name], "white" if name != "outside" else "#f7f7f7")
        dlo, dhi = result.domain
        ax.set_xlim(dlo[0], dhi[0])
        ax.set_ylim(dlo[1], dhi[1])
    for arc in result.boundary.arcs if result.boundary.decided else []:
        cx, cy = arc["center"]
        r = 0.5 * (arc["radius"][0] + arc["radius"][1])
        a0 = math.atan2(arc["from"][1] - cy, arc["from"][0] - cx)
        sweep = 0.5 * (arc["sweep"][0] + arc["sweep"][1])
        t = a0 + np.linspace(0.0, sweep, 400)
        ax.plot(cx + r * np.cos(t), cy + r * np.sin(t), color=COLOURS["arc"], linewidth=1.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    names = KINDS[result.robot.kind]
    orient = ", ".join(f"{n}={v}" for n, v in zip(names, result.orientation))
    zpart = "" if result.z is None else f"z = {result.z}, "
    area = result.boundary.area
    exact = f"exact area [{float(area.lo):.10g}, {float(area.hi):.10g}]" if area is not None else "exact area undecided"
    ax.set_title(f"{result.robot.name}\n{zpart}{orient}: {exact}\npaving: area in "
                 f"[{result.inner:.6g}, {result.outer:.6g}]", fontsize=9)
    legend = [Patch(color=COLOURS["inside"], label="inside"), Patch(color=COLOURS["boundary"], label="boundary"),
              Patch(color=COLOURS["outside"], label="outside"), Patch(color=COLOURS["arc"], label="exact arcs")]
    ax.legend(handles=legend, loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_volume(result: VolumeResult, path):
    """Inner and outer section areas per slab, against z."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    ar = np.array(result.areas()).reshape(-1, 2)
    z = result.bounds
    ax.stairs(ar[:, 1], z, color="#f2c14e", fill=True, label="outer (inside + boundary)")
    ax.stairs(ar[:, 0], z, color="#55a868", fill=True, label="inner (inside)")
    vin, vout = result.volume()
    ax.set_xlabel("z")
    ax.set_ylabel("section area")
    ax.set_title(f"{result.robot.name}: volume in [{vin:.6g}, {vout:.6g}]", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ---------------------------------------------------------------------------
# text and command line
# ---------------------------------------------------------------------------
def describe(result) -> str:
    """A few lines for the command line."""
    names = KINDS[result.robot.kind]
    orient = ",".join(names) + " = " + ",".join(result.orientation)
    ignored = _ignored(result.robot)
    note = f"\n  (leg-length limits only; ignored: {', '.join(ignored)})" if ignored else ""
    if isinstance(result, VolumeResult):
        vin, vout = result.volume()
        c = result.counts()
        return (f"{result.robot.name}: workspace volume for z in [{result.z_range[0]}, {result.z_range[1]}] "
                f"at {orient}: {result.status}\n"
                f"  volume in [{vin:.10g}, {vout:.10g}] ({len(result.pavings)} slabs; {c['inner_boxes']} inside, "
                f"{c['boundary_boxes']} boundary, {c['outside_boxes']} outside boxes) "
                f"[{result.stats['boxes']} boxes, {result.stats['seconds']:.3f} s]" + note)
    where = "" if result.z is None else f"z = {result.z}, "
    lines = [f"{result.robot.name}: section {where}{orient}: {result.status}"]
    b = result.boundary
    if b.decided and b.perimeter is not None:
        lines.append(f"  exact area in [{float(b.area.lo):.15g}, {float(b.area.hi):.15g}], perimeter in "
                     f"[{float(b.perimeter.lo):.15g}, {float(b.perimeter.hi):.15g}] ({len(b.arcs)} arcs, "
                     f"{b.loops} loop{'s' if b.loops != 1 else ''})")
    elif b.decided:
        lines.append(f"  exact area in [{float(b.area.lo):.15g}, {float(b.area.hi):.15g}] ({b.reason})")
    else:
        lines.append(f"  exact boundary undecided: {b.reason}")
    c = result.counts()
    lines.append(f"  paving: area in [{result.inner:.10g}, {result.outer:.10g}] ({c['inner_boxes']} inside, "
                 f"{c['boundary_boxes']} boundary, {c['outside_boxes']} outside boxes) "
                 f"[{result.stats['boxes']} boxes, {result.stats['seconds']:.3f} s]")
    return "\n".join(lines) + note


def add_arguments(parser) -> None:
    """The options of ``certkin workspace`` (the subparser is made by ``certkin.cli``)."""
    parser.add_argument("robot", help="robot file (TOML): gough-stewart or planar-3rpr, with limits.leg_length")
    parser.add_argument("--orientation", metavar="PSI,THETA,PHI", default=None,
                        help="fixed orientation (radians, or with a 'deg' suffix); planar robots: PHI; default 0")
    parser.add_argument("--z", metavar="Z", help="height of the section (exact decimal)")
    parser.add_argument("--z-range", metavar="LO:HI", help="volume bracket of the workspace between two heights")
    parser.add_argument("--slabs", metavar="N", help=f"number of z slabs for --z-range (default {DEFAULT_SLABS})")
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    parser.add_argument("--certificate", metavar="FILE", help="write the certificate to FILE")
    parser.add_argument("--plot", metavar="FILE.png", help="picture of the paving and arcs (needs matplotlib)")
    parser.add_argument("--progress", action="store_true", help="show progress on stderr")
    parser.add_argument("--max-boxes", type=int, default=DEFAULT_MAX_BOXES,
                        help=f"box budget (default {DEFAULT_MAX_BOXES})")
    parser.add_argument("--max-seconds", type=float, default=DEFAULT_MAX_SECONDS,
                        help=f"time budget (default {DEFAULT_MAX_SECONDS})")
    parser.add_argument("--min-width", type=float, default=None,
                        help=f"smallest box side still split, relative to the size of the section "
                             f"(default {DEFAULT_MIN_WIDTH})")


def run(args, out=None) -> int:
    """``certkin workspace``: prints a summary (or ``--json``), writes ``--certificate``/``--plot``; returns 0.

    Bad input raises ``InputError`` (the CLI prints it on one line and exits 2).
    """
    from . import load_robot
    from .certificates import write_json
    from .cli import _progress
    out = out or sys.stdout
    robot = load_robot(args.robot)
    _check_robot(robot)
    if args.z is not None and args.z_range is not None:
        raise InputError("--z-range", "", "give either --z (a section) or --z-range (a volume), not both")
    budget = {"max_boxes": args.max_boxes, "max_seconds": args.max_seconds}
    if args.z_range is not None:
        slabs = DEFAULT_SLABS
        if args.slabs is not None:
            try:
                slabs = int(str(args.slabs).strip())
            except ValueError:
                raise InputError("--slabs", "", f"expected an integer, got {args.slabs!r}") from None
        result = workspace_volume(robot, args.orientation, args.z_range, slabs,
                                  min_width=args.min_width if args.min_width is not None else DEFAULT_MIN_WIDTH,
                                  progress=_progress(args.progress), **budget)
    else:
        if args.slabs is not None:
            raise InputError("--slabs", "", "only with --z-range")
        if args.z is None and robot.kind != "planar-3rpr":
            raise InputError("--z", "z", "give --z Z (a section) or --z-range LO:HI (a volume)")
        result = workspace_section(robot, args.orientation, args.z,
                                   min_width=args.min_width if args.min_width is not None else DEFAULT_MIN_WIDTH,
                                   progress=_progress(args.progress), **budget)
    if args.certificate:
        write_json(args.certificate, result.certificate())
    if args.plot:
        result.plot(args.plot)
    if args.json:
        out.write(json.dumps(result.to_json()) + "\n")
    else:
        out.write(describe(result) + "\n")
    return 0
