"""Search trees in certificates: engine trees written breadth-first as body arrays (docs/certificates.md).

A ``Forest`` is the list of roots of a certificate (one per claim with a tree, in claim order), each
a node of an engine ``Tree`` with the problem's ``Rules``.  Level 0 is the roots; level k + 1 the
children of level k, in order (a split's lower then upper part, a contraction's child).  Each array
(``tree.kind``, ``tree.code``, ``tree.cut``, ``tree.box`` and the evidence) is produced level by
level, chunk by chunk, straight from the engine's columns: the only extra memory is one array of
node ids per level.  A split at the engine's default point (``SPLIT_RATIO``, evaluated as the
engine does) is kind 0, any other cut kind 1 with its value in ``tree.cut``; a contraction's child
box is stored as its bits XOR its parent's.
"""
from __future__ import annotations

import numpy as np

from ..engine import CONTRACTED, SPLIT
from ..engine.search import SPLIT_RATIO
from .writing import CHUNK, Array

KIND_SPLIT, KIND_CUT, KIND_CONTRACT, KIND_LEAF = 0, 1, 2, 3


class Rules:
    """A problem's mapping of engine nodes to certificate rules: ``code(tree, ids)`` gives the rule code
    of leaves and contractions (any value for splits), ``rows`` maps each evidence array name to
    ``(dtype, tail, function(tree, ids, code) -> rows of those nodes, in node order)``."""

    def __init__(self, code, rows=None):
        self.code, self.rows = code, rows or {}


def levels(tree, roots) -> list:
    """Node ids of the subtrees at ``roots`` (in order), breadth-first, one array per level."""
    out, ids = [], np.asarray(roots, dtype=np.int64)
    while len(ids):
        out.append(ids)
        kind = tree.kind[ids]
        first = tree.first_child[ids].astype(np.int64)
        split = kind == SPLIT
        kids = np.full((len(ids), 2), -1, dtype=np.int64)
        kids[split, 0], kids[split, 1] = first[split], first[split] + 1
        kids[kind == CONTRACTED, 0] = first[kind == CONTRACTED]
        ids = kids[kids >= 0]                        # row-major: each node's children, in node order
    return out


class Forest:
    """The roots ``[(tree, node, rules)]`` of a certificate's trees; ``arrays()`` gives the body arrays.

    Consecutive roots of one engine tree with the same rules are walked together (one part): the
    breadth-first order over them is the forest's, and a level is a few numpy operations."""

    def __init__(self, roots, d: int):
        self.d, self.roots = d, []
        for tree, node, rules in roots:
            if self.roots and self.roots[-1][0] is tree and self.roots[-1][2] is rules:
                self.roots[-1][1].append(node)
            else:
                self.roots.append((tree, [node], rules))
        self.levels = [levels(tree, nodes) for tree, nodes, _ in self.roots]
        self.segments = []                       # (part, ids, kinds, codes) in breadth-first order
        for k in range(max((len(lv) for lv in self.levels), default=0)):
            for p, ((tree, _, rules), lv) in enumerate(zip(self.roots, self.levels)):
                if k < len(lv):
                    seg = (p, lv[k], self._kind(tree, lv[k]), self._code(tree, rules, lv[k]))
                    if self.segments and self.segments[-1][0] == p:     # one part: one segment for all levels
                        last = self.segments.pop()
                        seg = (p, *(np.concatenate([a, b]) for a, b in zip(last[1:], seg[1:])))
                    self.segments.append(seg)

    def _chunks(self):
        """(tree, rules, ids, kinds, codes) in breadth-first order over the forest, a chunk at a time."""
        for p, ids, kinds, codes in self.segments:
            tree, _, rules = self.roots[p]
            for a in range(0, len(ids), CHUNK):
                yield tree, rules, ids[a:a + CHUNK], kinds[a:a + CHUNK], codes[a:a + CHUNK]

    @staticmethod
    def _kind(tree, ids):
        kind = np.full(len(ids), KIND_LEAF, dtype=np.uint8)
        split = tree.kind[ids] == SPLIT
        s = ids[split]
        dim = tree.split_dim[s].astype(np.int64)
        a, b = tree.lo[s, dim], tree.hi[s, dim]
        kind[split] = np.where(a + SPLIT_RATIO * (b - a) == tree.split_at[s], KIND_SPLIT, KIND_CUT)
        kind[tree.kind[ids] == CONTRACTED] = KIND_CONTRACT
        return kind

    def _code(self, tree, rules, ids):
        code = np.asarray(rules.code(tree, ids), dtype=np.uint8).copy()
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
        for tree, rules, ids, _, code in self._chunks():
            if name in rules.rows:
                yield rules.rows[name][2](tree, ids, code)

    def arrays(self) -> list:
        names = {}
        for _, _, rules in self.roots:
            for name, (dtype, tail, _) in rules.rows.items():
                names.setdefault(name, (dtype, tail))
        out = [Array("tree.kind", "|u1", (), lambda: (c[3] for c in self._chunks())),
               Array("tree.code", "|u1", (), lambda: (c[4] for c in self._chunks())),
               Array("tree.cut", "<f8", (), self._cuts),
               Array("tree.box", "<u8", (self.d, 2), self._boxes)]
        out += [Array(name, dtype, tail, lambda name=name: self._evidence(name)) for name, (dtype, tail) in names.items()]
        return out
