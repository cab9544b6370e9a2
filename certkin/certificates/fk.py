"""Forward-kinematics certificates (``docs/certificates.md``): per set of leg lengths, the domain, the
regions (each proved root box R with its Krawczyk matrix, X* = R), the solutions among them, and the
search tree with the evidence of each leaf and contraction (``proofs.fk`` re-checks them).
Leaves left in a cluster (``FKResult.clusters``: nothing proved there but the name) are
``in-cluster`` leaves; a length range ``"lo:hi"`` is written as ``length_ranges``.

A search too large to keep whole streamed its tree in segments (``segments``): segment 0 holds the
claims' roots, continued; the sink's segments follow, then the finished tree.

Preconditioners that the checker rebuilds from its own enclosures (codes + 64: the Gauss-Seidel P
and the C of emptiness and contraction steps) are not stored; the uniqueness proofs keep theirs, and
so do the steps whose C is too ill-conditioned to be rebuilt the same (``fk.step.fragile``: the
reasons "…, C kept", written with the code of the rule that reads its C).
"""
from __future__ import annotations

from collections import Counter

import numpy as np

from ..engine import CONTRACTED, EXCLUDED, PROVED, SPLIT, UNDECIDED
from .forest import Forest, Rules
from .segments import Roots, Segments, root_boxes
from .writing import Array, Document, box_json, header, one, outward_boxes

REBUILT = 64
LEAVES = {"equation": 0, "hc4-empty": 1, "position-empty": 2 + REBUILT, "krawczyk-empty": 3 + REBUILT,
          "slope-empty": 4 + REBUILT, "slope-gs-empty": 5 + REBUILT,
          "krawczyk-empty, C kept": 3, "slope-gs-empty, C kept": 5, "cm-bernstein-empty": 11,
          "cm-combination-empty": 12}
CONTRACTIONS = {"hc4": 0, "position": 2 + REBUILT, "krawczyk": 3 + REBUILT, "slope": 4 + REBUILT,
                "slope-gs": 5 + REBUILT, "krawczyk, C kept": 3, "slope-gs, C kept": 5}
KEPT_C = (3, 4, 5)           # rules whose C the certificate holds (their + REBUILT twins: the checker's own)
UNIQUE, OUTSIDE, IN_CLUSTER, UNDECIDED_LEAF, HC4_POSITION = 6, 7, 9, 10, 1 + REBUILT
RULE_NAMES = {**{c: n.removesuffix(", C kept") for n, c in LEAVES.items()}, UNIQUE: "krawczyk-unique",
              OUTSIDE: "krawczyk-outside", IN_CLUSTER: "in-cluster", UNDECIDED_LEAF: "undecided"}


class _Leaf:
    """A one-node tree (a tracked posture's single Krawczyk proof, or a search that did not run)."""

    def __init__(self, lo, hi):
        self.lo, self.hi = np.asarray(lo, float)[None], np.asarray(hi, float)[None]
        self.kind = np.array([PROVED], np.int8)
        self.first_child = self.split_dim = self.reason = np.zeros(1, np.int32)
        self.split_at = np.zeros(1)


class _Proved:
    """The proved leaves of one tree as arrays sorted by node: their rule (unique, outside or undecided)
    and evidence (X*, region and twin; the outside root box and its C), from the results' proofs."""

    def __init__(self, n, proofs):
        items = sorted(proofs.items())
        self.node = np.array([i for i, _ in items], np.int64)
        self.code = np.array([UNDECIDED_LEAF if p.get("undecided") else OUTSIDE if "outside" in p else UNIQUE
                              for _, p in items], np.int64)
        zero, zeros = np.zeros(n), np.zeros((n, n))
        pick = lambda f, shape, dt=float: np.array([f(p) for _, p in items], dt).reshape((-1,) + shape)  # noqa: E731
        self.star = np.swapaxes(pick(lambda p: p.get("star", (zero, zero)), (2, n)), -1, -2)
        self.index = pick(lambda p: (p.get("solution", 0), int(bool(p.get("twin")))), (2,), np.int32)
        self.root = np.swapaxes(pick(lambda p: p["outside"][:2] if "outside" in p else (zero, zero), (2, n)), -1, -2)
        self.root_C = pick(lambda p: p["outside"][2] if "outside" in p else zeros, (n, n))
        self.C = pick(lambda p: p.get("C", zeros), (n, n))

    def at(self, ids):
        """Rows of the proved leaves ``ids``."""
        return np.searchsorted(self.node, ids)


