"""Trajectory claims (``"problem": "trajectory"``, docs/certificates.md "Trajectory claims").

The leaves of every segment of a path must tile [0, 1] exactly, and every ``+``/``-`` leaf state is re-proved on its
t-interval (monotone or mean-value enclosures, docs/soundness.md §9; an undecided leaf bisected up to ``MAX_DEPTH``
levels and ``MAX_PIECES`` pieces, an enclosure proving the opposite refuting the claim at once); the verdict and the
``violations`` must follow from the leaf states."""
from __future__ import annotations

from bisect import bisect_left, bisect_right
import itertools
from fractions import Fraction

import numpy as np

from .arith import PI, Iv
from .models import MODELS, Dual, cross, det, det_interval, each_claim, header_model, lift, points, rotate, sincos
from .numbers import angle, enclose, exact, real
from .report import Rejected

MAX_DEPTH, MAX_PIECES = 12, 400
STATUSES = ("feasible", "infeasible", "undecided")
SHOWN = 20           # a path's failing ranges listed in the account (the certificate holds them all)
# per model: (pose indices of the position, rotation angles as [(pose index, sign)], rotation axes)
FRAMES = {"planar-3rpr/1": ((0, 1), (((2, 1),),), "z"),
          "spherical-3dof/1": ((), (((0, 1),), ((1, 1),), ((2, 1),)), "zyz"),
          "spherical-3dof-tt/1": ((), (((0, 1),), ((1, 1),), ((2, 1), (0, -1))), "zyz"),
          "gough-stewart/1": ((0, 1, 2), (((3, 1),), ((4, 1),), ((5, 1),)), "zxz")}
ANGLES = {"planar-3rpr/1": {"phi"}, "spherical-3dof/1": {"phi1", "phi2", "phi3"},
          "spherical-3dof-tt/1": {"phi1", "phi2", "sigma"}, "gough-stewart/1": {"psi", "theta", "phi"}}


def _dot(a, b):
    return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]


def _norm2(a):
    return _dot(a, a) if not isinstance(a[0], Iv) else (a[0].sqr() + a[1].sqr()) + a[2].sqr()


class Geometry:
    """The robot of a certificate: enclosed geometry and the canonical constraint instances."""

    def __init__(self, model, robot: dict):
        self.model, self.n = model, model.legs
        self.position, self.angles, self.axes = FRAMES[model.name]
        self.base2 = points(robot, "base", self.n, model.base_dim)
        self.platform = points(robot, "platform", self.n, model.platform_dim)
        self.base = [tuple(p) + (Iv(0.0),) * (3 - len(p)) for p in self.base2]
        limits = robot.get("limits", {})
        if not isinstance(limits, dict):
            raise Rejected("robot.limits: expected an object")
        for key in limits:
            if key not in ("leg_length", "leg_radius", "base_joints", "platform_joints"):
                raise Rejected(f"robot.limits.{key}: unknown limit")
        self.instances = []
        if "leg_length" in limits:
            self._leg_lengths(limits["leg_length"])
        for side in ("base", "platform"):
            if f"{side}_joints" in limits:
                self._joints(side, limits[f"{side}_joints"])
        if "leg_radius" in limits:
            self._pairs(limits["leg_radius"])
        self.instances.append(Instance("singularity", tuple(range(1, self.n + 1)), "", None))

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
            self.instances.append(Instance("leg-length", (i + 1,), "", (i, Iv.const(lo * lo), Iv.const(hi * hi))))

    def _vector(self, value, where):
        if not isinstance(value, list) or len(value) != 3:
            raise Rejected(f"{where}: expected 3 coordinates")
        if all(exact(c, where) == 0 for c in value):
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
            if not isinstance(table, dict) or not table or any(k not in ("normals", "axis", "half_angle") for k in table):
                raise Rejected(f"{w}: expected an object with 'normals' and/or 'axis' and 'half_angle'")
            normals = table.get("normals", [])
            if "normals" in table and (not isinstance(normals, list) or not normals):
                raise Rejected(f"{w}.normals: expected a non-empty list of vectors")
            for k, normal in enumerate(normals):
                vec = self._vector(normal, f"{w}.normals[{k}]")
                self.instances.append(Instance("joints", (i + 1,), f"{side} facet {k + 1}", (i, side, "facet", vec, None)))
            if ("axis" in table) != ("half_angle" in table):
                raise Rejected(f"{w}: a cone needs both 'axis' and 'half_angle'")
            if "axis" in table:
                axis = self._vector(table["axis"], f"{w}.axis")
                q, deg = angle(table["half_angle"], f"{w}.half_angle")
                alpha = enclose(table["half_angle"], f"{w}.half_angle", True)
                if q < 0 or not ((deg and q <= 90) or (not deg and alpha.hi <= (PI * 0.5).lo)):
                    raise Rejected(f"{w}.half_angle: expected an angle in [0, 90deg]")
                c2 = _norm2(axis) * sincos(alpha)[1].sqr()
                self.instances.append(Instance("joints", (i + 1,), f"{side} cone", (i, side, "cone", axis, c2)))

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
            self.instances.append(Instance("interference", (i + 1, j + 1), "", (i, j, r == 0, Iv.const(r * r), w0)))


