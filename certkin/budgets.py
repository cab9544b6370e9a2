"""Default budgets of the three searches, shared by the API and the command line.

A budget that runs out gives ``undecided`` (never a guess).  The FK default lets the seed 002
Gough-Stewart full domain finish (~220 k boxes) while staying below 1 GiB of memory.
"""

SINGULARITY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-7)
FORWARD_KINEMATICS = dict(max_boxes=500_000, max_seconds=300.0, min_width=1e-10)
TRAJECTORY = dict(max_boxes=200_000, max_seconds=60.0, min_width=1e-9)
