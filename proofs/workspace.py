"""Workspace claims (``"problem": "workspace-section"`` / ``"workspace-volume"``, docs/certificates.md "Workspace
claims"; soundness: docs/soundness.md §11).

Each claim's ``domain`` is re-proved to hold its section (every section of its slab), or to be ``"empty"``; the leaves
of its tree tile the domain, its inside and outside leaves are re-proved, and the claimed area (volume) bounds must
bracket the exact sums over the inside, and the inside and boundary, boxes."""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from . import tree
from .arith import Iv, sincos
from .models import each_claim, header_model, points, rotate
from .numbers import enclose, exact, real
from .report import Rejected

MODELS = {"gough-stewart-workspace/1": ("gough-stewart", ("psi", "theta", "phi"), 6, 3),
          "planar-3rpr-workspace/1": ("planar-3rpr", ("phi",), 3, 2)}
LEAVES = {0: ("inside", {}), 1: ("outside", {"tree.index": 1}), 2: ("boundary", {})}


class Legs:
    """u_i = a_i − R b_i (Iv (legs, 3)) and the squared limits, from the stated exact data."""

    def __init__(self, model, robot, orientation):
        kind, angles, n, dim = MODELS[model]
        self.planar, self.n = dim == 2, n
        a, b = points(robot, "base", n, dim), points(robot, "platform", n, dim)
        if not isinstance(orientation, dict) or sorted(orientation) != sorted(angles):
            raise Rejected(f"orientation: expected the angles {', '.join(angles)}")
        cs = [sincos(enclose(orientation[name], f"orientation.{name}", True)) for name in angles]
        a, b = ([tuple(p) + (Iv(0.0),) * (3 - dim) for p in pts] for pts in (a, b))     # in space (z = 0 in the plane)
        rb = [rotate("zxz" if not self.planar else "z", cs, p) for p in b]
        u = [[p[k] - q[k] for k in range(3)] for p, q in zip(a, rb)]
        self.u = [Iv(np.array([r[k].lo for r in u]), np.array([r[k].hi for r in u])) for k in range(3)]
        limits = robot.get("limits")
        pairs = limits.get("leg_length") if isinstance(limits, dict) else None
        if not isinstance(pairs, list) or len(pairs) != n or not all(isinstance(p, list) and len(p) == 2 for p in pairs):
            raise Rejected(f"robot.limits.leg_length: expected {n} [min, max] pairs")
        q = [(exact(p[0], f"robot.limits.leg_length[{i}]"), exact(p[1], f"robot.limits.leg_length[{i}]"))
             for i, p in enumerate(pairs)]
        if any(not 0 <= lo <= hi for lo, hi in q):
            raise Rejected("robot.limits.leg_length: expected 0 <= min <= max")
        self.rmin2 = Iv([Iv.const(lo * lo).lo for lo, _ in q], [Iv.const(lo * lo).hi for lo, _ in q])
        self.rmax2 = Iv([Iv.const(hi * hi).lo for _, hi in q], [Iv.const(hi * hi).hi for _, hi in q])

    def h2(self, Z: Iv) -> Iv:
        return (Iv(Z.lo, Z.hi) - self.u[2]).sqr()