class Spans:
    """t-intervals [lo, hi] of segments ``seg`` (arrays (N,)) of a path with pose P + t D."""

    def __init__(self, geo, P, D, seg, lo, hi):
        self.geo, self.seg, self.lo, self.hi = geo, seg, lo, hi
        self.P, self.D = P[seg], D[seg]                      # Iv (N, d)
        self.mid = np.minimum(np.maximum(0.5 * lo + 0.5 * hi, lo), hi)
        self.T, self.thrice = Iv(lo, hi), np.tile(np.arange(len(lo)), 3)
        self._frames = {}

    def frame(self, which):
        if which not in self._frames:
            d = self.P.shape[1]
            if which == "T":
                pose = [Dual(self.P[:, j] + self.T * self.D[:, j], Iv(self.D.lo[:, j, None], self.D.hi[:, j, None]))
                        for j in range(d)]
            else:                                           # "points": the poses at lo, hi, mid, stacked
                t, P, D = Iv(np.concatenate([self.lo, self.hi, self.mid])), self.P[self.thrice], self.D[self.thrice]
                pose = [P[:, j] + t * D[:, j] for j in range(d)]
            self._frames[which] = Frame(self.geo, pose)
        return self._frames[which]

    def enclose(self, fn, natural=None):
        """Enclosures over T of the quantities ``fn(frame)``: monotone, or mean-value form ∩ natural."""
        ys, points, N = fn(self.frame("T")), fn(self.frame("points")), len(self.lo)
        out = []
        for k, y in enumerate(ys):
            y = lift(y)
            nat = y.v if natural is None else natural[k]
            if y.g is None:
                out.append(nat)
                continue
            g, v = y.g[..., 0], lift(points[k]).v     # v varies with t: one row per pose, 3N rows (lo, hi, mid)
            a, b, mid = (Iv(*(np.broadcast_to(x, v.shape)[i * N:i * N + N] for x in (v.lo, v.hi))) for i in range(3))
            up, down = g.lo >= 0, g.hi <= 0
            h = self.T - self.mid
            extra = (1,) * (g.lo.ndim - 1)
            form = mid + g * Iv(h.lo.reshape(h.lo.shape + extra), h.hi.reshape(h.hi.shape + extra))
            m = nat.meet(form)
            out.append(Iv(np.where(up, a.lo, np.where(down, b.lo, m.lo)), np.where(up, b.hi, np.where(down, a.hi, m.hi))))
        return out


