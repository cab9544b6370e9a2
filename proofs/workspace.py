"""Workspace claims (``"problem": "workspace-section"`` / ``"workspace-volume"``, docs/certificates.md).

Models ``gough-stewart-workspace/1`` (orientation psi, theta, phi;
R = Rz(psi) Rx(theta) Rz(phi)) and ``planar-3rpr-workspace/1`` (orientation
phi; R the plane rotation, z = 0): with u_i = a_i − R b_i, the point C =
(X, Y, z) satisfies leg i when ρmin_i² ≤ (X − u_ix)² + (Y − u_iy)² +
(z − u_iz)² ≤ ρmax_i² (``limits.leg_length``, exact decimals).  Only these
constraints are claimed about.

A claim is one section (``"z"``: an exact decimal; no ``z`` for planar
robots) or one z-slab (``"slab"``: [lo, hi] floats, z ranging over it), with

- ``domain``: [[xlo, xhi], [ylo, yhi]] (floats) holding every point of the
  section (of every section of the slab), or ``"empty"``.  Re-proved from the
  outer disks D_i (centre u_i, radius² ρmax_i² − (z − u_iz)², at its largest
  over a slab): the extremes of the intersection of the D_i are among the
  *candidates* (four extreme points of each disk, pairwise intersection
  points of the circles) not proved outside a disk (docs/soundness.md), so
  each side holds when every such candidate is within it, or when one disk
  lies within it.  ``"empty"`` needs a disk with radius² < 0 or no candidate left;
- ``tree``: splits ``{"split": [dim, at], "children": [lower, upper]}`` (dim 0
  = x, 1 = y, lo < at < hi) and leaves ``{"leaf": "inside" | "outside" |
  "boundary", "box": ..., "leg": k}``; every leaf box must equal the box
  derived from the domain, so the leaves tile it.  ``inside``: for every leg
  the enclosure of ρ_i² over box (× z) lies in [ρmin², ρmax²]; ``outside``:
  for leg ``k`` (1-based) it is disjoint from it; ``boundary``: nothing;
- ``area``: ``inner`` ≤ the exact (rational) sum of the inside boxes' areas
  ≤ area ≤ the exact sum over inside and boundary boxes ≤ ``outer``.

A volume certificate's slabs must be contiguous and cover the
``requested`` z range; its ``volume`` inner and outer must be bounded by
Σ (hi − lo) × inside area and Σ (hi − lo) × (inside + boundary) area,
computed exactly.  A section with an empty domain claims area 0.
"""
from __future__ import annotations

from fractions import Fraction

from mpmath import iv

from . import tree
from .numbers import enclose, exact, real
from .report import Rejected
from .singularity import read_box

MODELS = {"gough-stewart-workspace/1": ("gough-stewart", ("psi", "theta", "phi"), 6, 3),
          "planar-3rpr-workspace/1": ("planar-3rpr", ("phi",), 3, 2)}
PROBLEMS = ("workspace-section", "workspace-volume")


