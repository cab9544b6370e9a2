"""The hot loops of the FK search for a quaternion rotation, box by box in machine code (numba).

- ``hc4_quaternion``: ``contract.hc4``'s pass: the same interval operations on the
  same operands and in the same order as the numpy version (steps 1-7 of
  ``fk.contract``), with the outward-rounded primitives of ``intervals.native``; only
  the float sums of the midpoint-radius R b_i (``FKSystem.rotated_midrad``) may
  be taken in another order, which their error bound allows (Higham 2002,
  eq. 3.5).  The centred form of R b_i (step 2) is computed by
  ``FKSystem.centred_form`` and passed in.
- (``slope_quaternion``, ``rotated_quaternion``, ``equations_quaternion``, beside the centred form
  of R b_i and R over the box of step 2: ``fk.centred``);
- ``position_gauss_seidel``: ``step.contract_position`` for a spatial robot (the
  difference equations, P [D | g] in midpoint-radius form, one Gauss-Seidel
  sweep), with the same operations and bounds.
- ``gap_splits_quaternion``: ``contract.gap_splits``, the same floats.

Each step intersects a variable with a set that holds its value at every root
of the box (``docs/soundness.md`` §8), so no root is lost; ``tests/test_fk_hc4.py``
and ``tests/test_fk.py`` compare the kernels with the numpy versions.  Boxes
with a non-finite input are left as they are (HC4, position: unchanged, not
empty; slope: entire entries).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from intervals.native import INF, MAX, div_regular, down, down_sum, gauss_jordan, gs_update, midrad, mul, scale, sqr, up, up_sum, upper

from .centred import rotation_entries


_U = 2.0 ** -53


@njit(cache=True, error_model="numpy")
def _root(xlo, xhi, tlo, thi):
    """``contract.root``: hull(x ∩ {y : y² ∈ t}); empty (lo > hi) if there is no such y; x itself
    if t is NaN (nothing known)."""
    if not (tlo == tlo and thi == thi):
        return xlo, xhi
    rlo = max(down(np.sqrt(max(tlo, 0.0))), 0.0)
    rhi = up(np.sqrt(max(thi, 0.0)))
    nlo, nhi = max(xlo, -rhi), min(xhi, -rlo)
    plo, phi = max(xlo, rlo), min(xhi, rhi)
    neg = nlo <= nhi and thi >= 0.0
    pos = plo <= phi and thi >= 0.0
    lo = nlo if neg else (plo if pos else INF)
    hi = phi if pos else (nhi if neg else -INF)
    return lo, hi


@njit(cache=True, error_model="numpy")
def _divide_into(xlo, xhi, nlo, nhi, dlo, dhi):
    """``contract.divide_into``: x ∩ num / den where 0 ∉ den, x itself elsewhere."""
    if dlo > 0.0 or dhi < 0.0:
        qlo, qhi = div_regular(nlo, nhi, dlo, dhi)
        return max(xlo, qlo), min(xhi, qhi)
    return xlo, xhi


@njit(cache=True, error_model="numpy")
def _sum_others(vlo, vhi, start, stop, k):
    """Σ_{j ≠ k} v_j over start ≤ j < stop, interval sums from left to right (``Interval.__add__``)."""
    olo = 0.0
    ohi = 0.0
    first = True
    for j in range(start, stop):
        if j != k:
            if first:
                olo, ohi = vlo[j], vhi[j]
                first = False
            else:
                olo, ohi = down_sum(olo + vlo[j]), up_sum(ohi + vhi[j])
    return olo, ohi


@njit(cache=True, error_model="numpy")
def _divide_at(zlo, zhi, t, glo, ghi, d):
    """z_t ← z_t ∩ g / z_d where 0 ∉ z_d (``_divide_into``), in place; True if z_t is now empty."""
    zlo[t], zhi[t] = _divide_into(zlo[t], zhi[t], glo, ghi, zlo[d], zhi[d])
    return zlo[t] > zhi[t]


@njit(cache=True, error_model="numpy")
def _norm_equation(zlo, zhi, slo, shi, p, n):
    """Step 1: r_k ← root(r_k, 1 − Σ_{j≠k} r_j²) for the rotation unknowns r, j increasing
    (``slo``/``shi``: their squares); True if the box holds no root."""
    for k in range(p, n):
        slo[k], shi[k] = sqr(zlo[k], zhi[k])
    for k in range(p, n):
        olo, ohi = _sum_others(slo, shi, p, n, k)
        zlo[k], zhi[k] = _root(zlo[k], zhi[k], down_sum(1.0 - ohi), up_sum(1.0 - olo))
        if zlo[k] > zhi[k]:
            return True
        slo[k], shi[k] = sqr(zlo[k], zhi[k])
    return False


@njit(cache=True, error_model="numpy")
def _rotated_points(box, zlo, zhi, p, Rm, Rr, bm, inner, outer, flo, fhi, alo, ahi, tm, te, ulo, uhi, Pm, Pr,
                    elo, ehi):
    """Step 2, second part: u_i = R b_i in midpoint-radius form (``rotated_midrad``, with the sums
    that leave column j out into [Pm ± Pr]) ∩ the centred form f of box ``box``; e_i = (u_i − a_i) + p."""
    legs = ulo.shape[0]
    K = 4 * 3 + 4
    for i in range(legs):
        for k in range(3):
            # the terms R_kj b_ij (midpoints tm, radius terms te), then R b_i (all three) and the
            # sums that leave column j out (the other two): ``rotated_midrad``'s blocks
            for jj in range(3):
                tm[jj] = Rm[k, jj] * bm[jj, i]
                te[jj] = abs(Rm[k, jj]) * inner[jj, i] + Rr[k, jj] * outer[jj, i]
            for blk in range(4):          # block 0: R b_i; block 1 + j: column j left out
                if blk == 0:
                    sm = (tm[0] + tm[1]) + tm[2]
                    sr = (te[0] + te[1]) + te[2]
                else:
                    a0, a1 = (1, 2) if blk == 1 else ((0, 2) if blk == 2 else (0, 1))
                    sm = tm[a0] + tm[a1]
                    sr = te[a0] + te[a1]
                sr = upper(sr, K) + 3 * 2.0 ** -1022
                if not (np.isfinite(sm) and np.isfinite(sr)):
                    sm, sr = 0.0, INF
                if blk == 0:
                    ul, uh = down(sm - sr), up(sm + sr)
                    if ul != ul:
                        ul = -INF
                    if uh != uh:
                        uh = INF
                    # ∩ the centred form (np.fmax / np.fmin: a NaN bound of the form is ignored)
                    fl, fh = flo[box, i, k], fhi[box, i, k]
                    ulo[i, k] = ul if fl != fl else max(ul, fl)
                    uhi[i, k] = uh if fh != fh else min(uh, fh)
                else:
                    Pm[i, k, blk - 1] = sm
                    Pr[i, k, blk - 1] = sr
        for k in range(3):
            vlo, vhi = down_sum(ulo[i, k] - ahi[i, k]), up_sum(uhi[i, k] - alo[i, k])
            if p:
                vlo, vhi = down_sum(vlo + zlo[k]), up_sum(vhi + zhi[k])
            elo[i, k], ehi[i, k] = vlo, vhi


@njit(cache=True, error_model="numpy")
def _entries_from_points(ulo, uhi, Pm, Pr, nonzero, invlo, invhi, Rlo, Rhi, R2lo, R2hi):
    """Step 6: R_kj ← R_kj ∩ (u_ik − Σ_{j'≠j} R_kj' b_ij') × (1/b_ij) for the legs with 0 ∉ b_ij, into
    [R2lo, R2hi]; True if an entry is empty."""
    legs = ulo.shape[0]
    dead = False
    for k in range(3):
        for j in range(3):
            vlo, vhi = Rlo[k, j], Rhi[k, j]
            for i in range(legs):
                if nonzero[i, j]:
                    rl, rh = down(Pm[i, k, j] - Pr[i, k, j]), up(Pm[i, k, j] + Pr[i, k, j])
                    if rl != rl:
                        rl = -INF
                    if rh != rh:
                        rh = INF
                    nl, nh = down_sum(ulo[i, k] - rh), up_sum(uhi[i, k] - rl)
                    cl, ch = mul(nl, nh, invlo[i, j], invhi[i, j])
                    vlo = max(vlo, cl)
                    vhi = min(vhi, ch)
            R2lo[k, j], R2hi[k, j] = vlo, vhi
            if vlo > vhi:
                dead = True
    return dead


@njit(cache=True, error_model="numpy")
def _quaternion_from_entries(zlo, zhi, R2lo, R2hi, p, entries, off):
    """Step 7: the quaternion from the entries of R, diagonal entries then off-diagonal ones
    (``rotation.DIAGONAL``, ``OFF_DIAGONAL``, as tables); True if the box holds no root."""
    for k in range(3):
        a, b_ = entries[k, k, 1], entries[k, k, 2]
        tlo, thi = down_sum(1.0 - R2hi[k, k]), up_sum(1.0 - R2lo[k, k])
        tlo, thi = scale(tlo, thi, 0.5)
        sl, sh = sqr(zlo[p + b_], zhi[p + b_])
        zlo[p + a], zhi[p + a] = _root(zlo[p + a], zhi[p + a], down_sum(tlo - sh), up_sum(thi - sl))
        if zlo[p + a] > zhi[p + a]:
            return True
        sl, sh = sqr(zlo[p + a], zhi[p + a])
        zlo[p + b_], zhi[p + b_] = _root(zlo[p + b_], zhi[p + b_], down_sum(tlo - sh), up_sum(thi - sl))
        if zlo[p + b_] > zhi[p + b_]:
            return True
    for e in range(6):
        k, j = off[e, 0], off[e, 1]
        ia, ib, ic, id_ = p + off[e, 2], p + off[e, 3], p + off[e, 4], p + off[e, 5]
        sigma = off[e, 6]
        hlo, hhi = scale(R2lo[k, j], R2hi[k, j], 0.5)
        clo, chi = mul(zlo[ic], zhi[ic], zlo[id_], zhi[id_])
        if sigma > 0:
            glo, ghi = down_sum(hlo - chi), up_sum(hhi - clo)
        else:
            glo, ghi = down_sum(hlo + clo), up_sum(hhi + chi)
        if _divide_at(zlo, zhi, ia, glo, ghi, ib) or _divide_at(zlo, zhi, ib, glo, ghi, ia):
            return True
        xlo, xhi = mul(zlo[ia], zhi[ia], zlo[ib], zhi[ib])
        glo, ghi = down_sum(hlo - xhi), up_sum(hhi - xlo)
        if sigma < 0:
            glo, ghi = -ghi, -glo
        if _divide_at(zlo, zhi, ic, glo, ghi, id_) or _divide_at(zlo, zhi, id_, glo, ghi, ic):
            return True
    return False


@njit(cache=True, error_model="numpy")
def _leg(elo, ehi, i, Llo, Lhi, eslo, eshi):
    """Step 3 for leg i: e_ik ← root(e_ik, ρ_i² − Σ_{k'≠k} e_ik'²), k = 0, 1, 2; True if one is empty."""
    dead = False
    for k in range(3):
        eslo[k], eshi[k] = sqr(elo[i, k], ehi[i, k])
    for k in range(3):
        olo, ohi = _sum_others(eslo, eshi, 0, 3, k)
        elo[i, k], ehi[i, k] = _root(elo[i, k], ehi[i, k], down_sum(Llo[i] - ohi), up_sum(Lhi[i] - olo))
        dead |= elo[i, k] > ehi[i, k]
        eslo[k], eshi[k] = sqr(elo[i, k], ehi[i, k])
    return dead


@njit(cache=True, error_model="numpy")
def _pair_terms(box, lo, hi, p, Rlo, Rhi, cm, cr, Dm, Dr, dblo, dbhi, dalo, dahi, h, Dlo, Dhi):
    """d_ij = R (b_i − b_j) − (a_i − a_j) for i < j, R (b_i − b_j) enclosed as Σ_m R_km (b_i − b_j)_m (m
    increasing) ∩ its centred form over the given box: R b_i − R b_j at the midpoint c, in
    [(cm_i − cm_j) ± (cr_i + cr_j)], plus Σ_r (∂(R b_i)/∂q_r − ∂(R b_j)/∂q_r)(Y) (q_r − c_r), each derivative
    in [Dm ± Dr] (the parts of the centred form of R b_i: exact for a quadratic, as in step 2); d_ji = −d_ij
    (the same operations on negated operands: outward rounding is symmetric)."""
    legs = Dlo.shape[0]
    for r in range(4):
        l, u = lo[box, p + r], hi[box, p + r]
        c = min(max(0.5 * max(l, -MAX) + 0.5 * min(u, MAX), l), u)     # Interval.mid, as the form's c
        h[r] = max(up_sum(c - l), up_sum(u - c))
    for i in range(legs):
        for j in range(i + 1, legs):
            for k in range(3):
                dlo, dhi = mul(Rlo[k, 0], Rhi[k, 0], dblo[i, j, 0], dbhi[i, j, 0])
                for m in range(1, 3):
                    tlo, thi = mul(Rlo[k, m], Rhi[k, m], dblo[i, j, m], dbhi[i, j, m])
                    dlo, dhi = down_sum(dlo + tlo), up_sum(dhi + thi)
                # the centred form: |fl(x − y)| ≤ (1 + u)|x − y| and the midpoint's own rounding (u|dm|) in rad;
                # non-negative terms, at most 12 roundings deep (``upper``)
                dm = cm[box, i, k] - cm[box, j, k]
                rad = (cr[box, i, k] + cr[box, j, k]) + abs(dm) * _U
                for r in range(4):
                    rad += (abs(Dm[box, r, i, k] - Dm[box, r, j, k]) * (1.0 + 2.0 * _U) + (Dr[box, r, i, k] + Dr[box, r, j, k])) * h[r]
                rad = upper(rad, 16)
                if rad == rad:
                    dlo, dhi = max(dlo, down(dm - rad)), min(dhi, up(dm + rad))
                dlo, dhi = down_sum(dlo - dahi[i, j, k]), up_sum(dhi - dalo[i, j, k])
                Dlo[i, j, k], Dhi[i, j, k] = dlo, dhi
                Dlo[j, i, k], Dhi[j, i, k] = -dhi, -dlo


@njit(cache=True, error_model="numpy")
def _pairs(elo, ehi, Dlo, Dhi, Llo, Lhi, eslo, eshi):
    """Step 3, leg pairs, leg after leg: e_i ← e_i ∩ ⋂_{j≠i} (e_j + d_ij) (``_pair_terms``), then leg i's
    roots (``_leg``); True if one is empty."""
    legs = elo.shape[0]
    for i in range(legs):
        for k in range(3):
            vlo, vhi = elo[i, k], ehi[i, k]
            for j in range(legs):
                if j != i:
                    vlo = max(vlo, down_sum(elo[j, k] + Dlo[i, j, k]))
                    vhi = min(vhi, up_sum(ehi[j, k] + Dhi[i, j, k]))
            elo[i, k], ehi[i, k] = vlo, vhi
        if _leg(elo, ehi, i, Llo, Lhi, eslo, eshi):
            return True
    return False


@njit(cache=True, error_model="numpy")
def hc4_quaternion(lo, hi, Llo, Lhi, flo, fhi, cm, cr, Dm, Dr, alo, ahi, bm, inner, outer, nonzero, invlo, invhi, dblo, dbhi, dalo, dahi,
                   rounds, p, entries, off):
    """One HC4 pass (``fk.contract``) over the boxes [lo, hi] (N, p + 4) of a quaternion system.

    ``L`` (N, legs) squared leg lengths, ``f`` (N, legs, 3) the centred form of R b_i over the given
    boxes and ``cm``, ``cr``, ``Dm``, ``Dr`` its parts (``FKSystem.centred_form``), ``a`` (legs, 3),
    ``bm``/``inner``/``outer`` (3, ≥ legs; the first legs columns) the factors of
    ``FKSystem.rotated_midrad`` (``b_midrad``), ``nonzero`` (legs, 3) where 0 ∉ b_ij, ``inv``
    (legs, 3) enclosures of 1/b_ij, ``db``/``da`` (legs, legs, 3) enclosures of b_i − b_j and a_i − a_j,
    ``rounds`` the leg-pair rounds of step 3 (a position only), ``entries``/``off`` the tables of
    ``_tables``.  Returns (lo, hi, empty) as ``contract.hc4``.  One pass, one algorithm that reads best whole: steps 1, 2,
    6 and 7 are helpers of their own, steps 3-5 stay inline on the box's working arrays (allocated
    once, passed on)."""
    N, n = lo.shape
    legs = Llo.shape[1]
    nlo_out = lo.copy()
    nhi_out = hi.copy()
    empty = np.zeros(N, dtype=np.bool_)
    zlo = np.empty(n)
    zhi = np.empty(n)
    slo = np.empty(n)
    shi = np.empty(n)
    Rlo = np.empty((3, 3))
    Rhi = np.empty((3, 3))
    Rm = np.empty((3, 3))
    Rr = np.empty((3, 3))
    R2lo = np.empty((3, 3))
    R2hi = np.empty((3, 3))
    ulo = np.empty((legs, 3))
    uhi = np.empty((legs, 3))
    Pm = np.empty((legs, 3, 3))
    Pr = np.empty((legs, 3, 3))
    elo = np.empty((legs, 3))
    ehi = np.empty((legs, 3))
    Dlo = np.empty((legs, legs, 3))
    Dhi = np.empty((legs, legs, 3))
    hh = np.empty(4)
    eslo = np.empty(3)
    eshi = np.empty(3)
    tm = np.empty(3)
    te = np.empty(3)
    for box in range(N):
        finite = True
        for k in range(n):
            finite &= np.isfinite(lo[box, k]) and np.isfinite(hi[box, k])
        for i in range(legs):
            finite &= np.isfinite(Llo[box, i]) and np.isfinite(Lhi[box, i])
        if not finite:
            continue
        for k in range(n):
            zlo[k] = lo[box, k]
            zhi[k] = hi[box, k]
        if _norm_equation(zlo, zhi, slo, shi, p, n):                                  # 1.
            empty[box] = True
            continue
        rotation_entries(zlo, zhi, slo, shi, p, entries, Rlo, Rhi, Rm, Rr)           # 2.
        _rotated_points(box, zlo, zhi, p, Rm, Rr, bm, inner, outer, flo, fhi, alo, ahi, tm, te,
                        ulo, uhi, Pm, Pr, elo, ehi)
        # 3. each leg equation, then (a position) ``rounds`` times the leg pairs, each leg's roots after its pairs
        dead = False
        for i in range(legs):
            dead |= _leg(elo, ehi, i, Llo[box], Lhi[box], eslo, eshi)
        if p and rounds and not dead:
            _pair_terms(box, lo, hi, p, Rlo, Rhi, cm, cr, Dm, Dr, dblo, dbhi, dalo, dahi, hh, Dlo, Dhi)
        for _ in range(rounds if p else 0):
            if dead:
                break
            dead = _pairs(elo, ehi, Dlo, Dhi, Llo[box], Lhi[box], eslo, eshi)
        if dead:
            empty[box] = True
            continue
        # 4. the position: p_k ← p_k ∩ ⋂_i ((e_ik − u_ik) + a_ik)
        for k in range(p):
            pl, ph = zlo[k], zhi[k]
            for i in range(legs):
                vlo, vhi = down_sum(elo[i, k] - uhi[i, k]), up_sum(ehi[i, k] - ulo[i, k])
                pl = max(pl, down_sum(vlo + alo[i, k]))
                ph = min(ph, up_sum(vhi + ahi[i, k]))
            zlo[k], zhi[k] = pl, ph
            if pl > ph:
                dead = True
        if dead:
            empty[box] = True
            continue
        # 5. u_ik ← u_ik ∩ ((e_ik − p_k) + a_ik)
        for i in range(legs):
            for k in range(3):
                vlo, vhi = elo[i, k], ehi[i, k]
                if p:
                    vlo, vhi = down_sum(vlo - zhi[k]), up_sum(vhi - zlo[k])
                ulo[i, k] = max(ulo[i, k], down_sum(vlo + alo[i, k]))
                uhi[i, k] = min(uhi[i, k], up_sum(vhi + ahi[i, k]))
        if _entries_from_points(ulo, uhi, Pm, Pr, nonzero, invlo, invhi, Rlo, Rhi, R2lo, R2hi):   # 6.
            empty[box] = True
            continue
        if _quaternion_from_entries(zlo, zhi, R2lo, R2hi, p, entries, off):                  # 7.
            empty[box] = True
            continue
        nan = False
        for k in range(n):
            nan |= zlo[k] != zlo[k] or zhi[k] != zhi[k]
        if nan:
            continue
        for k in range(n):
            nlo_out[box, k] = max(zlo[k], lo[box, k])
            nhi_out[box, k] = min(zhi[k], hi[box, k])
    return nlo_out, nhi_out, empty


@njit(cache=True, error_model="numpy")
def _difference_equations(b, rblo, rbhi, alo, ahi, klo, khi, Llo, Lhi, slo, shi, Dlo, Dhi):
    """The differences of the leg equations of box ``b``, D p = g into [Dlo, Dhi] (columns 0-2: D,
    column 3: g), as ``FKSystem.position_system`` (``slo``/``shi``: scratch for a_i · R b_i)."""
    legs = rblo.shape[1]
    # a_i · R b_i, then D = 2((R b_i − R b_1) − (a_i − a_1)), g (FKSystem.position_system)
    for i in range(legs):
        sl, sh = 0.0, 0.0
        for k in range(3):
            ml, mh = mul(alo[i, k], ahi[i, k], rblo[b, i, k], rbhi[b, i, k])
            if k == 0:
                sl, sh = ml, mh
            else:
                sl, sh = down_sum(sl + ml), up_sum(sh + mh)
        slo[i], shi[i] = sl, sh
    for i in range(1, legs):
        for k in range(3):
            t1l, t1h = down_sum(rblo[b, i, k] - rbhi[b, 0, k]), up_sum(rbhi[b, i, k] - rblo[b, 0, k])
            t2l, t2h = down_sum(alo[i, k] - ahi[0, k]), up_sum(ahi[i, k] - alo[0, k])
            t3l, t3h = down_sum(t1l - t2h), up_sum(t1h - t2l)
            Dlo[i - 1, k], Dhi[i - 1, k] = scale(t3l, t3h, 2.0)
        ul, uh = down_sum(slo[i] - shi[0]), up_sum(shi[i] - slo[0])
        ul, uh = scale(ul, uh, 2.0)
        cl, ch = down_sum(klo[i] - khi[0]), up_sum(khi[i] - klo[0])
        ul, uh = down_sum(ul - ch), up_sum(uh - cl)
        dl, dh = down_sum(Llo[b, i] - Lhi[b, 0]), up_sum(Lhi[b, i] - Llo[b, 0])
        Dlo[i - 1, 3], Dhi[i - 1, 3] = down_sum(ul + dl), up_sum(uh + dh)


@njit(cache=True, error_model="numpy")
def _sweep(Alo, Ahi, xlo, xhi, ylo, yhi):
    """One interval Gauss-Seidel sweep on [A | g] p = g over the position x (into y), as
    ``linalg.gauss_seidel`` with ``C=False``; True if the position is proved empty."""
    for k in range(3):
        ylo[k], yhi[k] = xlo[k], xhi[k]
    for i in range(3):
        sl, sh = 0.0, 0.0
        first = True
        for j in range(3):
            if j != i:
                ml, mh = mul(Alo[i, j], Ahi[i, j], ylo[j], yhi[j])
                if first:
                    sl, sh = ml, mh
                    first = False
                else:
                    sl, sh = down_sum(sl + ml), up_sum(sh + mh)
        nl, nh = down_sum(Alo[i, 3] - sh), up_sum(Ahi[i, 3] - sl)
        ylo[i], yhi[i] = gs_update(nl, nh, Alo[i, i], Ahi[i, i], ylo[i], yhi[i])
        if ylo[i] > yhi[i]:
            return True
    return False


@njit(cache=True, error_model="numpy")
def position_gauss_seidel(xlo, xhi, rblo, rbhi, alo, ahi, klo, khi, Llo, Lhi):
    """``step.contract_position`` for a spatial robot (position p = x[:, :3]): (lo, hi, empty, P).

    The differences of leg equations D p = g (``FKSystem.position_system``, the same interval
    operations, from R b_i over the box ``rb`` (N, legs, 3), ``a`` (legs, 3), ``k`` = |a_i|² + |b_i|²
    (legs,), ``L`` (N, legs)); P = (Dmᵀ Dm)⁻¹ Dmᵀ (float32 values; 0 where the solve fails: any P keeps
    the solutions); P [D | g] in midpoint-radius form (``linalg.product_midrad``'s bound); one
    interval Gauss-Seidel sweep on (P D) p = P g over the position (``linalg.gauss_seidel`` with
    ``C=False``).  Returns the new position bounds (N, 3) (not widened), the boxes proved empty and
    P (N, 3, legs − 1); rows with a non-finite input keep their position."""
    N = xlo.shape[0]
    legs = rblo.shape[1]
    m = legs - 1
    plo = np.empty((N, 3))
    phi = np.empty((N, 3))
    empty = np.zeros(N, dtype=np.bool_)
    Pout = np.zeros((N, 3, m))
    Dlo = np.empty((m, 4))            # [D | g]
    Dhi = np.empty((m, 4))
    Dm = np.empty((m, 4))
    Dw = np.empty((m, 4))
    G = np.empty((3, 3 + m))
    slo = np.empty(legs)
    shi = np.empty(legs)
    Alo = np.empty((3, 4))
    Ahi = np.empty((3, 4))
    ylo = np.empty(3)
    yhi = np.empty(3)
    gam = (m + 1) * 2.0 ** -53
    for b in range(N):
        for k in range(3):
            plo[b, k], phi[b, k] = xlo[b, k], xhi[b, k]
        finite = True
        for i in range(legs):
            finite &= np.isfinite(Llo[b, i]) and np.isfinite(Lhi[b, i])
            for k in range(3):
                finite &= np.isfinite(rblo[b, i, k]) and np.isfinite(rbhi[b, i, k])
        for k in range(3):
            finite &= np.isfinite(xlo[b, k]) and np.isfinite(xhi[b, k])
        if not finite:
            continue
        _difference_equations(b, rblo, rbhi, alo, ahi, klo, khi, Llo, Lhi, slo, shi, Dlo, Dhi)
        for r in range(m):
            for j in range(4):
                mm, rr = midrad(Dlo[r, j], Dhi[r, j])
                Dm[r, j] = mm
                Dw[r, j] = gam * abs(mm) + rr
        # P = (Dmᵀ Dm + 1e-300 I)⁻¹ Dmᵀ by Gaussian elimination with partial pivoting (a heuristic)
        for i in range(3):
            for j in range(3):
                acc = 1e-300 if i == j else 0.0
                for r in range(m):
                    acc += Dm[r, i] * Dm[r, j]
                G[i, j] = acc
            for r in range(m):
                G[i, 3 + r] = Dm[r, i]
        ok = gauss_jordan(G, 3)
        for i in range(3):
            for r in range(m):
                v = G[i, 3 + r] if ok else 0.0
                v = np.float64(np.float32(v)) if abs(v) < 2.0 ** 127 else 0.0   # NaN, huge: 0
                Pout[b, i, r] = v
        # P [D | g] in midpoint-radius form, then one Gauss-Seidel sweep on the position
        bad = False
        for i in range(3):
            for j in range(4):
                sm, sr = 0.0, 0.0
                for r in range(m):
                    sm += Pout[b, i, r] * Dm[r, j]
                    sr += abs(Pout[b, i, r]) * Dw[r, j]
                sr = upper(sr, 4 * m + 4) + m * 2.0 ** -1022
                Alo[i, j], Ahi[i, j] = down(sm - sr), up(sm + sr)
                bad |= not (np.isfinite(Alo[i, j]) and np.isfinite(Ahi[i, j]))
        if bad:
            continue
        empty[b] = _sweep(Alo, Ahi, xlo[b], xhi[b], ylo, yhi)
        if not empty[b]:
            for k in range(3):
                plo[b, k], phi[b, k] = ylo[k], yhi[k]
    return plo, phi, empty, Pout


@njit(cache=True, error_model="numpy")
def _np_max(a, b):
    """``np.maximum`` for two floats (a NaN operand gives NaN)."""
    return a if (a >= b or a != a) else b


@njit(cache=True, error_model="numpy")
def _np_min(a, b):
    """``np.minimum`` for two floats (a NaN operand gives NaN)."""
    return a if (a <= b or a != a) else b


@njit(cache=True, error_model="numpy")
def gap_splits_quaternion(lo, hi, Llo, rblo, rbhi, alo, ahi, p, at_least):
    """``contract.gap_splits`` box by box: (dim, at) for the boxes [lo, hi] (N, p + 4) of a quaternion
    system, the lower squared leg lengths ``Llo`` (N, legs), R b_i over the boxes (``rb``, (N, legs, 3):
    ``FKSystem.rotated_box``) and a (legs, 3) — the same float operations in the same order as the
    numpy version (``tests/test_fk_hc4.py`` compares them bit for bit).  Only a split point."""
    N, n = lo.shape
    legs = Llo.shape[1]
    dim = np.full(N, -1, dtype=np.int64)
    at = np.full(N, np.nan)
    sq = np.empty(4)
    mlo = np.empty((legs, 3))
    mhi = np.empty((legs, 3))
    e2 = np.empty((legs, 3))
    for b in range(N):
        best = 0.0
        bd = -1
        ba = np.nan
        for r in range(4):
            sq[r] = sqr(lo[b, p + r], hi[b, p + r])[1]
        total = ((sq[0] + sq[1]) + sq[2]) + sq[3]
        for k in range(p, n):       # the norm equation: r_k ∉ (−√t, √t)
            t = 1.0 - (total - sq[k - p])
            g = np.sqrt(_np_max(t, 0.0))
            glo, ghi = _np_max(-g, lo[b, k]), _np_min(g, hi[b, k])
            frac = (ghi - glo) / _np_max(hi[b, k] - lo[b, k], 1e-300) if t > 0 else 0.0
            if not np.isfinite(frac):
                frac = 0.0
            if frac > best:
                best, bd, ba = frac, k, 0.5 * (glo + ghi)
        if p:
            for i in range(legs):
                for k in range(3):
                    ml, mh = down_sum(rblo[b, i, k] - ahi[i, k]), up_sum(rbhi[b, i, k] - alo[i, k])
                    mlo[i, k], mhi[i, k] = ml, mh
                    e2[i, k] = sqr(down_sum(ml + lo[b, k]), up_sum(mh + hi[b, k]))[1]
            for k in range(p):      # leg i: p_k ∉ (−√t − m̲_ik, √t − m̄_ik)
                width = _np_max(hi[b, k] - lo[b, k], 1e-300)
                fbest = 0.0
                fat = 0.0
                for i in range(legs):
                    t = Llo[b, i] - (((e2[i, 0] + e2[i, 1]) + e2[i, 2]) - e2[i, k])
                    g = np.sqrt(_np_max(t, 0.0))
                    glo, ghi = _np_max(-g - mlo[i, k], lo[b, k]), _np_min(g - mhi[i, k], hi[b, k])
                    frac = (ghi - glo) / width if t > 0 else 0.0
                    if not np.isfinite(frac):
                        frac = 0.0
                    if i == 0 or frac > fbest:      # np.argmax: the first largest
                        fbest, fat = frac, 0.5 * (glo + ghi)
                if fbest > best:
                    best, bd, ba = fbest, k, fat
        if best >= at_least:
            dim[b], at[b] = bd, ba
    return dim, at
