"""Gough-Stewart platform, 6 legs (seeds 000, 002, 004).

Pose (x, y, z, psi, theta, phi): C = (x, y, z) is the platform frame origin
and R = Rz(psi) Rx(theta) Rz(phi) (seed 000: psi about z, theta about the new
x, phi about the new z).  Leg i: l_i = C + R b_i − a_i.  With
ρ_i ρ̇_i = l_i·(Ċ + ω × R b_i), A (Ċ, ω) + B ρ̇ = 0 gives

    row i of A = [ l_iᵀ , ((R b_i) × l_i)ᵀ ],   B = −diag(ρ_i)

(the Plücker lines of the legs scaled by ρ_i > 0, so the sign of det A is
that of the unit-line determinant).  6-3 and 3-3 designs are the same model
with coincident joints.  det A is enclosed from the compiled entries of A by
``intervals.linalg.det``.
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from .base import Robot
from .spherical import rot_x, rot_z


class GoughStewart(Robot):
    kind = "gough-stewart"
    n_legs = 6
    dim = 3
    pose_names = ("x", "y", "z", "psi", "theta", "phi")
    angle_names = frozenset({"psi", "theta", "phi"})

    @classmethod
    @lru_cache(maxsize=None)
    def symbols(cls):
        pose = sp.symbols("x y z psi theta phi", real=True)
        geom = sp.symbols(" ".join(f"a{i}{c}" for i in range(1, 7) for c in "xyz") + " "
                          + " ".join(f"b{i}{c}" for i in range(1, 7) for c in "xyz"), real=True)
        return pose, geom

    @classmethod
    @lru_cache(maxsize=None)
    def symbolic_model(cls):
        (x, y, z, psi, theta, phi), g = cls.symbols()
        R = rot_z(psi) * rot_x(theta) * rot_z(phi)
        C = sp.Matrix([x, y, z])
        rows, legs, points = [], [], []
        for i in range(6):
            a = sp.Matrix(g[3 * i:3 * i + 3])
            rb = R * sp.Matrix(g[18 + 3 * i:18 + 3 * i + 3])
            l = C + rb - a
            legs.append(tuple(l))
            points.append(tuple(C + rb))
            rows.append(list(l) + list(rb.cross(l)))
        A = sp.Matrix(rows)
        rho = [sp.sqrt(sum(c ** 2 for c in leg)) for leg in legs]
        return {"legs": legs, "points": points, "A": A, "B": -sp.diag(*rho), "R": R}