class Frame:
    """The pose (Iv at points, Dual in t over T), the rotation and the leg vectors l_i."""

    def __init__(self, geo, pose):
        self.geo, self.pose = geo, pose
        self.cs = []
        for combo in geo.angles:
            theta = None
            for i, s in combo:
                term = pose[i] if s > 0 else -pose[i]
                theta = term if theta is None else theta + term
            self.cs.append(sincos(theta))
        if geo.model.name == "planar-3rpr/1":        # turned: R b_i; legs: centre + R b_i - a_i
            (s, c), (x, y) = self.cs[0], pose[:2]
            self.turned = [(c * px - s * py, s * px + c * py, Iv(0.0)) for px, py in geo.platform]
            self.legs = [((x + r[0]) - bx, (y + r[1]) - by, Iv(0.0)) for (bx, by, _), r in zip(geo.base, self.turned)]
        else:
            centre, self.turned = [pose[i] for i in geo.position], [rotate(geo.axes, self.cs, b) for b in geo.platform]
            self.legs = [tuple((centre[k] + r[k] if centre else r[k]) - a[k] for k in range(3)) for a, r in zip(geo.base, self.turned)]
        self._sq = {}

    def leg_sq(self, i):
        return self._sq[i] if i in self._sq else self._sq.setdefault(i, _norm2(self.legs[i]))


class Instance:
    """One scalar constraint; ``prove(spans, ch)``: per span 1 proved, −1 refuted, 0 undecided."""

    def __init__(self, constraint, legs, detail, data):
        self.constraint, self.legs, self.detail, self.data = constraint, legs, detail, data
        self.json = {"constraint": constraint, "legs": list(legs), **({"detail": detail} if detail else {})}
        self.label = (f"{constraint} leg{'s' if len(legs) > 1 else ''} {'-'.join(map(str, legs))}"
                      + (f" ({detail})" if detail else ""))

    def prove(self, spans, ch):
        return self.verdict(*getattr(self, "_" + self.constraint.replace("-", "_"))(spans, ch), ch)

    @staticmethod
    def verdict(sat, viol, ch):
        """1 where the state ``ch`` (1 '+', 2 '-') is proved, −1 where the other one is, else 0."""
        want = ch == 1
        return np.where((sat & want) | (viol & ~want), 1, np.where(sat | viol, -1, 0))

    def _leg_length(self, sp, ch):
        i, lo2, hi2 = self.data
        (q,) = sp.enclose(lambda fr: [fr.leg_sq(i)])
        return (q.lo >= lo2.hi) & (q.hi <= hi2.lo), (q.hi < lo2.lo) | (q.lo > hi2.hi)

    def _joints(self, sp, ch):
        i, side, kind, vec, c2 = self.data

        def fn(fr):
            l = fr.legs[i]
            g = -_dot(rotate(fr.geo.axes, fr.cs, vec), l) if side == "platform" else _dot(l, vec)
            return [g] if kind == "facet" else [g, g * g - fr.leg_sq(i) * c2]

        vals = sp.enclose(fn)
        return np.all([v.lo >= 0 for v in vals], 0), np.any([v.hi < 0 for v in vals], 0)

    def _interference(self, sp, ch):
        sat, viol = interference(sp, [self])
        return sat[:, 0], viol[:, 0]

    def _singularity(self, sp, ch):
        rows = lambda f: f.geo.model.rows(f.pose, f.geo.base2, f.geo.platform)  # noqa: E731
        y = det(M := rows(fr := sp.frame("T")))     # in t over T; its value part: the natural enclosure, ∩ elimination
        D = det_interval([[lift(e).v for e in row] for row in M], lift(y).v)
        (D,) = sp.enclose(lambda f: [y if f is fr else det_interval(rows(f))], natural=[D])
        return D.pos(), D.neg()


