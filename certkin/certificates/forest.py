"""Search trees in certificates: engine trees written breadth-first as body arrays (docs/certificates.md).

A ``Forest`` is the list of roots of a certificate (one per claim with a tree, in claim order), each
a node of an engine ``Tree`` with the problem's ``Rules``.  Level 0 is the roots; level k + 1 the
children of level k, in order (a split's lower then upper part, a contraction's child).  Each array
(``tree.kind``, ``tree.code``, ``tree.cut``, ``tree.box`` and the evidence) is produced level by
level, chunk by chunk, straight from the engine's columns: the only extra memory is one array of
node ids per level.  A split at the engine's default point (``SPLIT_RATIO``, evaluated as the
engine does) is kind 0, any other cut kind 1 with its value in ``tree.cut``; a contraction's child
box is stored as its bits XOR its parent's.  A tree may mark nodes *continued* (``tree.continued(ids)``:
the nodes a search still held when it handed this segment over, ``certificates.segments``): kind 4,
no children, no rule; their subtrees are the next segment's.
"""
from __future__ import annotations

import numpy as np

from ..engine import CONTRACTED, SPLIT
from ..engine.search import SPLIT_RATIO
from .writing import CHUNK, Array

KIND_SPLIT, KIND_CUT, KIND_CONTRACT, KIND_LEAF, KIND_CONTINUED = 0, 1, 2, 3, 4


class Rules:
    """A problem's mapping of engine nodes to certificate rules: ``code(tree, ids)`` gives the rule code
    of leaves and contractions (any value for splits), ``rows`` maps each evidence array name to
    ``(dtype, tail, function(tree, ids, code) -> rows of those nodes, in node order)``."""

    def __init__(self, code, rows=None):
        self.code, self.rows = code, rows or {}


def levels(tree, roots) -> list:
    """Node ids of the subtrees at ``roots`` (in order), breadth-first, one array per level.  A small
    tree's children are tabled first (three numpy operations a level, then); a large one's are
    looked up level by level (the walk then costs its subtrees, not the whole tree)."""
    out, ids = [], np.asarray(roots, dtype=np.int64)
    table = _children(tree.kind, tree.first_child) if len(tree.kind) <= TABLE_NODES else None
    while len(ids):
        out.append(ids)
        kids = table[ids] if table is not None else _children(tree.kind[ids], tree.first_child[ids])
        ids = kids[kids >= 0]                        # row-major: each node's children, in node order
    return out


TABLE_NODES = 1 << 16


def _children(kind, first) -> np.ndarray:
    """(k, 2) children of nodes of these kinds and first children: a split's two, a contraction's one,
    then -1."""
    first = first.astype(np.int64)
    split = kind == SPLIT
    return np.stack([np.where(split | (kind == CONTRACTED), first, -1), np.where(split, first + 1, -1)], 1)


