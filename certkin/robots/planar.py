"""Planar 3-RPR robot (seed 003 §3, Gosselin & Angeles 1990).

Pose (x, y, phi): B_i(world) = t + Q(phi) p'_i with t = (x, y) (the "+"
convention: the digest shows the N_j of seed 003 Annex B need it).
A ṫ + B ρ̇ = 0 with twist ṫ = (φ̇, ẋ, ẏ) (the thesis column order, which
fixes the sign of det A):

    row i of A = [ u_iᵀ E q_i , u_iᵀ ],   u_i = t + q_i − b_i,  q_i = Q p'_i
    B = −diag(ρ_i)

and u_iᵀ E q_i simplifies to (y − b_iy) q_ix − (x − b_ix) q_iy (the q_ix q_iy
terms cancel), which keeps interval enclosures tight.  The symbolic model is
in ``robots.symbolic``; the float helpers below are the same formulas.
"""
from __future__ import annotations

import numpy as np

from .base import Robot


class Planar3RPR(Robot):
    kind = "planar-3rpr"
    n_legs = 3
    dim = 2
    pose_names = ("x", "y", "phi")
    angle_names = frozenset({"phi"})
    geometry_letters = ("b", "p")
    symbolic_det = True

    def rotation_float(self, pose) -> np.ndarray:
        phi = np.asarray(pose, dtype=np.float64)[..., 2]
        c, s = np.cos(phi), np.sin(phi)
        return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)

    def _q_and_u(self, pose):
        pose = np.asarray(pose, dtype=np.float64)
        base, platform = self.float_geometry
        q = platform @ np.swapaxes(self.rotation_float(pose), -1, -2)          # (..., 3, 2): Q p'_i
        return q, pose[..., None, :2] + q - base

    def leg_vectors_float(self, pose) -> np.ndarray:
        return self._q_and_u(pose)[1]

    def jacobian_float(self, pose) -> np.ndarray:
        pose = np.asarray(pose, dtype=np.float64)
        base, _ = self.float_geometry
        q, u = self._q_and_u(pose)
        x, y = pose[..., None, 0], pose[..., None, 1]
        first = (y - base[:, 1]) * q[..., 0] - (x - base[:, 0]) * q[..., 1]
        return np.concatenate([first[..., None], u], -1)
