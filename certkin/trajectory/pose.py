"""The pose along a path: leg vectors l_i (and R) over t-intervals, and the vector algebra on them.

Along a segment pose(t) = P + t D.  ``PathPose`` holds the leg vectors (and, for robots whose
model has one, the rotation R) over a batch of t-intervals in one of three forms: ``autodiff.Dual``
values over T (value and t-derivative), thin intervals at points of T, or polynomials in t
(``intervals.polynomial.Poly``), with the constructors for each.  The helpers (``dot``,
``cross``, ``vector``, ...) take the components of 3-vectors in any of these forms, so each
constraint family (``trajectory.families``) writes its functions once.
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, stack
from intervals.autodiff import Dual
from intervals.polynomial import Poly, padded

LENGTHS = "legs_sq"     # the name of the squared leg lengths in a path evaluator


def enclose_all(values) -> Interval:
    return Interval.from_bounds(np.array([float(v.lo) for v in values]), np.array([float(v.hi) for v in values]))


def columns(x, idx):
    """Columns ``idx`` of an (M, n) Interval or Dual."""
    if isinstance(x, Dual):
        return Dual(x.value[:, idx], x.grad[:, idx, :])
    return x[:, idx]


def stack_values(items):
    """(M,) values -> (M, n)."""
    if isinstance(items[0], Dual):
        return Dual(stack([i.value for i in items], axis=-1), stack([i.grad for i in items], axis=-2))
    return stack(items, axis=-1)


def dot(a, b):
    """a · b for 3-vectors given as component lists (Poly components: one stacked product)."""
    if isinstance(a[0], Poly) and all(isinstance(x, (Poly, Interval)) for x in (*a, *b)):
        return (vector(a) * vector(b)).sum(axis=-1)
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    """a × b for 3-vectors given as component lists (Poly components: two stacked products)."""
    if isinstance(a[0], Poly) and all(isinstance(x, (Poly, Interval)) for x in (*a, *b)):
        A, B = vector(a), vector(b)
        first, second = [1, 2, 0], [2, 0, 1]
        c = A[(slice(None),) * (A.ndim - 1) + (first,)] * B[(slice(None),) * (B.ndim - 1) + (second,)] \
            - A[(slice(None),) * (A.ndim - 1) + (second,)] * B[(slice(None),) * (B.ndim - 1) + (first,)]
        return [c[(slice(None),) * (c.ndim - 1) + (k,)] for k in range(3)]
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def vector(components) -> Poly:
    """Three Poly (or Interval) components stacked on a last batch axis, one common degree."""
    polys = [x if isinstance(x, Poly) else Poly.from_coefficients([x]) for x in components]
    n = max(p.degree for p in polys)
    shape = np.broadcast_shapes(*(p.shape for p in polys))
    lo = np.stack([np.broadcast_to(padded(p.lo, n), shape + (n + 1,)) for p in polys], -2)
    hi = np.stack([np.broadcast_to(padded(p.hi, n), shape + (n + 1,)) for p in polys], -2)
    return Poly(lo, hi)


def stacked(polys, axis) -> Poly:
    """Polynomials of one batch shape stacked on a new batch ``axis``, padded to one degree."""
    n = max(p.degree for p in polys)
    axis = axis if axis >= 0 else axis - 1
    return Poly(np.stack([padded(p.lo, n) for p in polys], axis), np.stack([padded(p.hi, n) for p in polys], axis))


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


class PathPose:
    """Leg vectors (and R) along the path, as (M, n) components: Duals over T or thin intervals."""

    def __init__(self, outputs, n, M, with_R):
        like = next((o for o in outputs if isinstance(o, Dual)), None)
        fixed = []
        for o in outputs:
            if like is not None and not isinstance(o, Dual):
                o = like.lift(o if isinstance(o, Interval) else Interval(o))
            if isinstance(o, Dual):
                shape = (M,)
                o = Dual(Interval.from_bounds(np.broadcast_to(o.value.lo, shape), np.broadcast_to(o.value.hi, shape)),
                         Interval.from_bounds(np.broadcast_to(o.grad.lo, shape + (1,)), np.broadcast_to(o.grad.hi, shape + (1,))))
            else:
                o = o if isinstance(o, Interval) else Interval(o)
                o = Interval.from_bounds(np.broadcast_to(o.lo, (M,)), np.broadcast_to(o.hi, (M,)))
            fixed.append(o)
        self.legs = [stack_values([fixed[3 * i + k] for i in range(n)]) for k in range(3)]   # 3 x (M, n)
        self.R = [fixed[3 * n + k] for k in range(9)] if with_R else None             # row-major, (M,)

    @classmethod
    def from_polys(cls, outputs, n, S, with_R):
        """Leg vectors (and R) from polynomial outputs of the compiled model (constants allowed)."""
        polys = [o if isinstance(o, Poly) else Poly.from_coefficients([o]) for o in outputs]
        deg = max(p.degree for p in polys)
        fixed = []
        for p in polys:
            fixed.append(Poly(np.broadcast_to(padded(p.lo, deg), (S, deg + 1)), np.broadcast_to(padded(p.hi, deg), (S, deg + 1))))
        self = cls.__new__(cls)
        self.legs = [Poly(np.stack([fixed[3 * i + k].lo for i in range(n)], 1), np.stack([fixed[3 * i + k].hi for i in range(n)], 1))
                     for k in range(3)]
        self.R = [fixed[3 * n + k] for k in range(9)] if with_R else None
        return self

    @classmethod
    def linear(cls, V, w, R, t: Interval, dual: bool):
        """Constant orientation: l_i(t) = V_i + t w exactly (V (M, n) and w (M,) enclosed per
        row), at the t-intervals ``t`` (M,), as Duals (derivative w) or as intervals."""
        self = cls.__new__(cls)
        self.legs = []
        tc = t[:, None]
        for k in range(3):
            wk = w[k][:, None]
            value = V[k] + tc * wk
            if dual:
                shape = value.shape + (1,)
                g = Interval.from_bounds(np.broadcast_to(wk.lo[..., None], shape), np.broadcast_to(wk.hi[..., None], shape))
                value = Dual(value, g)
            self.legs.append(value)
        self.R = R
        return self

    @classmethod
    def polynomial(cls, V, w, R):
        """Constant orientation: l_i(t) = V_i + t w as polynomials in t (one row per segment)."""
        self = cls.__new__(cls)
        self.legs = []
        for k in range(3):
            shape = V[k].shape
            self.legs.append(Poly(np.stack([V[k].lo, np.broadcast_to(w[k].lo[:, None], shape)], -1),
                                  np.stack([V[k].hi, np.broadcast_to(w[k].hi[:, None], shape)], -1)))
        self.R = R
        return self

    def vector(self) -> Poly:
        """Polynomial legs as one (S, n, 3) Poly (built once)."""
        if getattr(self, "_vector", None) is None:
            self._vector = stacked(self.legs, 2)
        return self._vector

    def rows(self, idx):
        """The same pose data restricted to the batch rows ``idx``."""
        out = PathPose.__new__(PathPose)
        out.legs = [x[idx] for x in self.legs]
        out.R = None if self.R is None else [r[idx] for r in self.R]
        return out

    def rotate(self, v):
        """R v for constant vectors v (3 arrays of shape (n,)) -> 3 x (M, n)."""
        R = self.R
        return [stack_rows(R[3 * r], v[0]) + stack_rows(R[3 * r + 1], v[1]) + stack_rows(R[3 * r + 2], v[2])
                for r in range(3)]


def stack_rows(x, v: Interval):
    """x (M,) times v (n,) -> (M, n)."""
    n = v.shape[0]
    if isinstance(x, Poly):
        xv = Poly(np.repeat(x.lo[:, None], n, 1), np.repeat(x.hi[:, None], n, 1))
    elif isinstance(x, Dual):
        xv = Dual(Interval.from_bounds(np.repeat(x.value.lo[:, None], n, 1), np.repeat(x.value.hi[:, None], n, 1)),
                  Interval.from_bounds(np.repeat(x.grad.lo[:, None, :], n, 1), np.repeat(x.grad.hi[:, None, :], n, 1)))
    else:
        xv = Interval.from_bounds(np.repeat(x.lo[:, None], n, 1), np.repeat(x.hi[:, None], n, 1))
    return xv * v


def broadcast(v: Interval, like):
    """A constant (n,) interval vector broadcast to the (M, n) shape of ``like`` (Interval or Dual)."""
    shape = like.value.shape if isinstance(like, Dual) else like.shape
    return Interval.from_bounds(np.broadcast_to(v.lo, shape), np.broadcast_to(v.hi, shape))


def legs_squared(pose: PathPose):
    """|l_i|² for every leg: the squared leg lengths, shared by the leg-length and joint families."""
    L = pose.legs
    if isinstance(L[0], Poly):
        vec = pose.vector()
        return [(vec * vec).sum(axis=-1)]
    return [dot(L, L)]
