"""Forward-backward (HC4-revise) contraction of the FK equations, batched over boxes.

One pass, in this fixed order (``docs/soundness.md`` §8 proves each step keeps
every root of the box; the checker, ``proofs/fk.py``, repeats exactly these
operations in mpmath interval arithmetic, so it finds a box inside ours):

1. norm equation, for k = 1..m in turn (r = the m rotation unknowns):
   r_k ← root(r_k, 1 − Σ_{j≠k} r_j²)   (sum over j in increasing order);
2. R = R(z) and, per leg i, u_i = R b_i (``FKSystem.rotation``/``rotated``),
   for a quaternion intersected with the centred form R b_i(c) + Σ_r ∂(R b_i)/∂q_r(Y)(x_r − c_r),
   c the float midpoint of the given box x, Y ∋ (x + c)/2 (``FKSystem.rotated_centred`` over the
   given box; the checker evaluates it over the box after step 1, a subset: its u lies inside ours);
   e_i = (u_i − a_i) + p;
3. leg equation i, for coordinates k = 1..dim in turn:
   e_ik ← root(e_ik, ρ_i² − Σ_{k'≠k} e_ik'²);
   then, for a Gough-Stewart robot, ``PAIR_ROUNDS`` times, for leg i = 1..legs in turn: the leg
   pairs e_i ← e_i ∩ ⋂_j (e_j + (R (b_i − b_j) − (a_i − a_j))) from the current e (e_i − e_j does
   not hold p: a relation on the rotation alone, and R (b_i − b_j) is enclosed far tighter than
   R b_i − R b_j), R (b_i − b_j) = Σ_m R_km (b_i − b_j)_m with the R of step 2, m increasing, ∩ its
   centred form over the given box (from the parts of R b_i's, step 2); then leg i's equation
   again, as above;
4. position: p_k ← p_k ∩ ⋂_i ((e_ik − u_ik) + a_ik);
5. u_ik ← u_ik ∩ ((e_ik − p_k) + a_ik)   (no p for the spherical robot);
6. entries of R, all from the R of step 2: for every leg i and column j with
   0 ∉ b_ij, R_kj ← R_kj ∩ (u_ik − Σ_{j'≠j} R_kj' b_ij') / b_ij (computed here as
   × an outward enclosure of 1/b_ij: the same exact operation, enclosed);
7. rotation unknowns from R: planar c ← c ∩ R_00 ∩ R_11, s ← s ∩ R_10 ∩ (−R_01);
   quaternion, in this order:
   (R_00, q2, q3), (R_11, q1, q3), (R_22, q1, q2), with t = (1 − R_kk)·0.5:
   q_a ← root(q_a, t − q_b²), then q_b ← root(q_b, t − q_a²);
   then for each off-diagonal entry R_kj = 2(q_a q_b + σ q_c q_d) of ``OFF_DIAGONAL``,
   with h = R_kj·0.5: g = h − σ(q_c q_d), q_a ← q_a ∩ g / q_b, q_b ← q_b ∩ g / q_a;
   g' = σ(h − q_a q_b), q_c ← q_c ∩ g' / q_d, q_d ← q_d ∩ g' / q_c
   (a division only where 0 ∉ divisor; elsewhere the variable is kept).

root(x, t) = hull(x ∩ {y : y² ∈ t}): x ∩ [−√t̄, −√t̲] and x ∩ [√t̲, √t̄] (t̲ clipped
at 0), the hull of the pieces that are not empty; nothing if t̄ < 0.

Every step is an intersection of a variable with a set that holds its value at
every root of the box, so no root is lost; a variable left empty proves that the
box holds no root.  Every operation is monotone for inclusion (the divisions are
skipped only where the divisor holds 0, and a divisor that is a subset of one
without 0 has no 0), and each of ours encloses the exact image of its operands,
which is why a re-computation of the same exact operations with correctly
rounded, tighter arithmetic (the checker's) finds a box inside this one.
"""
from __future__ import annotations

import numpy as np