def check_claims(cert, counts: dict) -> None:
    """Everything after the common header (format, version): model, robot, orientation, claims."""
    problem = cert.get("problem")
    if problem not in PROBLEMS:
        raise Rejected(f"problem: unknown problem {problem!r} (known: {', '.join(PROBLEMS)})")
    model = cert.get("model")
    if not isinstance(model, str) or model not in MODELS:
        raise Rejected(f"model: unknown model {model!r} (known: {', '.join(MODELS)})")
    legs = Legs(model, cert.get("robot"), cert.get("orientation"))
    claims = cert.get("claims")
    if not isinstance(claims, list) or not claims:
        raise Rejected("claims: expected a non-empty list")
    counts["claims"] = len(claims)
    if problem == "workspace-section":
        for k, claim in enumerate(claims):
            where = f"claims[{k}]"
            if not isinstance(claim, dict):
                raise Rejected(f"{where}: expected an object")
            if legs.planar:
                if "z" in claim:
                    raise Rejected(f"{where}.z: a planar model has no z")
                Z = iv.mpf(0)
            else:
                Z = enclose(claim.get("z"), f"{where}.z")
            _claim(legs, claim, Z, where, counts)
        return
    if legs.planar:
        raise Rejected("problem: a planar model has no volume")
    total_in, total_out, prev = Fraction(0), Fraction(0), None
    first = last = None
    for k, claim in enumerate(claims):
        where = f"claims[{k}]"
        if not isinstance(claim, dict):
            raise Rejected(f"{where}: expected an object")
        slab = claim.get("slab")
        if not isinstance(slab, list) or len(slab) != 2:
            raise Rejected(f"{where}.slab: expected [lo, hi]")
        lo, hi = real(slab[0], f"{where}.slab"), real(slab[1], f"{where}.slab")
        if not lo < hi:
            raise Rejected(f"{where}.slab: lo must be below hi")
        if prev is not None and lo != prev:
            raise Rejected(f"{where}.slab: does not start where the previous slab ends ({prev!r})")
        prev = hi
        first = lo if first is None else first
        last = hi
        inside, outer = _claim(legs, claim, iv.mpf([lo, hi]), where, counts)
        h = Fraction(hi) - Fraction(lo)
        total_in += h * inside
        total_out += h * outer
    req = cert.get("requested")
    if not isinstance(req, dict) or not isinstance(req.get("z"), list) or len(req["z"]) != 2:
        raise Rejected("requested.z: expected [lo, hi] exact decimals")
    zl, zh = exact(req["z"][0], "requested.z"), exact(req["z"][1], "requested.z")
    if not (Fraction(first) <= zl < zh <= Fraction(last)):
        raise Rejected(f"requested.z: [{req['z'][0]}, {req['z'][1]}] is not covered by the slabs [{first!r}, {last!r}]")
    _bounds(cert.get("volume"), total_in, total_out, "volume")


class Legs:
    """u_i = a_i − R b_i and the squared limits, as iv intervals, from the stated exact data."""

    def __init__(self, model, robot, orientation):
        kind, angles, n, dim = MODELS[model]
        self.planar = dim == 2
        if not isinstance(robot, dict):
            raise Rejected("robot: expected an object")
        if robot.get("kind") != kind:
            raise Rejected(f"robot.kind: {robot.get('kind')!r} does not fit model {model}")
        a = _points(robot, "base", n, dim)
        b = _points(robot, "platform", n, dim)
        if not isinstance(orientation, dict) or sorted(orientation) != sorted(angles):
            raise Rejected(f"orientation: expected the angles {', '.join(angles)}")
        ang = [_angle(orientation[name], f"orientation.{name}") for name in angles]
        if self.planar:
            c, s = iv.cos(ang[0]), iv.sin(ang[0])
            rb = [(c * p[0] - s * p[1], s * p[0] + c * p[1], iv.mpf(0)) for p in b]
            a = [(p[0], p[1], iv.mpf(0)) for p in a]
        else:
            (c1, s1), (c2, s2), (c3, s3) = [(iv.cos(t), iv.sin(t)) for t in ang]
            rb = []
            for x, y, z in b:                       # Rz(psi) Rx(theta) Rz(phi) b
                x, y = c3 * x - s3 * y, s3 * x + c3 * y
                y, z = c2 * y - s2 * z, s2 * y + c2 * z
                x, y = c1 * x - s1 * y, s1 * x + c1 * y
                rb.append((x, y, z))
        self.u = [tuple(p[k] - q[k] for k in range(3)) for p, q in zip(a, rb)]
        limits = robot.get("limits")
        pairs = limits.get("leg_length") if isinstance(limits, dict) else None
        if not isinstance(pairs, list) or len(pairs) != n:
            raise Rejected(f"robot.limits.leg_length: expected {n} [min, max] pairs")
        self.rmin2, self.rmax2 = [], []
        for i, p in enumerate(pairs):
            where = f"robot.limits.leg_length[{i}]"
            if not isinstance(p, list) or len(p) != 2:
                raise Rejected(f"{where}: expected [min, max]")
            lo, hi = exact(p[0], where), exact(p[1], where)
            if not 0 <= lo <= hi:
                raise Rejected(f"{where}: expected 0 <= min <= max")
            self.rmin2.append(enclose(p[0], where) ** 2)
            self.rmax2.append(enclose(p[1], where) ** 2)
        self.n = n

    def rho2(self, X, Y, h2):
        return [(X - u[0]) ** 2 + (Y - u[1]) ** 2 + h for u, h in zip(self.u, h2)]

    def h2(self, Z):
        return [(Z - u[2]) ** 2 for u in self.u]


