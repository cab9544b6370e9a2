"""The expansions of R b_i around the box midpoints (quaternion), box by box in machine code (numba).

- ``slope_quaternion``: ``FKSystem.slope`` and ``FKSystem.equations`` at the
  midpoints, from the same enclosures of R b_i, with the same operations
  (``tests/test_fk.py`` compares them).
- ``rotation_entries``: R over a box (``FKSystem.rotation``), step 2 of the HC4 kernel
  (``fk.kernels``);
- ``rotated_quaternion``: R b_i over boxes, the natural enclosure (R by ``rotation_entries``,
  R b_i in midpoint-radius form), ∩ a centred form (``FKSystem.rotated_box``);
- ``equations_quaternion``: ``FKSystem.equations`` over boxes from a known R b_i, the same floats.

``centred_form_quaternion`` is ``RotatedPoints.centred_form`` (``fk.rotation``): the same
operations, with the outward-rounded primitives of ``intervals.native``, for

- c, the float midpoint of the box (``Interval.mid``);
- R(c) in [Rm ± Rr] (``rotation_at_points``: the float entries, their Σ|terms| bound);
- R b_i(c) in [cm ± cr] (``rotated_midrad``) and the derivatives ∂(R b_i)/∂q_r over Y ∋ (x + c)/2 in
  [Dm ± Dr] (``rotated_derivatives_midrad``: ``product_midrad`` with the tables G);
- the form [cm ± (cr + Σ_r (|Dm_r| + Dr_r) h_r)], h_r ≥ |x_r − c_r|.

Only the float sums of the midpoint-radius products may be taken in another order than numpy's
matrix products, which their error bounds allow (Higham 2002, eq. 3.5; docs/soundness.md §8,
"midpoint-radius R b_i"); ``tests/test_fk_hc4.py`` compares the two.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from intervals.native import INF, MAX, down, down_sum, midrad, mul, scale, sqr, up, up_sum, upper

_U = 2.0 ** -53
_ETA = 2.0 ** -1022


@njit(cache=True, error_model="numpy")
def _rotation_at_point(q, Rm, Rr):
    """``rotation_at_points`` for one quaternion q: R(q) in [Rm ± Rr] (the expressions of
    ``FKSystem.float_rotation``, the Σ|terms| bound with 6 roundings)."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    Rm[0, 0], Rm[0, 1], Rm[0, 2] = 1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)
    Rm[1, 0], Rm[1, 1], Rm[1, 2] = 2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)
    Rm[2, 0], Rm[2, 1], Rm[2, 2] = 2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)
    mags = ((1.0 + 2.0 * (q2 * q2 + q3 * q3), 2.0 * (abs(q1 * q2) + abs(q0 * q3)), 2.0 * (abs(q1 * q3) + abs(q0 * q2))),
            (2.0 * (abs(q1 * q2) + abs(q0 * q3)), 1.0 + 2.0 * (q1 * q1 + q3 * q3), 2.0 * (abs(q2 * q3) + abs(q0 * q1))),
            (2.0 * (abs(q1 * q3) + abs(q0 * q2)), 2.0 * (abs(q2 * q3) + abs(q0 * q1)), 1.0 + 2.0 * (q1 * q1 + q2 * q2)))
    for k in range(3):
        for j in range(3):
            Rr[k, j] = upper(4.0 * _U * mags[k][j], 6) + 3 * _ETA


