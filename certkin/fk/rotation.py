"""Enclosures of the rotated platform points R b_i: midpoint-radius, centred, derivatives, slopes.

A base class of ``FKSystem`` (``fk.system``): for a quaternion, R(q) b_i is quadratic in q, so

- R b_i over a box is enclosed in midpoint-radius form (``rotated_midrad``: one float matrix
  product and a proved rounding bound, ``intervals.midrad``), at float points as well
  (``rotation_at_points``);
- its centred form R b_i(c) + Σ_r ∂(R b_i)/∂q_r(Y)(x_r − c_r), Y ∋ (x + c)/2, is exact for a
  quadratic (``rotated_centred``, ``centred_form``), and the derivatives are linear in q, each
  q_s once (``rotated_derivatives_midrad``);
- the slope matrix of the equations at c (``slope``) follows from the same parts, about half as
  wide as the Jacobian over the box (docs/soundness.md §8).

The planar rotation (c, s) is linear: its enclosures are the natural interval ones.
"""
from __future__ import annotations

import numpy as np

from intervals import Interval
from intervals.midrad import ETA, U, midrad, product_midrad, upper
from intervals.rounding import down, down_sum, up, up_sum


# dR/dq_r of the quaternion rotation (see FKSystem.rotation_derivatives) as indices into
# [0, 2q0..2q3, -2q0..-2q3, -4q0..-4q3]
DQ_INDEX = np.array([[[0, 8, 3], [4, 0, 6], [7, 2, 0]],
                      [[0, 3, 4], [3, 10, 5], [4, 1, 10]],
                      [[11, 2, 1], [2, 0, 4], [5, 4, 11]],
                      [[12, 5, 2], [1, 12, 3], [2, 3, 0]]])

# the entries of the quaternion rotation R(q) (module docstring), quaternion indices 0..3:
# R_kj = 2(q_a q_b + σ q_c q_d) off the diagonal: ((k, j), (a, b), (c, d), σ)
OFF_DIAGONAL = (((0, 1), (1, 2), (0, 3), -1), ((1, 0), (1, 2), (0, 3), 1),
                ((0, 2), (1, 3), (0, 2), 1), ((2, 0), (1, 3), (0, 2), -1),
                ((1, 2), (2, 3), (0, 1), -1), ((2, 1), (2, 3), (0, 1), 1))

DIAGONAL = ((0, 2, 3), (1, 1, 3), (2, 1, 2))     # R_kk = 1 − 2(q_a² + q_b²): (k, a, b)


def _tables():
    """R(q)'s entries as integer tables for the kernels (from ``DIAGONAL`` / ``OFF_DIAGONAL``): entries
    (3, 3, 5) rows (kind, a, b, c, d), kind 0 for 1 − 2(q_a² + q_b²), kind σ = ±1 for
    2(q_a q_b + σ q_c q_d); off (6, 7) rows (k, j, a, b, c, d, σ) in the order of HC4's step 7."""
    entries = np.zeros((3, 3, 5), dtype=np.int64)
    for k, a, b in DIAGONAL:
        entries[k, k] = (0, a, b, 0, 0)
    for (k, j), (a, b), (c, d), sigma in OFF_DIAGONAL:
        entries[k, j] = (sigma, a, b, c, d)
    off = np.array([(k, j, a, b, c, d, sigma) for (k, j), (a, b), (c, d), sigma in OFF_DIAGONAL], dtype=np.int64)
    return entries, off


TABLES = _tables()


def from_midrad(m, r) -> Interval:
    """[m ± r] outward rounded (an infinite r gives the entire line)."""
    with np.errstate(invalid="ignore", over="ignore"):
        lo, hi = down(m - r), up(m + r)
    bad = np.isnan(lo)
    if bad.any():
        lo = np.where(bad, -np.inf, lo)
    bad = np.isnan(hi)
    if bad.any():
        hi = np.where(bad, np.inf, hi)
    return Interval.from_bounds(lo, hi)


