"""Trajectories: is a motion feasible for every instant, and a path whose every segment is.

- ``path``: a polyline of poses (exact texts and enclosures);
- ``pose``: the leg vectors (and R) along a path, and the vector algebra on them;
- ``families``: the constraints, one module per family behind one protocol (leg lengths, joints,
  interference, singularity), and ``constraints``: the selection of a robot's families;
- ``evaluate``: enclosures of the families' functions over t-intervals (mean-value forms,
  Bernstein bounds); ``crossings``: where to cut an interval (a heuristic);
- ``verify``: ``verify_trajectory``/``verify_trajectories`` (the engine over t), with the verdict
  in ``result``; ``plan``: a path whose every segment is certified feasible.
"""
from .constraints import Constraints
from .path import Path, parse_path
from .plan import PlanResult, plan
from .result import TrajectoryResult
from .verify import TrajectoryProblem, verify_trajectories, verify_trajectory

__all__ = ["verify_trajectory", "verify_trajectories", "plan", "parse_path", "Path", "Constraints",
           "TrajectoryProblem", "TrajectoryResult", "PlanResult"]