def interference(sp, insts):
    """(proved >= r, proved < r) per span and instance (N, P) for the interference instances ``insts``,
    every pair at once (the quantities of docs/certificates.md "Re-verification", on arrays of pairs)."""
    I, J = [x.data[0] for x in insts], [x.data[1] for x in insts]
    zero = np.array([x.data[2] for x in insts])
    r2 = Iv(np.array([x.data[3].lo for x in insts]), np.array([x.data[3].hi for x in insts]))
    w0 = tuple(Iv(np.array([x.data[4][k].lo for x in insts]), np.array([x.data[4][k].hi for x in insts]))
               for k in range(3))
    legs = lambda fr, idx: tuple(_stack([fr.legs[i][k] for i in idx]) for k in range(3))  # noqa: E731
    sq = lambda fr, idx: _stack([fr.leg_sq(i) for i in idx])  # noqa: E731
    gap = lambda fr: tuple(_stack([(fr.turned[j][k] - fr.turned[i][k]) - (fr.geo.base[j][k] - fr.geo.base[i][k])
                                   for i, j in zip(I, J)]) for k in range(3))  # noqa: E731  l_j - l_i, without the centre

    def line(fr):
        cr = cross(legs(fr, I), gap(fr))                      # l_i x l_j = l_i x (l_j - l_i)
        d = _dot(w0, cr)
        return [d * d - _norm2(cr) * r2, _norm2(cr)]

    def feet(fr):
        u, v = legs(fr, I), legs(fr, J)
        a, b, c = sq(fr, I), _dot(u, v), sq(fr, J)
        d, e = _dot(u, w0), _dot(v, w0)
        dl = a * c - b * b
        s_num, t_num = b * e - c * d, a * e - b * d
        return [s_num, s_num - dl, t_num, t_num - dl]

    def ends(fr):
        u, v, w, nu, nv, out = legs(fr, I), legs(fr, J), w0, sq(fr, I), sq(fr, J), []
        c1, m = cross(u, gap(fr)), tuple(-x for x in w)      # c1 = u x v; (w + u) x v = w x v + c1, (v - w) x u = -w x u - c1
        a, b = cross(w, v), cross(m, u)
        for q, sg, n2, qs in ((w, v, nv, a), (tuple(w[k] + u[k] for k in range(3)), v, nv, tuple(a[k] + c1[k] for k in range(3))),
                              (m, u, nu, b), (tuple(v[k] - w[k] for k in range(3)), u, nu, tuple(b[k] - c1[k] for k in range(3)))):
            tau = _dot(q, sg)
            out += [tau, tau - n2, n2, _norm2(qs) - n2 * r2,
                    _norm2(q) - r2, _norm2(tuple(q[k] - sg[k] for k in range(3))) - r2]
        return out

    E, delta = sp.enclose(line)
    sat, viol = E.pos() | zero, np.zeros(E.lo.shape, bool)   # a zero radius: a distance is never < 0
    if sat.all():                                             # the line distance settles every span
        return sat, viol
    s0, s1, t0, t1 = sp.enclose(feet)
    feet_in = (s0.lo >= 0) & (s1.hi <= 0) & (t0.lo >= 0) & (t1.hi <= 0) & delta.pos()
    feet_out = s0.neg() | s1.pos() | t0.neg() | t1.pos()
    vals = sp.enclose(ends)
    lower, witness = np.ones(E.lo.shape, bool), np.zeros(E.lo.shape, bool)
    for p in range(4):
        tau, tau1, n2, eps, f0, f1 = vals[6 * p:6 * p + 6]
        lower &= ((tau.hi <= 0) & (f0.lo >= 0)) | ((tau1.lo >= 0) & (f1.lo >= 0)) | (n2.pos() & (eps.lo >= 0))
        witness |= f0.neg() | f1.neg() | ((tau.lo >= 0) & (tau1.hi <= 0) & n2.pos() & eps.neg())
    # the points of one leg against the other's line (decides parallel legs, digest E11; docs/soundness.md):
    # |c0|² - r²|v|² >= 0 and |c0 + c1|² - r²|v|² - Δ >= 0, c0 = w0 x v, c1 = u x v (and i, j exchanged)
    to_line = np.zeros(E.lo.shape, bool)
    for p in (0, 2):
        to_line |= (vals[6 * p + 3].lo >= 0) & ((vals[6 * p + 9] - delta).lo >= 0)
    return sat | (feet_out & lower) | to_line, ~zero & ((feet_in & E.neg()) | witness)


