"""Trajectory claims (``"problem": "trajectory"``, docs/certificates.md).

A claim is one path, a polyline of exact poses P_0 … P_n.  On segment k the
pose is P_k + t (P_{k+1} − P_k), t ∈ [0, 1] (a straight line in position,
the pose angles interpolated linearly); the global parameter is s = k + t.
Leg i is the segment [A_i, B_i] from the base joint A_i (a base point;
planar points get z = 0) to the world platform joint B_i, l_i = B_i − A_i:

- ``planar-3rpr/1``: l_i = (x, y) + R(phi) p_i − b_i (z = 0);
- ``spherical-3dof/1``, ``-tt/1``: l_i = Q b_i − a_i, Q = Rz Ry Rz (the models of
  ``models.py``); ``gough-stewart/1``: l_i = C + R b_i − a_i.

The constraint instances are rebuilt from the robot's ``limits``, in this
order (a claim may list any subsequence, nothing else):

- ``leg-length`` (one per leg): ρ_min² ≤ |l_i|² ≤ ρ_max² (ρ_min ≥ 0);
- ``joints``: the base joints of leg 1..n, then the platform joints; per
  joint one instance per facet normal n (``base facet k``: n·l_i ≥ 0;
  ``platform facet k``: −(R n)·l_i ≥ 0) and one per cone (``base cone`` /
  ``platform cone``, axis a, half-angle α ∈ [0°, 90°]: g = a·u ≥ 0 and
  h = g² − |a|² cos²α |l_i|² ≥ 0, with u = l_i, or −Rᵀl_i on the platform);
- ``interference`` (pairs i < j): dist([A_i, B_i], [A_j, B_j]) ≥ r = r_i + r_j;
- ``singularity`` (legs 1..n): det(A) of ``models.py`` ≠ 0.

Leaf state characters: ``+`` satisfied at every t of the leaf, ``-``
violated at every t of it (for ``singularity``: the sign of det A), ``?``
nothing.  The checker

1. checks that the leaves of every segment tile [0, 1] exactly;
2. re-proves every ``+``/``-`` with ``iv`` enclosures over t-intervals T:
   each quantity g(t) is evaluated with forward differentiation in t
   (``ad.Dual``), and enclosed by hull(g(lo), g(hi)) when dg/dt has one sign
   on T, else by (g(m) + g'(T)(T − m)) ∩ g(T) (mean-value theorem).  Runs of
   equal characters are proved on their union first, then on halves (split
   at leaf boundaries), then a single leaf is bisected up to ``MAX_DEPTH``
   levels: a statement proved on pieces that cover T holds on T.  An
   enclosure that proves the opposite on T refutes the claim at once;
3. checks the verdict (``feasible``: only ``+``, and one det sign on every
   leaf; ``infeasible``: a ``-``, or both det signs — det is continuous along
   the path, so it vanishes between them; ``undecided``: nothing) and the
   ``violations``: per instance, the union of its intervals must contain every
   leaf not ``+`` (for ``singularity``: every ``?`` leaf), and a violation
   marked ``certain`` must meet a ``-`` leaf (for ``singularity``: a ``+``
   leaf and a ``-`` leaf).

Interference, as in the solver (docs/soundness.md).  With u = l_i, v = l_j,
w0 = A_i − A_j, Δ = |u×v|², the line distance² is (w0·(u×v))²/Δ and the feet
of the common perpendicular are s* = (b e − c d)/Δ, t* = (a e − b d)/Δ
(a = u·u, b = u·v, c = v·v, d = u·w0, e = v·w0).  Proved ``+`` on T when
E = (w0·(u×v))² − r² Δ > 0 on T (the line distance bounds the segment
distance from below; E > 0 forces Δ > 0), or when the feet are outside
[0, 1]² on the whole of T (s*·Δ < 0, > Δ, or the same for t*: then Δ > 0 and
the minimum of the convex distance over the square is on its border) and
each end point P of one leg is at distance ≥ r from the other leg [X, Y]:
with q = P − X, σ = Y − X, τ = q·σ: τ ≤ 0 and |q|² ≥ r², or τ ≥ |σ|² and
|q − σ|² ≥ r², or |σ|² > 0 and |q×σ|² − r²|σ|² ≥ 0 (point-line distance).
Proved ``-`` on T by a pair of points closer than r at every t: the feet
inside [0, 1]² with Δ > 0 and E < 0, or an end point with |q|² < r² or
|q − σ|² < r², or with 0 ≤ τ ≤ |σ|², |σ|² > 0 and |q×σ|² − r²|σ|² < 0.
"""
from __future__ import annotations

