"""Budgets: how much work a search may do, and every default of the API and the command line.

A budget that runs out gives ``undecided`` (never a guess).  The FK default lets the seed 002
Gough-Stewart full domain finish (~220 k boxes) while staying below 1 GiB of memory.  The
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
FORWARD_KINEMATICS = dict(max_boxes=500_000, max_seconds=300.0, min_width=1e-10)
FK_BOXES_PER_INSTANCE = 20_000              # a batch of M instances may decide max(max_boxes, this × M) boxes
TRAJECTORY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-9)
PLAN = dict(max_boxes=50_000, max_seconds=30.0, min_width=1e-9)               # each batch of segments verified
PLAN_SECONDS = 120.0                        # the whole plan
WORKSPACE = dict(max_boxes=1_000_000, max_seconds=60.0, min_width=1e-3)
