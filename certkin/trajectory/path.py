"""A path: a polyline of poses P_0 … P_n, exact texts and their enclosures.

On segment k the pose is P_k + t (P_{k+1} − P_k), t ∈ [0, 1]: a straight line in position and a
linear interpolation of the pose angles (seed 000 eq. 1.82–1.83; constant orientation when the
angles are equal).  The global parameter is s = k + t.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervals import Interval

from ..errors import InputError
from ..robots.poses import parse_pose, unmasked


@dataclass
class Path:
    """A polyline of poses (exact texts and their enclosures)."""

    texts: list
    poses: Interval                      # (n + 1, d)

    @property
    def segments(self) -> int:
        return self.poses.shape[0] - 1

    def start_and_step(self):
        """Per segment, P_k and P_{k+1} − P_k; a coordinate whose exact text is the same at
        both ends has a step of exactly 0 (so constant angles give the constant-orientation path)."""
        P0 = self.poses[:-1]
        D = self.poses[1:] - self.poses[:-1]
        same = np.array([[a == b for a, b in zip(p, q)] for p, q in zip(self.texts[:-1], self.texts[1:])])
        if same.any():
            D = Interval.from_bounds(np.where(same, 0.0, D.lo), np.where(same, 0.0, D.hi))
        return P0, D


def angle_step(robot, D: Interval) -> float:
    """The largest change of a pose angle along one segment (radians; 0 without angles)."""
    cols = [k for k, name in enumerate(robot.pose_names) if name in robot.angle_names]
    if not cols:
        return 0.0
    return float(np.max(np.maximum(np.abs(D.lo[:, cols]), np.abs(D.hi[:, cols]))))


def parse_path(robot, start, goal, waypoints=()) -> Path:
    """``start``, ``goal`` and optional ``waypoints`` (pose texts or sequences) -> ``Path``."""
    if isinstance(waypoints, (str, dict)):         # one pose, not a list of them (a text was read letter by letter)
        raise InputError("waypoints", "", "expected a list of poses: give [pose] for one")
    waypoints = unmasked(waypoints, "waypoints")
    try:                                           # (a 2-D array has no truth value: never ``waypoints or ()``)
        waypoints = [] if waypoints is None else list(waypoints)
    except TypeError:
        raise InputError("waypoints", "", f"expected a list of poses, got {type(waypoints).__name__}") from None
    items = [("start", start)] + [(f"waypoints[{k}]", w) for k, w in enumerate(waypoints)] + [("goal", goal)]
    ivs, texts = [], []
    for parameter, pose in items:
        iv, t = parse_pose(pose, robot, parameter)
        ivs.append(iv)
        texts.append(t)
    lo = np.stack([i.lo for i in ivs])
    hi = np.stack([i.hi for i in ivs])
    return Path(texts, Interval.from_bounds(lo, hi))