class _Wanted(dict):
    """``_WANTED[codes]``: a table of 256 booleans, true at these rule codes (codes are bytes)."""

    def __missing__(self, codes):
        table = self[codes] = np.zeros(256, bool)
        table[list(codes)] = True
        return table


_WANTED = _Wanted()


def _rules(tree, proved, n, cluster_of=None):
    """The rules of a tree: the engine's (``proved``: its ``_Proved``; ``cluster_of``: undecided
    leaf -> its cluster in the claim), or a ``_Leaf``'s."""
    cluster_of = cluster_of or {}
    in_cluster = np.array(sorted(cluster_of), np.int64)
    cluster = np.array([cluster_of[i] for i in in_cluster.tolist()], np.int32)
    names = getattr(tree, "reasons", ())
    leaf_lut = np.array([LEAVES.get(x, 255) for x in names] or [255], np.int64)
    con_lut = np.array([CONTRACTIONS.get(x, 255) for x in names] or [255], np.int64)
    has_p = getattr(tree, "evidence_rows", {}).get("P")
    own_C = not isinstance(tree, _Leaf)          # a search leaf's C is its evidence; a tracked proof's, its own

    def code(t, ids):
        kind, reason = t.kind[ids], np.clip(t.reason[ids], 0, None)
        out = np.full(len(ids), UNDECIDED_LEAF, np.int64)
        out[kind == EXCLUDED] = leaf_lut[reason[kind == EXCLUDED]]
        c = kind == CONTRACTED
        out[c] = con_lut[reason[c]]
        if has_p is not None:                      # an hc4 contraction followed by the position sweep
            out[c & (out == 0) & (has_p[ids] >= 0)] = HC4_POSITION
        p = kind == PROVED
        out[p] = proved.code[proved.at(ids[p])] if p.any() else []
        u = kind == UNDECIDED
        if len(in_cluster) and u.any():
            out[u] = np.where(np.isin(ids[u], in_cluster), IN_CLUSTER, UNDECIDED_LEAF)
        return out

    def leaves(t, ids, c, *codes):
        kind = t.kind[ids]
        return (kind != CONTRACTED) & (kind != SPLIT) & _WANTED[codes][c]

    def rows(counts, dtype, tail):
        first = np.cumsum(counts) - counts
        return np.zeros((int(counts.sum()),) + tail, dtype), first

    def index(t, ids, c):
        eq, uq, cl = leaves(t, ids, c, 0), leaves(t, ids, c, UNIQUE), leaves(t, ids, c, IN_CLUSTER)
        cm = leaves(t, ids, c, LEAVES["cm-bernstein-empty"], LEAVES["cm-combination-empty"])
        out, first = rows(eq * 1 + uq * 2 + cl * 1 + cm * 1, np.int32, ())
        if cl.any():
            out[first[cl]] = cluster[np.searchsorted(in_cluster, ids[cl])]
        if eq.any():
            out[first[eq]] = t.evidence_values("equation", ids[eq])
        if cm.any():
            out[first[cm]] = t.evidence_values("cm", ids[cm])
        k = proved.at(ids[uq])
        out[first[uq]], out[first[uq] + 1] = proved.index[k, 0], proved.index[k, 1]
        return out

    def matrices(t, ids, c):
        uq, ou = leaves(t, ids, c, UNIQUE, OUTSIDE), leaves(t, ids, c, OUTSIDE)
        kept = _WANTED[KEPT_C][c] & (t.kind[ids] != SPLIT)          # leaves and contractions
        out, first = rows(uq * 1 + ou * 1 + kept * 1, np.float32, (n, n))
        if uq.any():
            out[first[uq]] = t.evidence_values("C", ids[uq]) if own_C else proved.C[proved.at(ids[uq])]
        out[first[ou] + 1] = proved.root_C[proved.at(ids[ou])]
        if kept.any():
            out[first[kept]] = t.evidence_values("C", ids[kept])
        return out

    def weights(t, ids, c):
        sel = leaves(t, ids, c, LEAVES["cm-combination-empty"])
        return t.evidence_values("weights", ids[sel]) if sel.any() else np.zeros((0, 15), np.float32)

    def boxes(which):
        def get(t, ids, c):
            sel = leaves(t, ids, c, UNIQUE, OUTSIDE) if which == "star" else leaves(t, ids, c, OUTSIDE)
            k = proved.at(ids[sel])
            return proved.star[k] if which == "star" else proved.root[k]
        return get

    return Rules(code, {"tree.index": ("<i4", (), index), "tree.C": ("<f4", (n, n), matrices),
                        "tree.star": ("<f8", (n, 2), boxes("star")), "tree.rootbox": ("<f8", (n, 2), boxes("root")),
                        "tree.weights": ("<f4", (15,), weights)})


