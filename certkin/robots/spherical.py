"""Spherical 3-DOF robot with prismatic legs (seed 003 §4).

A passive spherical joint at O carries the platform; leg i runs from A_i
(base, a_i = OA_i = [w_i, u_i, −h] in the seed's frame) to B_i
(b_i = Q b'_i).  Pose: ZYZ Euler angles (phi1, phi2, phi3),
Q = Rz(phi1) Ry(phi2) Rz(phi3) (seed 003 eq. 4.12–4.13).  With
ρ_i ρ̇_i = (a_i × b_i)·ω (eq. 4.7), A ω + B ρ̇ = 0 gives

    row i of A = (a_i × b_i)ᵀ,   B = −diag(ρ_i).

Tilt-and-torsion angles (phi1, phi2, sigma) are Euler (phi1, phi2, sigma − phi1).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from .base import Robot, det3


def rot_z(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rot_y(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_x(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


class Spherical3DOF(Robot):
    kind = "spherical-3dof"
    n_legs = 3
    dim = 3
    pose_names = ("phi1", "phi2", "phi3")
    angle_names = frozenset(pose_names)

    @classmethod
    @lru_cache(maxsize=None)
    def symbols(cls):
        pose = sp.symbols("phi1 phi2 phi3", real=True)
        geom = sp.symbols(" ".join(f"a{i}{c}" for i in (1, 2, 3) for c in "xyz") + " "
                          + " ".join(f"b{i}{c}" for i in (1, 2, 3) for c in "xyz"), real=True)
        return pose, geom

    @classmethod
    @lru_cache(maxsize=None)
    def symbolic_model(cls):
        (p1, p2, p3), g = cls.symbols()
        return _model(rot_z(p1) * rot_y(p2) * rot_z(p3), g)

    def with_angles(self, angles: str):
        """The same robot with pose angles ``zyz`` (Euler) or ``tilt-torsion``."""
        cls = {"zyz": Spherical3DOF, "tilt-torsion": Spherical3DOFTiltTorsion}.get(angles)
        if cls is None:
            raise ValueError(f"unknown angles {angles!r} (zyz or tilt-torsion)")
        return cls(self.name, self.base, self.platform, self.limits, self.home if cls is type(self) else None, self.source)


def _model(Q, g):
    rows, legs, points = [], [], []
    for i in range(3):
        a = sp.Matrix(g[3 * i:3 * i + 3])
        b = Q * sp.Matrix(g[9 + 3 * i:9 + 3 * i + 3])
        legs.append(tuple(b - a))
        points.append(tuple(b))
        rows.append(list(a.cross(b)))
    A = sp.Matrix(rows)
    rho = [sp.sqrt(sum(c ** 2 for c in leg)) for leg in legs]
    return {"legs": legs, "points": points, "A": A, "B": -sp.diag(*rho), "det": det3(A), "R": Q}


class Spherical3DOFTiltTorsion(Spherical3DOF):
    """The same robot with tilt-and-torsion angles (phi1, phi2, sigma) (Bonev & Ryu; seed 003 §4.3.2).

    Q = Rz(phi1) Ry(phi2) Rz(sigma − phi1): azimuth phi1, tilt phi2, torsion sigma.
    """

    pose_names = ("phi1", "phi2", "sigma")
    angle_names = frozenset(pose_names)
    model_name = "spherical-3dof-tt"

    @classmethod
    @lru_cache(maxsize=None)
    def symbols(cls):
        pose = sp.symbols("phi1 phi2 sigma", real=True)
        return pose, Spherical3DOF.symbols()[1]

    @classmethod
    @lru_cache(maxsize=None)
    def symbolic_model(cls):
        (p1, p2, sg), g = cls.symbols()
        return _model(rot_z(p1) * rot_y(p2) * rot_z(sg - p1), g)


def rotation_float(kind: str, pose) -> np.ndarray:
    """Rotation matrices at float poses (..., d) -> (..., 3, 3) (not certified).

    Gough-Stewart: Rz(psi) Rx(theta) Rz(phi) from pose[..., 3:6]; spherical:
    Rz(phi1) Ry(phi2) Rz(phi3) from pose[..., 0:3] (ZYZ Euler angles).
    """
    pose = np.asarray(pose, dtype=np.float64)
    if kind == "gough-stewart":
        a, b, c = pose[..., 3], pose[..., 4], pose[..., 5]
        return _rz(a) @ _rx(b) @ _rz(c)
    a, b, c = pose[..., 0], pose[..., 1], pose[..., 2]
    return _rz(a) @ _ry(b) @ _rz(c)


def _rz(t):
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _ry(t):
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rx(t):
    c, s, z, o = np.cos(t), np.sin(t), np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)