class RotatedPoints:
    """The enclosures of R b_i of an ``FKSystem`` (see the module docstring)."""

    def rotation_at_points(self, c: np.ndarray):
        """Quaternion: (Rm, Rr), (N, 3, 3): R(c) at the float points c (N, n) lies in [Rm ± Rr].

        Each entry is a float dot product of length at most three with exact factors 2
        (1 − 2(q_a² + q_b²) or 2(q_a q_b ± q_c q_d)), so it is within γ_3 Σ|terms| ≤ 4u Σ|terms| of the
        exact value, plus 3·2⁻¹⁰²² for underflow (Higham 2002, eq. 3.5, any order of summation); the
        float Σ|terms| (non-negative, at most 4 roundings) is bounded by ``midrad.upper``
        (docs/soundness.md §8, "midpoint-radius R b_i")."""
        p = self.n_pos
        q = [c[:, p + k] for k in range(4)]
        with np.errstate(invalid="ignore", over="ignore"):
            Rm = self.float_rotation(c)                               # the float dot products
            mag = np.empty_like(Rm)                                    # Σ|terms| of each entry
            for k, a, b in DIAGONAL:                                   # 1 − 2(q_a² + q_b²)
                mag[:, k, k] = 1.0 + 2.0 * (q[a] * q[a] + q[b] * q[b])
            for (k, j), (a, b), (c_, d), _ in OFF_DIAGONAL:            # 2(q_a q_b + σ q_c q_d)
                mag[:, k, j] = 2.0 * (np.abs(q[a] * q[b]) + np.abs(q[c_] * q[d]))
            Rr = upper(4.0 * U * mag, 6) + 3 * ETA
        return Rm, Rr

    def rotated_at_points(self, c: np.ndarray) -> Interval:
        """R b_i at the float points c (N, n): (N, legs, dim) (quaternion: from ``rotation_at_points``)."""
        if self.kind == "planar-3rpr":
            return self.rotated(self.rotation(Interval.from_bounds(c, c.copy())))
        return from_midrad(*self.rotated_midrad(self.rotation_at_points(c)))

    def b_midrad(self):
        """(bm, inner, outer), each (dim, (dim + 1) legs): b_ij in [bm ± br], inner = (n + 1) u |bm| + br,
        outer = |bm| + br (n = dim), the factors of ``rotated_midrad``: the first legs columns for
        R b_i, then, for each column j of R, the same with b_ij set to 0 (the sums that leave column j
        out).  Computed once."""
        t = self.__dict__.get("_b_midrad_")
        if t is None:
            bm, br = midrad(self.b.lo, self.b.hi)
            dim = bm.shape[1]
            full = (bm.T, ((dim + 1) * U * np.abs(bm) + br).T, (np.abs(bm) + br).T)   # (dim, legs)
            keep = np.concatenate([np.ones((1, dim)), 1.0 - np.eye(dim)])[:, :, None]   # (dim + 1, dim, 1)
            t = self._b_midrad_ = tuple(np.ascontiguousarray(np.moveaxis(keep * v[None], 0, 1).reshape(dim, -1))
                                        for v in full)
        return t

    def rotated_midrad(self, R: Interval, columns: bool = False):
        """(m, r): R b_i in [m ± r] for every R in the interval matrices (..., dim, dim) and every b_ij
        in its enclosure: (..., legs, dim) each.  With R_kj in [Rm ± Rr], b_ij in [bm ± br],
        |R_kj b_ij − Rm bm| ≤ |Rm| br + Rr (|bm| + br); the float sum of the dim products
        Rm_kj bm_ij (a float matrix product, any order) is within γ_dim Σ_j |Rm_kj||bm_ij| +
        dim·2⁻¹⁰²² of the exact one (Higham 2002, eq. 3.5, γ_n ≤ (n + 1) u), and the float radius is
        bounded by ``midrad.upper`` (docs/soundness.md §8, "midpoint-radius R b_i"): the bound of
        ``midrad.product_midrad``.  ``columns``: also, per column j, the same for the sums that leave
        column j out, Σ_{j'≠j} R_kj' b_ij' (b_ij set to 0): (..., legs, dim, dim) each, j last.
        ``R`` may also be given as (Rm, Rr), R in [Rm ± Rr] (``rotation_at_points``)."""
        bm, inner, outer = self.b_midrad()
        dim = bm.shape[0]
        legs = self.legs
        if not columns:
            bm, inner, outer = bm[:, :legs], inner[:, :legs], outer[:, :legs]
        with np.errstate(invalid="ignore", over="ignore"):
            Rm, Rr = midrad(R.lo, R.hi) if isinstance(R, Interval) else R
            lead = Rm.shape[:-2]
            Rm, Rr = Rm.reshape(-1, dim), Rr.reshape(-1, dim)
            m = Rm @ bm
            r = upper(np.abs(Rm) @ inner + Rr @ outer, 4 * dim + 4) + dim * ETA
            bad = ~(np.isfinite(m) & np.isfinite(r))
            if bad.any():
                m, r = np.where(bad, 0.0, m), np.where(bad, np.inf, r)
        if not columns:
            return (np.swapaxes(m.reshape(lead + (dim, legs)), -1, -2),
                    np.swapaxes(r.reshape(lead + (dim, legs)), -1, -2))
        m = m.reshape(lead + (dim, dim + 1, legs))                # (..., k, block, i)
        r = r.reshape(lead + (dim, dim + 1, legs))
        full = (np.swapaxes(m[..., 0, :], -1, -2), np.swapaxes(r[..., 0, :], -1, -2))
        left_out = tuple(np.moveaxis(v[..., 1:, :], (-3, -2, -1), (-2, -1, -3)) for v in (m, r))   # (..., i, k, j)
        return full + left_out

    def rotated_centred(self, X: Interval, c: np.ndarray | None = None, rb: Interval | None = None,
                        parts: bool = False, form: tuple | None = None):
        """R b_i over the boxes (N, legs, dim): the natural enclosure (``rotated``, or ``rb``) intersected,
        for a quaternion, with the centred form R b_i(c) + Σ_r ∂(R b_i)/∂q_r(Y) (X_r − c_r), c = X.mid()
        unless given (any float points) and Y ∋ (x + c)/2 — exact for R b_i, quadratic in q
        (docs/soundness.md §8).  ``parts`` (quaternion): also R b_i at c and the derivatives over Y
        (midpoints and radii, (N, 4, legs, dim) each), which ``slope`` at the same c reuses (they
        depend only on the rotation part of X and c).  ``form``: ``centred_form(X)``, if known
        (c = X.mid())."""
        if self.kind == "planar-3rpr":
            return self.rotated(self.rotation(X)) if rb is None else rb
        if c is None:
            lo, hi, cm, cr, Dm, Dr = self.centred_form(X) if form is None else form
        else:
            lo, hi, cm, cr, Dm, Dr = self._centred_form_at(X, c)
        if rb is None:      # the natural enclosure ∩ the form in one machine-code pass
            out = self.rotated_box(X, form=(lo, hi))
        else:
            with np.errstate(invalid="ignore"):
                out = Interval.from_bounds(np.fmax(rb.lo, lo), np.fmin(rb.hi, hi))   # NaN (non-finite input): natural
        if not parts:
            return out
        return out, from_midrad(cm, cr), (Dm, Dr)

    def rotated_box(self, X: Interval, form: tuple | None = None) -> Interval:
        """R b_i over the boxes X (N, legs, dim), the natural enclosure ``rotated(rotation(X))``; for a
        quaternion by the machine-code ``kernels.rotated_quaternion`` (the same interval operations
        for R, the same bound for R b_i, its float sums in another order), intersected with the
        bounds (lo, hi) ``form`` of a centred form if given (a NaN bound there is ignored)."""
        if self.kind == "planar-3rpr":
            return self.rotated(self.rotation(X))
        from .centred import rotated_quaternion      # numba: imported by the spatial searches only
        bm, inner, outer = self.b_midrad()
        f64 = np.ascontiguousarray
        flo, fhi = (f64(v, dtype=np.float64) for v in form) if form is not None else (np.empty((0, self.legs, 3)),) * 2
        lo, hi = rotated_quaternion(f64(X.lo, dtype=np.float64), f64(X.hi, dtype=np.float64), self.n_pos, bm, inner,
                                    outer, TABLES[0], flo, fhi, form is not None)
        return Interval.from_bounds(lo, hi)

    def centred_form(self, X: Interval, native: bool = True):
        """Quaternion: (lo, hi, cm, cr, Dm, Dr): the centred form of R b_i over the boxes X around
        their midpoints c = X.mid(), [lo, hi] (N, legs, dim), with R b_i(c) in [cm ± cr] and the
        derivatives over Y ∋ (x + c)/2 in [Dm ± Dr] (N, 4, legs, dim) (``rotated_centred``); by the
        machine-code twin (``fk.centred``) unless ``native`` is false."""
        p = self.n_pos
        if native:      # the same operations box by box (``fk.centred``)
            from .centred import centred_form_quaternion      # numba: imported by the spatial searches only
            return centred_form_quaternion(np.ascontiguousarray(X.lo, dtype=np.float64),
                                           np.ascontiguousarray(X.hi, dtype=np.float64), p, *self._centred_tables())
        c = X.mid()
        cm, cr, Dm, Dr = self._centre_parts(X, c)
        with np.errstate(invalid="ignore", over="ignore"):
            # c = X.mid(): X_r − c_r ⊆ [−h_r, h_r], so Σ_r ∂(R b_i)/∂q_r(Y) (X_r − c_r) ⊆ ±Σ_r (|Dm_r| + Dr_r) h_r,
            # and R b_i(c) + that lies in [cm ± (cr + Σ_r (|Dm_r| + Dr_r) h_r)], whose float radius
            # (non-negative terms, at most 8 roundings) is bounded by ``_upper``
            h = np.maximum(up_sum(c[:, p:] - X.lo[:, p:]), up_sum(X.hi[:, p:] - c[:, p:]))      # (N, 4)
            rad = upper(cr + np.add.reduce((np.abs(Dm) + Dr) * h[:, :, None, None], axis=1), 8)
            lo, hi = down(cm - rad), up(cm + rad)
        return lo, hi, cm, cr, Dm, Dr

    def _centred_tables(self):
        """The constant factors of ``centred_form_quaternion``: ``b_midrad`` and the derivative tables G
        with ``product_midrad``'s factors 5u|Gm| + Gr and |Gm| + Gr.  Computed once."""
        t = self.__dict__.get("_centred_tables_")
        if t is None:
            Gm, Gr = self._quaternion_tables()
            t = self._centred_tables_ = tuple(np.ascontiguousarray(v) for v in (
                *self.b_midrad(), Gm, 5 * U * np.abs(Gm) + Gr, np.abs(Gm) + Gr))
        return t

    def _centre_parts(self, X: Interval, c: np.ndarray):
        """R b_i at the points c in midpoint-radius form [cm ± cr] (N, legs, dim) and its quaternion
        derivatives over Y ∋ (x + c)/2, x ∈ X, in [Dm ± Dr] (N, 4, legs, dim)."""
        cm, cr = self.rotated_midrad(self.rotation_at_points(c))
        with np.errstate(invalid="ignore", over="ignore"):
            Y = Interval.from_bounds(down(0.5 * down_sum(X.lo + c)), up(0.5 * up_sum(X.hi + c)))
            Dm, Dr = self.rotated_derivatives_midrad(Y)
        return cm, cr, Dm, Dr

    def _centred_form_at(self, X: Interval, c: np.ndarray):
        """``centred_form`` around any float points c in the boxes."""
        p = self.n_pos
        cm, cr, Dm, Dr = self._centre_parts(X, c)
        with np.errstate(invalid="ignore", over="ignore"):
            # any c: X_r − c_r in [em ± er]; the five-term sum cm + Σ_r Dm_r em_r is within
            # γ_5 (|cm| + Σ_r |Dm_r em_r|) + 5·2⁻¹⁰²² of its float value (Higham 2002, eq. 3.5), the exact
            # radius cr + Σ_r |Dm_r| er_r + Dr_r (|em_r| + er_r) is evaluated in floats and bounded by
            # ``_upper`` (at most 40 roundings)
            em, er = midrad(down_sum(X.lo[:, p:] - c[:, p:]), up_sum(X.hi[:, p:] - c[:, p:]))
            em, er = em[:, :, None, None], er[:, :, None, None]
            t = Dm * em
            mid = cm + np.add.reduce(t, axis=1)
            rad = np.add.reduce(np.abs(Dm) * er + Dr * (np.abs(em) + er), axis=1)
            mag = np.abs(cm) + np.add.reduce(np.abs(t), axis=1)
            rad = upper(cr + rad + 6.0 * U * mag, 40) + 5 * ETA
            lo, hi = down(mid - rad), up(mid + rad)
        return lo, hi, cm, cr, Dm, Dr

    def slope(self, X: Interval, c: np.ndarray, rb: Interval | None = None, rbc: Interval | None = None,
              drbs: list | None = None) -> Interval:
        """Enclosure of slope matrices of the equations at the points ``c`` (N, n) in the boxes X:
        (N, n, n) holding, for every x in X, a matrix S with f(x) − f(c) = S (x − c) (``rb``,
        ``rbc``, ``drbs``: R b_i over X, at c and its derivatives over Y below, if known).

        R b_i is quadratic in the rotation unknowns (linear in (c, s)), so R b_i(x) − R b_i(c) =
        ∇(R b_i)(y) (x − c) exactly at y = (x + c)/2; with ell = p + R b_i − a_i,
        ell_k(x)² − ell_k(c)² = (ell_k(x) + ell_k(c)) (ell_k(x) − ell_k(c)).  Hence row i is
        Σ_k (ell_ik(X) + ell_ik(c)) [e_k, ∇(R b_i)_k(Y)] with Y ∋ (x + c)/2, and the norm row is
        (X_r + c_r) over the rotation unknowns r: about half as wide as the Jacobian over X
        (docs/soundness.md §8, slopes).
        """
        N = X.shape[0]
        p = self.n_pos
        point = Interval.from_bounds(c, c.copy())
        if rb is None:
            rb = self.rotated(self.rotation(X))
        if rbc is None:
            rbc = self.rotated_at_points(c)
        ell = rb - self.a[None, :, :]
        ellc = rbc - self.a[None, :, :]
        if p:
            ell = ell + X[:, None, :p]
            ellc = ellc + point[:, None, :p]
        s = ell + ellc                                        # (N, legs, dim)
        with np.errstate(invalid="ignore", over="ignore"):
            Y = Interval.from_bounds(down(0.5 * down_sum(X.lo + c)), up(0.5 * up_sum(X.hi + c)))  # ∋ (x + c)/2
        S = Interval.from_bounds(np.zeros((N, self.n, self.n)), np.zeros((N, self.n, self.n)))
        legs = self.legs
        for k in range(p):
            S[:, :legs, k] = s[..., k]
        if self.kind != "planar-3rpr":
            # quaternion: Σ_k s_k ∂(R b_i)_k/∂q_r(Y), interval products and sums, the 4 unknowns at once
            Dm, Dr = self.rotated_derivatives_midrad(Y) if drbs is None else drbs   # (N, 4, legs, dim)
            D = from_midrad(Dm, Dr)
            s4 = Interval.from_bounds(s.lo[:, None], s.hi[:, None])
            col = s4[..., 0] * D[..., 0]
            for k in range(1, D.shape[-1]):
                col = col + s4[..., k] * D[..., k]                                 # (N, 4, legs)
            S.lo[:, :legs, p:] = np.swapaxes(col.lo, 1, 2)
            S.hi[:, :legs, p:] = np.swapaxes(col.hi, 1, 2)
        else:
            if drbs is None:
                drbs = self._rotated_derivatives(Y)
            for r, drb in enumerate(drbs):                      # ∂(R b_i)_k / ∂r over Y: (N, legs, dim)
                col = s[..., 0] * drb[..., 0]
                for k in range(1, drb.shape[-1]):
                    col = col + s[..., k] * drb[..., k]
                S[:, :legs, p + r] = col
        for k in range(p, self.n):
            S[:, legs, k] = X[:, k] + point[:, k]
        return S

    def _rotated_derivatives(self, X: Interval):
        """∂(R b_i)/∂r over the boxes for each rotation unknown r: a list of (N, legs, dim).

        Quaternion: ∂(R b_i)_k/∂q_r = Σ_s G[s, r, i, k] q_s is linear in q, each q_s once
        (``_quaternion_tables``), so its range over the box is mid ± radius, enclosed in
        midpoint-radius arithmetic (``midrad.product_midrad``: one float matrix product and a
        proved rounding bound).  Planar: constant matrices, ``rotated`` of ``rotation_derivatives``."""
        if self.kind == "planar-3rpr":
            return [self.rotated(dR) for dR in self.rotation_derivatives(X)]
        return self._derivatives_from_midrad(*self.rotated_derivatives_midrad(X))

    def rotated_derivatives_midrad(self, X: Interval):
        """Quaternion: (m, r), (N, 4, legs, dim): ∂(R b_i)_k/∂q_r over the boxes lies in [m ± r]
        (``midrad.product_midrad``; rows with a non-finite input: m = 0, r = ∞)."""
        Gm, Gr = self._quaternion_tables()
        p = self.n_pos
        N = X.shape[0]
        with np.errstate(invalid="ignore", over="ignore"):
            qm, qr = midrad(X.lo[:, p:], X.hi[:, p:])
            m, r = product_midrad(qm, qr, Gm, Gr)                        # (N, 4 legs dim)
            bad = ~(np.isfinite(m) & np.isfinite(r))
        if bad.any():
            m, r = np.where(bad, 0.0, m), np.where(bad, np.inf, r)
        shape = (N, 4, self.legs, self.b.shape[1])
        return m.reshape(shape), r.reshape(shape)

    def _derivatives_from_midrad(self, m, r):
        """The list of the 4 derivative enclosures (N, legs, dim) from (m, r) (N, 4, legs, dim)."""
        D = from_midrad(m, r)
        return [Interval.from_bounds(D.lo[:, k], D.hi[:, k]) for k in range(4)]

    def _quaternion_tables(self):
        """(Gm, Gr), (4, 4 legs dim): ∂(R b_i)_k/∂q_r = Σ_s G[s, r, i, k] q_s with G in [Gm ± Gr].
        Each row of dR/dq_r (``rotation_derivatives``) holds distinct unknowns, so each entry is
        c b_ij for one j, c in {±2, ±4}: a scaling by a power of two, exact on the enclosure of b_ij."""
        tables = self.__dict__.get("_quaternion_tables_")
        if tables is None:
            bm, br = midrad(self.b.lo, self.b.hi)                          # (legs, dim)
            legs, dim = bm.shape
            Gm, Gr = np.zeros((4, 4, legs, dim)), np.zeros((4, 4, legs, dim))
            coef = np.array([0.0, 2.0, 2.0, 2.0, 2.0, -2.0, -2.0, -2.0, -2.0, -4.0, -4.0, -4.0, -4.0])
            var = np.array([-1, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3])
            for r in range(4):
                for k in range(3):
                    for j in range(3):
                        t = DQ_INDEX[r, k, j]
                        if t:
                            Gm[var[t], r, :, k] += coef[t] * bm[:, j]
                            Gr[var[t], r, :, k] += abs(coef[t]) * br[:, j]
            tables = self._quaternion_tables_ = (Gm.reshape(4, -1), Gr.reshape(4, -1))
        return tables
