"""Forward-kinematics claims (``"problem": "forward-kinematics"``, docs/certificates.md).

A claim is one set of leg lengths (or length ranges): a domain, regions (each a box X* proved to hold exactly one root
by K(X*) ⊂ int X*, and a box R ⊆ X* proved to hold it), solutions (the regions whose R lies in the domain, pairwise
distinct postures), clusters, and a tree whose leaves are excluded or attributed to a region.  The equations and
operators are in ``fk_system``; the rules of the tree (leaf and contraction codes) are listed below and in
docs/certificates.md."""
from __future__ import annotations

import numpy as np
from mpmath import iv

from . import cayley_menger, tree
from .arith import Iv
from .fk_system import MODELS, System
from .models import each_claim, header_model
from .numbers import exact
from .report import Rejected

LEAVES = {0: ("equation", {"tree.index": 1}), 1: ("hc4-empty", {}), 2: ("position-empty", {"tree.P": 1}),
          3: ("krawczyk-empty", {"tree.C": 1}), 4: ("slope-empty", {"tree.C": 1}),
          5: ("slope-gs-empty", {"tree.C": 1}), 6: ("krawczyk-unique", {"tree.star": 1, "tree.C": 1, "tree.index": 2}),
          7: ("krawczyk-outside", {"tree.star": 1, "tree.C": 2, "tree.rootbox": 1}),
          8: ("in-region", {"tree.index": 1}), 9: ("in-cluster", {"tree.index": 1}), 10: ("undecided", {}),
          11: ("cm-bernstein-empty", {"tree.index": 1}), 12: ("cm-combination-empty", {"tree.index": 1, "tree.weights": 1})}
CONTRACTIONS = {0: ("hc4", {}), 1: ("hc4-position", {"tree.P": 1}), 2: ("position", {"tree.P": 1}),
                3: ("krawczyk", {"tree.C": 1}), 4: ("slope", {"tree.C": 1}), 5: ("slope-gs", {"tree.C": 1})}
REBUILT = 64     # code + 64: the same rule, its C or P not stored but rebuilt by the checker (fk_system)
for _table in (LEAVES, CONTRACTIONS):
    _table.update({c + REBUILT: (name, {}) for c, (name, uses) in list(_table.items()) if set(uses) in ({"tree.C"}, {"tree.P"})})
# ----------------------------------------------------------------------------- claims
class _Claim:
    """One set of leg lengths: its squared lengths, domain, regions (X*, R, C*, C_R) and clusters."""

    EXCLUDED = ("equation", "hc4-empty", "position-empty", "krawczyk-empty", "slope-empty", "slope-gs-empty",
                "krawczyk-outside", "cm-bernstein-empty", "cm-combination-empty")

    def figures(self):
        return {"solutions": self.solutions, "regions": len(self.regions[0]), "leaves": self.rules}

    def summary(self):
        if self.domain is None:
            return f"{self.text}: no posture at all (the leg-length balls do not meet)"
        excluded = sum(v for k, v in self.rules.items() if k in self.EXCLUDED)
        text = f"{self.text}: {self.solutions} unique postures in the domain, {excluded} boxes excluded"
        if self.clusters.size:
            text += f", {len(self.clusters)} unresolved clusters"
        return text + (", complete: proved" if self.complete else ", complete: not claimed")