def record_sink(n: int, reasons) -> Segments:
    """The sink of an FK search that streams its tree (``n`` unknowns, the problem's ``reasons``).  The
    search records no preconditioner that the certificate does not write: a C only for a proved leaf
    or a step whose C is kept (the checker rebuilds the others), a P only for an ``hc4`` contraction
    (it marks ``hc4-position``)."""
    hc4 = reasons.index("hc4")
    with_C = _WANTED[tuple(k for k, r in enumerate(reasons) if "C kept" in r)]   # (reasons < 0 wrap past 127)

    def kept(name, kind, reason):
        return (kind == PROVED) | with_C[reason.astype(np.uint8)] if name == "C" else \
            (kind == CONTRACTED) & (reason == hc4) if name == "P" else np.ones(len(kind), bool)
    return Segments(n, lambda tree: _rules(tree, _Proved(n, {}), n), kept)


def _streamed(results):
    """The results with their trees whole or streamed: a search that forgot its excluded leaves runs
    again, streamed; a streamed tree serves only when the list holds its results in the order of its
    roots, all of them (segment 1's roots), and it is the only one (else that search runs again, kept
    whole in memory)."""
    results = [r.recorded() if r.recorded and r.tree is not None and not r.tree.complete_record else r for r in results]
    streams = {id(r.tree): r.tree for r in results if r.tree is not None and r.tree.record_sink and not r.tracked}
    tree = next(iter(streams.values())) if len(streams) == 1 else None
    if tree is not None and [r.node for r in results if r.tree is tree] != list(range(tree.n_roots)):
        tree = None
    return [r.recorded(whole=True) if id(r.tree) in streams and tree is None else r for r in results], tree