import bisect
from fractions import Fraction
import math
import itertools

from mpmath import iv

from . import ad
from .det import det, det_interval
from .models import points, rot
from .numbers import enclose, exact, real
from .report import Rejected

MAX_DEPTH = 12        # bisection levels inside one leaf
MAX_PIECES = 400      # pieces tried inside one leaf before giving up
STATUSES = ("feasible", "infeasible", "undecided")

# per model: (pose indices of the position, rotation angles as pose-index
# combinations [(index, sign), ...], rotation axes); R = R_ax0(θ0) R_ax1(θ1) R_ax2(θ2)
_FRAMES = {
    "planar-3rpr/1": ((0, 1), (((2, 1),),), "z"),
    "spherical-3dof/1": ((), (((0, 1),), ((1, 1),), ((2, 1),)), "zyz"),
    "spherical-3dof-tt/1": ((), (((0, 1),), ((1, 1),), ((2, 1), (0, -1))), "zyz"),
    "gough-stewart/1": ((0, 1, 2), (((3, 1),), ((4, 1),), ((5, 1),)), "zxz"),
}
_ANGLES = {"planar-3rpr/1": {"phi"}, "spherical-3dof/1": {"phi1", "phi2", "phi3"},
           "spherical-3dof-tt/1": {"phi1", "phi2", "sigma"}, "gough-stewart/1": {"psi", "theta", "phi"}}


def check_claims(model, robot: dict, claims, counts: dict) -> None:
    geo = Geometry(model, robot)
    for c, claim in enumerate(claims):
        _claim(geo, claim, f"claims[{c}]", counts)


# ----- numbers ------------------------------------------------------------------------
def _fraction_iv(q: Fraction):
    return iv.mpf(q.numerator) / q.denominator if q.denominator != 1 else iv.mpf(q.numerator)


def _angle_text(value, where: str):
    """(exact value, in degrees?) of ``<decimal>`` or ``<decimal>deg``."""
    if isinstance(value, str) and value.strip().lower().endswith("deg"):
        return exact(value.strip()[:-3], where), True
    return exact(value, where), False


def _radians(q: Fraction, deg: bool):
    x = _fraction_iv(q)
    return x * iv.pi / 180 if deg else x