def check(cert, report) -> None:
    h = cert.header
    header_model(h, MODELS, lambda m: m[0], "unknowns", lambda m: m[1])
    system = System(h["model"], h["robot"])
    n, counts = system.n, report.checked
    claims = [_read_claim(system, cert, c, where) for where, c in each_claim(h["claims"])]
    for k, cl in enumerate(claims):
        _regions(system, cl, f"claims[{k}]")
        counts["solutions"] = counts.get("solutions", 0) + cl.solutions
    roots = [cl for cl in claims if cl.tree]
    dims = {"tree.C": ((n, n), ("<f4", "<f8")), "tree.P": ((system.p, system.legs - 1), ("<f4", "<f8")),
            "tree.index": ((), ("<i4",)), "tree.star": ((n, 2), ("<f8",)), "tree.rootbox": ((n, 2), ("<f8",)),
            "tree.weights": ((15,), ("<f4",))}
    forest = tree.Forest(cert, n, [c.domain[0] for c in roots], [c.domain[1] for c in roots], LEAVES, CONTRACTIONS, dims,
                         [f"claims[{c.index}].tree" for c in roots])
    L = Iv(np.array([c.L.lo for c in roots] or np.zeros((0, system.legs))),
           np.array([c.L.hi for c in roots] or np.zeros((0, system.legs))))
    rules = np.zeros((len(roots), 2 * REBUILT), dtype=np.int64)

    def visit(kind, code, ids, lo, hi, root, child):
        at = lambda i, what: (  # noqa: E731
            f"claims[{roots[root[i]].index}].tree: node {ids[i]} ({(LEAVES if kind == tree.LEAF else CONTRACTIONS)[code][0]}): {what}")
        if kind == tree.CONTRACT:
            _contraction(system, forest, code, ids, lo, hi, child, L[root], at)
            counts["contractions"] = counts.get("contractions", 0) + len(ids)
        else:
            _leaf(system, forest, code, ids, lo, hi, L[root], [roots[r] for r in root], at)
            np.add.at(rules[:, code], root, 1)
            counts["leaves"] += len(ids)

    forest.walk(visit, report.progress)
    for j, cl in enumerate(roots):
        for c in np.nonzero(rules[j])[0]:
            cl.rules[LEAVES[c][0]] = cl.rules.get(LEAVES[c][0], 0) + int(rules[j, c])
        if "figures" in cl.raw and cl.raw["figures"] != cl.figures():
            raise Rejected(f"claims[{cl.index}].figures: stated {cl.raw['figures']}, found {cl.figures()}")
    report.about["question"] = (f"every assembly mode for {len(claims)} set(s) of leg lengths; first: {claims[0].text}, domain: " + (
        f"the box {c0.get('domain')} (floats)" if (c0 := h["claims"][0]).get("covers") == "box" else c0.get("covers", "empty")))
    for cl in claims[:5]:
        report.proved.append(cl.summary())
    if len(claims) > 5:
        report.proved.append(f"... and {len(claims) - 5} more leg-length sets, "
                             f"{sum(c.solutions for c in claims[5:])} unique postures in all")


