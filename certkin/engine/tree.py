"""The record of a branch-and-bound search: nodes, their boxes, kinds, reasons and evidence.

``Store`` holds the growing columns while the search runs, ``Evidence`` the evidence rows of the
nodes that have some; ``Tree`` is the finished record that results and certificates read: every
box of the domain ends in exactly one leaf (``PROVED``, ``EXCLUDED`` or ``UNDECIDED``), and
``Tree.nested`` gives the subtree of a root as nested dicts.
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

    def __init__(self, d: int, capacity: int = 1024):
        self.n = 0
        self.lo = np.empty((capacity, d))
        self.hi = np.empty((capacity, d))
        self.root = np.empty(capacity, dtype=np.int32)
        self.parent = np.empty(capacity, dtype=np.int32)
        self.kind = np.empty(capacity, dtype=np.int8)
        self.reason = np.empty(capacity, dtype=np.int8)
        self.split_dim = np.empty(capacity, dtype=np.int8)
        self.split_at = np.empty(capacity)
        self.first_child = np.empty(capacity, dtype=np.int32)

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


class Evidence:
    """Evidence rows per name, stored only for the nodes that have them.

    ``add(node_ids, evidence, positions)``: node ``node_ids[k]`` was box
    ``positions[k]`` of the batch.  ``evidence[name]`` is either an array
    with one row per box of the batch, or a pair ``(mask, rows)`` with rows
    only for the boxes where ``mask`` is true.
    """

    def __init__(self):
        self.parts: dict[str, list] = {}    # name -> [(node ids, rows)]

    def add(self, node_ids, evidence: dict, positions):
        positions = np.asarray(positions, dtype=np.int64)
        for name, value in evidence.items():
            if isinstance(value, tuple):
                mask, rows = np.asarray(value[0], dtype=bool), np.asarray(value[1])
                keep = mask[positions]
                index = np.cumsum(mask) - 1
                self.parts.setdefault(name, []).append((node_ids[keep], rows[index[positions[keep]]]))
            else:
                self.parts.setdefault(name, []).append((node_ids, np.asarray(value)[positions]))

    def finish(self, n_nodes):
        values, rows = {}, {}
        for name in list(self.parts):
            parts = self.parts.pop(name)           # freed as we go: evidence is not held twice
            values[name] = np.concatenate([r for _, r in parts])
            index = np.full(n_nodes, -1, dtype=np.int32 if len(values[name]) < 2 ** 31 else np.int64)
            first = 0
            for ids, r in parts:
                index[ids] = np.arange(first, first + len(r))
                first += len(r)
            rows[name] = index
        return values, rows


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

    def __init__(self, store: Store, n_roots: int, reasons, evidence, evidence_rows):
        n = store.n
        for name in COLUMNS:
            setattr(self, name, getattr(store, name)[:n])
        self.n_roots = n_roots
        self.reasons = tuple(reasons)
        self.evidence = evidence
        self.evidence_rows = evidence_rows

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

    def evidence_of(self, i: int, keys=None) -> dict:
        """The evidence of a node as plain Python values (``keys``: a subset of the names)."""
        out = {}
        for name, index in self.evidence_rows.items():
            if (keys is None or name in keys) and index[i] >= 0:
                out[name] = self.evidence[name][index[i]].tolist()
        return out

    def evidence_values(self, name: str, ids) -> np.ndarray:
        """Evidence ``name`` of the nodes ``ids`` (which must all have it)."""
        rows = self.evidence_rows[name][ids]
        if np.any(rows < 0):
            raise KeyError(f"some nodes have no evidence {name!r}")
        return self.evidence[name][rows]

    def nested(self, i: int, leaf, contraction=None) -> dict:
        """The subtree at node ``i`` as nested dicts (for certificates).

        Splits become ``{"split": [dim, at], "children": [lower, upper]}``,
        leaves ``leaf(id)``, contractions ``contraction(id)`` updated with
        ``{"child": ...}``.  Iterative: deep trees do not hit the recursion limit.
        """
        out: dict = {}
        stack = [(i, out)]
        while stack:
            j, slot = stack.pop()
            k = self.kind[j]
            if k == SPLIT:
                a, b = {}, {}
                slot.update({"split": [int(self.split_dim[j]), float(self.split_at[j])], "children": [a, b]})
                c = int(self.first_child[j])
                stack.append((c + 1, b))
                stack.append((c, a))
            elif k == CONTRACTED:
                child: dict = {}
                slot.update(contraction(j))
                slot["child"] = child
                stack.append((int(self.first_child[j]), child))
            else:
                slot.update(leaf(j))
        return out
