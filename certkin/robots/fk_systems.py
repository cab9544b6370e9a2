"""Forward-kinematics equation systems, one per robot kind.

Each system has unknowns that keep the equations quadratic and cover every
real posture (see ``docs/soundness.md``, forward kinematics):

- planar 3-RPR: (x, y, c, s) with c = cos phi, s = sin phi:
  |(x, y) + [[c, −s], [s, c]] p_i − b_i|² − ρ_i² = 0 (i = 1..3) and
  c² + s² − 1 = 0.  (c, s) ranges over the whole unit circle, so every
  real posture is a solution, and phi = atan2(s, c).

The equations are compiled once per kind with the geometry and the squared
leg lengths as parameters, so a batch of instances is one evaluation.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from intervals import Interval, atan2, sqrt, sqr
from intervals.compiler import compile_exprs

from ..errors import InputError


class PlanarFK:
    unknowns = ("x", "y", "c", "s")

    def __init__(self, robot):
        self.robot = robot
        self.equations = _planar_compiled()
        self.user_phi = None

    def domain(self, robot, rows, user=None):
        """Boxes of unknowns holding every real posture of each instance (M, 4)."""
        b = [robot.parameters[2 * i:2 * i + 2] for i in range(3)]
        p = [robot.parameters[6 + 2 * i:6 + 2 * i + 2] for i in range(3)]
        lo, hi = [], []
        for row in rows:
            xl, xh, yl, yh = -np.inf, np.inf, -np.inf, np.inf
            for i in range(3):
                reach = row[i] + sqrt(sqr(p[i][0]) + sqr(p[i][1]))  # |t - b_i| <= rho_i + |p_i|
                xl = max(xl, float((b[i][0] - reach).lo))
                xh = min(xh, float((b[i][0] + reach).hi))
                yl = max(yl, float((b[i][1] - reach).lo))
                yh = min(yh, float((b[i][1] + reach).hi))
            if xl > xh or yl > yh:  # the disks do not meet: no posture; keep a valid empty-ish box
                xl, xh, yl, yh = xl, max(xl, xh), yl, max(yl, yh)
            lo.append([xl, yl, -1.0, -1.0])
            hi.append([xh, yh, 1.0, 1.0])
        lo, hi = np.array(lo), np.array(hi)
        if user is not None:
            lo, hi = self._apply_user_domain(lo, hi, user)
        return lo, hi

    def _apply_user_domain(self, lo, hi, user):
        from ..poses import parse_box
        box, _ = parse_box(user, self.robot, "--domain")
        lo[:, 0] = np.maximum(lo[:, 0], box.lo[0])
        hi[:, 0] = np.minimum(hi[:, 0], box.hi[0])
        lo[:, 1] = np.maximum(lo[:, 1], box.lo[1])
        hi[:, 1] = np.minimum(hi[:, 1], box.hi[1])
        if np.any(lo[:, :2] > hi[:, :2]):
            raise InputError("--domain", "x", "the domain misses every reachable position")
        self.user_phi = (float(box.lo[2]), float(box.hi[2]))
        return lo, hi

    def in_user_domain(self, R) -> bool:
        if self.user_phi is None:
            return True
        phi = atan2(R[3], R[2])
        return bool(phi.lo >= self.user_phi[0] and phi.hi <= self.user_phi[1])

    def pose(self, R):
        return {"x": R[0], "y": R[1], "phi": atan2(R[3], R[2])}

    def points(self, robot, R, P):
        x, y, c, s = R[0], R[1], R[2], R[3]
        out = []
        for i in range(3):
            px, py = robot.parameters[6 + 2 * i], robot.parameters[7 + 2 * i]
            out.append([x + c * px - s * py, y + s * px + c * py])
        return out


@lru_cache(maxsize=None)
def _planar_compiled():
    x, y, c, s = sp.symbols("x y c s", real=True)
    g = sp.symbols("b1x b1y b2x b2y b3x b3y p1x p1y p2x p2y p3x p3y", real=True)
    L = sp.symbols("L1 L2 L3", real=True)
    eqs = []
    for i in range(3):
        bx, by, px, py = g[2 * i], g[2 * i + 1], g[6 + 2 * i], g[7 + 2 * i]
        eqs.append((x + c * px - s * py - bx) ** 2 + (y + s * px + c * py - by) ** 2 - L[i])
    eqs.append(c ** 2 + s ** 2 - 1)
    return compile_exprs(eqs, [x, y, c, s], list(g) + list(L))


def fk_system(robot):
    if robot.kind == "planar-3rpr":
        return PlanarFK(robot)
    raise InputError("fk", "kind", f"forward kinematics of {robot.kind} robots is not available yet")