@njit(cache=True, error_model="numpy")
def centred_form_quaternion(lo, hi, p, bm, inner, outer, Gm, Ginner, Gouter):
    """(lo, hi, cm, cr, Dm, Dr) of ``centred_form`` over the boxes [lo, hi] (N, p + 4): the form
    (N, legs, 3), R b_i at the midpoints in [cm ± cr] (N, legs, 3), the derivatives in [Dm ± Dr]
    (N, 4, legs, 3).  ``bm``/``inner``/``outer`` (3, ≥ legs): ``b_midrad``; ``Gm`` (4, 4 legs 3) the
    derivative tables, ``Ginner`` = 5u|Gm| + Gr, ``Gouter`` = |Gm| + Gr (``product_midrad``'s factors)."""
    N = lo.shape[0]
    legs = Gm.shape[1] // 12
    flo = np.empty((N, legs, 3))
    fhi = np.empty((N, legs, 3))
    cm = np.empty((N, legs, 3))
    cr = np.empty((N, legs, 3))
    Dm = np.empty((N, 4, legs, 3))
    Dr = np.empty((N, 4, legs, 3))
    c = np.empty(4)
    h = np.empty(4)
    ym = np.empty(4)
    yr = np.empty(4)
    Rm = np.empty((3, 3))
    Rr = np.empty((3, 3))
    T = 4 * legs * 3
    dm = np.empty(T)
    dr = np.empty(T)
    for box in range(N):
        for r in range(4):
            l, u = lo[box, p + r], hi[box, p + r]
            m = 0.5 * max(l, -MAX) + 0.5 * min(u, MAX)          # Interval.mid
            c[r] = min(max(m, l), u)
            ym[r], yr[r] = midrad(down(0.5 * down_sum(l + c[r])), up(0.5 * up_sum(u + c[r])))   # Y ∋ (x + c)/2
            h[r] = max(up_sum(c[r] - l), up_sum(u - c[r]))
        _rotation_at_point(c, Rm, Rr)
        # ∂(R b_i)_k/∂q_r over Y, t = (r, i, k): product_midrad, each sum over s in increasing order
        # (the loops over t are independent: the same floats, several at a time)
        for t in range(T):
            dm[t] = 0.0
            dr[t] = 0.0
        for s in range(4):
            a, b = ym[s], yr[s]
            for t in range(T):
                dm[t] += a * Gm[s, t]
                dr[t] += abs(a) * Ginner[s, t] + b * Gouter[s, t]
        for t in range(T):
            v = upper(dr[t], 20) + 4 * _ETA
            if np.isfinite(dm[t]) and np.isfinite(v):
                dr[t] = v
            else:
                dm[t], dr[t] = 0.0, INF
        for i in range(legs):
            for k in range(3):
                sm = 0.0
                sr = 0.0
                for j in range(3):            # R b_i(c): rotated_midrad
                    sm += Rm[k, j] * bm[j, i]
                    sr += abs(Rm[k, j]) * inner[j, i] + Rr[k, j] * outer[j, i]
                sr = upper(sr, 16) + 3 * _ETA
                if not (np.isfinite(sm) and np.isfinite(sr)):
                    sm, sr = 0.0, INF
                cm[box, i, k], cr[box, i, k] = sm, sr
                acc = 0.0
                for r in range(4):
                    t = r * legs * 3 + i * 3 + k
                    Dm[box, r, i, k], Dr[box, r, i, k] = dm[t], dr[t]
                    acc += (abs(dm[t]) + dr[t]) * h[r]
                rad = upper(sr + acc, 8)
                flo[box, i, k], fhi[box, i, k] = down(sm - rad), up(sm + rad)
    return flo, fhi, cm, cr, Dm, Dr


@njit(cache=True, error_model="numpy")
def slope_quaternion(xlo, xhi, c, rblo, rbhi, rclo, rchi, Dm, Dr, alo, ahi, Llo, Lhi, p):
    """(S lo, S hi, f lo, f hi): ``FKSystem.slope`` (N, n, n) at the points c (N, n) over the boxes x, and
    ``FKSystem.equations`` at c (N, n), from R b_i over x (``rb``) and at c (``rc``), (N, legs, 3), and the
    derivatives of R b_i over Y ∋ (x + c)/2 in [Dm ± Dr] (N, 4, legs, 3).  Rows with a non-finite input
    get entire slope entries and equation values."""
    N, n = xlo.shape
    legs = rblo.shape[1]
    Slo = np.zeros((N, n, n))
    Shi = np.zeros((N, n, n))
    flo = np.empty((N, n))
    fhi = np.empty((N, n))
    slo = np.empty(3)
    shi = np.empty(3)
    for b in range(N):
        finite = True
        for k in range(n):
            finite &= np.isfinite(xlo[b, k]) and np.isfinite(xhi[b, k]) and np.isfinite(c[b, k])
        for i in range(legs):
            finite &= np.isfinite(Llo[b, i]) and np.isfinite(Lhi[b, i])
            for k in range(3):
                finite &= np.isfinite(rblo[b, i, k]) and np.isfinite(rbhi[b, i, k])
                finite &= np.isfinite(rclo[b, i, k]) and np.isfinite(rchi[b, i, k])
                for r in range(4):
                    finite &= np.isfinite(Dm[b, r, i, k]) and np.isfinite(Dr[b, r, i, k])
        if not finite:
            for i in range(n):
                flo[b, i], fhi[b, i] = -INF, INF
                for j in range(n):
                    Slo[b, i, j], Shi[b, i, j] = -INF, INF
            continue
        for i in range(legs):
            # ell = (R b_i − a_i) + p over x, ellc the same at c; s = ell + ellc
            glo = 0.0
            ghi = 0.0
            for k in range(3):
                el, eh = down_sum(rblo[b, i, k] - ahi[i, k]), up_sum(rbhi[b, i, k] - alo[i, k])
                cl, ch = down_sum(rclo[b, i, k] - ahi[i, k]), up_sum(rchi[b, i, k] - alo[i, k])
                if p:
                    el, eh = down_sum(el + xlo[b, k]), up_sum(eh + xhi[b, k])
                    cl, ch = down_sum(cl + c[b, k]), up_sum(ch + c[b, k])
                slo[k], shi[k] = down_sum(el + cl), up_sum(eh + ch)
                ql, qh = sqr(cl, ch)                   # leg equation at c: Σ_k ellc_k² − L_i
                if k == 0:
                    glo, ghi = ql, qh
                else:
                    glo, ghi = down_sum(glo + ql), up_sum(ghi + qh)
            flo[b, i], fhi[b, i] = down_sum(glo - Lhi[b, i]), up_sum(ghi - Llo[b, i])
            for k in range(p):
                Slo[b, i, k], Shi[b, i, k] = slo[k], shi[k]
            for r in range(4):                          # Σ_k s_k ∂(R b_i)_k/∂q_r(Y)
                tlo = 0.0
                thi = 0.0
                for k in range(3):
                    dl, dh = down(Dm[b, r, i, k] - Dr[b, r, i, k]), up(Dm[b, r, i, k] + Dr[b, r, i, k])
                    ml, mh = mul(slo[k], shi[k], dl, dh)
                    if k == 0:
                        tlo, thi = ml, mh
                    else:
                        tlo, thi = down_sum(tlo + ml), up_sum(thi + mh)
                Slo[b, i, p + r], Shi[b, i, p + r] = tlo, thi
        # the norm row: x_r + c_r; the norm equation at c: Σ_r c_r² − 1
        glo = 0.0
        ghi = 0.0
        for k in range(p, n):
            Slo[b, legs, k], Shi[b, legs, k] = down_sum(xlo[b, k] + c[b, k]), up_sum(xhi[b, k] + c[b, k])
            ql, qh = sqr(c[b, k], c[b, k])
            if k == p:
                glo, ghi = ql, qh
            else:
                glo, ghi = down_sum(glo + ql), up_sum(ghi + qh)
        flo[b, legs], fhi[b, legs] = down_sum(glo - 1.0), up_sum(ghi - 1.0)
    return Slo, Shi, flo, fhi


