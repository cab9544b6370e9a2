"""Budgets: how much work a search may do, and every default of the API and the command line.

A budget that runs out gives ``undecided`` (never a guess).  The FK default lets Dietmaier's
40-posture robot finish (~2.5 M boxes); past ``FK_RECORD_NODES`` tree nodes the search forgets
its excluded leaves, so memory stays below 1 GiB.  The
workspace's ``min_width`` is relative to the size of the section (``workspace.paving``).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Budget:
    max_boxes: int = 200_000                # boxes decided (all roots together)
    max_seconds: float = 60.0
    min_width: float = 1e-9                 # scaled width under which a box is not split


SINGULARITY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-7)
LARGEST_FREE_BOX = dict(max_boxes=20_000, max_seconds=10.0, min_width=1e-7)   # each box tried by the bisection on s
FORWARD_KINEMATICS = dict(max_boxes=4_000_000, max_seconds=300.0, min_width=1e-10)
FK_RECORD_NODES = 2_000_000                 # beyond this many tree nodes an FK search keeps only what its answer
                                            # needs (``engine.search`` record_limit): a certificate runs it again
FK_BOXES_PER_INSTANCE = 20_000              # a batch of M instances may decide max(max_boxes, this × M) boxes
TRAJECTORY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-9)
PLAN = dict(max_boxes=50_000, max_seconds=30.0, min_width=1e-9)               # each batch of segments verified
PLAN_SECONDS = 120.0                        # the whole plan
WORKSPACE = dict(max_boxes=1_000_000, max_seconds=60.0, min_width=1e-3)