def _stack(values):
    """Per-leg values (Iv or Dual, each (N,)) as one (N, P) value."""
    if isinstance(values[0], Dual):
        g = [v.g for v in values]
        return Dual(_stack([v.v for v in values]), None if any(x is None for x in g) else
                    Iv(np.stack([x.lo for x in g], 1), np.stack([x.hi for x in g], 1)))
    values = [lift(v).v if isinstance(v, Dual) else v for v in values]
    return Iv(np.stack([np.broadcast_to(v.lo, values[0].lo.shape) for v in values], -1),
              np.stack([np.broadcast_to(v.hi, values[0].lo.shape) for v in values], -1))


def check(cert, report) -> None:
    h = cert.header
    model = header_model(h, MODELS, lambda m: m.kind, "pose", lambda m: m.pose)
    geo, counts, verdicts, groups = Geometry(model, h["robot"]), report.checked, {}, {}
    for c, (where, claim) in enumerate(each_claim(h["claims"])):
        status = claim.get("status")
        if status not in STATUSES:
            raise Rejected(f"{where}.status: unknown status {status!r:.60} (known: {', '.join(STATUSES)})")
        P, D = _path(geo, claim.get("path"), f"{where}.path")
        insts = _instances(geo, claim.get("instances"), f"{where}.instances")
        seg, lo, hi, states = _leaves(cert, claim.get("leaves"), P.shape[0] + 1, len(insts), f"{where}.leaves")
        _verdict(insts, states, status, f"{where}.status")
        _violations(insts, seg, lo, hi, states, claim.get("violations"), f"{where}.violations")
        groups.setdefault(tuple(map(id, insts)), (insts, []))[1].append((c, P, D, seg, lo, hi, states))
        counts["leaves"] += len(seg)
        counts["undecided"] += status == "undecided"
        verdicts[status] = verdicts.get(status, 0) + 1
    for insts, members in groups.values():      # the claims with one instance list: their leaves together
        c, P, D, seg, lo, hi, states = zip(*members)
        sizes, offset = [len(x) for x in seg], np.cumsum([0] + [x.shape[0] for x in P])
        member = np.repeat(np.arange(len(members)), sizes)
        first = np.repeat(np.cumsum([0] + sizes)[:-1], sizes)
        local = np.concatenate(seg)                     # segment numbers within each path
        P, D = (Iv(np.concatenate([x.lo for x in v]), np.concatenate([x.hi for x in v])) for v in (P, D))
        lo, hi, states = (np.concatenate(v) for v in (lo, hi, states))
        name = lambda i: f"claims[{c[member[i]]}].leaves[{i - first[i]}]"  # noqa: E731
        spans = Spans(geo, P, D, local + offset[member], lo, hi)   # the leaves' frames, shared by the instances
        pairs = [k for k, inst in enumerate(insts) if inst.constraint == "interference"]
        both = interference(spans, [insts[k] for k in pairs]) if pairs else None   # every pair at once
        for k, inst in enumerate(insts):
            got = None if k not in pairs else inst.verdict(*(x[:, pairs.index(k)] for x in both), states[:, k])
            counts["pieces"] += _prove(geo, P, D, inst, spans, states[:, k], name, got, local)
    first = h["claims"][0]
    report.about["question"] = (f"{len(h['claims'])} path(s); first: {' -> '.join(','.join(p) for p in first['path'])}, "
                                f"constraints: {', '.join(sorted({i['constraint'] for i in first['instances']}))}")
    report.proved.append(", ".join(f"{n} path{'s' * (n > 1)} {s}" for s, n in verdicts.items())
                         + " (each relative to its listed constraints)")
    if "route" in h:                     # a plan: its paths join route.from to route.to, one after another, all feasible
        r, paths = h["route"], [claim["path"] for claim in h["claims"]]     # (for one list of constraints)
        if not isinstance(r, dict) or set(r) != {"from", "to"} or set(verdicts) != {"feasible"} or len(groups) != 1 \
                or [r["from"]] + [p[-1] for p in paths] != [p[0] for p in paths] + [r["to"]]:
            raise Rejected("route: the paths must be feasible for the same constraints and join its from to its to")
        report.proved.append(f"a route from {','.join(r['from'])} to {','.join(r['to'])}: the {len(paths)} paths, end to "
                             f"end, for {', '.join(sorted({i['constraint'] for i in first['instances']}))}")
    for c, claim in list(enumerate(h["claims"]))[:5]:      # (at most SHOWN ranges a path: they are in the certificate)
        more = len(claim["violations"]) - SHOWN
        report.proved.append(f"path {c + 1}: {claim['status']}" + "".join(
            f"; {v['constraint']} (legs {', '.join(map(str, v.get('legs', [])))}) "
            f"{'fails' if v['certain'] else 'not proved'} for s in [{v['s'][0]}, {v['s'][1]}]"
            for v in claim["violations"][:SHOWN]) + (f"; and {more} more range{'s' * (more > 1)}" if more > 0 else ""))


