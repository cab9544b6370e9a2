"""The record of a branch-and-bound search: nodes, their boxes, kinds, reasons and evidence.

``Store`` holds the growing columns while the search runs, ``Evidence`` the evidence rows of the
nodes that have some; ``Tree`` is the finished record that results and certificates read: every
box of the domain ends in exactly one leaf (``PROVED``, ``EXCLUDED`` or ``UNDECIDED``);
``certificates.forest`` writes it breadth-first as arrays.
"""
from __future__ import annotations

import numpy as np

OPEN, PROVED, EXCLUDED = 0, 1, 2
# node kinds in the tree (leaves: PROVED, EXCLUDED, UNDECIDED)
UNDECIDED, SPLIT, CONTRACTED = 3, 4, 5

# reasons of undecided leaves (engine codes, negative to keep them apart from the problem's)
BUDGET, RESOLUTION, NOT_NEEDED, INTERRUPTED = -1, -2, -3, -4
UNDECIDED_REASONS = {BUDGET: "budget: boxes or time exhausted",
                     INTERRUPTED: "interrupted: Ctrl-C stopped the search",
                     RESOLUTION: "resolution: box narrower than min_width",
                     NOT_NEEDED: "not needed: the answer for this box was found"}


COLUMNS = ("lo", "hi", "root", "parent", "kind", "reason", "split_dim", "split_at", "first_child")


