"""The symbolic models (sympy) of every robot kind, and their compiled interval evaluators.

Each model is written once with the geometry as *symbols* (seed 003 form
A ṫ + B ρ̇ = 0): leg vectors, platform points, A, B, det(A) where it is short
(planar, spherical), the rotation R where there is one.  ``compiled(cls, what)``
compiles expressions once per kind with ``intervals.compiler``; they are then
evaluated on batches of boxes with the robot's exact geometry enclosed as
parameter intervals (``Robot.det_enclosure`` and the others).

This is the only module of ``robots`` that imports sympy.  ``Robot`` loads it
on first use (``robots.models.symbolic``): reading robot files, forward
kinematics and poses never need it, and importing sympy costs about half a
second per process.
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from intervals.compiler import compile_exprs

_COMPILED: dict = {}  # (class name, what) -> CompiledExprs or bool, shared by the robots of one kind


def det3(M):
    """Cofactor expansion of a 3x3 sympy matrix, left unexpanded.

    Keeping the products of the (short) entries instead of the expanded
    polynomial makes far fewer interval operations and tighter enclosures.
    """
    return (M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
            - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
            + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))


def rot_z(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rot_y(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_x(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


# ----- the models (formulas in the docstrings of robots.planar, robots.spherical, robots.gough) -----
def _planar(pose_names, geometry_names):
    (x, y, phi), g = sp.symbols(pose_names, real=True), sp.symbols(geometry_names, real=True)
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


def _spherical(pose_names, geometry_names, tilt_torsion: bool):
    (p1, p2, p3), g = sp.symbols(pose_names, real=True), sp.symbols(geometry_names, real=True)
    Q = rot_z(p1) * rot_y(p2) * rot_z(p3 - p1 if tilt_torsion else p3)
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


def _gough(pose_names, geometry_names):
    (x, y, z, psi, theta, phi), g = sp.symbols(pose_names, real=True), sp.symbols(geometry_names, real=True)
    R = rot_z(psi) * rot_x(theta) * rot_z(phi)
    C = sp.Matrix([x, y, z])
    rows, legs, points = [], [], []
    for i in range(6):
        a = sp.Matrix(g[3 * i:3 * i + 3])
        rb = R * sp.Matrix(g[18 + 3 * i:18 + 3 * i + 3])
        leg = C + rb - a
        legs.append(tuple(leg))
        points.append(tuple(C + rb))
        rows.append(list(leg) + list(rb.cross(leg)))
    A = sp.Matrix(rows)
    rho = [sp.sqrt(sum(c ** 2 for c in leg)) for leg in legs]
    return {"legs": legs, "points": points, "A": A, "B": -sp.diag(*rho), "R": R}


@lru_cache(maxsize=None)
def symbols(cls):
    """(pose symbols, geometry symbols) of the model of a robot class."""
    return sp.symbols(cls.pose_names, real=True), sp.symbols(cls.geometry_names(), real=True)


@lru_cache(maxsize=None)
def model(cls) -> dict:
    """Sympy expressions of a robot class: ``legs``, ``points``, ``A``, ``B``, and ``det``, ``R`` where
    the kind has them."""
    names, geometry = cls.pose_names, cls.geometry_names()
    if cls.kind == "planar-3rpr":
        return _planar(names, geometry)
    if cls.kind == "spherical-3dof":
        return _spherical(names, geometry, tilt_torsion=names[2] == "sigma")
    if cls.kind == "gough-stewart":
        return _gough(names, geometry)
    raise KeyError(cls.kind)


def compiled(cls, what: str):
    """The compiled interval evaluator of ``what`` (det, A, legs_sq, R, points, leg_vectors)."""
    key = (cls.__name__, what)
    if key not in _COMPILED:
        pose, geom = symbols(cls)
        m = model(cls)
        if what == "det":
            exprs = [m["det"]]
        elif what == "A":
            exprs = list(m["A"])
        elif what == "legs_sq":
            exprs = [sum(c ** 2 for c in leg) for leg in m["legs"]]
        elif what == "R":
            exprs = list(m["R"])
        elif what == "points":
            exprs = [c for p in m["points"] for c in p]
        elif what == "leg_vectors":   # l_i padded to 3 coordinates, then R row by row if modelled
            exprs = [c for leg in m["legs"] for c in (list(leg) + [0] * (3 - len(leg)))]
            if "R" in m:
                exprs += list(m["R"])
        else:
            raise KeyError(what)
        _COMPILED[key] = compile_exprs(exprs, pose, geom)
    return _COMPILED[key]


def rigid_legs(cls) -> bool:
    """Whether the model's leg vectors are l_i = C + R b_i − a_i (C the position variables, a_i, b_i
    the base and platform geometry), checked symbolically once per kind."""
    key = (cls.__name__, "rigid_legs")
    if key not in _COMPILED:
        pose, geom = symbols(cls)
        m = model(cls)
        ok = "R" in m and cls.dim == 3
        if ok:
            R = sp.Matrix(m["R"]).reshape(3, 3)
            C = [v for v in pose if str(v) not in cls.angle_names]
            C = sp.Matrix(C + [0] * (3 - len(C)))
            n = cls.n_legs
            for i, leg in enumerate(m["legs"]):
                a, b = sp.Matrix(geom[3 * i:3 * i + 3]), sp.Matrix(geom[3 * n + 3 * i:3 * n + 3 * i + 3])
                ok = ok and all(sp.expand(x - y) == 0 for x, y in zip(leg, C + R * b - a))
        _COMPILED[key] = bool(ok)
    return _COMPILED[key]