def _path(geo, path, where):
    """Per segment, the start pose P and the step D (exact differences of the decimals, enclosed)."""
    d = len(geo.model.pose)
    if not isinstance(path, list) or len(path) < 2:
        raise Rejected(f"{where}: expected a list of at least 2 poses")
    texts = []
    for p, pose in enumerate(path):
        if not isinstance(pose, list) or len(pose) != d or not all(isinstance(v, str) for v in pose):
            raise Rejected(f"{where}[{p}]: expected {d} exact decimal strings {list(geo.model.pose)}")
        values = []
        for name, v in zip(geo.model.pose, pose):
            q, deg = angle(v, f"{where}[{p}].{name}")
            if deg and name not in ANGLES[geo.model.name]:
                raise Rejected(f"{where}[{p}].{name}: 'deg' is only allowed for angles")
            values.append((q, deg))
        texts.append(values)
    rad = lambda q, deg: Iv.const(q) * PI * Iv.const(Fraction(1, 180)) if deg else Iv.const(q)  # noqa: E731
    P, D = [], []
    for a, b in zip(texts, texts[1:]):
        P.append([rad(*x) for x in a])
        D.append([rad(y[0] - x[0], x[1]) if x[1] == y[1] else rad(*y) - rad(*x) for x, y in zip(a, b)])
    to = lambda rows: Iv(np.array([[v.lo for v in r] for r in rows]), np.array([[v.hi for v in r] for r in rows]))  # noqa: E731
    return to(P), to(D)


def _instances(geo, value, where):
    if not isinstance(value, list) or not value:
        raise Rejected(f"{where}: expected a non-empty list of constraint instances")
    out, pos, canon = [], 0, geo.instances
    for k, item in enumerate(value):
        while pos < len(canon) and canon[pos].json != item:
            pos += 1
        if pos == len(canon):
            known = any(c.json == item for c in canon)
            why = "duplicated or out of the canonical order" if known else "not implied by the robot's limits"
            raise Rejected(f"{where}[{k}]: {item!r:.80} is {why}")
        out.append(canon[pos])
        pos += 1
    names, ids = {i.constraint for i in out}, set(map(id, out))    # a constraint's instances: all of them or none
    if missing := [c.json for c in canon if c.constraint in names and id(c) not in ids]:
        raise Rejected(f"{where}: {missing[0]!r:.80} is missing (the instances of a constraint are listed all or none)")
    return out


