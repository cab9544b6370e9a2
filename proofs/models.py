"""det(A) of each model (docs/certificates.md "Models"), over batches of boxes, with its gradient.

The formulas use +, −, ×, sin and cos only, so the same code evaluates them on intervals (``arith.Iv``, one per box)
and on ``Dual`` numbers (value and gradient enclosures: forward-mode differentiation, each operation applying the
exact rule in interval arithmetic).  ``det`` is the Laplace expansion (minors memoised by their columns);
``det_interval`` intersects it, for n ≥ 4, with a preconditioned elimination (Rump, Acta Numerica 2010, §10): a float
LU factorisation of the midpoint matrix gives a permutation P and a unit lower-triangular X whose diagonal is exactly
1, so det(X P M) = ±det(M); Y = X P M is enclosed and eliminated without pivoting, det Y being the product of the
pivots when no pivot used as a divisor holds 0."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import arith
from .arith import Iv
from .numbers import enclose
from .report import Rejected


class Dual:
    """A value enclosure ``v`` (Iv, shape S) and gradient enclosures ``g`` (Iv, S + (d,); None = 0)."""

    __slots__ = ("v", "g")

    def __init__(self, v, g=None):
        self.v, self.g = v, g

    def __add__(self, o):
        o = lift(o)
        g = o.g if self.g is None else self.g if o.g is None else self.g + o.g
        return Dual(self.v + o.v, g)

    __radd__ = __add__

    def __neg__(self):
        return Dual(-self.v, None if self.g is None else -self.g)

    def __sub__(self, o):
        return self + (-lift(o))

    def __rsub__(self, o):
        return lift(o) + (-self)

    def __mul__(self, o):
        o = lift(o)
        parts = [x for x in (None if self.g is None else self.g * _col(o.v),
                             None if o.g is None else o.g * _col(self.v)) if x is not None]
        g = None if not parts else parts[0] if len(parts) == 1 else parts[0] + parts[1]
        return Dual(self.v * o.v, g)

    __rmul__ = __mul__


def _col(v):
    return Iv(v.lo[..., None], v.hi[..., None])


def lift(x):
    return x if isinstance(x, Dual) else Dual(x if isinstance(x, Iv) else Iv(x))


def variables(lo, hi):
    """The pose variables over boxes (N, d) as Duals with unit gradients."""
    n, d = lo.shape
    eye = np.broadcast_to(np.eye(d), (n, d, d))
    return [Dual(Iv(lo[:, i], hi[:, i]), Iv(eye[:, i])) for i in range(d)]


def sincos(x):
    """(sin x, cos x) of an interval or a Dual (d sin = cos dx, d cos = −sin dx)."""
    if not isinstance(x, Dual):
        return arith.sincos(x)
    s, c = arith.sincos(x.v)
    return (Dual(s, None if x.g is None else x.g * _col(c)), Dual(c, None if x.g is None else x.g * _col(-s)))


def rot(axis: str, c, s, v):
    """R_axis(angle) v from c = cos, s = sin of the angle."""
    x, y, z = v
    if axis == "z":
        return (c * x - s * y, s * x + c * y, z)
    return (c * x + s * z, y, c * z - s * x) if axis == "y" else (x, c * y - s * z, s * y + c * z)


def rotate(axes: str, cs, v):
    """R v for R the product of the rotations about ``axes`` (``"zxz"``: Rz Rx Rz), ``cs`` their (sin, cos)."""
    for axis, (s, c) in zip(reversed(axes), reversed(cs)):
        v = rot(axis, c, s, v)
    return v


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def planar_rows(pose, base, platform):
    x, y, phi = pose
    s, c = sincos(phi)
    rows = []
    for (bx, by), (px, py) in zip(base, platform):
        qx, qy = c * px - s * py, s * px + c * py
        rows.append([(y - by) * qx - (x - bx) * qy, (x + qx) - bx, (y + qy) - by])
    return rows


def _spherical(p1, p2, p3, base, platform):
    (s1, c1), (s2, c2), (s3, c3) = [sincos(t) for t in (p1, p2, p3)]
    return [list(cross(a, rot("z", c1, s1, rot("y", c2, s2, rot("z", c3, s3, b))))) for a, b in zip(base, platform)]


def gough_rows(pose, base, platform):
    x, y, z, psi, theta, phi = pose
    (s1, c1), (s2, c2), (s3, c3) = [sincos(t) for t in (psi, theta, phi)]
    rows = []
    for a, b in zip(base, platform):
        rb = rot("z", c1, s1, rot("x", c2, s2, rot("z", c3, s3, b)))
        l = ((x + rb[0]) - a[0], (y + rb[1]) - a[1], (z + rb[2]) - a[2])
        rows.append(list(l) + list(cross(rb, (x - a[0], y - a[1], z - a[2]))))   # R b x l = R b x (C - a): R b x R b = 0
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
    Model("spherical-3dof/1", "spherical-3dof", ("phi1", "phi2", "phi3"), 3, 3, 3,
          lambda p, a, b: _spherical(p[0], p[1], p[2], a, b)),
    Model("spherical-3dof-tt/1", "spherical-3dof", ("phi1", "phi2", "sigma"), 3, 3, 3,
          lambda p, a, b: _spherical(p[0], p[1], p[2] - p[0], a, b)),
    Model("gough-stewart/1", "gough-stewart", ("x", "y", "z", "psi", "theta", "phi"), 6, 3, 3, gough_rows))}


def header_model(h, table, kind, names_key=None, names=None):
    """The header's model, looked up in ``table`` and checked against robot.kind (and pose/unknown names)."""
    name = h.get("model")
    if not isinstance(name, str) or name not in table:
        raise Rejected(f"model: unknown model {name!r:.60} (known: {', '.join(table)})")
    if h["robot"].get("kind") != kind(table[name]):
        raise Rejected(f"robot.kind: {h['robot'].get('kind')!r:.60} does not fit model {name}")
    if names_key and h.get(names_key) != list(names(table[name])):
        raise Rejected(f"{names_key}: expected {list(names(table[name]))} for model {name}")
    return table[name]


