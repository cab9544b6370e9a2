"""The generic branch-and-bound engine shared by every solver.

A *problem* decides batches of boxes; the engine owns the frontier, the
bisection, the budgets and the record of the search tree:

    class Problem:
        def decide(self, lo, hi, roots) -> Decisions
            # lo, hi: float arrays (N, d); roots: (N,) index of the initial box of each

``Decisions`` gives, per box, a status (``PROVED``, ``EXCLUDED`` or
``OPEN``), a reason string and a JSON-able evidence dict for the decided
boxes, and optionally contracted boxes for the open ones.  Open boxes are
bisected (widest side scaled by ``scale``, split off-centre at ``SPLIT`` so
that symmetric roots do not land on faces) until they are decided, narrower
than ``min_width``, or a budget (boxes, seconds) runs out.  Nothing is
dropped: every box of the domain ends in exactly one leaf of the returned
tree, with status ``proved``, ``excluded`` or ``undecided`` (and why).

The frontier is processed depth-first in batches (the last ``batch`` boxes
first), so memory stays bounded by about ``batch * depth`` boxes.  Results
are deterministic: no randomness, and the order of work depends only on the
input.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import time

import numpy as np

OPEN, PROVED, EXCLUDED = 0, 1, 2
SPLIT = 0.4921875  # off-centre bisection ratio (exact in binary)


@dataclass
class Decisions:
    """What a problem says about a batch of N boxes."""

    status: np.ndarray                      # (N,) int: OPEN | PROVED | EXCLUDED
    reason: list                            # (N,) str, for decided boxes
    evidence: list                          # (N,) dict or None, for decided boxes
    contracted: tuple | None = None         # optional (lo, hi) replacing the open boxes
    finished: tuple = ()                    # initial boxes (roots) whose answer is known: stop them


@dataclass
class Budget:
    max_boxes: int = 200_000                # boxes processed
    max_seconds: float = 60.0
    min_width: float = 1e-9                 # scaled width under which a box is not split


@dataclass
class Node:
    """A node of the search tree: a leaf, or a split into two children."""

    lo: np.ndarray
    hi: np.ndarray
    status: str = "undecided"               # proved | excluded | undecided | split
    reason: str = ""
    evidence: dict | None = None
    root: int = 0
    split_dim: int = -1
    split_at: float = 0.0
    children: list = field(default_factory=list)
    contracted_from: tuple | None = None    # (lo, hi) before a contraction, if any

    def leaves(self):
        stack = [self]
        while stack:
            n = stack.pop()
            if n.children:
                stack.extend(reversed(n.children))
            else:
                yield n


@dataclass
class SearchResult:
    roots: list                             # one Node per initial box
    boxes: int
    seconds: float
    exhausted: bool                         # a budget ran out

    def leaves(self):
        for r in self.roots:
            yield from r.leaves()


def choose_split(lo, hi, scale):
    """Per box, the dimension with the widest scaled side."""
    w = (hi - lo) / scale
    return np.argmax(w, axis=1), np.max(w, axis=1)


def search(problem, lo, hi, scale=None, budget: Budget | None = None, batch: int = 1024,
           progress=None) -> SearchResult:
    """Branch and bound from the boxes ``[lo, hi]`` (arrays (M, d)).

    ``progress(processed_boxes, frontier_size)`` is called after each batch.
    """
    budget = budget or Budget()
    lo = np.atleast_2d(np.asarray(lo, dtype=np.float64))
    hi = np.atleast_2d(np.asarray(hi, dtype=np.float64))
    if scale is None:
        scale = np.where(hi[0] > lo[0], hi[0] - lo[0], 1.0)
    scale = np.asarray(scale, dtype=np.float64)
    roots = [Node(lo[i].copy(), hi[i].copy(), root=i) for i in range(len(lo))]
    finished = set()
    frontier = list(reversed(roots))  # a stack: the last entries are processed first
    processed = 0
    t0 = time.perf_counter()
    exhausted = False
    while frontier:
        if processed >= budget.max_boxes or time.perf_counter() - t0 > budget.max_seconds:
            exhausted = True
            break
        take = frontier[-batch:]
        del frontier[-batch:]
        take.reverse()
        blo = np.stack([n.lo for n in take])
        bhi = np.stack([n.hi for n in take])
        dec = problem.decide(blo, bhi, np.array([n.root for n in take]))
        processed += len(take)
        open_idx = []
        for k, node in enumerate(take):
            s = dec.status[k]
            if s == PROVED or s == EXCLUDED:
                node.status = "proved" if s == PROVED else "excluded"
                node.reason = dec.reason[k]
                node.evidence = dec.evidence[k]
            else:
                open_idx.append(k)
        if len(dec.finished):
            finished.update(int(r) for r in dec.finished)
            for k in list(open_idx):
                if take[k].root in finished:
                    take[k].status = "undecided"
                    take[k].reason = "not needed: the answer for this box was found"
                    open_idx.remove(k)
            keep = []
            for node in frontier:
                if node.root in finished:
                    node.status = "undecided"
                    node.reason = "not needed: the answer for this box was found"
                else:
                    keep.append(node)
            frontier = keep
        if not open_idx:
            if progress:
                progress(processed, len(frontier))
            continue
        idx = np.array(open_idx)
        olo, ohi = blo[idx], bhi[idx]
        if dec.contracted is not None:
            clo, chi = dec.contracted
            clo, chi = clo[idx], chi[idx]
            for j, k in enumerate(open_idx):
                if np.any(clo[j] != olo[j]) or np.any(chi[j] != ohi[j]):
                    node = take[k]
                    child = Node(clo[j].copy(), chi[j].copy(), root=node.root)
                    node.status = "contracted"
                    node.contracted_from = (node.lo, node.hi)
                    node.children = [child]
                    take[k] = child
            olo, ohi = clo, chi
        dims, widths = choose_split(olo, ohi, scale)
        new = []
        for j, k in enumerate(open_idx):
            node = take[k]
            if widths[j] <= budget.min_width:
                node.status = "undecided"
                node.reason = node.reason or "resolution: box narrower than min_width"
                continue
            d = int(dims[j])
            at = olo[j, d] + SPLIT * (ohi[j, d] - olo[j, d])
            if not (olo[j, d] < at < ohi[j, d]):  # too narrow to split in floating point
                node.status = "undecided"
                node.reason = "resolution: box cannot be split further"
                continue
            left_hi = ohi[j].copy()
            left_hi[d] = at
            right_lo = olo[j].copy()
            right_lo[d] = at
            node.status = "split"
            node.split_dim, node.split_at = d, float(at)
            node.children = [Node(olo[j].copy(), left_hi, root=node.root),
                             Node(right_lo, ohi[j].copy(), root=node.root)]
            new.extend(node.children)
        frontier.extend(reversed(new))
        if progress:
            progress(processed, len(frontier))
    for node in frontier:
        node.status = "undecided"
        node.reason = "budget: boxes or time exhausted"
    return SearchResult(roots, processed, time.perf_counter() - t0, exhausted)
