"""Planar 3-RPR robot (seed 003 §3, Gosselin & Angeles 1990).

Pose (x, y, phi): B_i(world) = t + Q(phi) p'_i with t = (x, y) (the "+"
convention: the digest shows the N_j of seed 003 Annex B need it).
A ṫ + B ρ̇ = 0 with twist ṫ = (φ̇, ẋ, ẏ) (the thesis column order, which
fixes the sign of det A):

    row i of A = [ u_iᵀ E q_i , u_iᵀ ],   u_i = t + q_i − b_i,  q_i = Q p'_i
    B = −diag(ρ_i)

and u_iᵀ E q_i simplifies to (y − b_iy) q_ix − (x − b_ix) q_iy (the q_ix q_iy
terms cancel), which keeps interval enclosures tight.
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from .base import Robot, det3


class Planar3RPR(Robot):
    kind = "planar-3rpr"
    n_legs = 3
    dim = 2
    pose_names = ("x", "y", "phi")
    angle_names = frozenset({"phi"})

    @classmethod
    @lru_cache(maxsize=None)
    def symbols(cls):
        pose = sp.symbols("x y phi", real=True)
        geom = sp.symbols("b1x b1y b2x b2y b3x b3y p1x p1y p2x p2y p3x p3y", real=True)
        return pose, geom

    @classmethod
    @lru_cache(maxsize=None)
    def symbolic_model(cls):
        (x, y, phi), g = cls.symbols()
        b = [(g[0], g[1]), (g[2], g[3]), (g[4], g[5])]
        p = [(g[6], g[7]), (g[8], g[9]), (g[10], g[11])]
        c, s = sp.cos(phi), sp.sin(phi)
        rows, legs, points = [], [], []
        for (bx, by), (px, py) in zip(b, p):
            qx, qy = c * px - s * py, s * px + c * py
            ux, uy = x + qx - bx, y + qy - by
            legs.append((ux, uy))
            points.append((x + qx, y + qy))
            rows.append([(y - by) * qx - (x - bx) * qy, ux, uy])
        A = sp.Matrix(rows)
        rho = [sp.sqrt(ux ** 2 + uy ** 2) for ux, uy in legs]
        return {"legs": legs, "points": points, "A": A, "B": -sp.diag(*rho), "det": det3(A)}
