"""The model equations of docs/certificates.md, rebuilt from the stated geometry.

Each model maps a pose and the geometry to the matrix A of A ṫ + B ρ̇ = 0;
``det.det_interval`` encloses det(A) (Laplace, and for 6×6 also a
preconditioned elimination).  The formulas use only +, −, ×, sin and cos
(``ad.sin``/``ad.cos``), so the same code gives an interval enclosure of
det(A) over a box (``iv`` numbers) or, with ``ad.Dual`` numbers, enclosures
of det(A) and of its gradient.

- ``planar-3rpr/1`` (x, y, phi): q_i = R(phi) p_i, u_i = (x, y) + q_i − b_i,
  row i = [(y − b_iy) q_ix − (x − b_ix) q_iy, u_ix, u_iy].
- ``spherical-3dof/1`` (phi1, phi2, phi3): Q = Rz(phi1) Ry(phi2) Rz(phi3),
  row i = a_i × (Q b_i).
- ``spherical-3dof-tt/1`` (phi1, phi2, sigma): Q = Rz(phi1) Ry(phi2) Rz(sigma − phi1).
- ``gough-stewart/1`` (x, y, z, psi, theta, phi): R = Rz(psi) Rx(theta) Rz(phi),
  l_i = (x, y, z) + R b_i − a_i, row i = [l_i, (R b_i) × l_i].
"""
from __future__ import annotations

from dataclasses import dataclass

from mpmath import iv

from . import ad
from .det import det, det_interval
from .numbers import enclose
from .report import Rejected


def _cs(angle):
    return ad.cos(angle), ad.sin(angle)


def rot(axis: str, cs, v):
    """R_axis(angle) v, with cs = (cos, sin) of the angle: Rz = [[c,−s,0],[s,c,0],[0,0,1]],
    Ry = [[c,0,s],[0,1,0],[−s,0,c]], Rx = [[1,0,0],[0,c,−s],[0,s,c]]."""
    c, s = cs
    x, y, z = v
    if axis == "z":
        return (c * x - s * y, s * x + c * y, z)
    if axis == "y":
        return (c * x + s * z, y, c * z - s * x)
    return (x, c * y - s * z, s * y + c * z)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def planar_rows(pose, base, platform):
    x, y, phi = pose
    c, s = ad.cos(phi), ad.sin(phi)
    rows = []
    for (bx, by), (px, py) in zip(base, platform):
        qx, qy = c * px - s * py, s * px + c * py
        rows.append([(y - by) * qx - (x - bx) * qy, x + qx - bx, y + qy - by])
    return rows


def _spherical(p1, p2, p3, base, platform):
    rows = []
    c1, c2, c3 = _cs(p1), _cs(p2), _cs(p3)
    for a, b in zip(base, platform):
        qb = rot("z", c1, rot("y", c2, rot("z", c3, b)))
        rows.append(list(_cross(a, qb)))
    return rows


def spherical_rows(pose, base, platform):
    phi1, phi2, phi3 = pose
    return _spherical(phi1, phi2, phi3, base, platform)


def spherical_tt_rows(pose, base, platform):
    phi1, phi2, sigma = pose
    return _spherical(phi1, phi2, sigma - phi1, base, platform)


def gough_rows(pose, base, platform):
    x, y, z, psi, theta, phi = pose
    rows = []
    c1, c2, c3 = _cs(psi), _cs(theta), _cs(phi)
    for a, b in zip(base, platform):
        rb = rot("z", c1, rot("x", c2, rot("z", c3, b)))
        l = (x + rb[0] - a[0], y + rb[1] - a[1], z + rb[2] - a[2])
        rows.append(list(l) + list(_cross(rb, l)))
    return rows


@dataclass(frozen=True)
class Model:
    name: str
    kind: str            # the robot ``kind`` the model applies to
    pose: tuple          # pose variable names, in order
    legs: int
    base_dim: int
    platform_dim: int
    rows: object         # (pose, base, platform) -> rows of A


MODELS = {m.name: m for m in (
    Model("planar-3rpr/1", "planar-3rpr", ("x", "y", "phi"), 3, 2, 2, planar_rows),
    Model("spherical-3dof/1", "spherical-3dof", ("phi1", "phi2", "phi3"), 3, 3, 3, spherical_rows),
    Model("spherical-3dof-tt/1", "spherical-3dof", ("phi1", "phi2", "sigma"), 3, 3, 3, spherical_tt_rows),
    Model("gough-stewart/1", "gough-stewart", ("x", "y", "z", "psi", "theta", "phi"), 6, 3, 3, gough_rows),
)}


def points(robot: dict, key: str, count: int, dim: int):
    pts = robot.get(key)
    if not isinstance(pts, list) or len(pts) != count:
        raise Rejected(f"robot.{key}: expected {count} points")
    out = []
    for i, p in enumerate(pts):
        if not isinstance(p, list) or len(p) != dim:
            raise Rejected(f"robot.{key}[{i}]: expected {dim} coordinates")
        out.append(tuple(enclose(c, f"robot.{key}[{i}][{j}]") for j, c in enumerate(p)))
    return out


class Robot:
    """A model with its geometry enclosed; evaluates det(A) over boxes.

    A box is a sequence of (lo, hi) floats (lo == hi for a point).
    """

    def __init__(self, model: Model, robot: dict):
        self.model = model
        self.base = points(robot, "base", model.legs, model.base_dim)
        self.platform = points(robot, "platform", model.legs, model.platform_dim)
        lift = lambda pts: [tuple(ad.lift(c) for c in p) for p in pts]
        self._lifted = lift(self.base), lift(self.platform)  # constants for ``ad.Dual`` evaluation

    def det(self, box):
        """Interval enclosure of det(A) over the box."""
        pose = [iv.mpf([lo, hi]) for lo, hi in box]
        return det_interval(self.model.rows(pose, self.base, self.platform))

    def det_gradient(self, box):
        """(enclosure of det(A), enclosures of ∂det/∂x_i) over the box."""
        pose = ad.variables([iv.mpf([lo, hi]) for lo, hi in box])
        base, platform = self._lifted
        return ad.gradient(det(self.model.rows(pose, base, platform)), len(box))
