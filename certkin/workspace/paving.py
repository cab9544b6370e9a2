"""The paving of a section (or of z-slabs) by the shared engine, and its area bracket.

A box is *inside* when for every leg the interval of ρ_i² over the box — the exact range up to
rounding, every variable occurring once under ``sqr`` — lies in [ρmin², ρmax²]; *outside* when it
is disjoint from it for one leg; otherwise it is bisected down to ``min_width`` (relative to the
set) and left as a *boundary* box.  area(inside) ≤ area(section) ≤ area(inside ∪ boundary),
whatever the budget.  Each root of one search is one section or one z-slab.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from itertools import chain
import math
import time

import numpy as np

from intervals import Interval, sqr
from intervals.rounding import down, down_sum, up, up_sum

from ..engine import EXCLUDED, OPEN, PROVED, UNDECIDED, Decisions, search
from .annuli import Legs

AREA_CHUNK = 1 << 18     # boxes whose areas are computed at once
SCALE_SHARE = 0.25       # of the time, at most, for the first search (the scale only): once all of it, leaving
                         # the answer's search nothing when a large box budget let the first one run on
SEARCH_SHARE = 0.6       # of the time left and of the memory budget, for the paving's search: the rest is for
                         # its answer (areas, the certificate's tree, the JSON document), which grows with the boxes

REASONS = ("inside: every leg length within its limits on the whole box",
           "outside: one leg length outside its limits on the whole box")


SLACK = 2.0 ** -48      # relative margin of a decided box's ρ² from the leg-length limits (``decide``)


class PavingProblem:
    """Decides batches of (X, Y) boxes; root k carries the z-interval Z[k]."""

    reasons = REASONS

    def __init__(self, legs: Legs, Z: Interval):
        self.legs = legs
        self.h2 = legs.h2(Z)                                   # (m, n)

    def rho2(self, lo, hi, roots) -> Interval:
        """Exact range (up to rounding) of ρ_i² over each box: (N, n)."""
        L = self.legs
        X = Interval.from_bounds(lo[:, 0:1], hi[:, 0:1])
        Y = Interval.from_bounds(lo[:, 1:2], hi[:, 1:2])
        return sqr(X - L.ux) + sqr(Y - L.uy) + self.h2[roots]

    def decide(self, lo, hi, roots):
        """Inside when every leg's ρ² is within its limits, outside when one leg's is beyond them, each
        by ``SLACK`` of the limit: a box decided by the last bits of ρ² (one 1e-15 wide at a tangency)
        stays open, since the checker's own enclosure may reach the limit there."""
        L = self.legs
        d2 = self.rho2(lo, hi, roots)
        smin, smax = np.abs(L.rmin2.lo) * SLACK, np.abs(L.rmax2.hi) * SLACK
        inside = ((d2.lo >= L.rmin2.hi + smin) & (d2.hi <= L.rmax2.lo - smax)).all(axis=1)
        out = (d2.hi < L.rmin2.lo - smin) | (d2.lo > L.rmax2.hi + smax)
        excluded = out.any(axis=1) & ~inside
        leg = np.argmax(out, axis=1)
        status = np.where(inside, PROVED, np.where(excluded, EXCLUDED, OPEN)).astype(np.int8)
        reason = np.where(inside, 0, 1)
        return Decisions(status=status, reason=reason, evidence={"leg": (excluded, leg[excluded])})


@dataclass
class Paving:
    """The leaves of one root of the search: boxes (lo, hi) and kind, with the excluding leg."""

    tree: object
    root: int
    _areas: dict = field(default_factory=dict, repr=False, compare=False)   # computed once

    def leaves(self, kind):
        ids, starts = self.tree.leaves_by_root(kind)
        return ids[starts[self.root]:starts[self.root + 1]]

    def counts(self) -> dict:
        return {"inner_boxes": int(len(self.leaves(PROVED))), "boundary_boxes": int(len(self.leaves(UNDECIDED))),
                "outside_boxes": int(len(self.leaves(EXCLUDED)))}

    def _bounds(self, ids, upper: bool):
        """The areas of the boxes ``ids``, each rounded down (or up), ``AREA_CHUNK`` boxes at a time: a paving
        of millions of boxes needs no temporary arrays of its size."""
        t = self.tree
        for k in range(0, len(ids), AREA_CHUNK):
            w = t.hi[ids[k:k + AREA_CHUNK]] - t.lo[ids[k:k + AREA_CHUNK]]
            if upper:
                w = up_sum(w)
                yield up(w[:, 0] * w[:, 1])
            else:
                w = down_sum(w)
                yield np.maximum(down(w[:, 0] * w[:, 1]), 0.0)

    def inner_area(self) -> float:
        """A lower bound of the area of the inside boxes (rounded down; ``math.fsum`` is exact until its
        one rounding)."""
        if "inner" not in self._areas:
            total = math.fsum(chain.from_iterable(self._bounds(self.leaves(PROVED), False)))
            self._areas["inner"] = float(np.nextafter(total, -np.inf)) if total > 0 else 0.0
        return self._areas["inner"]

    def outer_area(self) -> float:
        """An upper bound of the area of the inside and boundary boxes (rounded up)."""
        if "outer" not in self._areas:
            ids = np.concatenate([self.leaves(PROVED), self.leaves(UNDECIDED)])
            total = math.fsum(chain.from_iterable(self._bounds(ids, True)))
            self._areas["outer"] = float(np.nextafter(total, np.inf)) if len(ids) else 0.0
        return self._areas["outer"]

    def boxes(self, kind) -> tuple[np.ndarray, np.ndarray]:
        ids = self.leaves(kind)
        return self.tree.lo[ids], self.tree.hi[ids]


def pave(legs, Z, lo, hi, budget, progress, floor=0.0):
    """Pave the domains [lo, hi] (k, 2) with z-intervals Z (k,) in one search.

    ``budget.min_width`` is relative to the extent of the set, not of the
    domain (the outer disks' box can be far larger than a section bounded by
    inner circles): a first search at resolution 1/64 gives the hull of the
    boxes not proved outside, whose widths become the scale.  The scale only
    decides when to stop splitting; the tree of the second search, rooted at
    the domain, is the answer.  ``floor``: an absolute side below which
    splitting is pointless (for z-slabs, how far the boundary moves across
    the slab).
    """
    problem = PavingProblem(legs, Z)
    width = np.max(hi - lo, axis=0)
    scale = np.where(width > 0, width, 1.0)
    t0 = time.perf_counter()
    first = search(problem, lo, hi, scale=scale, budget=replace(budget.within(SCALE_SHARE * budget.max_seconds),
                                                                 min_width=1.0 / 64))
    t = first.tree
    live = t.leaf_mask() & (t.kind != EXCLUDED)
    if live.any() and not first.exhausted:
        hull = np.max(t.hi[live], axis=0) - np.min(t.lo[live], axis=0)
        scale = np.where(hull > 0, np.minimum(hull, scale), scale)
    left = budget.max_seconds - (time.perf_counter() - t0)
    min_width = max(budget.min_width, min(float(np.max(floor / scale)), 1.0 / 64))
    budget = replace(budget.within(SEARCH_SHARE * left), min_width=min_width,
                     max_memory=int(SEARCH_SHARE * budget.max_memory))
    return search(problem, lo, hi, scale=scale, budget=budget, progress=progress)
