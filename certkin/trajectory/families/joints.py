"""``joints``: each leg's direction inside its passive joints' pyramids or cones.

Base joints use u = B_i − A_i in the base frame, platform joints u = Rᵀ(A_i − B_i) in the platform
frame; the leg is inside a pyramid when n·u ≥ 0 for every facet normal n, inside a cone when
angle(u, axis) ≤ half-angle.  Margin n̂·û (facet) or cos(angle(u, axis)) − cos(half-angle) (cone),
dimensionless (seed 000 §1.3).
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, cos, sqr, sqrt

from ...errors import InputError
from ...robots.poses import parse_number
from ..pose import PathPose, broadcast, columns, dot, enclose_all
from .base import SATISFIED, UNKNOWN, VIOLATED, Family, Instance, cached, states


class Joints(Family):
    constraint = "joints"
    key = "joints"
    uses_lengths = True

    def __init__(self, robot):
        self.facets = cached(robot, "joints", lambda: joint_data(robot))
        self.instances = [f["instance"] for f in self.facets]

    @staticmethod
    def missing(robot):
        limits = robot.limits
        if "base_joints" in limits or "platform_joints" in limits:
            return None
        return "no [limits] base_joints or platform_joints in the robot file"

    @staticmethod
    def partial(robot):
        for side, other in (("base", "platform"), ("platform", "base")):
            if f"{side}_joints" in robot.limits and f"{other}_joints" not in robot.limits:
                return f"the {other} joints: no [limits] {other}_joints in the robot file"
        return None

    def functions(self, pose: PathPose):
        """Per facet n·u (base) or −(R n)·l (platform); per cone a·u and (a·u)² − |a|²cos²α |u|²."""
        out = []
        L = [pose.legs[k] for k in range(3)]
        for f in self.facets:
            leg = f["leg"]
            l = [columns(L[k], [leg]) for k in range(3)]
            vec = f["vector"]                      # 3 Intervals of shape (1,)
            if f["side"] == "platform":
                vec = pose.rotate(vec)
                g = -dot(vec, l)
            else:
                g = dot([broadcast(v, l[0]) for v in vec], l)
            out.append(g)
            if f["kind"] == "cone":
                out.append(g * g - f["c2"] * dot(l, l))
        return out

    def margins(self, path, rho, upper):
        glo, ghi = path.range(self.key, self.functions)
        return self._margins(rho, glo, ghi)

    def _margins(self, rho, glo, ghi):
        """Margins n̂·û (facets) or cos(angle(u, axis)) − cos α (cones) and the states."""
        los, his, sts = [], [], []
        col = 0
        for f in self.facets:
            r = rho[:, f["leg"]]
            g = Interval.from_bounds(glo[:, col], ghi[:, col])
            if f["kind"] == "facet":
                m = g / (f["norm"] * r)
                st = states(g.lo, g.hi)
                col += 1
            else:
                h = Interval.from_bounds(glo[:, col + 1], ghi[:, col + 1])
                m = g / (f["norm"] * r) - f["cos"]
                ok = (g.lo >= 0) & (h.lo >= 0)
                bad = (g.hi < 0) | (h.hi < 0)
                st = np.where(ok, SATISFIED, np.where(bad, VIOLATED, UNKNOWN))
                col += 2
            los.append(np.where(np.isnan(m.lo), -np.inf, m.lo))
            his.append(np.where(np.isnan(m.hi), np.inf, m.hi))
            sts.append(st)
        return np.stack(los, 1), np.stack(his, 1), np.stack(sts, 1).astype(np.int8)

    def crossings(self, polys, put):
        fns, k = polys[self.key], 0
        for col, f in zip(range(self.columns.start, self.columns.stop), self.facets):
            put(col, 0, fns[k][:, 0])
            if f["kind"] == "cone":
                put(col, 1, fns[k + 1][:, 0])
            k += 1 if f["kind"] == "facet" else 2


def joint_data(robot):
    """The facets and cones of the joint limits, enclosed from their exact decimals."""
    out = []
    for side in ("base_joints", "platform_joints"):
        for i, table in enumerate(robot.limits.get(side, [])):
            field = f"limits.{side}[{i}]"
            where = side[:-7]
            if where == "platform" and "R" not in robot.model_parts():
                raise InputError(robot.source, field, f"platform joint limits are not modelled for {robot.kind} robots")
            for k, normal in enumerate(table.get("normals", [])):
                vec = [parse_number(c, robot.source, f"{field}.normals[{k}]")[0] for c in normal]
                norm = sqrt(sqr(vec[0]) + sqr(vec[1]) + sqr(vec[2]))
                out.append({"instance": Instance("joints", (i + 1,), f"{where} facet {k + 1}"), "leg": i,
                            "side": where, "kind": "facet", "vector": [enclose_all([v]) for v in vec], "norm": norm})
            if "axis" in table:
                axis = [parse_number(c, robot.source, field + ".axis")[0] for c in table["axis"]]
                alpha = parse_number(table["half_angle"], robot.source, field + ".half_angle", angle=True)[0]
                ca = cos(alpha)
                if ca.lo < 0:
                    raise InputError(robot.source, field + ".half_angle", "cones wider than 90deg are not supported")
                a2 = sqr(axis[0]) + sqr(axis[1]) + sqr(axis[2])
                out.append({"instance": Instance("joints", (i + 1,), f"{where} cone"), "leg": i, "side": where,
                            "kind": "cone", "vector": [enclose_all([v]) for v in axis], "norm": sqrt(a2),
                            "cos": ca, "c2": a2 * sqr(ca)})
    return out