def _points(robot, key, n, dim):
    pts = robot.get(key)
    if not isinstance(pts, list) or len(pts) != n:
        raise Rejected(f"robot.{key}: expected {n} points")
    out = []
    for i, p in enumerate(pts):
        if not isinstance(p, list) or len(p) != dim:
            raise Rejected(f"robot.{key}[{i}]: expected {dim} coordinates")
        out.append(tuple(enclose(c, f"robot.{key}[{i}]") for c in p))
    return out


def _angle(value, where):
    if isinstance(value, str) and value.strip().lower().endswith("deg"):
        return enclose(value.strip()[:-3], where) * iv.pi / 180
    return enclose(value, where)


# ----- the domain -------------------------------------------------------------
def _domain_ok(legs, h2, domain, where):
    """Re-prove that the section (every section of the slab) lies in ``domain`` ("empty": is empty)."""
    r2 = [m - h for m, h in zip(legs.rmax2, h2)]
    if any(r.b < 0 for r in r2):               # a disk is empty for every z: so is the section
        return
    cx = [u[0] for u in legs.u]
    cy = [u[1] for u in legs.u]
    r = [iv.sqrt(iv.mpf([max(v.a, 0), v.b])) for v in r2]
    cand = []                                  # (x, y) boxes, None coordinates for unbounded ones
    for i in range(legs.n):
        cand += [(cx[i] + r[i], cy[i]), (cx[i] - r[i], cy[i]), (cx[i], cy[i] + r[i]), (cx[i], cy[i] - r[i])]
    for i in range(legs.n):
        for j in range(i + 1, legs.n):
            dx, dy = cx[j] - cx[i], cy[j] - cy[i]
            D = dx ** 2 + dy ** 2
            s = D + r2[i] - r2[j]
            disc = 4 * D * r2[i] - s ** 2
            if disc.b < 0:
                continue                       # the circles do not meet (whatever the radii in the slab)
            if not D.a > 0:
                cand += [(None, None), (None, None)]
                continue
            t = s / (2 * D)
            q = iv.sqrt(iv.mpf([max(disc.a, 0), disc.b])) / (2 * D)
            px, py = cx[i] + t * dx, cy[i] + t * dy
            cand += [(px - q * dy, py + q * dx), (px + q * dy, py - q * dx)]
    alive = [p for p in cand if p[0] is None or not any(
        ((p[0] - cx[k]) ** 2 + (p[1] - cy[k]) ** 2).a > r2[k].b for k in range(legs.n))]
    if domain == "empty":
        if alive:
            raise Rejected(f"{where}.domain: 'empty' not proved (a candidate extreme point survives every disk)")
        return
    box = read_box(domain, 2, f"{where}.domain")
    (xlo, xhi), (ylo, yhi) = box
    sides = [("x", 0, "lo", lambda p: p[0] is not None and p[0].a >= xlo, lambda i: (cx[i] - r[i]).a >= xlo),
             ("x", 0, "hi", lambda p: p[0] is not None and p[0].b <= xhi, lambda i: (cx[i] + r[i]).b <= xhi),
             ("y", 1, "lo", lambda p: p[1] is not None and p[1].a >= ylo, lambda i: (cy[i] - r[i]).a >= ylo),
             ("y", 1, "hi", lambda p: p[1] is not None and p[1].b <= yhi, lambda i: (cy[i] + r[i]).b <= yhi)]
    for name, _, end, cand_ok, disk_ok in sides:
        if not (all(cand_ok(p) for p in alive) or any(disk_ok(i) for i in range(legs.n))):
            raise Rejected(f"{where}.domain: the {end} bound of {name} may cut the section")
    return box


