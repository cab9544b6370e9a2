"""``leg-length``: ρ_min ≤ ρ_i ≤ ρ_max; margin min(ρ_i − ρ_min, ρ_max − ρ_i) (length unit).

ρ_i² is convex along a straight segment (seed 000 digest, E4), so ρ can have an interior
minimum: the margin is bounded over the whole interval, not at its ends.
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, sqr

from ..crossings import derivative, midpoint
from ..pose import LENGTHS, enclose_all
from .base import Family, Instance, states


class LegLengths(Family):
    constraint = "leg-length"
    uses_lengths = True

    def __init__(self, robot):
        limits = robot.limits["leg_length"]
        self.rho_min = enclose_all([Interval(a) for a, _ in limits])
        self.rho_max = enclose_all([Interval(b) for _, b in limits])
        self.instances = [Instance("leg-length", (i + 1,)) for i in range(robot.n_legs)]

    @staticmethod
    def missing(robot):
        return None if "leg_length" in robot.limits else "no [limits] leg_length in the robot file"

    def margins(self, path, rho, upper):
        a = rho - self.rho_min
        b = self.rho_max - rho
        lo, hi = np.minimum(a.lo, b.lo), np.minimum(a.hi, b.hi)
        return lo, hi, states(lo, hi)

    def crossings(self, polys, put):
        sq = polys[LENGTHS][0]                                       # (S, n), one column per leg
        put(self.columns, 0, sq - sqr(self.rho_min))
        put(self.columns, 1, -sq + sqr(self.rho_max))
        put(self.columns, 2, derivative(midpoint(sq)))