def _read_claim(system, cert, raw, where):
    cl = _Claim()
    cl.raw, cl.index, cl.rules = raw, int(where[7:-1]), {}
    if "length_ranges" in raw:
        rng = raw["length_ranges"]
        if not isinstance(rng, list) or len(rng) != system.legs or not all(isinstance(r, list) and len(r) == 2 for r in rng):
            raise Rejected(f"{where}.length_ranges: expected {system.legs} [lo, hi] exact decimals")
        qs = [(exact(a, f"{where}.length_ranges"), exact(b, f"{where}.length_ranges")) for a, b in rng]
        cl.text = "lengths in " + ", ".join(f"[{a}, {b}]" for a, b in rng)
    else:
        ls = raw.get("lengths")
        if not isinstance(ls, list) or len(ls) != system.legs:
            raise Rejected(f"{where}.lengths: expected {system.legs} exact decimals")
        qs = [(exact(v, f"{where}.lengths[{i}]"),) * 2 for i, v in enumerate(ls)]
        cl.text = "lengths " + ", ".join(map(str, ls))
    if any(not 0 <= a <= b for a, b in qs):
        raise Rejected(f"{where}: leg lengths must satisfy 0 <= lo <= hi")
    cl.L = Iv([Iv.const(a * a).lo for a, _ in qs], [Iv.const(b * b).hi for _, b in qs])
    cl.rho_q = [b for _, b in qs]
    cl.complete = raw.get("complete")
    if type(cl.complete) is not bool:             # (1 == True: a number is not a claim of completeness)
        raise Rejected(f"{where}.complete: expected true or false")
    cl.regions = (np.zeros((0, system.n, 2)),) * 2 + (np.zeros((0, system.n, system.n)),) * 2
    cl.clusters, cl.solutions, cl.tree = np.zeros((0, system.n, 2)), 0, False
    if raw.get("domain") == "empty":
        _no_position(system, cl, f"{where}.domain")
        if raw.get("solutions") != [] or cl.complete is not True:
            raise Rejected(f"{where}: an empty domain has no solutions and is complete")
        cl.domain = None
        return cl
    lo, hi = tree.read_box(raw.get("domain"), system.n, f"{where}.domain")
    cl.domain = (lo, hi)
    if raw.get("covers") == "all-postures":
        _covers_all(system, cl, f"{where}.domain")
    elif raw.get("covers") != "box":
        raise Rejected(f"{where}.covers: expected 'all-postures' or 'box'")
    reg = raw.get("regions", [0, 0])
    if not (isinstance(reg, list) and len(reg) == 2 and all(type(v) is int and v >= 0 for v in reg)):
        raise Rejected(f"{where}.regions: expected [first, count]")
    names = ("fk.region.star", "fk.region.box", "fk.region.star_C", "fk.region.box_C")
    if reg[1]:                        # without fk.region.star (and _C): X* = R (and C* = C_R)
        names = names if cert.has(names[0]) else (names[1], names[1], names[3], names[3])
        arrs = [cert.array(nm, *(((("<f8",), (system.n, 2))) if "C" not in nm else (("<f4", "<f8"), (system.n, system.n))))
                for nm in names]
        if any(len(a) < reg[0] + reg[1] for a in arrs):
            raise Rejected(f"{where}.regions: rows {reg[0]}..{reg[0] + reg[1] - 1} are not all in the body")
        cl.regions = tuple(a[reg[0]:reg[0] + reg[1]].astype(np.float64) for a in arrs)
    clusters = raw.get("clusters", [])
    if not isinstance(clusters, list):
        raise Rejected(f"{where}.clusters: expected a list of boxes")
    cl.clusters = np.array([np.stack(tree.read_box(c, system.n, f"{where}.clusters[{j}]"), -1) for j, c in enumerate(clusters)]
                           or np.zeros((0, system.n, 2)))
    cl.tree = True                    # a domain is proved only by its tree: never without one
    if raw.get("tree") is not True:
        raise Rejected(f"{where}.tree: expected true (the tree of the domain is in the body)")
    return cl


def _reach(system, cl, k):
    """Bounds (lows, highs) per leg of a_ik ∓ (ρ_i + |b_i|): every posture has max(lows) <= p_k <= min(highs).
    Exact rationals and a 120-bit square root (mpmath), so that a domain computed tightly in floats fits."""
    q = lambda x: iv.mpf(x.numerator) / x.denominator  # noqa: E731
    lows, highs, saved = [], [], iv.prec
    iv.prec = 120
    try:
        for i in range(system.legs):
            reach = q(cl.rho_q[i]) + iv.sqrt(q(sum(b * b for b in system.b_q[i])))
            lo, hi = q(system.a_q[i][k]) - reach, q(system.a_q[i][k]) + reach
            f, g = float(lo.a), float(hi.b)             # to nearest; one float further when on the wrong side
            lows.append(f if (iv.mpf(f) <= lo) is True else float(np.nextafter(f, -np.inf)))
            highs.append(g if (iv.mpf(g) >= hi) is True else float(np.nextafter(g, np.inf)))
    finally:
        iv.prec = saved
    return np.array(lows), np.array(highs)


def _covers_all(system, cl, where):
    lo, hi = cl.domain
    for k in range(system.p, system.n):
        need = 0.0 if (not system.planar and k == system.p) else -1.0
        if not (lo[k] <= need and hi[k] >= 1.0):
            raise Rejected(f"{where}: {system.names[k]} does not cover [{need}, 1]")
    for k in range(system.p):
        lows, highs = _reach(system, cl, k)
        if not (lo[k] <= np.max(lows) and hi[k] >= np.min(highs)):
            raise Rejected(f"{where}: {system.names[k]} does not cover the reachable positions")


def _no_position(system, cl, where):
    for k in range(system.p):
        lows, highs = _reach(system, cl, k)
        if np.max(lows) > np.min(highs):
            return
    raise Rejected(f"{where}: 'empty' is not proved: the leg-length balls may meet")


def _unique(system, lo, hi, C, L):
    """K(X) ⊂ int X, per box (exactly one root in X)."""
    K = system.krawczyk(lo, hi, C, L)
    return np.all((K.lo > lo) & (K.hi < hi), axis=1)