def each_claim(claims):
    """(``claims[k]``, claim) for each claim in turn, rejected unless it is an object."""
    for k, claim in enumerate(claims):
        if not isinstance(claim, dict):
            raise Rejected(f"claims[{k}]: expected an object")
        yield f"claims[{k}]", claim


def points(robot: dict, key: str, count: int, dim: int):
    """The exact decimal points robot[key] as lists of scalar enclosures."""
    pts = robot.get(key)
    if not isinstance(pts, list) or len(pts) != count:
        raise Rejected(f"robot.{key}: expected {count} points")
    out = []
    for i, p in enumerate(pts):
        if not isinstance(p, list) or len(p) != dim:
            raise Rejected(f"robot.{key}[{i}]: expected {dim} coordinates")
        out.append(tuple(enclose(c, f"robot.{key}[{i}][{j}]") for j, c in enumerate(p)))
    return out


def det(M):
    """Laplace expansion along the rows (minors of the lower rows memoised by column set)."""
    n, memo = len(M), {}

    def minor(cols):
        if len(cols) == 1:
            return M[n - 1][cols[0]]
        if cols not in memo:
            r, total = n - len(cols), None
            for k, j in enumerate(cols):
                term = M[r][j] * minor(cols[:k] + cols[k + 1:])
                total = term if total is None else (total - term if k % 2 else total + term)
            memo[cols] = total
        return memo[cols]

    return minor(tuple(range(n)))


def det_interval(M, D=None):
    """Enclosure of det over interval matrices (lists of Iv (N,)): Laplace (or D given), ∩ elimination for n ≥ 4."""
    D = det(M) if D is None else D
    if len(M) < 4:
        return D
    E, ok = _det_elimination(arith.stack([arith.stack(row) for row in M], axis=1))   # (N, row, column), as A
    return Iv(np.where(ok, np.maximum(D.lo, E.lo), D.lo), np.where(ok, np.minimum(D.hi, E.hi), D.hi))


def _det_elimination(M: Iv):
    """(enclosure, valid mask) of det M for M (N, n, n), by preconditioned elimination."""
    N, n, _ = M.lo.shape
    with np.errstate(all="ignore"):
        U = 0.5 * M.lo + 0.5 * M.hi
        U = np.where(np.isfinite(U), U, 0.0)
        L = np.zeros_like(U)
        perm = np.broadcast_to(np.arange(n), (N, n)).copy()
        sign = np.ones(N)
        rows = np.arange(N)
        for k in range(n):                          # float LU with partial pivoting
            p = k + np.argmax(np.abs(U[:, k:, k]), axis=1)
            sign = np.where(p != k, -sign, sign)
            for A in (U, L, perm):
                A[rows, k], A[rows, p] = A[rows, p].copy(), A[rows, k].copy()
            piv = np.where(U[:, k, k] == 0, 1.0, U[:, k, k])
            f = U[:, k + 1:, k] / piv[:, None]
            L[:, k + 1:, k] = f
            U[:, k + 1:, k:] -= f[..., None] * U[:, k, None, k:]
        X = np.zeros_like(U)                        # ≈ L⁻¹, exactly unit lower triangular
        for i in range(n):
            X[:, i, i] = 1.0
            for j in range(i):
                X[:, i, j] = -np.sum(L[:, i, j:i] * X[:, j:i, j], axis=1)
        X = np.where(np.isfinite(X), X, 0.0)
        Y = arith.pmatmul(X, M[rows[:, None], perm])
        Y = [[Y[:, i, j] for j in range(n)] for i in range(n)]
        d, ok = Iv(np.ones(N)), np.ones(N, dtype=bool)
        for k in range(n):
            piv = Y[k][k]
            d = d * piv
            if k == n - 1:
                break
            ok &= piv.pos() | piv.neg()
            for i in range(k + 1, n):
                f = Y[i][k] / piv
                for j in range(k + 1, n):
                    Y[i][j] = Y[i][j] - f * Y[k][j]
    return Iv(np.where(sign > 0, d.lo, -d.hi), np.where(sign > 0, d.hi, -d.lo)), ok


class Robot:
    """A model with its geometry enclosed: det(A) and its gradient over batches of boxes (N, d)."""

    def __init__(self, model: Model, robot: dict):
        self.model = model
        self.base = points(robot, "base", model.legs, model.base_dim)
        self.platform = points(robot, "platform", model.legs, model.platform_dim)

    def det(self, lo, hi) -> Iv:
        pose = [Iv(lo[:, i], hi[:, i]) for i in range(lo.shape[1])]
        return det_interval(self.model.rows(pose, self.base, self.platform))

    def det_gradient(self, lo, hi):
        """(enclosure of det(A), enclosures of ∂det/∂x_i (N, d)) over the boxes."""
        y = det(self.model.rows(variables(lo, hi), self.base, self.platform))
        return y.v, (y.g if y.g is not None else Iv(np.zeros(lo.shape)))