# ----- one claim -----------------------------------------------------------------
def _claim(legs, claim, Z, where, counts):
    """Re-verify one section or slab; returns the exact (inside, inside + boundary) areas."""
    h2 = legs.h2(Z)
    domain = claim.get("domain")
    box = _domain_ok(legs, h2, domain, where)
    if domain == "empty":
        if claim.get("tree") is not None:
            raise Rejected(f"{where}.tree: an empty domain has no tree")
        inside = outer = Fraction(0)
    else:
        if box is None:                            # a disk is empty: the stated box is just read
            box = read_box(domain, 2, f"{where}.domain")
        inside, outer = _tree(legs, claim.get("tree"), box, h2, f"{where}.tree", counts)
    _bounds(claim.get("area"), inside, outer, f"{where}.area")
    return inside, outer


def _bounds(value, inside, outer, where):
    if not isinstance(value, dict):
        raise Rejected(f"{where}: expected {{'inner': a, 'outer': b}}")
    lo, hi = real(value.get("inner"), f"{where}.inner"), real(value.get("outer"), f"{where}.outer")
    if not Fraction(lo) <= inside:
        raise Rejected(f"{where}.inner: {lo!r} exceeds the area of the inside boxes ({float(inside)!r})")
    if not Fraction(hi) >= outer:
        raise Rejected(f"{where}.outer: {hi!r} is below the area of the inside and boundary boxes ({float(outer)!r})")


def _tree(legs, root, box, h2, where, counts):
    inside = outer = Fraction(0)
    stack = [(root, box, ())]
    while stack:
        node, nbox, path = stack.pop()
        at = tree.label(where, node, path)
        if "split" in node:
            (c0, lower), (c1, upper) = tree.split(node, nbox, at)
            stack.append((c1, upper, path + (1,)))
            stack.append((c0, lower, path + (0,)))
            continue
        kind = node.get("leaf")
        if kind not in ("inside", "outside", "boundary"):
            raise Rejected(f"{at}: unknown leaf {kind!r} (inside, outside, boundary)")
        if read_box(node.get("box"), 2, f"{at}: box") != nbox:
            raise Rejected(f"{at}: box does not match the derived box")
        (xlo, xhi), (ylo, yhi) = nbox
        area = (Fraction(xhi) - Fraction(xlo)) * (Fraction(yhi) - Fraction(ylo))
        X, Y = iv.mpf([xlo, xhi]), iv.mpf([ylo, yhi])
        if kind == "inside":
            for i, v in enumerate(legs.rho2(X, Y, h2)):
                if not (v.a >= legs.rmin2[i].b and v.b <= legs.rmax2[i].a):
                    raise Rejected(f"{at}: inside not proved (leg {i + 1} may leave its limits)")
            inside += area
            outer += area
        elif kind == "outside":
            k = node.get("leg")
            if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= legs.n:
                raise Rejected(f"{at}: 'leg' must be 1..{legs.n}")
            u = legs.u[k - 1]
            v = (X - u[0]) ** 2 + (Y - u[1]) ** 2 + h2[k - 1]
            if not (v.b < legs.rmin2[k - 1].a or v.a > legs.rmax2[k - 1].b):
                raise Rejected(f"{at}: outside not proved (leg {k} may be within its limits)")
        else:
            outer += area
        counts["leaves"] += 1
    return inside, outer