class Store:
    """Growable columns of the tree (amortised growth by half, one column copied at a time).

    Compact types: node ids and roots are int32 (fewer than 2³¹ nodes), kinds,
    reasons and split dimensions int8 (reason codes are small, engine codes
    -1..-4); the boxes and split points stay float64.  16 d + 33 bytes per node.
    """

    def __init__(self, d: int, capacity: int = 1024, n_roots: int = 1):
        self.n = 0
        self.forgotten = np.zeros(n_roots, dtype=np.int64)   # nodes dropped by ``compact``, per root
        self.lo = np.empty((capacity, d))
        self.hi = np.empty((capacity, d))
        self.root = np.empty(capacity, dtype=np.int32)
        self.parent = np.empty(capacity, dtype=np.int32)
        self.kind = np.empty(capacity, dtype=np.int8)
        self.reason = np.empty(capacity, dtype=np.int8)
        self.split_dim = np.empty(capacity, dtype=np.int8)
        self.split_at = np.empty(capacity)
        self.first_child = np.empty(capacity, dtype=np.int32)

    def nbytes(self) -> int:
        """Bytes held by the columns (their capacity, not only the nodes used)."""
        return sum(getattr(self, name).nbytes for name in COLUMNS)

    def add(self, lo, hi, root, parent) -> np.ndarray:
        k = len(lo)
        if self.n + k > len(self.root):
            cap = max(self.n + k, len(self.root) + len(self.root) // 2)
            if cap >= 2 ** 31:
                raise MemoryError("search tree larger than 2**31 nodes")
            for name in COLUMNS:
                old = getattr(self, name)
                arr = np.empty((cap,) + old.shape[1:], dtype=old.dtype)
                arr[:self.n] = old[:self.n]
                setattr(self, name, arr)
        ids = np.arange(self.n, self.n + k)
        self.lo[ids], self.hi[ids] = lo, hi
        self.root[ids], self.parent[ids] = root, parent
        self.kind[ids] = OPEN
        self.reason[ids] = 0
        self.split_dim[ids] = -1
        self.split_at[ids] = 0.0
        self.first_child[ids] = -1
        self.n += k
        return ids

    def compact(self, keep, evidence) -> np.ndarray:
        """Keep only the nodes ``keep`` (sorted ids): the others are forgotten (counted per root in
        ``forgotten``) with their evidence; the kept nodes lose their parent and child links.
        Returns the new id of every old node (−1: forgotten)."""
        new = np.full(self.n, -1, dtype=np.int64)
        new[keep] = np.arange(len(keep))
        dropped = np.ones(self.n, dtype=bool)
        dropped[keep] = False
        self.forgotten += np.bincount(self.root[:self.n][dropped], minlength=len(self.forgotten))
        for name in COLUMNS:
            col = getattr(self, name)
            col[:len(keep)] = col[keep]
        self.parent[:len(keep)] = -1
        self.first_child[:len(keep)] = -1
        self.n = len(keep)
        evidence.nbytes = 0
        for name, parts in evidence.parts.items():
            ids = new[np.concatenate([i for i, _ in parts])]
            rows = np.concatenate([r for _, r in parts])
            mask = ids >= 0                       # one part per name, possibly empty (dtype and shape kept)
            evidence.parts[name] = [(ids[mask], rows[mask])]
            evidence.nbytes += ids[mask].nbytes + rows[mask].nbytes
        return new


class Evidence:
    """Evidence rows per name, stored only for the nodes that have them.

    ``add(node_ids, evidence, positions)``: node ``node_ids[k]`` was box
    ``positions[k]`` of the batch.  ``evidence[name]`` is either an array
    with one row per box of the batch, or a pair ``(mask, rows)`` with rows
    only for the boxes where ``mask`` is true.  ``kept(name, ids)``, if given, says which of those
    rows are recorded at all (the others are dropped).
    """

    def __init__(self, kept=None):
        self.parts: dict[str, list] = {}    # name -> [(node ids, rows)]
        self.nbytes = 0                     # bytes held by the parts
        self.kept = kept

    def _append(self, name, ids, rows):
        if self.kept is not None:
            mine = self.kept(name, ids)
            ids, rows = ids[mine], rows[mine]
        self.parts.setdefault(name, []).append((ids, rows))
        self.nbytes += ids.nbytes + rows.nbytes

    def add(self, node_ids, evidence: dict, positions):
        positions = np.asarray(positions, dtype=np.int64)
        for name, value in evidence.items():
            if isinstance(value, tuple):
                mask, rows = np.asarray(value[0], dtype=bool), np.asarray(value[1])
                keep = mask[positions]
                index = np.cumsum(mask) - 1
                self._append(name, node_ids[keep], rows[index[positions[keep]]])
            else:
                self._append(name, np.asarray(node_ids), np.asarray(value)[positions])

    def index(self, name, n_nodes):
        """Per node, its row of evidence ``name`` in the order of the parts (−1: none)."""
        index, first = np.full(n_nodes, -1, dtype=np.int32 if n_nodes < 2 ** 31 else np.int64), 0
        for ids, r in self.parts.get(name, []):
            index[ids] = np.arange(first, first + len(r))
            first += len(r)
        return index

    def finish(self, n_nodes):
        values, rows = {}, {}
        for name in list(self.parts):
            values[name] = np.concatenate([r for _, r in self.parts[name]])
            rows[name] = self.index(name, n_nodes)
            del self.parts[name]                   # freed as we go: evidence is not held twice
        return values, rows


class _Gathered(dict):
    """Evidence arrays concatenated from ``Evidence`` parts on first use."""

    def __init__(self, evidence):
        super().__init__()
        self.parts = evidence.parts

    def __missing__(self, name):
        self[name] = np.concatenate([r for _, r in self.parts[name]])
        return self[name]


class Tree:
    """The search tree as arrays; node ``i`` has ``lo[i]``, ``hi[i]``, ``kind[i]``, ...

    Nodes ``0 .. n_roots - 1`` are the initial boxes.  A ``SPLIT`` node has
    children ``first_child[i]`` (lower part, ``x[dim] <= at``) and
    ``first_child[i] + 1`` (upper part); a ``CONTRACTED`` node has one child
    ``first_child[i]`` whose box is inside its own.  Leaves are ``PROVED``,
    ``EXCLUDED`` or ``UNDECIDED``; their ``reason`` indexes ``reasons``
    (problem rules) or ``UNDECIDED_REASONS`` (negative codes).  Evidence of
    decided and contracted nodes: ``evidence[name][evidence_rows[name][i]]``
    (row -1: node ``i`` has no such evidence).
    """

    def __init__(self, store: Store, n_roots: int, reasons, evidence, evidence_rows, complete_record: bool = True):
        n = store.n
        for name in COLUMNS:
            setattr(self, name, getattr(store, name)[:n])
        self.n_roots = n_roots
        self.complete_record = complete_record   # False: only open, proved and undecided nodes were kept
        self.forgotten = store.forgotten.copy()  # nodes dropped per root (``Store.compact``)
        self._by_root = {}
        self.reasons = tuple(reasons)
        self.evidence = evidence
        self.evidence_rows = evidence_rows
        self.stopped_by = None                   # what stopped the search early (``search._stopped``), if anything
        self.spent = None                        # (``independent``) per root: its own box budget stopped it
        self.pressed = None                      # (``independent``) per root: the memory may have shortened
                                                 # a batch of that root searched alone (``search._pressed``)

    @classmethod
    def view(cls, store: Store, reasons, evidence: Evidence) -> "Tree":
        """The record as it stands (columns shared with ``store``, valid until it changes); an evidence
        array is gathered from the parts only when read (``evidence_values``)."""
        tree = cls(store, len(store.forgotten), reasons, _Gathered(evidence), {})
        tree.evidence_rows = {name: evidence.index(name, store.n) for name in evidence.parts}
        return tree

    def nodes_per_root(self) -> np.ndarray:
        """How many nodes each root's search made (kept or forgotten)."""
        return np.bincount(self.root, minlength=len(self.forgotten)) + self.forgotten

    def __len__(self):
        return len(self.kind)

    def reason_name(self, i: int) -> str:
        r = int(self.reason[i])
        return UNDECIDED_REASONS[r] if r < 0 else self.reasons[r]

    def leaf_mask(self) -> np.ndarray:
        return (self.kind == PROVED) | (self.kind == EXCLUDED) | (self.kind == UNDECIDED)

    def leaves(self, root: int | None = None, kind: int | None = None) -> np.ndarray:
        """Ids of the leaves (of one root, of one kind), in creation order."""
        m = self.leaf_mask() if kind is None else (self.kind == kind)
        if root is not None:
            m &= self.root == root
        return np.nonzero(m)[0]

    def leaves_by_root(self, kind: int) -> tuple[np.ndarray, np.ndarray]:
        """The leaves of one kind grouped by root: (ids, starts), the leaves of root r being
        ``ids[starts[r]:starts[r + 1]]`` in creation order (computed once per kind: reading every
        root's leaves costs one pass over the tree, not one per root)."""
        if kind not in self._by_root:
            ids = np.nonzero(self.kind == kind)[0]
            ids = ids[np.argsort(self.root[ids], kind="stable")]
            self._by_root[kind] = ids, np.searchsorted(self.root[ids], np.arange(self.n_roots + 1))
        return self._by_root[kind]

    def evidence_values(self, name: str, ids) -> np.ndarray:
        """Evidence ``name`` of the nodes ``ids`` (which must all have it)."""
        rows = self.evidence_rows[name][ids]
        if np.any(rows < 0):
            raise KeyError(f"some nodes have no evidence {name!r}")
        return self.evidence[name][rows]