from intervals import Interval, mul, sqr
from intervals.interval import div
from intervals.midrad import U, upper
from intervals.rounding import down, up, up_sum

from .rotation import DIAGONAL, OFF_DIAGONAL, TABLES, from_midrad   # R(q)'s entries as products of q's


PAIR_ROUNDS = 2     # rounds of the leg-pair step (step 3) for a Gough-Stewart robot


def root(x: Interval, t: Interval) -> Interval:
    """hull(x ∩ {y : y² ∈ t}); empty (lo > hi) where there is no such y.

    √t̲ and √t̄ are bounded by the correctly rounded square root widened by one
    ``down``/``up`` step (docs/soundness.md §1).
    """
    with np.errstate(invalid="ignore"):
        rlo = np.maximum(down(np.sqrt(np.maximum(t.lo, 0.0))), 0.0)
        rhi = up(np.sqrt(np.maximum(t.hi, 0.0)))
        nlo, nhi = np.maximum(x.lo, -rhi), np.minimum(x.hi, -rlo)
        plo, phi = np.maximum(x.lo, rlo), np.minimum(x.hi, rhi)
        neg = (nlo <= nhi) & (t.hi >= 0)
        pos = (plo <= phi) & (t.hi >= 0)
        lo = np.where(neg, nlo, np.where(pos, plo, np.inf))
        hi = np.where(pos, phi, np.where(neg, nhi, -np.inf))
    return Interval.from_bounds(lo, hi)


def divide_into(x: Interval, num: Interval, den: Interval) -> Interval:
    """x ∩ num / den where 0 ∉ den; x itself elsewhere."""
    with np.errstate(all="ignore"):
        ok = (den.lo > 0) | (den.hi < 0)
        q = div(num, Interval.from_bounds(np.where(ok, den.lo, 1.0), np.where(ok, den.hi, 1.0)))
        return Interval.from_bounds(np.where(ok, np.maximum(x.lo, q.lo), x.lo), np.where(ok, np.minimum(x.hi, q.hi), x.hi))


def _inverse(system) -> Interval:
    """Enclosures of 1/b_ij (legs, dim), computed once per system (1 where 0 ∈ b_ij: unused)."""
    def build():
        b = system.b
        ok = (b.lo > 0) | (b.hi < 0)
        one = np.ones(b.shape)
        return div(Interval.from_bounds(one, one), Interval.from_bounds(np.where(ok, b.lo, 1.0), np.where(ok, b.hi, 1.0)))
    return system.memo("hc4_inverse", build)


def _differences(system) -> tuple[Interval, Interval]:
    """Enclosures of b_i − b_j and a_i − a_j, (legs, legs, dim) each (step 3's leg pairs)."""
    b, a = system.b, system.a
    return b[:, None, :] - b[None, :, :], a[:, None, :] - a[None, :, :]


def _legs(e: Interval, L: Interval, empty):
    """Step 3: e_ik ← root(e_ik, ρ_i² − Σ_{k'≠k} e_ik'²), k in turn, for every leg; returns the new empty mask."""
    dim = e.shape[-1]
    s = sqr(e)
    for k in range(dim):
        others = None
        for kk in range(dim):
            if kk != k:
                others = s[..., kk] if others is None else others + s[..., kk]
        ek = root(e[..., k], L - others)
        e[..., k] = ek
        s[..., k] = sqr(ek)
        empty = empty | np.any(ek.lo > ek.hi, axis=1)
    return empty