def check(cert, report) -> None:
    h = cert.header
    header_model(h, MODELS, lambda m: m[0])
    legs = Legs(h["model"], h["robot"], h.get("orientation"))
    if (volume := h["problem"] == "workspace-volume") and legs.planar:
        raise Rejected("problem: a planar model has no volume")
    claims = h["claims"]
    Z = _heights(legs, claims, volume)
    h2 = [legs.h2(z) for z in Z]
    boxes = [_domain(legs, h2[k], c.get("domain"), f"claims[{k}]") for k, c in enumerate(claims)]
    roots = [k for k, b in enumerate(boxes) if b is not None]
    if any(claims[k].get("tree") is not True for k in roots):
        raise Rejected("claims: a claim with a domain box has \"tree\": true (its tree is in the body)")
    for k, b in enumerate(boxes):
        if b is None and claims[k].get("tree") is not None:
            raise Rejected(f"claims[{k}].tree: an empty domain has no tree")
    forest = tree.Forest(cert, 2, [boxes[k][0] for k in roots], [boxes[k][1] for k in roots], LEAVES, {},
                         {"tree.index": ((), ("<i4",))}, [f"claims[{k}].tree" for k in roots])
    H2 = Iv(np.array([h2[k].lo for k in roots] or np.zeros((0, legs.n))),
            np.array([h2[k].hi for k in roots] or np.zeros((0, legs.n))))
    sums = [[0, 0] for _ in roots]                 # exact integers: inside, boundary areas (scaled)

    def visit(kind, code, ids, lo, hi, root, child):
        X, Y = Iv(lo[:, 0:1], hi[:, 0:1]), Iv(lo[:, 1:2], hi[:, 1:2])
        r2 = (((X - legs.u[0]).sqr() + (Y - legs.u[1]).sqr()) + H2[root]).meet(Iv(0.0, np.inf))   # squares: >= 0
        if code == 0:
            bad = ~np.all((r2.lo >= legs.rmin2.hi) & (r2.hi <= legs.rmax2.lo), axis=1)
        elif code == 1:
            j = forest.rows("tree.index", ids) - 1
            if np.any((j < 0) | (j >= legs.n)):
                raise Rejected(f"claims[{roots[root[0]]}].tree: 'leg' must be 1..{legs.n}")
            r, a, b = r2[np.arange(len(j)), j], legs.rmin2[j], legs.rmax2[j]
            bad = ~((r.hi < a.lo) | (r.lo > b.hi))
        else:
            bad = np.zeros(len(ids), bool)
        if bad.any():
            i = np.nonzero(bad)[0][0]
            raise Rejected(f"{forest.at(ids[i], root[i])} ({LEAVES[code][0]}): {LEAVES[code][0]} not proved")
        if code != 1:
            for r, area in zip(*_areas(lo, hi, root)):
                sums[r][code // 2] += area
        report.checked["leaves"] += len(ids)

    forest.walk(visit, report.progress)
    report.about["question"] = ("the workspace at orientation " + ", ".join(f"{a} = {v}" for a, v in h["orientation"].items())
                                + (f", z in {h.get('requested', {}).get('z')}" if volume else f", {len(claims)} section(s)"))
    totals = [(Fraction(0), Fraction(0)) for _ in claims]
    for j, k in enumerate(roots):
        inside = Fraction(sums[j][0], 2 ** _SHIFT)
        totals[k] = (inside, inside + Fraction(sums[j][1], 2 ** _SHIFT))
    for k, claim in enumerate(claims):
        _bounds(claim.get("area"), *totals[k], f"claims[{k}].area")
    if not volume:
        for claim in claims[:5]:
            report.proved.append(f"section{' z = ' + str(claim['z']) if 'z' in claim else ''}: area in "
                                 f"[{claim['area']['inner']!r}, {claim['area']['outer']!r}] (inside, inside + boundary boxes)")
        return
    req = h.get("requested")
    if not isinstance(req, dict) or not isinstance(req.get("z"), list) or len(req["z"]) != 2:
        raise Rejected("requested.z: expected [lo, hi] exact decimals")
    zl, zh = exact(req["z"][0], "requested.z"), exact(req["z"][1], "requested.z")
    if not (Fraction(float(Z[0].lo)) <= zl < zh <= Fraction(float(Z[-1].hi))):
        raise Rejected(f"requested.z: [{req['z'][0]}, {req['z'][1]}] is not covered by the slabs")
    dz = [(max(min(Fraction(float(z.hi)), zh) - max(Fraction(float(z.lo)), zl), 0), Fraction(float(z.hi)) - Fraction(float(z.lo)))
          for z in Z]     # inner: the slab's part in the requested range; outer: the whole slab
    _bounds(h.get("volume"), sum(d[0] * t[0] for d, t in zip(dz, totals)), sum(d[1] * t[1] for d, t in zip(dz, totals)), "volume")
    report.proved.append(f"{len(claims)} slabs covering z in [{req['z'][0]}, {req['z'][1]}]: volume in "
                         f"[{h['volume']['inner']!r}, {h['volume']['outer']!r}]")


_SHIFT = 2 * 1100       # areas are integers times 2^-_SHIFT (products of float differences)


def _heights(legs, claims, volume):
    """z of each claim as an interval: the exact decimal ``z``, or the float ``slab`` (contiguous slabs)."""
    Z = []
    for where, claim in each_claim(claims):
        if volume:
            slab = claim.get("slab")
            if not isinstance(slab, list) or len(slab) != 2:
                raise Rejected(f"{where}.slab: expected [lo, hi]")
            lo, hi = real(slab[0], f"{where}.slab"), real(slab[1], f"{where}.slab")
            if not lo < hi:
                raise Rejected(f"{where}.slab: lo must be below hi")
            if Z and lo != Z[-1].hi:
                raise Rejected(f"{where}.slab: does not start where the previous slab ends ({float(Z[-1].hi)!r})")
            Z.append(Iv(lo, hi))
        elif legs.planar and "z" in claim:
            raise Rejected(f"{where}.z: a planar model has no z")
        else:
            Z.append(Iv(0.0) if legs.planar else enclose(claim.get("z"), f"{where}.z"))
    return Z


def _areas(lo, hi, root):
    """Exact areas of the boxes as Python integers times 2^-_SHIFT, grouped by root: (roots, areas)."""
    m, e = np.frexp(np.stack([lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]]))
    ints = (m * 2.0 ** 53).astype(np.int64).astype(object)
    shift = (e.astype(np.int64) - 53 + 1100)
    if np.any(shift < 0):
        raise Rejected("tree: a box bound below 2^-1100: its area is not computed")
    scaled = ints * (np.ones(shift.shape, dtype=object) * 2) ** shift.astype(object)
    area = (scaled[1] - scaled[0]) * (scaled[3] - scaled[2])
    order = np.argsort(root, kind="stable")
    r, starts = np.unique(root[order], return_index=True)
    return r, [sum(area[order][a:b]) for a, b in zip(starts, list(starts[1:]) + [len(order)])]