@njit(cache=True, error_model="numpy")
def rotation_entries(zlo, zhi, slo, shi, p, entries, Rlo, Rhi, Rm, Rr):
    """R over the box z (``FKSystem.rotation``: the same interval operations; ``slo``/``shi`` the
    squares of z) into [Rlo, Rhi], and in midpoint-radius form [Rm ± Rr] (``rotation.TABLES[0]``:
    ``entries``); step 2 of the HC4 kernel, first part."""
    for k in range(3):
        for j in range(3):
            kind = entries[k, j, 0]
            a, b_, c, d = entries[k, j, 1], entries[k, j, 2], entries[k, j, 3], entries[k, j, 4]
            if kind == 0:
                tlo, thi = down_sum(slo[p + a] + slo[p + b_]), up_sum(shi[p + a] + shi[p + b_])
                tlo, thi = scale(tlo, thi, 2.0)
                vlo, vhi = down_sum(1.0 - thi), up_sum(1.0 - tlo)
            else:
                xlo, xhi = mul(zlo[p + a], zhi[p + a], zlo[p + b_], zhi[p + b_])
                ylo, yhi = mul(zlo[p + c], zhi[p + c], zlo[p + d], zhi[p + d])
                if kind > 0:
                    tlo, thi = down_sum(xlo + ylo), up_sum(xhi + yhi)
                else:
                    tlo, thi = down_sum(xlo - yhi), up_sum(xhi - ylo)
                vlo, vhi = scale(tlo, thi, 2.0)
            Rlo[k, j], Rhi[k, j] = vlo, vhi
            m = 0.5 * vlo + 0.5 * vhi
            Rm[k, j] = m
            Rr[k, j] = up(max(vhi - m, m - vlo))