def _pairs(system, R: Interval, form, lo, hi, e: Interval, L: Interval, empty):
    """Step 3, leg pairs, leg after leg: e_i ← e_i ∩ ⋂_j (e_j + d_ij) from the current e, then leg i's roots
    (``_legs``); d_ij = R (b_i − b_j) − (a_i − a_j), R (b_i − b_j) as Σ_m R_km (b_i − b_j)_m (m increasing)
    ∩ its centred form over the given boxes [lo, hi] from the parts of R b_i's (``form``; the operations of
    ``kernels._pair_terms``).  Returns the new empty mask (e in place)."""
    db, da = _differences(system)
    d = None
    for m in range(db.shape[-1]):   # (N, i, j, k)
        t = R[:, None, None, :, m] * db[None, :, :, None, m]
        d = t if d is None else d + t
    _, _, cm, cr, Dm, Dr = form
    p = system.n_pos
    X = Interval.from_bounds(lo[:, p:], hi[:, p:])
    c = X.mid()
    h = np.maximum(up_sum(c - X.lo), up_sum(X.hi - c))[:, :, None, None, None]              # (N, 4, 1, 1, 1)
    with np.errstate(invalid="ignore", over="ignore"):
        dm = cm[:, :, None, :] - cm[:, None, :, :]                                           # (N, i, j, k)
        rad = (cr[:, :, None, :] + cr[:, None, :, :]) + np.abs(dm) * U
        terms = (np.abs(Dm[:, :, :, None, :] - Dm[:, :, None, :, :]) * (1.0 + 2.0 * U)
                 + (Dr[:, :, :, None, :] + Dr[:, :, None, :, :])) * h
        for r in range(4):
            rad = rad + terms[:, r]
        rad = upper(rad, 16)
        ok = ~np.isnan(rad)
        d = Interval.from_bounds(np.where(ok, np.maximum(d.lo, down(dm - rad)), d.lo),
                                 np.where(ok, np.minimum(d.hi, up(dm + rad)), d.hi)) - da[None]
    for i in range(e.shape[1]):
        cand = e + d[:, i]                               # (N, j, k): e_j + d_ij
        e.lo[:, i] = np.maximum(e.lo[:, i], np.max(cand.lo, axis=1))
        e.hi[:, i] = np.minimum(e.hi[:, i], np.min(cand.hi, axis=1))
        leg = e[:, i:i + 1]
        empty = _legs(leg, L[:, i:i + 1], empty)
        e[:, i:i + 1] = leg
    return empty


def _meet(x: Interval, y: Interval) -> Interval:
    return Interval.from_bounds(np.maximum(x.lo, y.lo), np.minimum(x.hi, y.hi))