def _bounds(value, inside, outer, where):
    if not isinstance(value, dict):
        raise Rejected(f"{where}: expected {{'inner': a, 'outer': b}}")
    lo, hi = real(value.get("inner"), f"{where}.inner"), real(value.get("outer"), f"{where}.outer")
    if not Fraction(lo) <= inside:
        raise Rejected(f"{where}.inner: {lo!r} exceeds the area of the inside boxes ({float(inside)!r})")
    if not Fraction(hi) >= outer:
        raise Rejected(f"{where}.outer: {hi!r} is below the area of the inside and boundary boxes ({float(outer)!r})")


def _domain(legs, h2, domain, where):
    """Re-prove that the section (every section of the slab) lies in ``domain``; None when "empty" (K's extremes are
    candidates not outside any disk, K lies in every disk's box: "empty" when these bounds cross)."""
    r2 = legs.rmax2 - h2
    box = None if domain == "empty" else tree.read_box(domain, 2, f"{where}.domain")
    if np.any(r2.hi < 0):               # a disk is empty for every z: so is the section
        return box
    cx, cy, r = legs.u[0], legs.u[1], Iv(np.maximum(r2.lo, 0.0), r2.hi).sqrt()
    cand = [(cx + r, cy), (cx - r, cy), (cx, cy + r), (cx, cy - r)]    # each (legs,) boxes
    i, j = np.triu_indices(legs.n, 1)
    dx, dy = cx[j] - cx[i], cy[j] - cy[i]
    D = dx.sqr() + dy.sqr()
    s = (D + r2[i]) - r2[j]
    disc = D * r2[i] * 4.0 - s.sqr()
    meet = ~(disc.hi < 0)
    unbounded = meet & ~(D.lo > 0)
    t = s / (D * 2.0)
    q = Iv(np.maximum(disc.lo, 0.0), disc.hi).sqrt() / (D * 2.0)
    px, py = cx[i] + t * dx, cy[i] + t * dy
    for x, y in ((px - q * dy, py + q * dx), (px + q * dy, py - q * dx)):
        x, y = Iv(np.where(unbounded, -np.inf, x.lo), np.where(unbounded, np.inf, x.hi)), \
               Iv(np.where(unbounded, -np.inf, y.lo), np.where(unbounded, np.inf, y.hi))
        cand.append((x[meet], y[meet]))
    X = Iv(np.concatenate([c[0].lo for c in cand]), np.concatenate([c[0].hi for c in cand]))
    Y = Iv(np.concatenate([c[1].lo for c in cand]), np.concatenate([c[1].hi for c in cand]))
    dist = (Iv(X.lo[:, None], X.hi[:, None]) - cx).sqr() + (Iv(Y.lo[:, None], Y.hi[:, None]) - cy).sqr()
    alive = ~np.any(dist.lo > r2.hi, axis=1)
    X, Y = X[alive], Y[alive]
    if box is None:     # K empty: no candidate left, or the range of those left and the disks' boxes cross (docstring)
        lo = [max(V.lo.min(initial=np.inf), (c - r).lo.max()) for V, c in ((X, cx), (Y, cy))]
        hi = [min(V.hi.max(initial=-np.inf), (c + r).hi.min()) for V, c in ((X, cx), (Y, cy))]
        if not (lo[0] > hi[0] or lo[1] > hi[1]):
            raise Rejected(f"{where}.domain: 'empty' not proved (a candidate extreme point survives every disk)")
        return None
    (xlo, ylo), (xhi, yhi) = box
    for name, ok_cand, ok_disk in (("lo bound of x", X.lo >= xlo, (cx - r).lo >= xlo),
                                   ("hi bound of x", X.hi <= xhi, (cx + r).hi <= xhi),
                                   ("lo bound of y", Y.lo >= ylo, (cy - r).lo >= ylo),
                                   ("hi bound of y", Y.hi <= yhi, (cy + r).hi <= yhi)):
        if not (ok_cand.all() or ok_disk.any()):
            raise Rejected(f"{where}.domain: the {name} may cut the section")
    return box
