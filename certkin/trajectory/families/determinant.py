"""``singularity``: det(A) ≠ 0 along the path (its sign is decided interval by interval; the path is
free of singularities when every interval has the same sign).

The robot's symbolic det(A), or for Gough-Stewart robots (no symbolic det of the 6 × 6 A) the
natural LU-preconditioned enclosure of the compiled entries of A (``intervals.linalg.det``), a
Laplace expansion on dual numbers for the t-derivative, and for polynomials the generalised
Laplace expansion along the first three columns (``block_det``).
"""
from __future__ import annotations

import itertools

import numpy as np

from intervals import Interval, linalg
from intervals.interval import mul
from intervals.polynomial import Poly, padded

from ..pose import broadcast, cross
from .base import SATISFIED, UNKNOWN, Family, Instance

_SUBSETS = np.array(list(itertools.combinations(range(6), 3)))
_COMPLEMENTS = np.array([[i for i in range(6) if i not in S] for S in _SUBSETS])
_SIGNS = np.where((_SUBSETS.sum(axis=1) + 3) % 2 == 0, 1.0, -1.0)


def gough_det(legs, base, C):
    """det(A) with rows [l_i, (A_i − C) × l_i] (= (R b_i) × l_i, as l_i × l_i = 0), natural
    enclosure by ``intervals.linalg.det`` (LU-preconditioned) over (M,) boxes."""
    arm = [base[k][None, :] - C[k][:, None] for k in range(3)]          # A_i − C, (M, n)
    mom = cross(arm, legs)
    cols = legs + mom                                                     # 6 x (M, n)
    A = Interval.from_bounds(np.stack([c.lo for c in cols], axis=-1), np.stack([c.hi for c in cols], axis=-1))
    return linalg.det(A)


def det3(X):
    """det of 3 x 3 matrices of polynomials, X indexed [..., row, col] over the batch axes:
    x00 (x11 x22 − x12 x21) − x01 (x10 x22 − x12 x20) + x02 (x10 x21 − x11 x20), the six
    products of the minors in one stacked product and the three of row 0 in another."""
    pre = (slice(None),) * (X.ndim - 2)
    p = X[pre + ([1] * 6, [1, 2, 0, 2, 0, 1])] * X[pre + ([2] * 6, [2, 1, 2, 0, 1, 0])]      # (..., 6)
    minors = p[pre + (slice(0, None, 2),)] - p[pre + (slice(1, None, 2),)]                 # (..., 3)
    t = X[pre + ([0, 0, 0], [0, 1, 2])] * minors
    return t[pre + (0,)] - t[pre + (1,)] + t[pre + (2,)]


def gough_det_poly(V, w, base, C0):
    """Constant orientation: det(A) as a polynomial in t (degree ≤ 6) per segment.

    Rows [l_i, (A_i − C) × l_i] = [V_i + t w, (A_i − C_0 − t w) × R b_i] with
    R b_i = V_i + A_i − C_0 constant: both blocks are linear in t."""
    shape = V[0].shape
    st = lambda xs, end: np.stack([np.broadcast_to(getattr(x, end), shape) for x in xs], -1)  # noqa: E731
    arm0 = [base[k][None, :] - C0[k][:, None] for k in range(3)]                 # A_i − C_0: (M, 6)
    arm = Interval.from_bounds(st(arm0, "lo"), st(arm0, "hi"))                         # (M, 6, 3)
    wb = Interval.from_bounds(st([w[k][:, None] for k in range(3)], "lo"), st([w[k][:, None] for k in range(3)], "hi"))
    Vs = Interval.from_bounds(st(V, "lo"), st(V, "hi"))
    Rb = Vs + arm                                                                # R b_i = V_i + A_i − C_0
    first, second = [1, 2, 0], [2, 0, 1]
    X = Interval.from_bounds(np.stack([arm.lo, wb.lo]), np.stack([arm.hi, wb.hi]))    # (2, M, 6, 3): arm, w
    m = mul(X[..., first], Rb[..., second]) - mul(X[..., second], Rb[..., first])   # arm × R b_i, w × R b_i
    L = [Poly(np.stack([Vs.lo[..., k], wb.lo[..., k]], -1), np.stack([Vs.hi[..., k], wb.hi[..., k]], -1)) for k in range(3)]
    M = [Poly(np.stack([m.lo[0, ..., k], -m.hi[1, ..., k]], -1), np.stack([m.hi[0, ..., k], -m.lo[1, ..., k]], -1))
         for k in range(3)]
    return block_det(L, M)