def _negated(system, lo, hi):
    p = system.p
    if system.planar:
        return lo, hi
    return np.concatenate([lo[..., :p], -hi[..., p:]], -1), np.concatenate([hi[..., :p], -lo[..., p:]], -1)


def _disjoint(alo, ahi, blo, bhi):
    return np.any((ahi < blo) | (bhi < alo), axis=-1)


def _inside(alo, ahi, blo, bhi):
    return np.all((blo <= alo) & (ahi <= bhi), axis=-1)


def _regions(system, cl, where):
    """Each region: K(X*) ⊂ int X* (one root), R ⊆ X*, K(R) ⊂ int R (that root is in R); the R pairwise
    disjoint (and from the negated quaternions); classified against the domain."""
    star, box, Cs, Cb = cl.regions
    K = len(star)
    if not K:
        return
    L = Iv(np.broadcast_to(cl.L.lo, (K, system.legs)), np.broadcast_to(cl.L.hi, (K, system.legs)))
    slo, shi, blo, bhi = star[..., 0], star[..., 1], box[..., 0], box[..., 1]
    bad = np.nonzero(~(slo <= shi).all(1) | ~(blo <= bhi).all(1) | ~_inside(blo, bhi, slo, shi)
                     | ~_unique(system, slo, shi, Cs, L) | ~_unique(system, blo, bhi, Cb, L))[0]
    if len(bad):
        raise Rejected(f"{where}.regions[{bad[0]}]: K(X*) ⊂ int X*, R ⊆ X* and K(R) ⊂ int R not all proved")
    nlo, nhi = _negated(system, blo, bhi)
    meet = ~_disjoint(blo[:, None], bhi[:, None], blo[None], bhi[None])
    if not system.planar:
        meet |= ~_disjoint(blo[:, None], bhi[:, None], nlo[None], nhi[None])
    np.fill_diagonal(meet, False)
    if meet.any():
        i, j = np.argwhere(meet)[0]
        raise Rejected(f"{where}.regions[{i}]: meets regions[{j}] (or its negated quaternion): "
                       "the postures are not proved distinct")
    if cl.domain is None:
        raise Rejected(f"{where}: an empty domain has no regions")
    inside, outside = _inside(blo, bhi, *cl.domain), _disjoint(blo, bhi, *cl.domain)
    if cl.complete and not np.all(inside | outside):
        raise Rejected(f"{where}: complete, but regions[{np.nonzero(~(inside | outside))[0][0]}] straddles the domain")
    cl.inside, cl.solutions, sols = inside, int(inside.sum()), cl.raw.get("solutions")
    if not isinstance(sols, list) or [s.get("region") if isinstance(s, dict) else None for s in sols] \
            != np.nonzero(inside)[0].tolist():
        raise Rejected(f"{where}.solutions: must list, in order, the regions whose box lies in the domain")
    for j, s in enumerate(sols):
        lo, hi = tree.read_box(s.get("box"), system.n, f"{where}.solutions[{j}].box")
        r = s["region"]
        if not (np.all(lo <= blo[r]) and np.all(bhi[r] <= hi)):
            raise Rejected(f"{where}.solutions[{j}].box: does not enclose the box of region {r}")
        if np.any(lo < np.nextafter(blo[r], -np.inf)) or np.any(hi > np.nextafter(bhi[r], np.inf)):
            raise Rejected(f"{where}.solutions[{j}].box: wider than the box of region {r} and its next floats")


def _evidence(forest, name, ids, code):
    """The stored C or P of the nodes, or None when the rule's code says the checker rebuilds it."""
    return None if code >= REBUILT else forest.rows(name, ids).astype(float)