def fk_certificate(results) -> Document:
    """The certificate of one FKResult or a list of them (one claim per set of leg lengths)."""
    results = results if isinstance(results, (list, tuple)) else [results]
    results, streamed = _streamed(results)
    r0 = results[0]
    n = r0.system.n
    claims, roots, regions, shared = [], [], [], {}
    stream_roots = Roots(streamed.n_roots) if streamed is not None else None
    for r in results:                            # one rules object per engine tree shared by the results
        if r.tree is not None and not r.tracked:
            shared.setdefault(id(r.tree), []).append(r)
    rules = {key: _rules(rs[0].tree, _Proved(n, {i: p for r in rs for i, p in r.leaf_proofs.items()}), n,
                         {i: c for r in rs for i, c in r.cluster_of.items()})
             for key, rs in shared.items()}
    for r in results:
        claim = _lengths(r.lengths)
        if np.any(r.domain[0] > r.domain[1]):       # the leg-length balls do not meet: no posture at all
            claims.append({**claim, "domain": "empty", "covers": "all-postures", "complete": True,
                           "solutions": [], "tree": None})
            continue
        first = len(regions)
        regions += r.all_solutions
        dlo, dhi = np.asarray(r.domain[0], float), np.asarray(r.domain[1], float)
        blo = np.array([s["box"].lo for s in r.all_solutions]).reshape(-1, n)
        bhi = np.array([s["box"].hi for s in r.all_solutions]).reshape(-1, n)
        inside = np.nonzero(np.all((blo >= dlo) & (bhi <= dhi), axis=1))[0]
        # (a tracked posture's claim: complete in its box, exactly one posture there)
        claim.update(domain=box_json(dlo, dhi), covers="box" if r.user_domain or r.tracked else "all-postures",
                     complete=bool(r.complete or r.tracked), tree=True, regions=[first, len(r.all_solutions)],
                     solutions=[{"region": int(j), "box": box} for j, box in zip(inside, outward_boxes(blo[inside], bhi[inside]))])
        if r.clusters:
            claim["clusters"] = outward_boxes(np.array([c["box"].lo for c in r.clusters]).reshape(-1, n),
                                              np.array([c["box"].hi for c in r.clusters]).reshape(-1, n))
        claims.append(claim)
        if streamed is not None and r.tree is streamed:
            roots.append((stream_roots, r.node, stream_roots.rules))
        elif r.tree is not None and not r.tracked:
            roots.append((r.tree, r.node, rules[id(r.tree)]))
        else:
            leaf = _Leaf(dlo, dhi)
            proof = {"star": (dlo, dhi), "solution": 0, "twin": False, "C": r.track_C} if r.tracked else {"undecided": True}
            roots.append((leaf, 0, _rules(leaf, _Proved(n, {0: proof}), n)))
    forest, segments = Forest(roots, n), []
    if streamed is not None:                     # the sink's segments, then the finished tree
        sink, last = streamed.record_sink, Forest([(streamed, streamed.segment_roots, rules[id(streamed)])], n)
        prefix = f"segment{len(sink.written) + 1}/"
        segments = sink.arrays() + [root_boxes(streamed, streamed.segment_roots, n, prefix)] + last.arrays(prefix)
        stream_roots.counts = sink.leaves + Counter(last.leaf_counts(0))
    _figures(claims, forest)
    R = np.stack([np.array([s["box"].lo for s in regions]).reshape(-1, n),
                  np.array([s["box"].hi for s in regions]).reshape(-1, n)], -1)
    C = np.array([np.asarray(s["C"], float) for s in regions]).reshape(-1, n, n)
    body = forest.arrays() + [Array("fk.region.box", "<f8", (n, 2), one(R)),      # X* = R: no fk.region.star
                              Array("fk.region.box_C", "<f8", (n, n), one(C))] + segments
    more = {"segments": len(streamed.record_sink.written) + 2} if streamed is not None else {}
    hdr = header(r0.robot, "forward-kinematics", r0.system.model_name, unknowns=list(r0.system.unknowns), claims=claims,
                 **more)
    return Document(hdr, body)


def _lengths(texts) -> dict:
    """``lengths`` (exact decimals), or ``length_ranges`` when one of them is a range ``"lo:hi"``."""
    texts = [str(t) for t in texts]
    if not any(":" in t for t in texts):
        return {"lengths": texts}
    return {"length_ranges": [t.split(":") if ":" in t else [t, t] for t in texts]}


def _figures(claims, forest):
    """Per claim with a tree: the number of solutions, of regions, and of leaves by rule (a streamed
    search's: counted over its segments)."""
    with_tree = iter([c for c in claims if c.get("tree")])
    for part, (tree, nodes, rules) in enumerate(forest.roots):
        by_root = {}
        for (root, code), k in sorted((getattr(tree, "counts", None) or forest.leaf_counts(part)).items()):
            rule = RULE_NAMES.get(code, str(code))        # (a rule's two codes, C kept or not, count as one)
            by_root.setdefault(root, {})[rule] = by_root.get(root, {}).get(rule, 0) + k
        for node in nodes:                       # the leaves of each claim: those of its root
            claim = next(with_tree)
            counts = by_root.get(int(tree.root[node]) if hasattr(tree, "root") else 0, {})
            claim["figures"] = {"solutions": len(claim["solutions"]), "regions": claim["regions"][1], "leaves": counts}