def _leaves(cert, value, n_seg, K, where):
    """(segment, t lo, t hi, states (N, K) in 0 '?', 1 '+', 2 '-'), checked to tile each segment's [0, 1]."""
    if not (isinstance(value, list) and len(value) == 2 and all(type(v) is int and v >= 0 for v in value)):
        raise Rejected(f"{where}: expected [first, count] rows of traj.segment, traj.t, traj.state")
    a, b = value[0], value[0] + value[1]
    seg, t = cert.array("traj.segment", ("<i4",))[a:b], cert.array("traj.t", ("<f8",), (2,))[a:b]
    states = cert.array("traj.state", ("|u1",))[a:b]
    if len(seg) != value[1] or len(t) != value[1] or states.shape != (value[1], K) or np.any(states > 2):
        raise Rejected(f"{where}: rows {a}..{b - 1} are not all in the body, or a state is not 0, 1, 2")
    seg, lo, hi = seg.astype(np.int64), t[:, 0].astype(float), t[:, 1].astype(float)
    if not len(seg):
        raise Rejected(f"{where}: no leaves")
    first, last = np.concatenate([[True], seg[1:] != seg[:-1]]), np.concatenate([seg[1:] != seg[:-1], [True]])
    starts = seg[first]
    bad = ~np.isfinite(lo) | ~np.isfinite(hi) | ~(lo < hi) | (hi > 1.0) | (first & (lo != 0.0)) | (last & (hi != 1.0))
    bad |= ~first & (lo != np.concatenate([[0.0], hi[:-1]]))
    if bad.any() or not np.array_equal(starts, np.arange(n_seg - 1)):
        i = int(np.nonzero(bad)[0][0]) if bad.any() else 0
        raise Rejected(f"{where}[{i}]: the leaves do not tile [0, 1] on every one of the {n_seg - 1} segments, in order, "
                       f"up to t = 1 (segment {seg[i]}, t = [{float(lo[i])!r}, {float(hi[i])!r}])")
    return seg, lo, hi, states


def _verdict(insts, states, status, where):
    det = [k for k, inst in enumerate(insts) if inst.constraint == "singularity"]
    others = [k for k in range(len(insts)) if k not in det]
    signs = set(np.unique(states[:, det]).tolist()) if det else set()
    if status == "feasible":
        bad = np.nonzero(states[:, others] != 1)
        if len(bad[0]):
            i, k = bad[0][0], others[bad[1][0]]
            raise Rejected(f"{where}: feasible, but leaf {i} has '{'?+-'[states[i, k]]}' for {insts[k].label}")
        if det and signs not in ({1}, {2}):
            raise Rejected(f"{where}: feasible, but det(A) does not have one proved sign on every leaf")
    elif status == "infeasible" and not np.any(states[:, others] == 2) and not {1, 2} <= signs:
        raise Rejected(f"{where}: infeasible, but no leaf is proved violated and det(A) has no two signs")


