"""The search trees of a certificate, stored breadth-first as arrays (docs/certificates.md "Search trees" and
"Segments"; docs/soundness.md §13).

``Forest`` derives every node's box from the roots so that the leaves tile each root (a cut strictly inside its side,
a contraction's child inside its parent, every evidence row used; a continued leaf proves nothing, its box being tiled
by the next segment), and hands leaves and contractions to the problem in batches, grouped by rule."""
from __future__ import annotations

import numpy as np

from .numbers import real
from .report import Rejected

SPLIT, CUT, CONTRACT, LEAF, CONTINUED = 0, 1, 2, 3, 4
SPLIT_RATIO, BATCH = 0.4921875, 8192
MAX_DEPTH = 1 << 16     # levels of a segment (genuine trees: a few hundred)


class Forest:
    """``leaves``/``contractions``: {code: (name, {evidence array: rows per node})}."""

    def __init__(self, cert, d, roots_lo, roots_hi, leaves: dict, contractions: dict, evidence: dict, labels=None):
        self.cert, self.leaves, self.contractions, self.d, self.shapes = cert, leaves, contractions, d, evidence
        self.labels, self.segments, self.segment = labels or [], cert.header.get("segments", 1), 0
        self.lo0, self.hi0 = (np.asarray(b, float).reshape(-1, d) for b in (roots_lo, roots_hi))
        self._load("")

    def _load(self, prefix):
        """The arrays of one segment (``prefix``: ``segment<k>/`` for k >= 1)."""
        cert, t = self.cert, prefix + "tree"
        self.t = t
        self.kind, self.code = cert.array(t + ".kind", ("<u1",)), cert.array(t + ".code", ("<u1",))
        if self.kind.ndim != 1 or self.code.shape != self.kind.shape:
            raise Rejected(f"{t}: {t}.kind and {t}.code must be two arrays of one length")
        for i in np.nonzero(self.kind > CONTINUED)[0][:1]:
            raise Rejected(f"{t}: node {i}: unknown kind {self.kind[i]}")
        if len(self.kind) > max(1 << 22, 16 * cert.size):      # ~4 genuine nodes a byte at most: a bomb
            raise Rejected(f"{t}: {len(self.kind)} nodes in a certificate of {cert.size} bytes")
        rows = {name: np.zeros(len(self.kind), np.uint8) for name in self.shapes}      # (rows per node: 0 to 2)
        rows["tree.cut"], rows["tree.box"] = (self.kind == CUT).view(np.uint8), (self.kind == CONTRACT).view(np.uint8)
        for kind, table in ((LEAF, self.leaves), (CONTRACT, self.contractions)):
            mine = self.kind == kind
            unknown = mine & ~np.isin(self.code, list(table))
            for i in np.nonzero(unknown)[0][:1]:
                raise Rejected(f"{t}: node {i}: unknown {'leaf' if kind == LEAF else 'contraction'} rule code {self.code[i]}")
            for c, (_, uses) in table.items():
                for name, k in uses.items():
                    rows[name][mine & (self.code == c)] += k
        self.users, self.offset, self.evidence = {}, {}, {}
        shapes = {"tree.cut": ((), ("<f8",)), "tree.box": ((self.d, 2), ("<u8",)), **self.shapes}
        for name, per_node in rows.items():    # the nodes using each array, and their first rows
            users = self.users[name] = np.nonzero(per_node)[0]
            self.offset[name] = np.concatenate([[0], np.cumsum(per_node[users], dtype=np.int64)])
            total, (tail, dtypes) = int(self.offset[name][-1]), shapes[name]
            if (n := (cert._entries().get(prefix + name) or {"shape": [total]})["shape"][:1]) != [total]:   # not read
                raise Rejected(f"{t}: {prefix + name} has {n[0] if n else 0} rows, the nodes use {total}")
            arr = cert.array(prefix + name, dtypes, tail) if total or cert.has(prefix + name) else np.zeros((0,) + tail)
            if len(arr) != total:
                raise Rejected(f"{t}: {prefix + name} has {len(arr)} rows, the nodes use {total}")
            self.evidence[name] = arr
        self.nodes = len(self.kind)

    def at(self, node, root):
        """'claims[k].tree: node i' (of segment s) for messages."""
        label = self.labels[root] if root < len(self.labels) else "tree"
        return f"{label}: node {node}" + (f" of segment {self.segment}" if self.segment else "")

    def rows(self, name, ids, k=0):
        """Row k of evidence ``name`` of each node ``ids``."""
        return self.evidence[name][self.offset[name][np.searchsorted(self.users[name], ids)] + k]

    def walk(self, visit, progress=None):
        """Call ``visit(kind, code, ids, lo, hi, claim, child)`` on batches of leaves (child None) and
        contractions (child = (lo, hi) of the child boxes), grouped by rule; segment by segment, the
        continued leaves of one being the roots of the next (ids: node numbers in the segment)."""
        lo, hi, claim = self.lo0, self.hi0, np.arange(len(self.lo0))
        for s in range(self.segments):
            if s:                                # the previous segment's arrays are dropped, this one's read
                self.cert.forget(("tree.", "segment"))
                self.segment, want = s, np.stack([lo, hi], -1)
                self._load(f"segment{s}/")
                roots = self.cert.array(self.t + ".roots", ("<f8",), (self.d, 2))
                differ = np.nonzero(np.any(roots != want, axis=(1, 2)))[0] if roots.shape == want.shape else [0]
                if len(differ):
                    raise Rejected(f"{self.t}.roots: root {differ[0]} is not continued leaf {differ[0]} of segment "
                                   f"{s - 1} ({len(roots)} roots, {len(lo)} continued leaves)")
            lo, hi, claim = self._walk(visit, progress, lo, hi, claim)
            if (len(lo) > 0) != (s + 1 < self.segments):
                raise Rejected(f"segment {s}: {len(lo)} continued leaves, {self.segments - s - 1} segments follow")

    def _walk(self, visit, progress, lo, hi, claim):
        """One segment from the roots ``lo``, ``hi``; returns its continued leaves in order."""
        start, pending, size, level, cont = 0, {}, 0, 0, []
        if self.nodes != (want := len(lo) + 2 * np.count_nonzero(self.kind <= CUT) + np.count_nonzero(self.kind == CONTRACT)):
            raise Rejected(f"{self.t}: {self.nodes} nodes, but {len(lo)} roots and the splits and contractions make {want}")
        while len(lo):
            if level > MAX_DEPTH or len(lo) > max(1 << 20, 8 * self.cert.size):    # (memory: a few bombs' bytes)
                raise Rejected(f"{self.t}: level {level} of {len(lo)} boxes: deeper or wider than {self.cert.size} bytes hold")
            m = len(lo)
            if start + m > self.nodes:
                raise Rejected(f"{self.t}: level {level} needs {m} nodes, only {self.nodes - start} are left")
            ids = np.arange(start, start + m)
            kind, code = self.kind[ids], self.code[ids]
            split = kind <= CUT
            for i in np.nonzero(split & (code >= self.d))[0][:1]:
                raise Rejected(f"{self.at(ids[i], claim[i])}: split dimension {code[i]} (the boxes have {self.d})")
            nkids = np.where(split, 2, np.where(kind == CONTRACT, 1, 0))
            cont.append((lo[kind == CONTINUED], hi[kind == CONTINUED], claim[kind == CONTINUED]))
            first = np.concatenate([[0], np.cumsum(nkids)])[:-1]
            new_lo = np.empty((int(nkids.sum()), self.d))
            new_hi = np.empty_like(new_lo)
            s = np.nonzero(split)[0]
            if len(s):
                dim = code[s].astype(np.int64)
                a, b = lo[s, dim], hi[s, dim]
                at = a + SPLIT_RATIO * (b - a)
                cut = kind[s] == CUT
                at[cut] = self.rows("tree.cut", ids[s][cut])
                for i in np.nonzero(~((a < at) & (at < b)))[0][:1]:
                    raise Rejected(f"{self.at(ids[s][i], claim[s][i])}: split point {float(at[i])!r} not strictly "
                                   f"inside [{float(a[i])!r}, {float(b[i])!r}] on dimension {dim[i]}")
                new_lo[first[s]], new_hi[first[s]], new_lo[first[s] + 1], new_hi[first[s] + 1] = lo[s], hi[s], lo[s], hi[s]
                new_hi[first[s], dim] = new_lo[first[s] + 1, dim] = at
            c = np.nonzero(kind == CONTRACT)[0]
            if len(c):
                box = self.rows("tree.box", ids[c])            # the child's bits XOR the parent's
                box = (np.ascontiguousarray(np.stack([lo[c], hi[c]], -1)).view(np.uint64) ^ box).view(np.float64)
                clo, chi = box[..., 0], box[..., 1]
                for i in np.nonzero(~np.all((lo[c] <= clo) & (clo <= chi) & (chi <= hi[c]), axis=1))[0][:1]:
                    raise Rejected(f"{self.at(ids[c][i], claim[c][i])}: contracted box not inside its parent")
                new_lo[first[c]], new_hi[first[c]] = clo, chi
            for kd in (CONTRACT, LEAF):
                mine = kind == kd
                for cd in np.unique(code[mine]):
                    sel = np.nonzero(mine & (code == cd))[0]
                    kids = (new_lo[first[sel]], new_hi[first[sel]]) if kd == CONTRACT else ()
                    pending.setdefault((kd, int(cd)), []).append((ids[sel], lo[sel], hi[sel], claim[sel]) + kids)
                    size += len(sel)
            if size >= BATCH:
                self._flush(pending, visit)
                pending, size = {}, 0
            claim = np.repeat(claim, nkids)
            lo, hi, start, level = new_lo, new_hi, start + m, level + 1
            if progress:
                progress(start, self.nodes)
        self._flush(pending, visit)
        if start != self.nodes:
            raise Rejected(f"{self.t}: {self.nodes - start} nodes after the last level belong to no box")
        return [np.concatenate([c[k] for c in cont] or [empty]) for k, empty in enumerate((self.lo0[:0],) * 2 + (claim,))]

    @staticmethod
    def _flush(pending, visit):     # BATCH nodes a call: a rule's temporaries stay small, however wide the level
        for (kd, cd), parts in pending.items():
            cols = [np.concatenate([p[k] for p in parts]) for k in range(6 if kd == CONTRACT else 4)]
            for s in range(0, len(cols[0]), BATCH):
                c = [x[s:s + BATCH] for x in cols]
                visit(kd, cd, *c[:4], (c[4], c[5]) if kd == CONTRACT else None)


def halves(lo, hi, scale):
    """The boxes (N, d) cut at the midpoint of the side widest relative to ``scale``: (lo, hi) of the lower
    halves then of the upper halves, and whether every cut lies strictly inside its side."""
    dim, r = np.argmax((hi - lo) / scale, axis=1), np.arange(len(lo))
    mid = 0.5 * lo[r, dim] + 0.5 * hi[r, dim]
    upper_lo, lower_hi = lo.copy(), hi.copy()
    upper_lo[r, dim], lower_hi[r, dim] = mid, mid
    return np.concatenate([lo, upper_lo]), np.concatenate([lower_hi, hi]), bool(np.all((lo[r, dim] < mid) & (mid < hi[r, dim])))


def read_box(value, d, where):
    """A box of the header: ``d`` pairs [lo, hi] of exact finite floats, lo <= hi; returns (lo, hi) arrays."""
    if not isinstance(value, list) or len(value) != d or not all(isinstance(p, list) and len(p) == 2 for p in value):
        raise Rejected(f"{where}: expected {d} intervals [lo, hi]")
    lo, hi = (np.array([real(p[k], where) for p in value]) for k in (0, 1))
    if not np.all(lo <= hi):
        raise Rejected(f"{where}: lo > hi")
    return lo, hi