def hc4(system, lo, hi, L: Interval, generic: bool = False, keep: dict | None = None, native: bool = True):
    """One forward-backward pass over the boxes [lo, hi] (N, n), squared leg lengths L (N, legs).

    Returns (lo, hi, empty): the contracted boxes (inside the given ones) and the
    mask of boxes proved to hold no root (their rows are meaningless); ``keep`` (a dict), for a
    quaternion: keep["form"] = ``FKSystem.centred_form`` of the given boxes (step 2).  The planar
    robot takes ``_hc4_planar`` (the same operations, stacked) unless ``generic``; a quaternion
    system takes the machine-code twin (``fk.kernels``) unless ``native`` is false.
    """
    if system.kind == "planar-3rpr" and not generic:
        return _hc4_planar(system, lo, hi, L)
    if system.kind != "planar-3rpr" and native:
        return _hc4_native(system, lo, hi, L, keep)
    lo, hi = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    N, n = lo.shape
    p = system.n_pos
    quaternion = system.kind != "planar-3rpr"
    empty = np.zeros(N, dtype=bool)
    with np.errstate(all="ignore"):
        z = [Interval.from_bounds(lo[:, k], hi[:, k]) for k in range(n)]

        def put(k, v):
            nonlocal empty
            z[k] = v
            empty |= v.lo > v.hi

        # 1. the norm equation
        squares = {j: sqr(z[j]) for j in range(p, n)}
        for k in range(p, n):
            others = None
            for j in range(p, n):
                if j != k:
                    others = squares[j] if others is None else others + squares[j]
            put(k, root(z[k], 1.0 - others))
            squares[k] = sqr(z[k])
        X = Interval.from_bounds(np.stack([v.lo for v in z], 1), np.stack([v.hi for v in z], 1))
        # 2. forward: R, u_i = R b_i, e_i = (u_i − a_i) + p
        R = system.rotation(X)                               # (N, dim, dim)
        b = system.b
        if quaternion:      # u_i = R b_i in midpoint-radius form, and its column terms for step 6
            um, ur, Pm, Pr = system.rotated_midrad(R, columns=True)
            u = from_midrad(um, ur)
        else:
            T = R[:, None, :, :] * b[None, :, None, :]       # (N, legs, k, j): R_kj b_ij, also for step 6
            u = T[..., 0]                                    # u_i = R b_i: the products and sums of
            for j in range(1, T.shape[-1]):                  # FKSystem.rotated, in its order
                u = u + T[..., j]
        # ∩ the centred form over the given box, around its midpoint (FKSystem.rotated_centred; a superset
        # of the checker's, which is over the box after step 1)
        if quaternion:
            form = system.centred_form(Interval.from_bounds(lo, hi))
            if keep is not None:
                keep["form"] = form
            u = system.rotated_centred(Interval.from_bounds(lo, hi), rb=u, form=form)
        a = system.a[None, :, :]
        e = u - a
        if p:
            e = e + X[:, None, :p]
        dim = e.shape[-1]
        # 3. backward through each leg equation; then, for a position and a quaternion, the leg pairs
        # and each leg equation again, PAIR_ROUNDS times
        empty = _legs(e, L, empty)
        for _ in range(PAIR_ROUNDS if p and quaternion else 0):
            empty = _pairs(system, R, form, lo, hi, e, L, empty)
        # 4. the position
        if p:
            for k in range(p):
                cand = (e[..., k] - u[..., k]) + a[..., k]   # (N, legs)
                put(k, Interval.from_bounds(np.maximum(z[k].lo, np.max(cand.lo, axis=1)),
                                     np.minimum(z[k].hi, np.min(cand.hi, axis=1))))
        # 5. u_ik from e_ik
        for k in range(dim):
            back = e[..., k] - z[k][:, None] if p else e[..., k]
            u[..., k] = _meet(u[..., k], back + a[..., k])
        # 6. entries of R from u_i = R b_i (all candidates from the R of step 2)
        R = _entries(system, R, u, T if not quaternion else None, (Pm, Pr) if quaternion else None)
        empty |= np.any(R.lo > R.hi, axis=(1, 2))
        # 7. the rotation unknowns from R
        _rotation_unknowns(system, R, z, put)
        nlo = np.stack([v.lo for v in z], 1)
        nhi = np.stack([v.hi for v in z], 1)
        bad = np.any(np.isnan(nlo) | np.isnan(nhi), axis=1) & ~empty   # never expected: keep the box
        nlo[bad], nhi[bad] = lo[bad], hi[bad]
        nlo, nhi = np.maximum(nlo, lo), np.minimum(nhi, hi)
    return nlo, nhi, empty


def _entries(system, R: Interval, u: Interval, T: Interval | None, parts) -> Interval:
    """Step 6: R_kj ← R_kj ∩ (u_ik − Σ_{j'≠j} R_kj' b_ij') / b_ij for the legs with 0 ∉ b_ij, every
    candidate from the R of step 2 (``T``: the products R_kj b_ij, planar; ``parts``: the sums that
    leave column j out in midpoint-radius form, quaternion)."""
    b = system.b
    dim = b.shape[1]
    nonzero = (b.lo > 0) | (b.hi < 0)                  # (legs, dim)
    inverse = _inverse(system)                           # enclosures of 1/b_ij
    Rlo, Rhi = R.lo.copy(), R.hi.copy()
    for j in range(dim):
        legs_j = np.nonzero(nonzero[:, j])[0]
        if not len(legs_j):
            continue
        if parts is not None:  # Σ_{j'≠j} R_kj' b_ij' in midpoint-radius form (``rotated_midrad``)
            Pm, Pr = parts
            rest = from_midrad(Pm[..., j][:, legs_j], Pr[..., j][:, legs_j])
            num = u[:, legs_j] - rest                    # (N, legs_j, k)
        else:
            rest = None
            for jj in range(dim):
                if jj != j:
                    rest = T[..., jj] if rest is None else rest + T[..., jj]
            num = (u - rest)[:, legs_j]                  # (N, legs_j, k)
        cand = num * inverse[legs_j, j][None, :, None]   # ÷ b_ij, as × an enclosure of 1/b_ij
        Rlo[:, :, j] = np.maximum(Rlo[:, :, j], np.max(cand.lo, axis=1))
        Rhi[:, :, j] = np.minimum(Rhi[:, :, j], np.min(cand.hi, axis=1))
    return Interval.from_bounds(Rlo, Rhi)


