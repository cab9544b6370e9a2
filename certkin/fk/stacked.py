"""The FK equations of ``fk.system`` evaluated with few, large interval operations.

``StackedFKSystem`` is an ``FKSystem`` whose rotation, rotated points,
equations and Jacobian perform *the same* outward-rounded interval
operations on the same operands as ``FKSystem``'s — so the enclosures are
identical, bit for bit (``tests/test_fk.py`` checks it) — but stacked: the
six quaternion products in one call, the rotated platform points of every
leg and coordinate in one call, the four rotation derivatives of the
Jacobian in one call.  ``FKSystem`` spends most of its time in the Python
and numpy overhead of ~200 small operations per evaluation; this class
makes ~30.  Used where few boxes are evaluated at a time (tracking).
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, mul, sqr
from intervals.rounding import down, down_sum, up, up_sum

from .system import FKSystem

# R(q) entries in the order [R00, R11, R22, R10, R02, R21, R01, R20, R12] (see rotation) -> row-major
_R_ORDER = np.array([0, 6, 4, 3, 1, 8, 7, 5, 2])
# dR/dq_r, as in FKSystem._rotation_derivatives with q_k = 2 X_k: indices into
# [0, q0..q3, -q0..-q3, (-2.0 q0)..(-2.0 q3)]
_DQ = np.array([[[0, 8, 3], [4, 0, 6], [7, 2, 0]],
                [[0, 3, 4], [3, 10, 5], [4, 1, 10]],
                [[11, 2, 1], [2, 0, 4], [5, 4, 11]],
                [[12, 5, 2], [1, 12, 3], [2, 3, 0]]])
# planar d/dc = [[1, 0], [0, 1]], d/ds = [[0, -1], [1, 0]]: indices into [0, 1, -1]
_DCS = np.array([[[1, 0], [0, 1]], [[0, 2], [1, 0]]])


def _scaled(x: Interval, k: float) -> Interval:
    """``x * k`` for a float k ≠ 0, with ``mul``'s operations on ``x`` and the point interval
    [k, k]: its four corner products are two distinct ones, so the same floats in fewer operations
    (no 0 · ∞ can occur, so no invalid-operation flag to silence)."""
    a, b = x.lo * k, x.hi * k
    return Interval.from_bounds(down(np.fmin(a, b)), up(np.fmax(a, b)))


def _sum_last(v: Interval) -> Interval:
    """v[..., 0] + v[..., 1] + ... (left to right, as FKSystem sums; Interval.__add__'s operations
    on the endpoint arrays)."""
    lo, hi = v.lo, v.hi
    slo, shi = lo[..., 0], hi[..., 0]
    for k in range(1, lo.shape[-1]):
        slo, shi = down_sum(slo + lo[..., k]), up_sum(shi + hi[..., k])
    return Interval.from_bounds(slo, shi)


class StackedFKSystem(FKSystem):
    """``FKSystem`` with stacked evaluation (identical enclosures; see the module docstring)."""

    @classmethod
    def of(cls, system: FKSystem) -> "StackedFKSystem":
        """The stacked twin of an existing system (shares its data; built once per system)."""
        if isinstance(system, cls):
            return system
        twin = system.__dict__.get("_stacked_twin")
        if twin is None:
            twin = object.__new__(cls)
            twin.__dict__.update(system.__dict__)
            system._stacked_twin = twin
        return twin

    def rotation(self, X: Interval) -> Interval:
        lead = X.shape[:-1]
        p = self.n_pos
        if self.kind == "planar-3rpr":
            c, s = X[..., 2], X[..., 3]
            lo = np.stack([c.lo, -s.hi, s.lo, c.lo], -1)
            hi = np.stack([c.hi, -s.lo, s.hi, c.hi], -1)
            return Interval.from_bounds(lo.reshape(lead + (2, 2)), hi.reshape(lead + (2, 2)))
        q = X[..., p:p + 4]
        a = Interval.from_bounds(q.lo[..., [1, 1, 2]], q.hi[..., [1, 1, 2]])   # q1 q2, q1 q3, q2 q3
        b = Interval.from_bounds(q.lo[..., [2, 3, 3]], q.hi[..., [2, 3, 3]])
        c = Interval.from_bounds(q.lo[..., [0, 0, 0]], q.hi[..., [0, 0, 0]])   # q0 q3, q0 q2, q0 q1
        d = Interval.from_bounds(q.lo[..., [3, 2, 1]], q.hi[..., [3, 2, 1]])
        u, v = mul(a, b), mul(c, d)
        plus, minus = u + v, u - v                                        # [R10, R02, R21] / 2, [R01, R20, R12] / 2
        s = sqr(q[..., 1:])                                               # s1, s2, s3
        diag = Interval.from_bounds(s.lo[..., [1, 0, 0]], s.hi[..., [1, 0, 0]]) \
            + Interval.from_bounds(s.lo[..., [2, 2, 1]], s.hi[..., [2, 2, 1]])    # s2 + s3, s1 + s3, s1 + s2
        parts = 2.0 * Interval.from_bounds(np.concatenate([diag.lo, plus.lo, minus.lo], -1),
                                    np.concatenate([diag.hi, plus.hi, minus.hi], -1))
        ones = 1.0 - parts[..., :3]
        lo = np.concatenate([ones.lo, parts.lo[..., 3:]], -1)[..., _R_ORDER]
        hi = np.concatenate([ones.hi, parts.hi[..., 3:]], -1)[..., _R_ORDER]
        return Interval.from_bounds(lo.reshape(lead + (3, 3)), hi.reshape(lead + (3, 3)))

    def rotated(self, R: Interval) -> Interval:
        """R b_i for every leg: (..., legs, dim) for R (..., dim, dim) (quaternion: ``FKSystem.rotated``,
        elementwise already)."""
        if self.kind != "planar-3rpr":
            return FKSystem.rotated(self, R)
        b = self.b
        prod = mul(Interval.from_bounds(R.lo[..., None, :, :], R.hi[..., None, :, :]),
                   Interval.from_bounds(b.lo[:, None, :], b.hi[:, None, :]))
        return _sum_last(prod)

    def _planar_drb(self) -> Interval:
        """Planar: d(R b_i)/dc and d(R b_i)/ds, (2, legs, 2): R is linear in (c, s), so these are
        ``rotated`` of the constant derivative matrices — computed once, with the same operations."""
        drb = self.__dict__.get("_planar_drb_")
        if drb is None:
            d = np.array([0.0, 1.0, -1.0])[_DCS]
            drb = self._planar_drb_ = self.rotated(Interval.from_bounds(d, d.copy()))
        return drb

    def position_system(self, X: Interval, L: Interval, R: Interval | None = None, rb: Interval | None = None):
        """``FKSystem.position_system`` with its constant differences (a_i − a_1, |a_i|² + |b_i|² −
        |a_1|² − |b_1|²) computed once and its scalings by 2 as ``_scaled``: the same floats."""
        if rb is None:
            rb = self.rotated(self.rotation(X) if R is None else R)
        consts = self.__dict__.get("_position_consts")
        if consts is None:
            a = self.a[None, :, :]
            const = (self.norm_a2 + self.norm_b2)[None, :]
            consts = self._position_consts = (a, a[:, 1:, :] - a[:, :1, :], const[:, 1:] - const[:, :1])
        a, a_diff, const_diff = consts
        D = _scaled((rb[:, 1:, :] - rb[:, :1, :]) - a_diff, 2.0)
        arb_sum = _sum_last(mul(a, rb))                                   # a_i · R b_i  (N, legs)
        rhs = (_scaled(arb_sum[:, 1:] - arb_sum[:, :1], 2.0) - const_diff) + (L[:, 1:] - L[:, :1])
        return D, rhs

    def _equations_from(self, X: Interval, ell: Interval, L: Interval) -> Interval:
        if self.kind == "planar-3rpr":   # c² + s² − 1 stacked as a fourth "leg" (dim = 2 rotation unknowns)
            v = Interval.from_bounds(np.concatenate([ell.lo, X.lo[..., None, 2:]], -2),
                              np.concatenate([ell.hi, X.hi[..., None, 2:]], -2))
            one = np.ones(L.shape[:-1] + (1,))
            return _sum_last(sqr(v)) - Interval.from_bounds(np.concatenate([L.lo, one], -1), np.concatenate([L.hi, one], -1))
        legs = _sum_last(sqr(ell)) - L
        norm = _sum_last(sqr(X[..., self.n_pos:])) - 1.0
        return Interval.from_bounds(np.concatenate([legs.lo, norm.lo[..., None]], -1),
                             np.concatenate([legs.hi, norm.hi[..., None]], -1))

    def _jacobian_from(self, X: Interval, ell: Interval) -> Interval:
        p, legs, n = self.n_pos, self.legs, self.n
        lead = X.shape[:-1]
        if self.kind == "planar-3rpr":   # 2 ell_i and 2 (c, s) in one product; d(R b_i) constant
            two = _scaled(Interval.from_bounds(np.concatenate([ell.lo, X.lo[..., None, 2:]], -2),
                                        np.concatenate([ell.hi, X.hi[..., None, 2:]], -2)), 2.0)
            cols = _sum_last(mul(two[..., None, :legs, :], self._planar_drb()))   # (..., 2, legs)
            Jlo = np.zeros(lead + (n, n))
            Jhi = np.zeros(lead + (n, n))
            Jlo[..., :legs, :p], Jhi[..., :legs, :p] = two.lo[..., :legs, :], two.hi[..., :legs, :]
            Jlo[..., :legs, p:], Jhi[..., :legs, p:] = np.swapaxes(cols.lo, -1, -2), np.swapaxes(cols.hi, -1, -2)
            Jlo[..., legs, p:], Jhi[..., legs, p:] = two.lo[..., legs, :], two.hi[..., legs, :]
            return Interval.from_bounds(Jlo, Jhi)
        two_ell = _scaled(ell, 2.0)                                       # (..., legs, dim)
        q = _scaled(X[..., p:], 2.0)
        q2 = _scaled(q, -2.0)
        zero = np.zeros(lead + (1,))
        dlo = np.concatenate([zero, q.lo, -q.hi, q2.lo], -1)[..., _DQ]
        dhi = np.concatenate([zero, q.hi, -q.lo, q2.hi], -1)[..., _DQ]
        drb = self.rotated(Interval.from_bounds(dlo, dhi))                      # (..., r, legs, dim)
        cols = _sum_last(mul(two_ell[..., None, :, :], drb))             # (..., r, legs)
        Jlo = np.zeros(lead + (n, n))
        Jhi = np.zeros(lead + (n, n))
        Jlo[..., :legs, :p], Jhi[..., :legs, :p] = two_ell.lo[..., :p], two_ell.hi[..., :p]
        Jlo[..., :legs, p:], Jhi[..., :legs, p:] = np.swapaxes(cols.lo, -1, -2), np.swapaxes(cols.hi, -1, -2)
        Jlo[..., legs, p:], Jhi[..., legs, p:] = q.lo, q.hi
        return Interval.from_bounds(Jlo, Jhi)

    def _ell(self, X: Interval, R: Interval | None = None, rb: Interval | None = None) -> Interval:
        if rb is None:
            rb = self.rotated(self.rotation(X) if R is None else R)
        ell = rb - self.a
        if self.n_pos:
            ell = ell + X[..., None, :self.n_pos]
        return ell

    def equations(self, X: Interval, L: Interval, R: Interval | None = None, rb: Interval | None = None) -> Interval:
        return self._equations_from(X, self._ell(X, R, rb), L)

    def jacobian(self, X: Interval, R: Interval | None = None, rb: Interval | None = None) -> Interval:
        return self._jacobian_from(X, self._ell(X, R, rb))

    def krawczyk_data(self, X: Interval, L: Interval, points: bool = False):
        """(f(c), J(X), c) for boxes X (N, n): c = X.mid(), f at the point c, J over X — one stacked
        evaluation of the N boxes and the N points (``points``: also ``self.points(X)``, from the
        same R b_i)."""
        N = X.shape[0]
        c = X.mid()
        rows = Interval.from_bounds(np.concatenate([X.lo, c]), np.concatenate([X.hi, c]))
        rb = self.rotated(self.rotation(rows))
        ell = self._ell(rows, rb=rb)
        f = self._equations_from(rows[N:], ell[N:], L)
        J = self._jacobian_from(X, ell[:N])
        if points:
            rb = rb[:N]
            return f, J, c, (rb + X[:, None, :self.n_pos] if self.n_pos else rb)
        return f, J, c
