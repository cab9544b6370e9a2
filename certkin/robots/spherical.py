"""Spherical 3-DOF robot with prismatic legs (seed 003 §4).

A passive spherical joint at O carries the platform; leg i runs from A_i
(base, a_i = OA_i = [w_i, u_i, −h] in the seed's frame) to B_i
(b_i = Q b'_i).  Pose: ZYZ Euler angles (phi1, phi2, phi3),
Q = Rz(phi1) Ry(phi2) Rz(phi3) (seed 003 eq. 4.12–4.13).  With
ρ_i ρ̇_i = (a_i × b_i)·ω (eq. 4.7), A ω + B ρ̇ = 0 gives

    row i of A = (a_i × b_i)ᵀ,   B = −diag(ρ_i).

Tilt-and-torsion angles (phi1, phi2, sigma) are Euler (phi1, phi2, sigma − phi1).
The symbolic model is in ``robots.symbolic``; the float helpers below are the
same formulas.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, shown
from .base import Robot


class Spherical3DOF(Robot):
    kind = "spherical-3dof"
    n_legs = 3
    dim = 3
    pose_names = ("phi1", "phi2", "phi3")
    angle_names = frozenset(pose_names)
    symbolic_det = True

    def with_angles(self, angles: str):
        """The same robot with pose angles ``zyz`` (Euler) or ``tilt-torsion``; anything else is an
        ``InputError`` naming ``angles``."""
        cls = {"zyz": Spherical3DOF, "tilt-torsion": Spherical3DOFTiltTorsion}.get(angles) \
            if isinstance(angles, str) else None
        if cls is None:
            raise InputError("angles", "", f"unknown angles {shown(angles)} (zyz or tilt-torsion)")
        return cls(self.name, self.base, self.platform, self.limits, self.home if cls is type(self) else None, self.source)

    def rotation_float(self, pose) -> np.ndarray:
        pose = np.asarray(pose, dtype=np.float64)
        return rot_z(pose[..., 0]) @ rot_y(pose[..., 1]) @ rot_z(pose[..., 2])

    def _points(self, pose):
        base, platform = self.float_geometry
        return platform @ np.swapaxes(self.rotation_float(pose), -1, -2), base    # (..., 3, 3): b_i = Q b'_i

    def leg_vectors_float(self, pose) -> np.ndarray:
        b, a = self._points(pose)
        return b - a

    def jacobian_float(self, pose) -> np.ndarray:
        b, a = self._points(pose)
        return np.cross(np.broadcast_to(a, b.shape), b)


class Spherical3DOFTiltTorsion(Spherical3DOF):
    """The same robot with tilt-and-torsion angles (phi1, phi2, sigma) (Bonev & Ryu; seed 003 §4.3.2).

    Q = Rz(phi1) Ry(phi2) Rz(sigma − phi1): azimuth phi1, tilt phi2, torsion sigma.
    """

    pose_names = ("phi1", "phi2", "sigma")
    angle_names = frozenset(pose_names)
    model_name = "spherical-3dof-tt"

    def rotation_float(self, pose) -> np.ndarray:
        pose = np.asarray(pose, dtype=np.float64)
        return rot_z(pose[..., 0]) @ rot_y(pose[..., 1]) @ rot_z(pose[..., 2] - pose[..., 0])


def rotation_float(kind: str, pose) -> np.ndarray:
    """Rotation matrices at float poses (..., d) -> (..., 3, 3) (not certified).

    Gough-Stewart: Rz(psi) Rx(theta) Rz(phi) from pose[..., 3:6]; spherical:
    Rz(phi1) Ry(phi2) Rz(phi3) from pose[..., 0:3] (ZYZ Euler angles).
    """
    pose = np.asarray(pose, dtype=np.float64)
    if kind == "gough-stewart":
        return rot_z(pose[..., 3]) @ rot_x(pose[..., 4]) @ rot_z(pose[..., 5])
    return rot_z(pose[..., 0]) @ rot_y(pose[..., 1]) @ rot_z(pose[..., 2])


def rot_z(t):
    """Rz(t) for float angles (...) -> (..., 3, 3)."""
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def rot_y(t):
    """Ry(t) for float angles (...) -> (..., 3, 3)."""
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_x(t):
    """Rx(t) for float angles (...) -> (..., 3, 3)."""
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)