def _violations(insts, seg, lo, hi, states, value, where):
    if not isinstance(value, list):
        raise Rejected(f"{where}: expected a list")
    regions, certain = [[] for _ in insts], [[] for _ in insts]
    for v, item in enumerate(value):
        w = f"{where}[{v}]"
        if not isinstance(item, dict):
            raise Rejected(f"{w}: expected an object")
        key = {k: item[k] for k in ("constraint", "legs", "detail") if k in item}
        idx = next((k for k, inst in enumerate(insts) if inst.json == key), None)
        if idx is None:
            raise Rejected(f"{w}: {key!r:.80} is not an instance of this claim")
        s = item.get("s")
        if not isinstance(s, list) or len(s) != 2:
            raise Rejected(f"{w}.s: expected [lo, hi]")
        s0, s1 = real(s[0], f"{w}.s"), real(s[1], f"{w}.s")
        if not s0 <= s1:
            raise Rejected(f"{w}.s: lo > hi")
        region = (Fraction(s0), Fraction(s1))
        if "segment" in item or "t" in item:
            k, t = item.get("segment"), item.get("t")
            if type(k) is not int or not isinstance(t, list) or len(t) != 2:
                raise Rejected(f"{w}: 'segment' (an integer) and 't' ([lo, hi]) go together")
            t0, t1 = real(t[0], f"{w}.t"), real(t[1], f"{w}.t")
            e0, e1 = k + Fraction(t0), k + Fraction(t1)
            outward = (Fraction(s0) <= e0 and Fraction(s1) >= e1 and s0 >= np.nextafter(float(e0), -np.inf)
                       and s1 <= np.nextafter(float(e1), np.inf))
            if not 0.0 <= t0 <= t1 <= 1.0 or not outward:
                raise Rejected(f"{w}: t must lie in [0, 1] and s must enclose segment + t (rounded outward)")
            region = (e0, e1)
        if not isinstance(item.get("certain"), bool):
            raise Rejected(f"{w}.certain: expected true or false")
        regions[idx].append(region)
        if item["certain"]:
            certain[idx].append((v, region))
    A, B = ([s + Fraction(x) for s, x in zip(seg.tolist(), t.tolist())] for t in (lo, hi))  # leaf s, exact, in order
    for k, inst in enumerate(insts):
        bad = states[:, k] == 0 if inst.constraint == "singularity" else states[:, k] != 1
        merged = []
        for a, b in sorted(regions[k]):
            if merged and a <= merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], b)
            else:
                merged.append([a, b])
        starts = [m[0] for m in merged]        # disjoint, sorted: only the last one starting at or before a leaf may cover it
        for i in np.nonzero(bad)[0]:
            if (m := bisect_right(starts, A[i]) - 1) < 0 or B[i] > merged[m][1]:
                raise Rejected(f"{where}: leaf {i} (segment {seg[i]}, t = [{float(lo[i])!r}, {float(hi[i])!r}]) is "
                               f"'{'?+-'[states[i, k]]}' for {inst.label} but no violation interval covers it")
        for v, (a, b) in certain[k]:        # the leaves meeting [a, b]: a run of them (they tile, in order)
            meets = set(states[bisect_left(B, a):bisect_right(A, b), k].tolist())
            if not (2 in meets and (inst.constraint != "singularity" or 1 in meets)):
                raise Rejected(f"{where}[{v}]: marked certain, but no leaf in its interval proves it")


def _prove(geo, P, D, inst, spans, ch, name, got, local):
    """Prove the character of every leaf for one instance (``got``: already evaluated on the leaves, or
    None); bisect undecided ones; ``name(i)``, ``local[i]``: leaf i's name and segment.  Returns the extra
    pieces used."""
    got = inst.prove(spans, ch) if got is None else got
    todo = np.nonzero((ch != 0) & (got != 1))[0]
    leaf, s, a, b, depth, pieces = todo, spans.seg[todo], spans.lo[todo], spans.hi[todo], 0, 0
    count = np.zeros(len(ch), dtype=np.int64)
    while len(leaf):
        got = got[leaf] if depth == 0 else inst.prove(Spans(geo, P, D, s, a, b), ch[leaf])
        bad = (got == -1) | ((got == 0) & ((depth == MAX_DEPTH) | (count[leaf] >= MAX_PIECES)))
        if bad.any():
            i = np.nonzero(bad)[0][0]
            what = "refuted" if got[i] == -1 else "not proved (undecided after bisecting)"
            raise Rejected(f"{name(leaf[i])}: '{'?+-'[ch[leaf[i]]]}' for {inst.label} {what} "
                           f"on segment {local[leaf[i]]}, t in [{float(a[i])!r}, {float(b[i])!r}]")
        open_ = got == 0
        leaf, s, a, b = leaf[open_], s[open_], a[open_], b[open_]
        m = 0.5 * a + 0.5 * b
        if not np.all((a < m) & (m < b)):
            depth = MAX_DEPTH
            continue
        leaf, s = np.concatenate([leaf, leaf]), np.concatenate([s, s])
        a, b = np.concatenate([a, m]), np.concatenate([m, b])
        np.add.at(count, leaf, 1)
        pieces += len(leaf) // 2
        depth += 1
    return pieces
