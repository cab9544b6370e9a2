"""Forward-kinematics certificates (``docs/certificates.md``): per set of leg lengths, the domain, the
regions (each proved root box R with its Krawczyk matrix, X* = R), the solutions among them, and the
search tree with the evidence of each leaf and contraction (``proofs.fk`` re-checks them).

Preconditioners that the checker rebuilds from its own enclosures (codes + 64: the Gauss-Seidel P
and the C of emptiness and contraction steps) are not stored; the uniqueness proofs keep theirs.
"""
from __future__ import annotations

import numpy as np

from ..engine import CONTRACTED, EXCLUDED, PROVED, SPLIT, UNDECIDED
from .forest import Forest, Rules
from .writing import Array, Document, box_json, decimal_box, header, one

REBUILT = 64
LEAVES = {"equation": 0, "hc4-empty": 1, "position-empty": 2 + REBUILT, "krawczyk-empty": 3 + REBUILT,
          "slope-empty": 4 + REBUILT, "slope-gs-empty": 5 + REBUILT}
CONTRACTIONS = {"hc4": 0, "position": 2 + REBUILT, "krawczyk": 3 + REBUILT, "slope": 4 + REBUILT,
                "slope-gs": 5 + REBUILT}
UNIQUE, OUTSIDE, UNDECIDED_LEAF, HC4_POSITION = 6, 7, 10, 1 + REBUILT
RULE_NAMES = {**{c: n for n, c in LEAVES.items()}, UNIQUE: "krawczyk-unique", OUTSIDE: "krawczyk-outside",
              UNDECIDED_LEAF: "undecided"}


class _Leaf:
    """A one-node tree (a tracked posture's single Krawczyk proof, or a search that did not run)."""

    def __init__(self, lo, hi):
        self.lo, self.hi = np.asarray(lo, float)[None], np.asarray(hi, float)[None]
        self.kind = np.array([PROVED], np.int8)
        self.first_child = self.split_dim = self.reason = np.zeros(1, np.int32)
        self.split_at = np.zeros(1)


def _proof(result, tree, i):
    if isinstance(tree, _Leaf):
        return ({"star": (tree.lo[0], tree.hi[0]), "solution": 0, "twin": False, "C": result.track_C}
                if result.tracked else {"undecided": True})
    return result.leaf_proofs.get(int(i), {"undecided": True})


def _rules(result, tree, n):
    """The rules of one claim's tree (``tree``: the engine tree, or a ``_Leaf``)."""
    names = getattr(tree, "reasons", ())
    leaf_lut = np.array([LEAVES.get(x, 255) for x in names] or [255], np.int64)
    con_lut = np.array([CONTRACTIONS.get(x, 255) for x in names] or [255], np.int64)
    has_p = getattr(tree, "evidence_rows", {}).get("P")

    def code(t, ids):
        kind, reason = t.kind[ids], np.clip(t.reason[ids], 0, None)
        out = np.full(len(ids), UNDECIDED_LEAF, np.int64)
        out[kind == EXCLUDED] = leaf_lut[reason[kind == EXCLUDED]]
        c = kind == CONTRACTED
        out[c] = con_lut[reason[c]]
        if has_p is not None:                      # an hc4 contraction followed by the position sweep
            out[c & (out == 0) & (has_p[ids] >= 0)] = HC4_POSITION
        for k in np.nonzero(kind == PROVED)[0]:
            proof = _proof(result, t, ids[k])
            out[k] = UNDECIDED_LEAF if proof.get("undecided") else OUTSIDE if "outside" in proof else UNIQUE
        out[kind == UNDECIDED] = UNDECIDED_LEAF
        return out

    def rows(counts, fill, dtype, tail):
        """Rows of the nodes in node order: ``counts`` per node, ``fill(out, position)``."""
        first = np.cumsum(counts) - counts
        out = np.zeros((int(counts.sum()),) + tail, dtype)
        fill(out, first)
        return out

    def index(t, ids, c):
        leaf = (t.kind[ids] != CONTRACTED) & (t.kind[ids] != SPLIT)
        eq, uq = leaf & (c == 0), leaf & (c == UNIQUE)

        def fill(out, first):
            out[first[eq]] = t.evidence_values("equation", ids[eq]) if eq.any() else []
            for k in np.nonzero(uq)[0]:
                proof = _proof(result, t, ids[k])
                out[first[k]:first[k] + 2] = [proof["solution"], int(bool(proof["twin"]))]
        return rows(eq * 1 + uq * 2, fill, np.int32, ())

    def matrices(t, ids, c):
        leaf = (t.kind[ids] != CONTRACTED) & (t.kind[ids] != SPLIT)
        uq, out_ = leaf & (c == UNIQUE), leaf & (c == OUTSIDE)

        def fill(out, first):
            for k in np.nonzero(uq | out_)[0]:
                proof = _proof(result, t, ids[k])
                own = proof["C"] if isinstance(t, _Leaf) else t.evidence_values("C", ids[k:k + 1])[0]
                out[first[k]] = own
                if out_[k]:
                    out[first[k] + 1] = proof["outside"][2]
        return rows(uq * 1 + out_ * 2, fill, np.float32, (n, n))

    def boxes(which):
        def get(t, ids, c):
            leaf = (t.kind[ids] != CONTRACTED) & (t.kind[ids] != SPLIT)
            sel = leaf & ((c == UNIQUE) | (c == OUTSIDE)) if which == "star" else leaf & (c == OUTSIDE)

            def fill(out, first):
                for k in np.nonzero(sel)[0]:
                    proof = _proof(result, t, ids[k])
                    lo, hi = proof["star"] if which == "star" else proof["outside"][:2]
                    out[first[k]] = np.stack([lo, hi], -1)
            return rows(sel * 1, fill, np.float64, (n, 2))
        return get

    return Rules(code, {"tree.index": ("<i4", (), index), "tree.C": ("<f4", (n, n), matrices),
                        "tree.star": ("<f8", (n, 2), boxes("star")), "tree.rootbox": ("<f8", (n, 2), boxes("root"))})