def block_det(L, M):
    """det of the 6 × 6 matrices with rows [L_i, M_i] (3 + 3 polynomial columns, batch (S, 6)):
    generalised Laplace expansion along the first three columns, det A = Σ_S ε(S) det L[S]
    det M[S^c] over the 20 row triples S, ε(S) = (−1)^(Σ_{i∈S} (i+1) + 6)."""
    n = max(p.degree for p in L + M)
    pad = lambda p: padded(p, n)  # noqa: E731
    lo = np.stack([np.stack([pad(x.lo) for x in L], 2), np.stack([pad(x.lo) for x in M], 2)], 1)   # (S, 2, 6, 3, n+1)
    hi = np.stack([np.stack([pad(x.hi) for x in L], 2), np.stack([pad(x.hi) for x in M], 2)], 1)
    rows = np.stack([_SUBSETS, _COMPLEMENTS])                                             # (2, 20, 3)
    sel = np.arange(2)[:, None, None]
    X = Poly(lo[:, sel, rows], hi[:, sel, rows])                                          # (S, 2, 20, 3, 3)
    d = det3(X)                                                                          # (S, 2, 20)
    terms = d[:, 0] * d[:, 1]                                                             # (S, 20)
    s = _SIGNS[:, None]
    tlo = np.where(s > 0, terms.lo, -terms.hi)
    thi = np.where(s > 0, terms.hi, -terms.lo)
    return Poly(tlo, thi).sum(axis=1)


class Determinant(Family):
    """det(A): the robot's symbolic det, or a Laplace expansion of the compiled entries of A."""

    constraint = "singularity"
    key = "det"
    sign_only = True

    @classmethod
    def build(cls, robot, base):
        return cls(robot, base)

    def __init__(self, robot, base):
        """``base``: the base points A_i as three (n,) enclosures (for the Gough-Stewart rows)."""
        self.robot = robot
        self.base = base
        self.laplace = "det" not in robot.model_parts()
        self.compiled = robot.compiled("A" if self.laplace else "det")
        self.n, self.d = robot.n_legs, len(robot.pose_names)
        self.instances = [Instance("singularity", tuple(range(1, self.n + 1)))]

    def __call__(self, variables):
        out = self.compiled.evaluate(variables, self.robot.parameters)
        if not self.laplace:
            return out[0]
        return linalg.laplace_det([[out[i * self.d + j] for j in range(self.d)] for i in range(self.n)])

    def natural(self, legs, C):
        """Gough-Stewart: the natural enclosure over (M,) boxes from the leg vectors and C."""
        return gough_det(legs, self.base, C)

    def polynomials(self, pose, linear=None, P0=None, var=None):
        if var is None:                      # constant orientation: Gough-Stewart only (degree ≤ 6)
            if not self.laplace:
                return None
            return [gough_det_poly(linear["V"], linear["w"], self.base, [P0[:, k] for k in range(3)])]
        if self.laplace:
            C = [var[k] for k in range(3)]
            arm = [broadcast(self.base[k], pose.legs[0]) - Poly(np.repeat(C[k].lo[:, None], self.n, 1),
                                                                 np.repeat(C[k].hi[:, None], self.n, 1))
                   for k in range(3)]
            return [block_det(pose.legs, cross(arm, pose.legs))]
        return [self(var)]

    def margins(self, path, rho, upper):
        dlo, dhi = path.range_det(self)
        state = np.where((dlo > 0) | (dhi < 0), SATISFIED, UNKNOWN)
        return dlo[:, None], dhi[:, None], state[:, None]

    def crossings(self, polys, put):
        if self.key in polys:
            put(self.columns.start, 0, polys[self.key][0])