@njit(cache=True, error_model="numpy")
def rotated_quaternion(lo, hi, p, bm, inner, outer, entries, flo, fhi, with_form):
    """R b_i over the boxes [lo, hi] (N, p + 4) of a quaternion system, (lo, hi) (N, legs, 3): the
    natural enclosure ``FKSystem.rotated(FKSystem.rotation(X))`` — R over the box as
    ``centred.rotation_entries`` (the interval operations of ``FKSystem.rotation``), then R b_i in
    midpoint-radius form as HC4's step 2 (``kernels.hc4_quaternion``) (``rotated_midrad``'s bound; its float sums in another order
    than numpy's matrix product, which the bound allows) — intersected, when ``with_form``, with
    [flo, fhi] (N, legs, 3), the centred form (as ``np.fmax``/``np.fmin``: a NaN bound is ignored).
    ``bm``/``inner``/``outer`` (3, ≥ legs; the first legs columns): ``b_midrad``.  Rows with a
    non-finite rotation side: the entire line (∩ the form)."""
    N, n = lo.shape
    legs = flo.shape[1] if with_form else bm.shape[1] // 4
    olo = np.empty((N, legs, 3))
    ohi = np.empty((N, legs, 3))
    zlo = np.empty(n)
    zhi = np.empty(n)
    slo = np.empty(n)
    shi = np.empty(n)
    Rlo = np.empty((3, 3))
    Rhi = np.empty((3, 3))
    Rm = np.empty((3, 3))
    Rr = np.empty((3, 3))
    K = 4 * 3 + 4
    for box in range(N):
        finite = True
        for k in range(p, n):
            zlo[k], zhi[k] = lo[box, k], hi[box, k]
            finite &= np.isfinite(zlo[k]) and np.isfinite(zhi[k])
        if finite:
            for k in range(p, n):
                slo[k], shi[k] = sqr(zlo[k], zhi[k])
            rotation_entries(zlo, zhi, slo, shi, p, entries, Rlo, Rhi, Rm, Rr)
        for i in range(legs):
            for k in range(3):
                ul, uh = -INF, INF
                if finite:
                    sm = (Rm[k, 0] * bm[0, i] + Rm[k, 1] * bm[1, i]) + Rm[k, 2] * bm[2, i]
                    sr = ((abs(Rm[k, 0]) * inner[0, i] + Rr[k, 0] * outer[0, i])
                          + (abs(Rm[k, 1]) * inner[1, i] + Rr[k, 1] * outer[1, i])) \
                        + (abs(Rm[k, 2]) * inner[2, i] + Rr[k, 2] * outer[2, i])
                    sr = upper(sr, K) + 3 * 2.0 ** -1022
                    if np.isfinite(sm) and np.isfinite(sr):
                        ul, uh = down(sm - sr), up(sm + sr)
                if with_form:
                    fl, fh = flo[box, i, k], fhi[box, i, k]
                    if fl == fl:
                        ul = max(ul, fl)
                    if fh == fh:
                        uh = min(uh, fh)
                olo[box, i, k], ohi[box, i, k] = ul, uh
    return olo, ohi


@njit(cache=True, error_model="numpy")
def equations_quaternion(xlo, xhi, rblo, rbhi, alo, ahi, Llo, Lhi, p):
    """(lo, hi) (N, n): ``FKSystem.equations`` over the boxes x (N, p + 4) of a quaternion system from
    R b_i over them (``rb``, (N, legs, 3)) — the same interval operations in the same order:
    ell_i = (R b_i − a_i) + p, Σ_k sqr(ell_ik) left to right, − L_i; the norm Σ_r sqr(q_r) − 1.  Rows
    with a non-finite input: the entire line."""
    N, n = xlo.shape
    legs = rblo.shape[1]
    flo = np.empty((N, n))
    fhi = np.empty((N, n))
    for b in range(N):
        finite = True
        for k in range(n):
            finite &= np.isfinite(xlo[b, k]) and np.isfinite(xhi[b, k])
        for i in range(legs):
            finite &= np.isfinite(Llo[b, i]) and np.isfinite(Lhi[b, i])
            for k in range(3):
                finite &= np.isfinite(rblo[b, i, k]) and np.isfinite(rbhi[b, i, k])
        if not finite:
            for k in range(n):
                flo[b, k], fhi[b, k] = -INF, INF
            continue
        for i in range(legs):
            glo = 0.0
            ghi = 0.0
            for k in range(3):
                el, eh = down_sum(rblo[b, i, k] - ahi[i, k]), up_sum(rbhi[b, i, k] - alo[i, k])
                if p:
                    el, eh = down_sum(el + xlo[b, k]), up_sum(eh + xhi[b, k])
                ql, qh = sqr(el, eh)
                if k == 0:
                    glo, ghi = ql, qh
                else:
                    glo, ghi = down_sum(glo + ql), up_sum(ghi + qh)
            flo[b, i], fhi[b, i] = down_sum(glo - Lhi[b, i]), up_sum(ghi - Llo[b, i])
        glo = 0.0
        ghi = 0.0
        for k in range(p, n):
            ql, qh = sqr(xlo[b, k], xhi[b, k])
            if k == p:
                glo, ghi = ql, qh
            else:
                glo, ghi = down_sum(glo + ql), up_sum(ghi + qh)
        flo[b, legs], fhi[b, legs] = down_sum(glo - 1.0), up_sum(ghi - 1.0)
    return flo, fhi