def fk_certificate(results) -> Document:
    """The certificate of one FKResult or a list of them (one claim per set of leg lengths)."""
    results = results if isinstance(results, (list, tuple)) else [results]
    r0 = results[0]
    n = r0.system.n
    claims, roots, regions = [], [], []
    for r in results:
        claim = {"lengths": list(r.lengths)}
        if np.any(r.domain[0] > r.domain[1]):       # the leg-length balls do not meet: no posture at all
            claims.append({**claim, "domain": "empty", "covers": "all-postures", "complete": True,
                           "solutions": [], "tree": None})
            continue
        first = len(regions)
        regions += r.all_solutions
        dlo, dhi = np.asarray(r.domain[0], float), np.asarray(r.domain[1], float)
        inside = [j for j, s in enumerate(r.all_solutions) if np.all(s["box"].lo >= dlo) and np.all(s["box"].hi <= dhi)]
        claim.update(domain=box_json(dlo, dhi), covers="box" if r.user_domain or r.tracked else "all-postures",
                     complete=bool(r.complete), tree=True, regions=[first, len(r.all_solutions)],
                     solutions=[{"region": j, "box": decimal_box(r.all_solutions[j]["box"].lo,
                                                                 r.all_solutions[j]["box"].hi)} for j in inside])
        claims.append(claim)
        tree = r.tree if (r.tree is not None and not r.tracked) else _Leaf(dlo, dhi)
        roots.append((tree, 0 if isinstance(tree, _Leaf) else r.node, _rules(r, tree, n)))
    forest = Forest(roots, n)
    _figures(claims, forest)
    R = np.array([np.stack([s["box"].lo, s["box"].hi], -1) for s in regions]).reshape(-1, n, 2)
    C = np.array([np.asarray(s["C"], float) for s in regions]).reshape(-1, n, n)
    body = forest.arrays() + [Array("fk.region.star", "<f8", (n, 2), one(R)), Array("fk.region.box", "<f8", (n, 2), one(R)),
                              Array("fk.region.star_C", "<f8", (n, n), one(C)), Array("fk.region.box_C", "<f8", (n, n), one(C))]
    hdr = header(r0.robot, "forward-kinematics", r0.system.model_name, unknowns=list(r0.system.unknowns), claims=claims)
    return Document(hdr, body)


def _figures(claims, forest):
    """Per claim with a tree: the number of solutions, of regions, and of leaves by rule."""
    with_tree = [c for c in claims if c.get("tree")]
    for claim, (tree, _, rules), levels in zip(with_tree, forest.roots, forest.levels):
        ids = np.concatenate(levels)
        leaves = ids[(tree.kind[ids] != CONTRACTED) & (tree.kind[ids] != SPLIT)]
        codes, counts = np.unique(np.asarray(rules.code(tree, leaves)), return_counts=True)
        counts = {RULE_NAMES.get(int(c), str(c)): int(k) for c, k in zip(codes, counts)}
        claim["figures"] = {"solutions": len(claim["solutions"]), "regions": claim["regions"][1], "leaves": counts}