def _rotation_unknowns(system, R: Interval, z: list, put):
    """Step 7: the rotation unknowns of ``z`` from the entries of R (``put(k, v)`` sets z[k])."""
    p = system.n_pos
    if system.kind == "planar-3rpr":
        put(2, _meet(_meet(z[2], R[:, 0, 0]), R[:, 1, 1]))
        put(3, _meet(_meet(z[3], R[:, 1, 0]), -R[:, 0, 1]))
        return
    q = z[p:]

    def setq(m, v):
        q[m] = v
        put(p + m, v)
    for k, ia, ib in DIAGONAL:
        t = (1.0 - R[:, k, k]) * 0.5
        setq(ia, root(q[ia], t - sqr(q[ib])))
        setq(ib, root(q[ib], t - sqr(q[ia])))
    for (k, j), (ia, ib), (ic, id_), sigma in OFF_DIAGONAL:
        h = R[:, k, j] * 0.5
        cd = q[ic] * q[id_]
        g = h - cd if sigma > 0 else h + cd
        setq(ia, divide_into(q[ia], g, q[ib]))
        setq(ib, divide_into(q[ib], g, q[ia]))
        g2 = h - q[ia] * q[ib]
        if sigma < 0:
            g2 = -g2
        setq(ic, divide_into(q[ic], g2, q[id_]))
        setq(id_, divide_into(q[id_], g2, q[ic]))


def _hc4_native(system, lo, hi, L: Interval, keep: dict | None):
    """``hc4`` for a quaternion system by ``kernels.hc4_quaternion`` (the same pass, box by box)."""
    from .kernels import hc4_quaternion      # numba: imported by the spatial searches only
    lo, hi = np.ascontiguousarray(lo, dtype=np.float64), np.ascontiguousarray(hi, dtype=np.float64)
    form = system.centred_form(Interval.from_bounds(lo, hi))
    if keep is not None:
        keep["form"] = form

    def build():
        bm, inner, outer = system.b_midrad()
        b, inverse = system.b, _inverse(system)
        db, da = _differences(system)
        return tuple(np.ascontiguousarray(v) for v in (
            system.a.lo, system.a.hi, bm, inner, outer, (b.lo > 0) | (b.hi < 0), inverse.lo, inverse.hi,
            db.lo, db.hi, da.lo, da.hi))
    consts = system.memo("hc4_native_consts", build)
    f64 = np.ascontiguousarray
    return hc4_quaternion(lo, hi, f64(L.lo, dtype=np.float64), f64(L.hi, dtype=np.float64),
                          *(f64(v) for v in form), *consts, PAIR_ROUNDS, system.n_pos, *TABLES)


