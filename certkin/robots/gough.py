"""Gough-Stewart platform, 6 legs (seeds 000, 002, 004).

Pose (x, y, z, psi, theta, phi): C = (x, y, z) is the platform frame origin
and R = Rz(psi) Rx(theta) Rz(phi) (seed 000: psi about z, theta about the new
x, phi about the new z).  Leg i: l_i = C + R b_i − a_i.  With
ρ_i ρ̇_i = l_i·(Ċ + ω × R b_i), A (Ċ, ω) + B ρ̇ = 0 gives

    row i of A = [ l_iᵀ , ((R b_i) × l_i)ᵀ ],   B = −diag(ρ_i)

(the Plücker lines of the legs scaled by ρ_i > 0, so the sign of det A is
that of the unit-line determinant).  6-3 and 3-3 designs are the same model
with coincident joints.  det A is enclosed from the compiled entries of A by
``intervals.linalg.det``.  The symbolic model is in ``robots.symbolic``; the
float helpers below are the same formulas.
"""
from __future__ import annotations

import numpy as np

from .base import Robot
from .spherical import rotation_float


class GoughStewart(Robot):
    kind = "gough-stewart"
    n_legs = 6
    dim = 3
    pose_names = ("x", "y", "z", "psi", "theta", "phi")
    angle_names = frozenset({"psi", "theta", "phi"})

    def rotation_float(self, pose) -> np.ndarray:
        return rotation_float(self.kind, pose)

    def _arms_and_legs(self, pose):
        pose = np.asarray(pose, dtype=np.float64)
        base, platform = self.float_geometry
        rb = platform @ np.swapaxes(self.rotation_float(pose), -1, -2)        # (..., 6, 3): R b_i
        return rb, pose[..., None, :3] + rb - base

    def leg_vectors_float(self, pose) -> np.ndarray:
        return self._arms_and_legs(pose)[1]

    def jacobian_float(self, pose) -> np.ndarray:
        rb, legs = self._arms_and_legs(pose)
        return np.concatenate([legs, np.cross(rb, legs)], -1)