class Forest:
    """The roots ``[(tree, node or array of nodes, rules)]`` of a certificate's trees; ``arrays()`` gives
    the body arrays.

    Consecutive roots of one engine tree with the same rules are walked together (one part): the
    breadth-first order over them is the forest's, and a level is a few numpy operations."""

    def __init__(self, roots, d: int):
        self.d, self.roots = d, []
        for tree, node, rules in roots:
            if self.roots and self.roots[-1][0] is tree and self.roots[-1][2] is rules:
                self.roots[-1][1].extend(np.atleast_1d(node).tolist())
            else:
                self.roots.append((tree, np.atleast_1d(node).tolist(), rules))
        self.levels = [levels(tree, nodes) for tree, nodes, _ in self.roots]
        parts = []                           # per part: (ids, kinds, codes) of all its levels, and where each level starts
        for (tree, _, rules), lv in zip(self.roots, self.levels):
            ids = np.concatenate(lv) if lv else np.zeros(0, np.int64)
            starts = np.cumsum([0] + [len(x) for x in lv]).tolist()
            parts.append((ids, self._kind(tree, ids), self._code(tree, rules, ids), starts))
        pieces = []                          # [part, start, stop] in breadth-first order, a part's consecutive levels joined
        for k in range(max((len(lv) for lv in self.levels), default=0)):
            for p, (_, _, _, starts) in enumerate(parts):
                if k + 1 < len(starts):
                    if pieces and pieces[-1][0] == p and pieces[-1][2] == starts[k]:
                        pieces[-1][2] = starts[k + 1]
                    else:
                        pieces.append([p, starts[k], starts[k + 1]])
        self.runs = [(p, *(x[a:b] for x in parts[p][:3])) for p, a, b in pieces]   # (part, ids, kinds, codes)

    def _chunks(self):
        """(tree, rules, ids, kinds, codes) in breadth-first order over the forest, a chunk at a time."""
        for p, ids, kinds, codes in self.runs:
            tree, _, rules = self.roots[p]
            for a in range(0, len(ids), CHUNK):
                yield tree, rules, ids[a:a + CHUNK], kinds[a:a + CHUNK], codes[a:a + CHUNK]

    def continued(self) -> np.ndarray:
        """The continued nodes in breadth-first order (node ids of the one part's tree)."""
        return np.concatenate([ids[kinds == KIND_CONTINUED] for _, ids, kinds, _ in self.runs] or [[]]).astype(np.int64)

    def leaf_counts(self, part) -> dict:
        """{(engine root, rule code): leaves} of one part."""
        tree = self.roots[part][0]
        runs = [(ids[k == KIND_LEAF], c[k == KIND_LEAF]) for p, ids, k, c in self.runs if p == part]
        ids = np.concatenate([r[0] for r in runs] or [[]]).astype(np.int64)
        root = tree.root[ids].astype(np.int64) if hasattr(tree, "root") else np.zeros(len(ids), np.int64)
        pairs, counts = np.unique(root * 256 + np.concatenate([r[1] for r in runs] or [[]]), return_counts=True)
        return {(p // 256, p % 256): k for p, k in zip(pairs.tolist(), counts.tolist())}

    @staticmethod
    def _kind(tree, ids):
        kind = np.full(len(ids), KIND_LEAF, dtype=np.uint8)
        if hasattr(tree, "continued"):
            kind[tree.continued(ids)] = KIND_CONTINUED
        split = tree.kind[ids] == SPLIT
        s = ids[split]
        dim = tree.split_dim[s].astype(np.int64)
        a, b = tree.lo[s, dim], tree.hi[s, dim]
        kind[split] = np.where(a + SPLIT_RATIO * (b - a) == tree.split_at[s], KIND_SPLIT, KIND_CUT)
        kind[tree.kind[ids] == CONTRACTED] = KIND_CONTRACT
        return kind

    def _code(self, tree, rules, ids):
        code = np.zeros(len(ids), np.uint8)
        ruled = ~tree.continued(ids) if hasattr(tree, "continued") else np.ones(len(ids), bool)
        code[ruled] = rules.code(tree, ids[ruled])
        split = tree.kind[ids] == SPLIT
        code[split] = tree.split_dim[ids[split]]
        return code

    def _cuts(self):
        for tree, _, ids, kind, _ in self._chunks():
            yield tree.split_at[ids[kind == KIND_CUT]]

    def _boxes(self):
        for tree, _, ids, _, _ in self._chunks():
            c = ids[tree.kind[ids] == CONTRACTED]
            child = tree.first_child[c]
            parent = np.ascontiguousarray(np.stack([tree.lo[c], tree.hi[c]], -1))
            kid = np.ascontiguousarray(np.stack([tree.lo[child], tree.hi[child]], -1))
            yield kid.view(np.uint64) ^ parent.view(np.uint64)

    def _evidence(self, name):
        for tree, rules, ids, kind, code in self._chunks():
            if name in rules.rows:
                ruled = kind != KIND_CONTINUED
                yield rules.rows[name][2](tree, ids[ruled], code[ruled])

    def arrays(self, prefix: str = "") -> list:
        names = {}
        for _, _, rules in self.roots:
            for name, (dtype, tail, _) in rules.rows.items():
                names.setdefault(name, (dtype, tail))
        out = [Array(prefix + "tree.kind", "|u1", (), lambda: (c[3] for c in self._chunks())),
               Array(prefix + "tree.code", "|u1", (), lambda: (c[4] for c in self._chunks())),
               Array(prefix + "tree.cut", "<f8", (), self._cuts),
               Array(prefix + "tree.box", "<u8", (self.d, 2), self._boxes)]
        out += [Array(prefix + name, dtype, tail, lambda name=name: self._evidence(name))
                for name, (dtype, tail) in names.items()]
        return out