def _hc4_planar(system, lo, hi, L: Interval):
    """``hc4`` for the planar robot: the same interval operations on the same operands, in the same
    order where one feeds the next, but stacked where they are independent (both coordinates of
    steps 4 and 5, both columns of step 6) and with the products R_kj b_ij of step 2 reused in
    step 6 — so the same floats (``tests/test_fk_hc4.py`` compares them bit for bit) in fewer
    operations."""
    lo, hi = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    with np.errstate(all="ignore"):
        # 1. the norm equation: c from s, then s from the new c
        c = root(Interval.from_bounds(lo[:, 2], hi[:, 2]), 1.0 - sqr(Interval.from_bounds(lo[:, 3], hi[:, 3])))
        s = root(Interval.from_bounds(lo[:, 3], hi[:, 3]), 1.0 - sqr(c))
        empty = (c.lo > c.hi) | (s.lo > s.hi)
        zlo = np.stack([lo[:, 0], lo[:, 1], c.lo, s.lo], 1)
        zhi = np.stack([hi[:, 0], hi[:, 1], c.hi, s.hi], 1)
        X = Interval.from_bounds(zlo, zhi)
        # 2. forward: R, the products R_kj b_ij, u_i = R b_i, e_i = (u_i − a_i) + p
        R = system.rotation(X)                                               # (N, 2, 2)
        b = system.b
        T = mul(R[:, None, :, :], Interval.from_bounds(b.lo[None, :, None, :], b.hi[None, :, None, :]))  # (N, legs, k, j)
        u = T[..., 0] + T[..., 1]                                           # (N, legs, 2)
        a = system.a[None, :, :]
        e = (u - a) + X[:, None, :2]
        # 3. backward through each leg equation: e_i0 from e_i1, then e_i1 from the new e_i0
        e0 = root(e[..., 0], L - sqr(e[..., 1]))
        e1 = root(e[..., 1], L - sqr(e0))
        empty |= np.logical_or.reduce(e0.lo > e0.hi, axis=1) | np.logical_or.reduce(e1.lo > e1.hi, axis=1)
        e = Interval.from_bounds(np.stack([e0.lo, e1.lo], -1), np.stack([e0.hi, e1.hi], -1))
        # 4. the position, both coordinates at once
        cand = (e - u) + a                                                   # (N, legs, 2)
        plo = np.maximum(zlo[:, :2], np.maximum.reduce(cand.lo, axis=1))
        phi = np.minimum(zhi[:, :2], np.minimum.reduce(cand.hi, axis=1))
        empty |= np.logical_or.reduce(plo > phi, axis=1)
        zlo[:, :2], zhi[:, :2] = plo, phi
        # 5. u_ik from e_ik, both coordinates at once
        u = _meet(u, (e - Interval.from_bounds(plo[:, None, :], phi[:, None, :])) + a)
        # 6. entries of R: column j from u_i − R_k(1−j) b_i(1−j), for the legs with 0 ∉ b_ij
        nonzero = (b.lo > 0) | (b.hi < 0)                                    # (legs, 2)
        inverse = _inverse(system)
        rest = T[..., ::-1]                                                  # [..., j] = R_k(1−j) b_i(1−j)
        num = Interval.from_bounds(u.lo[..., None], u.hi[..., None]) - rest         # (N, legs, k, j)
        cand = num * Interval.from_bounds(inverse.lo[None, :, None, :], inverse.hi[None, :, None, :])
        used = nonzero[None, :, None, :]
        Rlo = np.maximum(R.lo, np.maximum.reduce(np.where(used, cand.lo, -np.inf), axis=1))
        Rhi = np.minimum(R.hi, np.minimum.reduce(np.where(used, cand.hi, np.inf), axis=1))
        empty |= np.logical_or.reduce(Rlo > Rhi, axis=(1, 2))
        # 7. c ← c ∩ R_00 ∩ R_11, s ← s ∩ R_10 ∩ (−R_01)
        clo = np.maximum(np.maximum(zlo[:, 2], Rlo[:, 0, 0]), Rlo[:, 1, 1])
        chi = np.minimum(np.minimum(zhi[:, 2], Rhi[:, 0, 0]), Rhi[:, 1, 1])
        slo = np.maximum(np.maximum(zlo[:, 3], Rlo[:, 1, 0]), -Rhi[:, 0, 1])
        shi = np.minimum(np.minimum(zhi[:, 3], Rhi[:, 1, 0]), -Rlo[:, 0, 1])
        empty |= (clo > chi) | (slo > shi)
        zlo[:, 2], zhi[:, 2], zlo[:, 3], zhi[:, 3] = clo, chi, slo, shi
        bad = np.logical_or.reduce(np.isnan(zlo) | np.isnan(zhi), axis=1) & ~empty   # never expected: keep the box
        zlo[bad], zhi[bad] = lo[bad], hi[bad]
        nlo, nhi = np.maximum(zlo, lo), np.minimum(zhi, hi)
    return nlo, nhi, empty