def _contraction(system, forest, code, ids, lo, hi, child, L, at):
    clo, chi = child
    stored, code = code, code % REBUILT
    n, p = system.n, system.p
    if code in (1, 2) and not p:
        raise Rejected(at(0, "a position step needs a position"))
    if code in (0, 1, 2):                # hc4 (0); hc4, then one sweep on the position (1); the sweep alone (2)
        z, empty = system.hc4(lo, hi, L) if code < 2 else (Iv(lo, hi), np.zeros(len(lo), dtype=bool))
        if code:
            x, e2 = system.gauss_seidel([z[:, k] for k in range(n)], _evidence(forest, "tree.P", ids, stored), L)
            empty |= e2
            z = Iv(np.concatenate([x.lo, z.lo[:, p:]], 1), np.concatenate([x.hi, z.hi[:, p:]], 1))
        if code == 2 and (moved := np.any((clo[:, p:] != lo[:, p:]) | (chi[:, p:] != hi[:, p:]), axis=1)).any():
            raise Rejected(at(np.nonzero(moved)[0][0], "a position step changes only the position"))
    elif code in (3, 4):                 # K(X) ∩ X (slope: K_S)
        K = system.krawczyk(lo, hi, _evidence(forest, "tree.C", ids, stored), L, slope=code == 4)
        z = K.meet(Iv(lo, hi))
        empty = np.any(z.empty(), axis=1)
    else:                                # slope-gs
        z, empty = system.slope_gauss_seidel(lo, hi, _evidence(forest, "tree.C", ids, stored), L)
    bad = ~empty & ~np.all((z.lo >= clo) & (z.hi <= chi), axis=1)
    if bad.any() and stored >= REBUILT:  # its own C: the part of its result outside the child proved root-free?
        bad[bad] = ~_root_free_outside(system, z.lo[bad], z.hi[bad], clo[bad], chi[bad], L[bad], hi[bad] - lo[bad])
    if bad.any():
        i = np.nonzero(bad)[0][0]
        k = np.nonzero(~((z.lo[i] >= clo[i]) & (z.hi[i] <= chi[i])))[0][0]
        raise Rejected(at(i, f"the checker's result is not inside the child box on {system.names[k]}"))


def _root_free_outside(system, zlo, zhi, clo, chi, L, scale, depth=6):
    """Per row, whether Z minus the child Y holds no root: Z \\ Y lies in the slabs of Z beyond a face of Y
    (closed boxes), each proved root-free by the slope sweep on pieces bisected up to ``depth`` times."""
    rows, plo, phi = [], [], []
    for k in range(system.n):
        for below in (True, False):
            m = np.nonzero(zlo[:, k] < clo[:, k] if below else zhi[:, k] > chi[:, k])[0]
            a, b = zlo[m].copy(), zhi[m].copy()
            (b if below else a)[:, k] = (clo if below else chi)[m, k]
            rows.append(m), plo.append(a), phi.append(b)
    row, plo, phi = np.concatenate(rows), np.concatenate(plo), np.concatenate(phi)
    for _ in range(depth + 1):
        _, empty = system.slope_gauss_seidel(plo, phi, None, L[row])
        row, plo, phi = row[~empty], plo[~empty], phi[~empty]
        plo, phi, _ = tree.halves(plo, phi, scale[row])
        row = np.concatenate([row, row])
    return ~np.isin(np.arange(len(zlo)), row) & np.all(np.isfinite(zlo) & np.isfinite(zhi), axis=1)   # NaN: no