def _sqr(x):
    if isinstance(x, ad.Dual):
        return ad.Dual(x.v ** 2, {k: 2 * x.v * g for k, g in x.d.items()})
    return x ** 2


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _norm2(a):
    return _sqr(a[0]) + _sqr(a[1]) + _sqr(a[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _ge0(x):
    return (x >= 0) is True


def _gt0(x):
    return (x > 0) is True


def _lt0(x):
    return (x < 0) is True


def _le0(x):
    return (x <= 0) is True


def _lift3(v):
    return tuple(ad.lift(c) for c in v)


# ----- the robot ----------------------------------------------------------------------
class Geometry:
    """The robot of a certificate: enclosed geometry and the canonical constraint instances."""

    def __init__(self, model, robot: dict):
        if model.name not in _FRAMES:
            raise Rejected(f"model: {model.name} has no trajectory equations")
        self.model = model
        self.n = n = model.legs
        self.position, self.angles, self.axes = _FRAMES[model.name]
        self.angle_names = _ANGLES[model.name]
        self.base2 = points(robot, "base", n, model.base_dim)
        self.platform = points(robot, "platform", n, model.platform_dim)
        self.base = [tuple(p) + (0,) * (3 - len(p)) for p in self.base2]       # A_i in space
        self.base2_l = [tuple(ad.lift(c) for c in p) for p in self.base2]
        self.platform_l = [tuple(ad.lift(c) for c in p) for p in self.platform]
        self.base_l = [_lift3(p) for p in self.base]
        limits = robot.get("limits", {})
        if not isinstance(limits, dict):
            raise Rejected("robot.limits: expected an object")
        for key in limits:
            if key not in ("leg_length", "leg_radius", "base_joints", "platform_joints"):
                raise Rejected(f"robot.limits.{key}: unknown limit")
        self.instances = []
        if "leg_length" in limits:
            self._leg_lengths(limits["leg_length"])
        joints = [(side, limits[f"{side}_joints"]) for side in ("base", "platform") if f"{side}_joints" in limits]
        for side, tables in joints:
            self._joints(side, tables)
        if "leg_radius" in limits:
            self._pairs(limits["leg_radius"])
        self.instances.append(Instance(self, "singularity", tuple(range(1, n + 1)), "", None))

    def _leg_lengths(self, value):
        where = "robot.limits.leg_length"
        if not isinstance(value, list) or len(value) != self.n:
            raise Rejected(f"{where}: expected {self.n} [min, max] pairs")
        for i, pair in enumerate(value):
            if not isinstance(pair, list) or len(pair) != 2:
                raise Rejected(f"{where}[{i}]: expected [min, max]")
            lo, hi = exact(pair[0], f"{where}[{i}]"), exact(pair[1], f"{where}[{i}]")
            if not 0 <= lo <= hi:
                raise Rejected(f"{where}[{i}]: expected 0 <= min <= max")
            self.instances.append(Instance(self, "leg-length", (i + 1,), "",
                                           (i, _fraction_iv(lo * lo), _fraction_iv(hi * hi))))

    def _vector(self, value, where):
        if not isinstance(value, list) or len(value) != 3:
            raise Rejected(f"{where}: expected 3 coordinates")
        q = [exact(c, where) for c in value]
        if all(c == 0 for c in q):
            raise Rejected(f"{where}: a zero vector")
        return tuple(enclose(c, where) for c in value)

    def _joints(self, side, tables):
        where = f"robot.limits.{side}_joints"
        if not isinstance(tables, list) or len(tables) != self.n:
            raise Rejected(f"{where}: expected {self.n} joint tables, one per leg")
        if side == "platform" and self.model.kind == "planar-3rpr":
            raise Rejected(f"{where}: platform joint limits are not modelled for planar robots")
        for i, table in enumerate(tables):
            w = f"{where}[{i}]"
            if not isinstance(table, dict) or not table:
                raise Rejected(f"{w}: expected an object with 'normals' and/or 'axis' and 'half_angle'")
            for key in table:
                if key not in ("normals", "axis", "half_angle"):
                    raise Rejected(f"{w}.{key}: unknown field")
            normals = table.get("normals", [])
            if "normals" in table and (not isinstance(normals, list) or not normals):
                raise Rejected(f"{w}.normals: expected a non-empty list of vectors")
            for k, normal in enumerate(normals):
                vec = self._vector(normal, f"{w}.normals[{k}]")
                self.instances.append(Instance(self, "joints", (i + 1,), f"{side} facet {k + 1}",
                                               (i, side, "facet", vec, _lift3(vec), None)))
            if ("axis" in table) != ("half_angle" in table):
                raise Rejected(f"{w}: a cone needs both 'axis' and 'half_angle'")
            if "axis" in table:
                axis = self._vector(table["axis"], f"{w}.axis")
                q, deg = _angle_text(table["half_angle"], f"{w}.half_angle")
                alpha = _radians(q, deg)
                if q < 0 or not ((deg and q <= 90) or (alpha <= iv.pi / 2) is True):
                    raise Rejected(f"{w}.half_angle: expected an angle in [0, 90deg]")
                c2 = _norm2(axis) * iv.cos(alpha) ** 2
                self.instances.append(Instance(self, "joints", (i + 1,), f"{side} cone",
                                               (i, side, "cone", axis, _lift3(axis), c2)))

    def _pairs(self, value):
        where = "robot.limits.leg_radius"
        if not isinstance(value, list) or len(value) != self.n:
            raise Rejected(f"{where}: expected {self.n} radii")
        radius = [exact(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if any(r < 0 for r in radius):
            raise Rejected(f"{where}: a radius cannot be negative")
        for i, j in itertools.combinations(range(self.n), 2):
            r = radius[i] + radius[j]
            w0 = tuple(a - b for a, b in zip(self.base[i], self.base[j]))
            self.instances.append(Instance(self, "interference", (i + 1, j + 1), "",
                                           (i, j, r == 0, _fraction_iv(r * r), w0, _lift3(w0))))


# ----- the path -----------------------------------------------------------------------
class Segment:
    """Segment k of a path: pose(t) = P + t D, with D = None where it is exactly 0."""

    def __init__(self, geo: Geometry, k: int, start, end):
        self.geo, self.k = geo, k
        self.P, self.D = [], []
        for (q0, deg0), (q1, deg1) in zip(start, end):
            self.P.append(_radians(q0, deg0))
            if q0 == q1 and (deg0 == deg1 or q0 == 0):
                self.D.append(None)
            elif deg0 == deg1:
                self.D.append(_radians(q1 - q0, deg0))
            else:
                self.D.append(_radians(q1, deg1) - _radians(q0, deg0))
        self.angle = []            # rotation angles θ_j = Θ_j + t Δ_j
        for combo in geo.angles:
            theta = sum((self.P[i] if s > 0 else -self.P[i] for i, s in combo), iv.mpf(0))
            moving = [(i, s) for i, s in combo if self.D[i] is not None]
            delta = sum((self.D[i] if s > 0 else -self.D[i] for i, s in moving), iv.mpf(0)) if moving else None
            self.angle.append((theta, delta))
        self.fixed = all(d is None for _, d in self.angle)   # constant orientation
        self._cs = [(iv.cos(th), iv.sin(th)) if d is None else None for th, d in self.angle]
        self._rotated = {}

    def cs(self, j, t, dual):
        theta, delta = self.angle[j]
        if delta is None:
            c, s = self._cs[j]
            return (ad.lift(c), ad.lift(s)) if dual else (c, s)
        x = ad.Dual(theta + t * delta, {0: delta}) if dual else theta + t * delta
        return ad.cos(x), ad.sin(x)

    def rotated_fixed(self, key, v):
        """R v for a constant orientation (cached per vector)."""
        if key not in self._rotated:
            self._rotated[key] = _rotate(self.geo.axes, [self.cs(j, None, False) for j in range(len(self.angle))], v)
        return self._rotated[key]


def _rotate(axes, cs, v):
    for axis, c in zip(reversed(axes), reversed(cs)):
        v = rot(axis, c, v)
    return v


class Frame:
    """The path at one instant t (thin ``iv``) or over T (``ad.Dual`` in t): pose, legs, R."""

    def __init__(self, seg: Segment, t, dual: bool):
        geo = self.geo = seg.geo
        self.seg, self.dual = seg, dual
        pose = []
        for P, D in zip(seg.P, seg.D):
            if D is None:
                pose.append(ad.lift(P) if dual else P)
            else:
                pose.append(ad.Dual(P + t * D, {0: D}) if dual else P + t * D)
        self.pose = pose
        self.cs = [seg.cs(j, t, dual) for j in range(len(seg.angle))]
        base = geo.base_l if dual else geo.base
        plat = geo.platform_l if dual else geo.platform
        name = geo.model.name
        legs = []
        if name == "planar-3rpr/1":
            x, y = pose[0], pose[1]
            c, s = self.cs[0]
            for (bx, by, _), (px, py) in zip(base, plat):
                legs.append((x + (c * px - s * py) - bx, y + (s * px + c * py) - by, 0))
        else:
            centre = [pose[i] for i in geo.position]
            for i, (a, b) in enumerate(zip(base, plat)):
                rb = self.rot(("platform", i), geo.platform[i], b)
                if centre:
                    legs.append(tuple(centre[k] + rb[k] - a[k] for k in range(3)))
                else:
                    legs.append(tuple(rb[k] - a[k] for k in range(3)))
        self.legs = legs
        self._sq = {}

    def rot(self, key, v, v_lifted):
        """R v (a constant vector; ``v_lifted`` its ``ad.lift`` form)."""
        if self.seg.fixed:
            r = self.seg.rotated_fixed(key, v)
            return _lift3(r) if self.dual else r
        return _rotate(self.geo.axes, self.cs, v_lifted if self.dual else v)

    def leg_sq(self, i):
        if i not in self._sq:
            self._sq[i] = _norm2(self.legs[i])
        return self._sq[i]

    def lift(self, x):
        return ad.lift(x) if self.dual else x

    def det_rows(self):
        geo = self.geo
        base = geo.base2_l if self.dual else geo.base2
        plat = geo.platform_l if self.dual else geo.platform
        return geo.model.rows(self.pose, base, plat)


class Span:
    """A t-interval T = [lo, hi] of one segment, with its frames (built when first needed)."""

    def __init__(self, seg: Segment, lo: float, hi: float):
        self.seg, self.lo, self.hi = seg, lo, hi
        self.mid = min(max(0.5 * lo + 0.5 * hi, lo), hi)
        self.T = iv.mpf([lo, hi])
        self._frames = {}

    def frame(self, which):
        if which not in self._frames:
            if which == "T":
                self._frames[which] = Frame(self.seg, self.T, True)
            else:
                t = {"lo": self.lo, "mid": self.mid, "hi": self.hi}[which]
                self._frames[which] = Frame(self.seg, iv.mpf(t), False)
        return self._frames[which]

    def enclose(self, fn, natural=None):
        """Enclosures over T of the quantities ``fn(frame)`` (a list): monotone or mean-value form."""
        ys = fn(self.frame("T"))
        out = [None] * len(ys)
        ends, mids = [], []
        for i, y in enumerate(ys):
            if not isinstance(y, ad.Dual):
                out[i] = iv.mpf(y)
                continue
            g = y.d.get(0)
            if g is None:
                out[i] = y.v if natural is None else natural[i]
            elif _ge0(g):
                ends.append((i, True))
            elif _le0(g):
                ends.append((i, False))
            else:
                mids.append((i, g, y.v if natural is None else natural[i]))
        if ends:
            ylo, yhi = fn(self.frame("lo")), fn(self.frame("hi"))
            for i, up in ends:
                a, b = (ylo[i], yhi[i]) if up else (yhi[i], ylo[i])
                out[i] = iv.mpf([iv.mpf(a).a, iv.mpf(b).b])
        if mids:
            ym = fn(self.frame("mid"))
            h = self.T - iv.mpf(self.mid)
            for i, g, nat in mids:
                form = ym[i] + g * h
                out[i] = iv.mpf([max(form.a, nat.a), min(form.b, nat.b)])
        return out


# ----- the constraint instances -------------------------------------------------------
class Instance:
    """One scalar constraint; ``prove(span, ch)``: 1 proved on T, -1 refuted on T, 0 undecided."""

    def __init__(self, geo, constraint, legs, detail, data):
        self.geo, self.constraint, self.legs, self.detail, self.data = geo, constraint, legs, detail, data
        self.json = {"constraint": constraint, "legs": list(legs)}
        if detail:
            self.json["detail"] = detail
        self.label = (f"{constraint} leg{'s' if len(legs) > 1 else ''} {'-'.join(map(str, legs))}"
                      + (f" ({detail})" if detail else ""))

    def prove(self, span: Span, ch: str) -> int:
        sat, viol = getattr(self, "_" + self.constraint.replace("-", "_"))(span, ch)
        if (sat and ch == "+") or (viol and ch == "-"):
            return 1
        return -1 if sat or viol else 0

    # each returns (proved satisfied on T, proved violated on T); for singularity (det > 0, det < 0)
    def _leg_length(self, span, ch):
        i, lo2, hi2 = self.data
        (q,) = span.enclose(lambda fr: [fr.leg_sq(i)])
        return (q >= lo2) is True and (q <= hi2) is True, (q < lo2) is True or (q > hi2) is True

    def _joints(self, span, ch):
        i, side, kind, vec, vec_l, c2 = self.data

        def fn(fr):
            l = fr.legs[i]
            if side == "platform":
                g = -_dot(fr.rot((side, i, self.detail), vec, vec_l), l)
            else:
                g = _dot(l, vec_l if fr.dual else vec)
            return [g] if kind == "facet" else [g, _sqr(g) - fr.leg_sq(i) * c2]

        vals = span.enclose(fn)
        return all(_ge0(v) for v in vals), any(_lt0(v) for v in vals)

    def _interference(self, span, ch):
        i, j, zero, r2, w0, w0_l = self.data
        if zero:
            return True, False          # a distance is never < 0

        def line(fr):
            u, v, w = fr.legs[i], fr.legs[j], (w0_l if fr.dual else w0)
            cr = _cross(u, v)
            delta = _norm2(cr)
            return [_sqr(_dot(w, cr)) - delta * r2, delta]

        E, delta = span.enclose(line)
        if _gt0(E):
            return True, False

        def feet(fr):
            u, v, w = fr.legs[i], fr.legs[j], (w0_l if fr.dual else w0)
            a, b, c = fr.leg_sq(i), _dot(u, v), fr.leg_sq(j)
            d, e = _dot(u, w), _dot(v, w)
            delta = a * c - _sqr(b)
            s_num, t_num = b * e - c * d, a * e - b * d
            return [s_num, s_num - delta, t_num, t_num - delta]

        s0, s1, t0, t1 = span.enclose(feet)
        feet_in = _ge0(s0) and _le0(s1) and _ge0(t0) and _le0(t1) and _gt0(delta)
        if feet_in and _lt0(E):
            return False, True
        feet_out = _lt0(s0) or _gt0(s1) or _lt0(t0) or _gt0(t1)

        def ends(fr):
            u, v, w = fr.legs[i], fr.legs[j], (w0_l if fr.dual else w0)
            out = []
            for q, sg, n2 in ((w, v, fr.leg_sq(j)), (tuple(w[k] + u[k] for k in range(3)), v, fr.leg_sq(j)),
                              (tuple(-w[k] for k in range(3)), u, fr.leg_sq(i)),
                              (tuple(v[k] - w[k] for k in range(3)), u, fr.leg_sq(i))):
                tau = _dot(q, sg)
                out += [tau, tau - n2, n2, _norm2(_cross(q, sg)) - n2 * r2,
                        _norm2(q) - r2, _norm2(tuple(q[k] - sg[k] for k in range(3))) - r2]
            return out

        vals = span.enclose(ends)
        lower, witness = True, False
        for p in range(4):
            tau, tau1, n2, eps, f0, f1 = vals[6 * p:6 * p + 6]
            lower = lower and ((_le0(tau) and _ge0(f0)) or (_ge0(tau1) and _ge0(f1)) or (_gt0(n2) and _ge0(eps)))
            witness = witness or _lt0(f0) or _lt0(f1) or (_ge0(tau) and _le0(tau1) and _gt0(n2) and _lt0(eps))
        # the points of one segment against the other's line: |c0 + s c1|² >= min(|c0|², |c0 + c1|² - Δ)
        # on s in [0, 1] (c0 = w x v, c1 = u x v, Δ = |c1|²; docs/soundness.md), valid for parallel legs
        to_line = any(_ge0(vals[6 * p + 3]) and _ge0(vals[6 * p + 9] - delta) for p in (0, 2))
        return (feet_out and lower) or to_line, witness

    def _singularity(self, span, ch):
        fr = span.frame("T")
        rows = fr.det_rows()
        values = [[e.v if isinstance(e, ad.Dual) else iv.mpf(e) for e in row] for row in rows]
        D = det_interval(values)
        if not (_gt0(D) or _lt0(D)):
            y = det(rows)
            point = lambda f: [det_interval(f.det_rows())] if not f.dual else [y]  # noqa: E731
            (D2,) = span.enclose(point, natural=[D])
            D = D2
        return _gt0(D), _lt0(D)


# ----- one claim ----------------------------------------------------------------------
def _claim(geo: Geometry, claim, where, counts):
    if not isinstance(claim, dict):
        raise Rejected(f"{where}: expected an object")
    status = claim.get("status")
    if status not in STATUSES:
        raise Rejected(f"{where}.status: unknown status {status!r} (known: {', '.join(STATUSES)})")
    path = _path(geo, claim.get("path"), f"{where}.path")
    insts = _instances(geo, claim.get("instances"), f"{where}.instances")
    K = len(insts)
    segs, ts, states = _leaves(claim.get("leaves"), len(path) - 1, K, f"{where}.leaves")
    _verdict(insts, states, status, f"{where}.status")
    _violations(insts, segs, ts, states, claim.get("violations"), f"{where}.violations")
    if status == "undecided":
        counts["undecided"] += 1
    first = 0
    for k in range(len(path) - 1):
        seg = Segment(geo, k, path[k], path[k + 1])
        last = first
        while last < len(segs) and segs[last] == k:
            last += 1
        _prove_segment(seg, insts, ts[first:last], states[first:last], first, where, counts)
        first = last
    counts["leaves"] += len(segs)


def _path(geo, path, where):
    d = len(geo.model.pose)
    if not isinstance(path, list) or len(path) < 2:
        raise Rejected(f"{where}: expected a list of at least 2 poses")
    out = []
    for p, pose in enumerate(path):
        if not isinstance(pose, list) or len(pose) != d:
            raise Rejected(f"{where}[{p}]: expected {d} values {list(geo.model.pose)}")
        values = []
        for name, v in zip(geo.model.pose, pose):
            if not isinstance(v, str):
                raise Rejected(f"{where}[{p}].{name}: expected an exact decimal string, got {v!r}")
            q, deg = _angle_text(v, f"{where}[{p}].{name}")
            if deg and name not in geo.angle_names:
                raise Rejected(f"{where}[{p}].{name}: 'deg' is only allowed for angles")
            values.append((q, deg))
        out.append(values)
    return out


def _instances(geo, value, where):
    if not isinstance(value, list) or not value:
        raise Rejected(f"{where}: expected a non-empty list of constraint instances")
    out, pos = [], 0
    canon = geo.instances
    for k, item in enumerate(value):
        while pos < len(canon) and canon[pos].json != item:
            pos += 1
        if pos == len(canon):
            known = any(c.json == item for c in canon)
            why = "duplicated or out of the canonical order" if known else "not implied by the robot's limits"
            raise Rejected(f"{where}[{k}]: {item!r} is {why}")
        out.append(canon[pos])
        pos += 1
    return out


def _leaves(value, n_seg, K, where):
    if not isinstance(value, dict):
        raise Rejected(f"{where}: expected an object with 'segment', 't' and 'state'")
    segs, ts, states = value.get("segment"), value.get("t"), value.get("state")
    if not all(isinstance(x, list) for x in (segs, ts, states)) or not segs or not len(segs) == len(ts) == len(states):
        raise Rejected(f"{where}: 'segment', 't' and 'state' must be non-empty lists of one length")
    out_t = []
    seg, expect = 0, 0.0
    for idx, (k, t, st) in enumerate(zip(segs, ts, states)):
        w = f"{where}[{idx}]"
        if isinstance(k, bool) or not isinstance(k, int):
            raise Rejected(f"{w}: segment must be an integer")
        if not isinstance(t, list) or len(t) != 2:
            raise Rejected(f"{w}: t must be [lo, hi]")
        lo, hi = real(t[0], f"{w}.t"), real(t[1], f"{w}.t")
        if not isinstance(st, str) or len(st) != K or any(c not in "+-?" for c in st):
            raise Rejected(f"{w}: state must have one of '+', '-', '?' per instance ({K})")
        if k == seg + 1 and expect == 1.0 and idx > 0:
            seg, expect = k, 0.0
        if k != seg:
            raise Rejected(f"{w}: segment {k} where segment {seg} is not yet covered up to t = 1 (gap or unsorted)")
        if lo != expect:
            raise Rejected(f"{w}: t starts at {lo!r}, not at {expect!r}: the leaves do not tile segment {k}")
        if not lo < hi <= 1.0:
            raise Rejected(f"{w}: t = [{lo!r}, {hi!r}] is not a non-empty part of [0, 1]")
        expect = hi
        out_t.append((lo, hi))
    if seg != n_seg - 1 or expect != 1.0:
        raise Rejected(f"{where}: the leaves end at segment {seg}, t = {expect!r}; "
                       f"the path has {n_seg} segment(s) to cover up to t = 1")
    return segs, out_t, states


def _verdict(insts, states, status, where):
    det = [k for k, inst in enumerate(insts) if inst.constraint == "singularity"]
    others = [k for k in range(len(insts)) if k not in det]
    minus = next(((i, k) for i, st in enumerate(states) for k in others if st[k] == "-"), None)
    signs = {st[k] for st in states for k in det}
    if status == "feasible":
        for i, st in enumerate(states):
            for k in others:
                if st[k] != "+":
                    raise Rejected(f"{where}: feasible, but leaf {i} has '{st[k]}' for {insts[k].label}")
        if det and not (signs == {"+"} or signs == {"-"}):
            raise Rejected(f"{where}: feasible, but det(A) does not have one proved sign on every leaf")
    elif status == "infeasible" and minus is None and not {"+", "-"} <= signs:
        raise Rejected(f"{where}: infeasible, but no leaf is proved violated and det(A) has no two signs")


def _violations(insts, segs, ts, states, value, where):
    if not isinstance(value, list):
        raise Rejected(f"{where}: expected a list")
    regions = [[] for _ in insts]
    certain = [[] for _ in insts]
    for v, item in enumerate(value):
        w = f"{where}[{v}]"
        if not isinstance(item, dict):
            raise Rejected(f"{w}: expected an object")
        key = {k: item[k] for k in ("constraint", "legs", "detail") if k in item}
        idx = next((k for k, inst in enumerate(insts) if inst.json == key), None)
        if idx is None:
            raise Rejected(f"{w}: {key!r} is not an instance of this claim")
        s = item.get("s")
        if not isinstance(s, list) or len(s) != 2:
            raise Rejected(f"{w}.s: expected [lo, hi]")
        s0, s1 = real(s[0], f"{w}.s"), real(s[1], f"{w}.s")
        if not s0 <= s1:
            raise Rejected(f"{w}.s: lo > hi")
        region = (Fraction(s0), Fraction(s1))
        if "segment" in item or "t" in item:
            k, t = item.get("segment"), item.get("t")
            if isinstance(k, bool) or not isinstance(k, int) or not isinstance(t, list) or len(t) != 2:
                raise Rejected(f"{w}: 'segment' (an integer) and 't' ([lo, hi]) go together")
            t0, t1 = real(t[0], f"{w}.t"), real(t[1], f"{w}.t")
            e0, e1 = k + Fraction(t0), k + Fraction(t1)
            outward = (Fraction(s0) <= e0 and Fraction(s1) >= e1
                       and s0 >= math.nextafter(float(e0), -math.inf) and s1 <= math.nextafter(float(e1), math.inf))
            if not 0.0 <= t0 <= t1 <= 1.0 or not outward:
                raise Rejected(f"{w}: t must lie in [0, 1] and s must enclose segment + t (rounded outward)")
            region = (k + Fraction(t0), k + Fraction(t1))   # exact; s is its rounding
        if not isinstance(item.get("certain"), bool):
            raise Rejected(f"{w}.certain: expected true or false")
        regions[idx].append(region)
        if item["certain"]:
            certain[idx].append((v, region))
    for k, inst in enumerate(insts):
        bad = "?" if inst.constraint == "singularity" else "-?"
        merged = []
        for a, b in sorted(regions[k]):
            if merged and a <= merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], b)
            else:
                merged.append([a, b])
        starts = [a for a, _ in merged]
        for i, st in enumerate(states):
            if st[k] in bad:
                lo, hi = segs[i] + Fraction(ts[i][0]), segs[i] + Fraction(ts[i][1])
                p = bisect.bisect_right(starts, lo) - 1
                if p < 0 or merged[p][1] < hi:
                    raise Rejected(f"{where}: leaf {i} (segment {segs[i]}, t = [{ts[i][0]!r}, {ts[i][1]!r}]) is "
                                   f"'{st[k]}' for {inst.label} but no violation interval covers it")
        for v, (a, b) in certain[k]:
            meets = {states[i][k] for i in range(len(states))
                     if segs[i] + Fraction(ts[i][0]) <= b and a <= segs[i] + Fraction(ts[i][1])}
            if not ("-" in meets and (inst.constraint != "singularity" or "+" in meets)):
                raise Rejected(f"{where}[{v}]: marked certain, but no leaf in its interval proves it")


# ----- re-proving the leaves of one segment -------------------------------------------
def _prove_segment(seg, insts, ts, states, offset, where, counts):
    """Re-prove every '+'/'-' of the leaves of one segment (see the module docstring)."""
    n, K = len(ts), len(insts)
    if not n:
        return
    run_end = []                # run_end[k][p]: last leaf q >= p with the same char as p for instance k
    for k in range(K):
        ends = [0] * n
        ends[-1] = n - 1
        for p in range(n - 2, -1, -1):
            ends[p] = ends[p + 1] if states[p][k] == states[p + 1][k] else p
        run_end.append(ends)
    stack = [(0, n - 1, list(range(K)))]
    while stack:
        a, b, pending = stack.pop()
        span = Span(seg, ts[a][0], ts[b][1])
        rest = []
        for k in pending:
            if run_end[k][a] < b:
                rest.append(k)
                continue
            ch = states[a][k]
            if ch == "?":
                continue
            got = insts[k].prove(span, ch)
            if got == -1:
                raise Rejected(_at(where, offset + a, seg, span.lo, span.hi, insts[k], ch, "refuted"))
            if got == 0:
                if a == b:
                    counts["pieces"] += _bisect(seg, insts[k], ch, span, where, offset + a)
                else:
                    rest.append(k)
        if rest:
            mid = (a + b) // 2
            stack.append((mid + 1, b, rest))
            stack.append((a, mid, rest))


def _bisect(seg, inst, ch, span, where, leaf):
    """Prove ``ch`` on every piece of a bisection of the leaf; returns the pieces used beyond one."""
    todo = [(span.lo, span.hi, 0)]
    done = tried = 0
    while todo:
        lo, hi, depth = todo.pop()
        mid = 0.5 * lo + 0.5 * hi
        if depth == MAX_DEPTH or tried >= MAX_PIECES or not lo < mid < hi:
            raise Rejected(_at(where, leaf, seg, span.lo, span.hi, inst, ch,
                               f"not proved (piece [{lo!r}, {hi!r}] undecided after bisecting)"))
        for a, b in ((lo, mid), (mid, hi)):
            tried += 1
            got = inst.prove(Span(seg, a, b), ch)
            if got == -1:
                raise Rejected(_at(where, leaf, seg, a, b, inst, ch, "refuted"))
            if got == 0:
                todo.append((a, b, depth + 1))
            else:
                done += 1
    return done - 1


def _at(where, leaf, seg, lo, hi, inst, ch, what):
    return f"{where}.leaves[{leaf}]: '{ch}' for {inst.label} {what} on segment {seg.k}, t in [{lo!r}, {hi!r}]"