def gap_splits(system, lo, hi, L: Interval, at_least: float, native: bool = True):
    """(dim, at): for each box, the middle of the widest gap between the two branches of one of
    HC4's square roots (``root``), when that gap spans at least ``at_least`` of the side (dim −1,
    at NaN otherwise).

    Floats from the box: for the norm equation r_k² = 1 − Σ_{j≠k} r_j² ≥ t, so r_k ∉ (−√t, √t); for
    leg i and coordinate k, (p_k + m_ik)² = ρ_i² − Σ_{k'≠k} ell_ik'² ≥ t with m_i = R b_i − a_i and
    ell_i = p + m_i, so p_k ∉ (−√t − m̲_ik, √t − m̄_ik).  ``root`` keeps the hull of the branches, so a
    box holding both (a robot's mirror postures z and −z, a rotation and its reverse) is never
    contracted there; cut in the gap, each part holds one branch.  Only a split point: any point
    keeps the search sound (the checker recomputes nothing from it).  Sums of squares are taken left to
    right; R b_i is ``FKSystem.rotated_box``; a quaternion system takes the machine-code twin
    (``kernels.gap_splits_quaternion``, the same floats) unless ``native`` is false."""
    N, n = lo.shape
    p = system.n_pos
    if system.kind != "planar-3rpr" and native:
        from .kernels import gap_splits_quaternion      # numba: imported by the spatial searches only
        f64 = np.ascontiguousarray
        lo, hi = f64(lo, dtype=np.float64), f64(hi, dtype=np.float64)
        if p:
            rb = system.rotated_box(Interval.from_bounds(lo, hi))
            rblo, rbhi, alo, ahi = rb.lo, rb.hi, system.a.lo, system.a.hi
        else:
            rblo = rbhi = np.empty((N, 0, 3))
            alo = ahi = np.empty((0, 3))
        return gap_splits_quaternion(lo, hi, f64(L.lo, dtype=np.float64), rblo, rbhi, f64(alo), f64(ahi), p,
                                     float(at_least))
    best = np.zeros(N)
    dim = np.full(N, -1)
    at = np.full(N, np.nan)
    width = np.maximum(hi - lo, 1e-300)
    rows = np.arange(N)

    def consider(k, glo, ghi, t):
        nonlocal best, dim, at
        glo, ghi = np.maximum(glo, lo[:, k, None]), np.minimum(ghi, hi[:, k, None])
        frac = np.where(t > 0, (ghi - glo) / width[:, k, None], 0.0)
        frac = np.where(np.isfinite(frac), frac, 0.0)
        j = np.argmax(frac, axis=1)
        better = frac[rows, j] > best
        best = np.where(better, frac[rows, j], best)
        dim = np.where(better, k, dim)
        at = np.where(better, 0.5 * (glo[rows, j] + ghi[rows, j]), at)

    with np.errstate(all="ignore"):
        X = Interval.from_bounds(lo, hi)
        squares = sqr(X[:, p:]).hi
        total = squares[:, 0]
        for k in range(1, n - p):
            total = total + squares[:, k]
        for k in range(p, n):
            t = 1.0 - (total - squares[:, k - p])
            g = np.sqrt(np.maximum(t, 0.0))[:, None]
            consider(k, -g, g, t[:, None])
        if p:
            m = system.rotated_box(X) - system.a[None]
            e2 = sqr(m + X[:, None, :p]).hi
            esum = e2[..., 0]
            for k in range(1, e2.shape[-1]):
                esum = esum + e2[..., k]
            for k in range(p):
                t = L.lo - (esum - e2[..., k])
                g = np.sqrt(np.maximum(t, 0.0))
                consider(k, -g - m.lo[..., k], g - m.hi[..., k], t)
    use = best >= at_least
    return np.where(use, dim, -1), np.where(use, at, np.nan)