def _leaf(system, forest, code, ids, lo, hi, L, claims, at):
    n = system.n
    stored, code = code, (code % REBUILT if code >= REBUILT else code)

    def fail(mask, what):
        """Reject, naming the first leaf where ``mask`` holds."""
        if np.any(mask):
            raise Rejected(at(np.nonzero(mask)[0][0], what))

    if code == 10:
        fail(np.array([c.complete for c in claims]), "undecided leaf in a claim that says complete")
    elif code in (11, 12):    # e = 4·quad + chart (11), chart (12): F_quad, or Σ_quad w_quad F_quad, has no zero on the chart box
        e = forest.rows("tree.index", ids)
        fail((e < 0) | (e >= (60 if code == 11 else 4)), "the Cayley-Menger evidence must lie in 0..59 (rule 11), 0..3 (12)")
        if system.legs != 6 or system.p != 3:
            raise Rejected(at(0, "the Cayley-Menger rule needs a 6-6 Gough-Stewart robot"))
        for c in {id(c): c for c in claims}.values():      # the 15 forms, once per claim
            c.cm = getattr(c, "cm", None) or cayley_menger.forms(system, c.L)
        F = Iv(*(np.array([getattr(c.cm, s)[q] for c, q in zip(claims, e // 4)]) for s in ("lo", "hi"))) if code == 11 \
            else cayley_menger.combined(forest.rows("tree.weights", ids).astype(float), [c.cm for c in claims])
        proved, away = cayley_menger.proved_empty(F, e % 4, lo[:, 3:], hi[:, 3:])
        fail(~away, "the chart's quaternion side contains 0")
        what = "polynomial of the quad" if code == 11 else "polynomial combination"
        fail(~proved, f"no Cayley-Menger {what} is proved sign-definite on the chart box")
    elif code == 0:
        k = forest.rows("tree.index", ids)
        fail((k < 0) | (k > system.legs), f"the equation index must be below {n}")
        v = system.values([Iv(lo[:, j], hi[:, j]) for j in range(n)], L)[np.arange(len(ids)), np.clip(k, 0, n - 1)]
        fail(~(v.pos() | v.neg()), "the equation may vanish on the box")
    elif code == 1:
        fail(~system.hc4(lo, hi, L)[1], "the forward-backward pass does not empty the box")
    elif code == 2:
        if not system.p:
            raise Rejected(at(0, "needs a position"))
        _, empty = system.gauss_seidel([Iv(lo[:, j], hi[:, j]) for j in range(n)], _evidence(forest, "tree.P", ids, stored), L)
        fail(~empty, "Gauss-Seidel on the position does not empty the box")
    elif code in (3, 4):
        K = system.krawczyk(lo, hi, _evidence(forest, "tree.C", ids, stored), L, slope=code == 4)
        fail(~np.any((K.hi < lo) | (K.lo > hi), axis=1), "the image meets the box: emptiness not proved")
    elif code == 5:
        fail(~system.slope_gauss_seidel(lo, hi, _evidence(forest, "tree.C", ids, stored), L)[1],
             "the slope Gauss-Seidel sweep does not empty the box")
    elif code in (6, 7):
        star = forest.rows("tree.star", ids)
        slo, shi = star[..., 0], star[..., 1]
        fail(~_inside(lo, hi, slo, shi), "the leaf is not inside its uniqueness box X*")
        fail(~_unique(system, slo, shi, forest.rows("tree.C", ids).astype(float), L), "K(X*) ⊂ int X* not proved")
        if code == 7:               # X*'s root lies in a proved box that misses the leaf
            rb = forest.rows("tree.rootbox", ids)
            rlo, rhi = rb[..., 0], rb[..., 1]
            fail(~_inside(rlo, rhi, slo, shi) | ~_disjoint(rlo, rhi, lo, hi), "the root box must lie in X* and miss the leaf")
            fail(~_unique(system, rlo, rhi, forest.rows("tree.C", ids, 1).astype(float), L), "K(R) ⊂ int R not proved")
            return
        j, twin = forest.rows("tree.index", ids), forest.rows("tree.index", ids, 1)
        fail((j < 0) | (j >= np.array([len(c.regions[1]) for c in claims])) | (twin != 0) & (twin != 1), "names no region of its claim")
        fail((twin == 1) & np.array([c.complete and not c.inside[i] for c, i in zip(claims, j)]),
             "the twin of a region outside the domain, in a complete claim: that posture would be counted nowhere")
        blo, bhi = np.moveaxis(np.array([c.regions[1][i] for c, i in zip(claims, j)]), -1, 0)
        nlo, nhi = _negated(system, blo, bhi)
        blo, bhi = np.where(twin[:, None] == 1, nlo, blo), np.where(twin[:, None] == 1, nhi, bhi)
        fail(~_inside(blo, bhi, slo, shi), "its region's root box is not inside X*: the leaf's root is not that one")
    else:                            # 8 in-region, 9 in-cluster: the leaf lies in the named box
        j = forest.rows("tree.index", ids)
        tables = [c.regions[0] if code == 8 else c.clusters for c in claims]
        fail((j < 0) | (j >= np.array([len(t) for t in tables])), "names no region or cluster of its claim")
        box = np.array([t[i] for t, i in zip(tables, j)])
        fail(~_inside(lo, hi, box[..., 0], box[..., 1]), "the leaf is not inside the named box")
