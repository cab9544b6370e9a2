"""Streamed search trees (``docs/certificates.md``, "Segments"): a search past its record limit hands
each closed part of its tree to a ``Segments`` sink (``engine.search(record_sink=...)``) instead of
forgetting it.

Each segment is written like any forest, breadth-first from its roots, except that the nodes the
search still holds (open, proved, undecided) become *continued* leaves (kind 4, no rule), in the
order met: they are the roots of the next segment, whose root boxes are stored (``tree.roots``) so
that a checker matches them.  Segment 0 is the claims' roots, all continued (``Roots``); the sink's
segments are 1, 2, ...; the finished tree is the last one.  The arrays are appended to temporary
files as the search runs (memory: one segment's node ids and one chunk of rows) and read back, a
chunk at a time, when the certificate is written.
"""
from __future__ import annotations

from collections import Counter
from functools import partial
import os
import tempfile

import numpy as np

from ..engine import OPEN, PROVED, UNDECIDED
from .forest import Forest, Rules
from .writing import CHUNK, Array, one

HELD = (OPEN, PROVED, UNDECIDED)


class Roots:
    """Segment 0's nodes for the ``n`` roots of a streamed search: every one continued (the engine's
    root k is node k)."""

    def __init__(self, n):
        self.kind, self.root, self.split_at = np.full(n, OPEN, np.int8), np.arange(n), np.zeros(n)
        self.first_child = self.split_dim = np.zeros(n, np.int32)
        self.lo = self.hi = np.zeros((n, 1))
        self.rules = Rules(lambda t, ids: np.zeros(len(ids), np.int64))

    @staticmethod
    def continued(ids):
        return np.ones(len(ids), bool)


class Segments:
    """A record sink: ``rules(tree)`` gives the problem's ``Rules`` for a segment's nodes (none of them
    proved: a proved leaf is held, so continued, until the last segment); ``kept(name, kind, reason)``
    the evidence rows the certificate writes (``engine.search`` records no other).  ``leaves`` counts
    the rule leaves written, by (engine root, code)."""

    def __init__(self, d: int, rules, kept=None):
        self.d, self.rules, self.kept = d, rules, kept
        self.dir = None                          # made when the first segment is written (most searches never stream)
        self.written = []                        # per segment: [(name, dtype, tail, path)]
        self.leaves = Counter()

    def __call__(self, tree, roots) -> np.ndarray:
        tree.continued = lambda ids: np.isin(tree.kind[ids], HELD)
        forest = Forest([(tree, roots, self.rules(tree))], self.d)
        k, files = len(self.written) + 1, []
        if self.dir is None:
            self.dir = tempfile.TemporaryDirectory(prefix="certkin-segments-")
        for a in [root_boxes(tree, roots, self.d)] + forest.arrays():
            path = os.path.join(self.dir.name, f"{k}.{a.name}")
            with open(path, "wb") as fh:
                for _, raw in a._raw():
                    fh.write(raw)
            files.append((a.name, a.dtype, a.tail, path))
        self.written.append(files)
        self.leaves.update(forest.leaf_counts(0))
        return forest.continued()

    def arrays(self) -> list:
        """The body arrays of segments 1, 2, ... (``segment<k>/<name>``), read back from the files."""
        return [Array(f"segment{k}/{name}", dtype, tail, partial(_read, path, dtype, tail))
                for k, files in enumerate(self.written, 1) for name, dtype, tail, path in files]


def root_boxes(tree, roots, d, prefix="") -> Array:
    """``tree.roots``: the boxes of a segment's roots, [lo, hi] per side."""
    return Array(prefix + "tree.roots", "<f8", (d, 2), one(np.stack([tree.lo[roots], tree.hi[roots]], -1)))


def _read(path, dtype, tail):
    row = int(np.prod(tail, dtype=np.int64))
    with open(path, "rb") as fh:
        while True:
            chunk = np.fromfile(fh, dtype=np.dtype(dtype).newbyteorder("<"), count=CHUNK * row)
            if not len(chunk):
                return
            yield chunk.reshape((-1,) + tuple(tail))
