"""The Cayley-Menger rule of the FK search (6-6 Gough-Stewart robots): a box whose rotation no
posture can have, proved by the sign of one polynomial in the quaternion alone.

At a posture (p, q), the centres C_m = a_m − R(q) b_m of four legs m and the position p satisfy
|p − C_m|² = L_m, so the Cayley-Menger determinant of these five points vanishes (they lie in R³).
Its entries |C_m − C_n|² and L_m are, once multiplied by |q|², quadratic forms in q, so

    F(q) = CM(q) · |q|^8

is a form of degree 8 in q (165 coefficients), one per quadruple of legs (15).  On a box Q of
quaternions whose component q_k keeps one sign (chart k), every q in Q has q/q_k in the chart box
Y = (Q_i / Q_k)_{i≠k}, and F(q) = q_k^8 F(q/q_k): if the tensor Bernstein coefficients of the chart
polynomial F(·, q_k = 1) (degree 8 in each of its 3 variables) on a box containing Y all have one
strict sign, no q in Q is the rotation of a posture (Garloff 1986; Ratschek and Rokne 1984: the
range of a polynomial on a box lies in the hull of its Bernstein coefficients).  Leaf reason
``cm-bernstein-empty``, evidence 4·quad + chart (docs/certificates.md, leaf 11).  A box no single
quad excludes is tried with G = Σ λ_quad F_quad, which vanishes at every posture too: the weights λ
cancel G's first-order part at the box's centre (``_weights``), so that G keeps one sign on boxes
beside a curve where every F_quad nearly vanishes (leaf ``cm-combination-empty``, evidence chart
and λ; leaf 12).

- ``forms``: the 15 forms' coefficients in midpoint-radius float, enclosing the exact ones for every
  geometry and squared lengths in the given enclosures (``intervals.midrad``'s a-priori bound, Higham
  2002 eq. 3.5; Rump 1999), by a Horner scheme over the determinant's 130 terms;
- ``charts``: those coefficients as dense (4, 15, 9, 9, 9) chart polynomials, and packed by monomial;
- ``excluded``: the tests of a batch of boxes (compiled, box by box), with the rounding-error bound
  of docs/soundness.md §8 "The Cayley-Menger rule": a coefficient counts only beyond twice that
  bound, its radii's part taken ``ROOM`` times.

The issue-16 studies measured the rule (docs/benchmarks.md, "the Bernstein test as a node rule").
"""
from __future__ import annotations

import itertools
from math import comb

import numpy as np
from numba import njit

from intervals.midrad import ETA, U, midrad, product_midrad, upper

QUADS = tuple(itertools.combinations(range(6), 4))      # the evidence's quad: an index in this tuple
PAIR_LEGS = np.array([p for quad in QUADS for p in itertools.combinations(quad, 2)])    # (90, 2)
DEG, N1 = 8, 9
FIRST_ROWS = np.array([1, 4, 7])      # Bernstein rows tried first (``_all_beyond``)
OTHER_ROWS = np.array([0, 2, 3, 5, 6, 8])
ALL_ROWS = np.arange(N1)
END_ROWS, INNER_ROWS = np.array([0, DEG]), np.arange(1, DEG)
SLACK = 2.0 ** -40       # the relative part of the bound (docs/soundness.md §8: at least 10 times too large)
TINY = 2.0 ** -1000      # its absolute part (underflow), per unit of Σ|coefficients| and S^8
ROOM = 64.0              # room for a checker's wider enclosures of the coefficients (proofs/ encloses them
                         # up to 13 times wider: seen on Dietmaier's robot, where 1 leaf in 110 000 failed it)
COMB = np.array([[comb(j, m) for m in range(N1)] for j in range(N1)], float)           # C(j, m)
VERTEX_ORDER = np.array([0, 7, 1, 6, 2, 5, 4, 3])      # opposite vertices first: they differ most often
MONO3 = np.array([(i, j, l) for i in range(N1) for j in range(N1 - i) for l in range(N1 - i - j)])   # (165, 3)
PACKED = 168             # the 165 monomials, padded with zeros to a multiple of 4
RATIO = np.array([[comb(i, m) / comb(DEG, m) for m in range(N1)] for i in range(N1)])   # C(i, m)/C(8, m)


def determinant_terms():
    """The Cayley-Menger determinant of 4 centres and a point, expanded (Leibniz, 720 permutations):
    [(integer coefficient, exponents of d01, d02, d03, d12, d13, d23, L0, L1, L2, L3)]."""
    pairs = list(itertools.combinations(range(4), 2))

    def entry(r, c):         # 0 / 1 constants, or the variable's index (a point's row/column is 1..4)
        if r == c:
            return "0"
        if r == 0 or c == 0:
            return "1"
        if r == 5 or c == 5:
            return 6 + min(r, c) - 1
        return pairs.index((min(r, c) - 1, max(r, c) - 1))
    terms = {}
    for perm in itertools.permutations(range(6)):
        factors = [entry(r, c) for r, c in enumerate(perm)]
        if "0" in factors:
            continue
        sign = 1
        for i, j in itertools.combinations(range(6), 2):
            sign = -sign if perm[i] > perm[j] else sign
        e = [0] * 10
        for f in factors:
            if f != "1":
                e[f] += 1
        terms[tuple(e)] = terms.get(tuple(e), 0) + sign
    return [(c, e) for e, c in sorted(terms.items()) if c]


def _monomials(d):
    out = [e for e in itertools.product(range(d + 1), repeat=4) if sum(e) == d]
    return out, {e: i for i, e in enumerate(out)}


MONO = {d: _monomials(d) for d in (2, 4, 6, 8)}


def _pair_map(d1, d2):
    """Pairs of monomials of degrees d1, d2 sorted by their product: (order, run starts, longest run)."""
    (m1, _), (m2, _), (_, idx) = MONO[d1], MONO[d2], MONO[d1 + d2]
    target = np.array([idx[tuple(x + y for x, y in zip(e1, e2))] for e1 in m1 for e2 in m2])
    order = np.argsort(target, kind="stable")
    return order, np.searchsorted(target[order], np.arange(len(idx))), int(np.max(np.bincount(target)))


def _quadratic(terms):
    _, idx = MONO[2]
    v = np.zeros(len(idx))
    for c, (i, j) in terms:
        e = [0, 0, 0, 0]
        e[i] += 1
        e[j] += 1
        v[idx[tuple(e)]] += c
    return v


TERMS = determinant_terms()
T4, T6, T8 = _pair_map(2, 2), _pair_map(4, 2), _pair_map(6, 2)
N2 = _quadratic([(1, (i, i)) for i in range(4)])                   # |q|²
RT = np.array([[_quadratic(t) for t in row] for row in (           # R̃(q) = |q|² R(q), entrywise
    ([(1, (0, 0)), (1, (1, 1)), (-1, (2, 2)), (-1, (3, 3))], [(2, (1, 2)), (-2, (0, 3))], [(2, (1, 3)), (2, (0, 2))]),
    ([(2, (1, 2)), (2, (0, 3))], [(1, (0, 0)), (-1, (1, 1)), (1, (2, 2)), (-1, (3, 3))], [(2, (2, 3)), (-2, (0, 1))]),
    ([(2, (1, 3)), (-2, (0, 2))], [(2, (2, 3)), (2, (0, 1))], [(1, (0, 0)), (-1, (1, 1)), (-1, (2, 2)), (1, (3, 3))]))])


def _entries(a, b, L):
    """Midpoint-radius coefficients (15, 10, 10) of each quad's 10 entries times |q|²: the six
    |C_m − C_n|²|q|² = (|Δa|² + |Δb|²)|q|² − 2 Δaᵀ R̃(q) Δb, then the four L_m |q|².
    ``a``, ``b``: (mid, rad) of (6, 3); ``L``: (mid, rad) of (6,)."""
    (am, ar), (bm, br), (lm, lr) = a, b, L
    m, n = PAIR_LEGS.T                                     # the 90 pairs of legs, quad by quad
    dam, dbm = am[m] - am[n], bm[m] - bm[n]                # a rounding each: within one spacing
    dar, dbr = ar[m] + ar[n] + np.spacing(np.abs(dam)), br[m] + br[n] + np.spacing(np.abs(dbm))
    v, vr = np.concatenate([dam, dbm], 1), np.concatenate([dar, dbr], 1)
    s, sr = product_midrad(v[:, None], vr[:, None], v[:, :, None], vr[:, :, None])
    o, orad = product_midrad(dam[:, :, None], dar[:, :, None], dbm[:, None], dbr[:, None])
    lin, lrad = product_midrad(o.reshape(-1, 1, 9), orad.reshape(-1, 1, 9), RT.reshape(9, 10), None)
    mid = s[:, 0] * N2 - 2.0 * lin[:, 0]                   # (N2: 0 or 1; 2·: exact)
    rad = upper(N2 * sr[:, 0] + 2.0 * lrad[:, 0] + np.spacing(np.abs(mid)), 4)
    quads = np.array(QUADS)
    return (np.concatenate([mid.reshape(15, 6, 10), lm[quads][..., None] * N2], 1),
            np.concatenate([rad.reshape(15, 6, 10), lr[quads][..., None] * N2], 1))


def _times(am, ar, bm, br, T):
    """Products of forms (batched over the leading axes), midpoint-radius: every pair's product, then
    the sums per monomial (at most ``longest`` terms): |error| <= the radii's part + γ Σ|am bm|
    (Higham 2002, eq. 3.5), bounded by ``upper``."""
    order, starts, longest = T
    shape = am.shape[:-1]
    flat = lambda x: x.reshape(*shape, -1)[..., order]  # noqa: E731
    aa, ab = np.abs(am), np.abs(bm)
    pm = flat(am[..., :, None] * bm[..., None, :])
    pa = flat(aa[..., :, None] * ab[..., None, :])
    pr = flat(aa[..., :, None] * br[..., None, :] + ar[..., :, None] * (ab + br)[..., None, :])
    bound = np.add.reduceat(pr, starts, axis=-1) + (longest + 2) * U * np.add.reduceat(pa, starts, axis=-1)
    return np.add.reduceat(pm, starts, axis=-1), upper(bound, 4 * longest + 8) + longest * ETA


def _grouped_sum(m, r, keys):
    """Midpoint-radius sums of the rows (axis 1) with equal sorted ``keys``: (unique keys, sums)."""
    starts = np.concatenate([[0], np.nonzero(keys[1:] != keys[:-1])[0] + 1])
    n = int(np.max(np.diff(np.concatenate([starts, [len(keys)]]))))
    bound = np.add.reduceat(r, starts, axis=1) + (n + 1) * U * np.add.reduceat(np.abs(m), starts, axis=1)
    return keys[starts], np.add.reduceat(m, starts, axis=1), upper(bound, 2 * n + 2) + n * ETA


def forms(a, b, L):
    """Midpoint-radius coefficients (15, 165) (monomials ``MONO[8]``) of F = CM·|q|^8 per quad, for
    every base ``a`` and platform ``b`` (Intervals (6, 3)) and squared lengths ``L`` (Interval (6,)) in
    the enclosures: Horner over the terms c e_v1 e_v2 e_v3 e_v4 (v1 <= v2 <= v3 <= v4)."""
    em, er = _entries(midrad(a.lo, a.hi), midrad(b.lo, b.hi), midrad(L.lo, L.hi))
    rows = sorted((tuple(v for v, ev in enumerate(e) for _ in range(ev)), float(c)) for c, e in TERMS)
    f = np.array([v for v, _ in rows])
    coef = np.array([c for _, c in rows])                          # ±1, ±2, ±4: exact products
    keys3 = f[:, 0] * 100 + f[:, 1] * 10 + f[:, 2]
    k3, Lm, Lr = _grouped_sum(coef[None, :, None] * em[:, f[:, 3]], np.abs(coef)[None, :, None] * er[:, f[:, 3]], keys3)
    pm, pr = _times(em[:, k3 % 10], er[:, k3 % 10], Lm, Lr, T4)
    k2, Sm, Sr = _grouped_sum(pm, pr, k3 // 10)
    pm, pr = _times(Sm, Sr, em[:, k2 % 10], er[:, k2 % 10], T6)
    k1, Tm, Tr = _grouped_sum(pm, pr, k2 // 10)
    pm, pr = _times(Tm, Tr, em[:, k1], er[:, k1], T8)
    _, m, r = _grouped_sum(pm, pr, np.zeros(len(k1), dtype=int))
    return m[:, 0], r[:, 0]


CHART = np.array([[[e[i] for i in range(4) if i != k] for e in MONO[8][0]] for k in range(4)])   # (4, 165, 3)


def charts(m, r):
    """(mid, rad, packed, packed_rad) of the chart polynomials of the forms ``m`` ± ``r`` (``forms``):
    mid and rad (4, 15, 9, 9, 9): chart k, quad, exponents of the other three components in
    increasing order (F with q_k = 1; zero past total degree 8); packed and packed_rad
    (4, 15, ``PACKED``): the same by quad and monomial (``MONO3``, then 0)."""
    out = []
    for v in (m, r):
        A = np.zeros((4, 15, N1, N1, N1))
        for k in range(4):
            A[k][:, CHART[k, :, 0], CHART[k, :, 1], CHART[k, :, 2]] = v
        out.append(np.ascontiguousarray(A))
    for A in out[:2]:
        packed = np.zeros((4, 15, PACKED))
        packed[:, :, :len(MONO3)] = A[:, :, MONO3[:, 0], MONO3[:, 1], MONO3[:, 2]]
        out.append(packed)
    return tuple(out)


# ------------------------------------------------------------------ the test of a box (compiled)

@njit(cache=True, error_model="numpy")
def chart_box(qlo, qhi, lo, w):
    """Chart k (the component with the largest smallest |q_k| over the box; −1 if every side holds 0)
    and a box [lo, lo + w] containing Q_i / Q_k (i ≠ k, increasing): each quotient's rounding is
    covered by the next float outward, and w is rounded up."""
    best, k = 0.0, -1
    for c in range(4):
        m = qlo[c] if qlo[c] > 0.0 else -qhi[c] if qhi[c] < 0.0 else 0.0
        if m > best:
            best, k = m, c
    if k < 0:
        return -1
    v = 0
    for c in range(4):
        if c != k:
            r0, r1, r2, r3 = qlo[c] / qlo[k], qlo[c] / qhi[k], qhi[c] / qlo[k], qhi[c] / qhi[k]
            lo[v] = np.nextafter(min(min(r0, r1), min(r2, r3)), -np.inf)
            top = np.nextafter(max(max(r0, r1), max(r2, r3)), np.inf)
            w[v] = np.nextafter(top - lo[v], np.inf)
            v += 1
    return k


@njit(cache=True, error_model="numpy")
def _axis_matrices(lo, w, M, S, rows):
    """M[v, i, j] for i in ``rows``: Bernstein coefficient i (degree 8, on [lo_v, lo_v + w_v]) of x^j
    (rows 0 and 8: the values at the ends, all the vertex filter needs); S[v, e]: an upper bound of
    (|lo_v| + w_v)^e, which bounds |M[v, i, e]| (docs/soundness.md §8)."""
    for v in range(3):
        ap, wp = np.empty(N1), np.empty(N1)
        ap[0], wp[0], S[v, 0] = 1.0, 1.0, 1.0
        s = (abs(lo[v]) + w[v]) * (1.0 + 4 * U)
        for e in range(1, N1):
            ap[e], wp[e] = ap[e - 1] * lo[v], wp[e - 1] * w[v]
            S[v, e] = S[v, e - 1] * s * (1.0 + 4 * U)
        for i in rows:
            for j in range(N1):
                t = 0.0
                for m in range(min(i, j) + 1):
                    t += COMB[j, m] * ap[j - m] * wp[m] * RATIO[i, m]
                M[v, i, j] = t


@njit(cache=True, error_model="numpy")
def _bound(Am, Ar, S):
    """The margin a coefficient must pass: twice the bound on |computed − exact| of every Bernstein
    coefficient (docs/soundness.md §8), its radii's part taken ``ROOM`` times:
    2 ((SLACK Σ|Am_J| S^J + ROOM Σ Ar_J S^J)(1 + SLACK) + TINY (1 + Σ|Am_J|) Π_v max(1, S_v^8)),
    the last term for the underflows (each within 2⁻¹⁰⁷⁵, amplified by at most one |Am_J| and the
    S factors)."""
    a, c, r = 0.0, 0.0, 0.0
    for i in range(N1):
        for j in range(N1 - i):
            for l in range(N1 - i - j):
                s = S[0, i] * S[1, j] * S[2, l]
                a += abs(Am[i, j, l])
                c += abs(Am[i, j, l]) * s
                r += Ar[i, j, l] * s
    big = max(1.0, S[0, DEG]) * max(1.0, S[1, DEG]) * max(1.0, S[2, DEG])
    return 2.0 * ((SLACK * c + ROOM * r) * (1.0 + SLACK) + TINY * (1.0 + a) * big * (1.0 + SLACK))


@njit(cache=True, error_model="numpy")
def _vertex_monomials(M, V):
    """V[t, m]: monomial m (``MONO3``) at the box's vertex ``VERTEX_ORDER[t]`` (its Bernstein
    coefficient (8 c0, 8 c1, 8 c2), c = c0 + 2 c1 + 4 c2)."""
    for t in range(8):
        c = VERTEX_ORDER[t]
        s0, s1, s2 = 8 * (c & 1), 8 * ((c >> 1) & 1), 8 * (c >> 2)
        for m in range(MONO3.shape[0]):
            V[t, m] = M[0, s0, MONO3[m, 0]] * M[1, s1, MONO3[m, 1]] * M[2, s2, MONO3[m, 2]]


@njit(cache=True, error_model="numpy")
def _vertex_sign(P, V):
    """The sign (±1) shared by the float values of a polynomial (``P``: packed) at the 8 vertices,
    0 if they differ or vanish: a box where it changes sign holds a zero of it.  A filter only, in
    float (the proof is ``_all_beyond``); opposite vertices first, stopping at the first change."""
    sign = 0.0
    for t in range(8):
        v0, v1, v2, v3 = 0.0, 0.0, 0.0, 0.0      # four chains: the sum is not latency-bound
        for m in range(0, PACKED, 4):
            v0 += V[t, m] * P[m]
            v1 += V[t, m + 1] * P[m + 1]
            v2 += V[t, m + 2] * P[m + 2]
            v3 += V[t, m + 3] * P[m + 3]
        v = (v0 + v1) + (v2 + v3)
        if t == 0:
            sign = 1.0 if v > 0.0 else -1.0
        if not v * sign > 0.0:
            return 0.0
    return sign


@njit(cache=True, error_model="numpy")
def _stage_two(M, T0, T1, jjs):
    """T1[ii, jj, l] = Σ_j M[1, jj, j] T0[ii, j, l] for the rows ``jjs`` of axis 1."""
    for ii in range(N1):
        for l in range(N1):
            for jj in jjs:
                s = 0.0
                for j in range(N1 - l):
                    s += M[1, jj, j] * T0[ii, j, l]
                T1[ii, jj, l] = s


@njit(cache=True, error_model="numpy")
def _stage_three_beyond(M, T1, iis, jjs, sign, E):
    """True when sign · (Bernstein coefficient (ii, jj, ll)) > E for ii in ``iis``, jj in ``jjs``, every ll."""
    for ii in iis:
        for jj in jjs:
            for ll in range(N1):
                s = 0.0
                for l in range(N1):
                    s += M[2, ll, l] * T1[ii, jj, l]
                if not s * sign > E:
                    return False
    return True


@njit(cache=True, error_model="numpy")
def _all_beyond(A, M, T0, T1, sign, E):
    """True when sign · (every Bernstein coefficient of A) > E.  The coefficients of the rows 1, 4, 7
    of the first two axes are tried first: a polynomial that fails usually fails there (seed 002: 95 %
    of the failures), for a third of the work.  Each coefficient is the same sum in the same order
    either way: the verdict does not depend on this order."""
    for j in range(N1):
        for l in range(N1 - j):
            for ii in range(N1):
                s = 0.0
                for i in range(N1 - j - l):
                    s += M[0, ii, i] * A[i, j, l]
                T0[ii, j, l] = s
    _stage_two(M, T0, T1, FIRST_ROWS)
    if not _stage_three_beyond(M, T1, FIRST_ROWS, FIRST_ROWS, sign, E):
        return False
    _stage_two(M, T0, T1, OTHER_ROWS)
    return (_stage_three_beyond(M, T1, OTHER_ROWS, FIRST_ROWS, sign, E)
            and _stage_three_beyond(M, T1, ALL_ROWS, OTHER_ROWS, sign, E))


@njit(cache=True, error_model="numpy")
def _centre(P, lo, w, mono, vals, grads):
    """The 15 chart polynomials (``P``: packed, of one chart) at the chart box's centre c, and their
    gradients there times the box's sides: ``vals`` (15,), ``grads`` (15, 3) (floats: the weights'
    guess, not a proof); ``mono`` (4, ``PACKED``): the monomials and their scaled derivatives at c."""
    pw, dw = np.empty((3, N1)), np.empty((3, N1))
    for v in range(3):
        c = lo[v] + 0.5 * w[v]
        pw[v, 0], dw[v, 0] = 1.0, 0.0
        for e in range(1, N1):
            pw[v, e], dw[v, e] = pw[v, e - 1] * c, e * pw[v, e - 1] * w[v]
    for m in range(MONO3.shape[0]):
        i, j, l = MONO3[m, 0], MONO3[m, 1], MONO3[m, 2]
        a, b, c = pw[0, i], pw[1, j], pw[2, l]
        mono[0, m], mono[1, m], mono[2, m], mono[3, m] = a * b * c, dw[0, i] * b * c, a * dw[1, j] * c, a * b * dw[2, l]
    for q in range(15):
        s, g0, g1, g2 = 0.0, 0.0, 0.0, 0.0
        for m in range(PACKED):
            a = P[q, m]
            s += a * mono[0, m]
            g0 += a * mono[1, m]
            g1 += a * mono[2, m]
            g2 += a * mono[3, m]
        vals[q], grads[q, 0], grads[q, 1], grads[q, 2] = s, g0, g1, g2


@njit(cache=True, error_model="numpy")
def _weights(vals, grads, out):
    """Weights λ (float32 values, largest 1) with Σ λ_q ∇F_q ≈ 0 at the centre and Σ λ_q F_q > 0
    there: the values projected off the span of the (scaled) gradients (modified Gram-Schmidt).
    Any weights are sound; these cancel the first-order part of the combination on the box, which
    a single polynomial cannot (in the tubes along nearly self-moving postures every F_q has a
    zero surface near the box, their combination none).  False when the projection vanishes."""
    r = vals.copy()
    G = grads.copy()
    for a in range(3):
        n = 0.0
        for q in range(15):
            n += G[q, a] * G[q, a]
        if not n > 0.0:
            continue
        n = np.sqrt(n)
        for q in range(15):
            G[q, a] /= n
        for b in range(a + 1, 3):
            d = 0.0
            for q in range(15):
                d += G[q, a] * G[q, b]
            for q in range(15):
                G[q, b] -= d * G[q, a]
        d = 0.0
        for q in range(15):
            d += G[q, a] * r[q]
        for q in range(15):
            r[q] -= d * G[q, a]
    big = 0.0
    for q in range(15):
        big = max(big, abs(r[q]))
    if not (big > 0.0 and np.isfinite(big)):
        return False
    for q in range(15):
        out[q] = np.float32(r[q] / big)
    return True


@njit(cache=True, error_model="numpy")
def _combination(P, R, wq, gm, gr, Gm, Gr):
    """Gm ± Gr (dense) holding the coefficients of Σ_q wq_q F_q (``P`` ± ``R``: packed, of one chart;
    docs/soundness.md §8): the float sum, whose error is within 32 U Σ|wq_q P_q| (γ_15 with room),
    plus Σ|wq_q| R_q rounded up, plus the underflows (below 15 · 2⁻¹⁰⁷⁴: 2⁻¹⁰⁰⁰ covers them).
    ``gm``, ``gr`` (2, ``PACKED``): scratch."""
    gm[:] = 0.0
    gr[:] = 0.0
    for q in range(15):
        a = wq[q]
        for m in range(PACKED):
            t = a * P[q, m]
            gm[0, m] += t
            gm[1, m] += abs(t)
            gr[0, m] += abs(a) * R[q, m]
    for m in range(MONO3.shape[0]):
        i, j, l = MONO3[m, 0], MONO3[m, 1], MONO3[m, 2]
        Gm[i, j, l] = gm[0, m]
        Gr[i, j, l] = (gr[0, m] + 32.0 * U * gm[1, m]) * (1.0 + 64.0 * U) + TINY


def load():
    """numba's start-up and this kernel's machine code, on no box: about 1 s the first time in a
    process (numba's import and registries), which ``forward_kinematics`` keeps out of its seconds."""
    zero = np.zeros((4, 15, N1, N1, N1))
    excluded(zero, zero, np.zeros((4, 15, PACKED)), np.zeros((4, 15, PACKED)), np.zeros((0, 4)), np.zeros((0, 4)), np.arange(15),
             np.zeros((0, 15), np.float32))


@njit(cache=True, error_model="numpy")
def excluded(Am, Ar, P, R, qlo, qhi, order, weights):
    """Per box (quaternion sides (N, 4)): the evidence 4·quad + chart of the first quad (tried in
    ``order``) whose chart polynomial (``charts``: ``Am`` ± ``Ar``; ``P`` ± ``R``: packed) is proved
    of one sign on the chart box; else, when ``weights`` has a row per box, 60 + chart if the
    combination Σ λ_q F_q (λ: ``_weights``, written to that row) is; else −1."""
    n = qlo.shape[0]
    out = np.full(n, -1, np.int64)
    M, S = np.empty((3, N1, N1)), np.empty((3, N1))
    T0, T1 = np.zeros((N1, N1, N1)), np.zeros((N1, N1, N1))
    Gm, Gr = np.zeros((N1, N1, N1)), np.zeros((N1, N1, N1))
    V = np.zeros((8, PACKED))
    vals, grads, wq, mono = np.empty(15), np.empty((15, 3)), np.empty(15), np.zeros((4, PACKED))
    gm, gr = np.zeros((2, PACKED)), np.zeros((2, PACKED))
    lo, w = np.empty(3), np.empty(3)
    combine = weights.shape[0] == n
    for b in range(n):
        k = chart_box(qlo[b], qhi[b], lo, w)
        if k < 0:
            continue
        _axis_matrices(lo, w, M, S, END_ROWS)
        _vertex_monomials(M, V)
        inner = False       # rows 1-7 of M, computed for the first polynomial past the vertex filter
        for t in range(order.shape[0]):
            p = order[t]
            sign = _vertex_sign(P[k, p], V)
            if sign == 0.0:
                continue
            if not inner:
                _axis_matrices(lo, w, M, S, INNER_ROWS)
                inner = True
            if _all_beyond(Am[k, p], M, T0, T1, sign, _bound(Am[k, p], Ar[k, p], S)):
                out[b] = 4 * p + k
                break
        if out[b] >= 0 or not combine:
            continue
        _centre(P[k], lo, w, mono, vals, grads)
        if not _weights(vals, grads, wq):
            continue
        _combination(P[k], R[k], wq, gm, gr, Gm, Gr)
        centre = 0.0
        for q in range(15):
            centre += wq[q] * vals[q]
        if not inner:
            _axis_matrices(lo, w, M, S, INNER_ROWS)
        if _all_beyond(Gm, M, T0, T1, 1.0 if centre > 0.0 else -1.0, _bound(Gm, Gr, S)):
            out[b] = 60 + k
            weights[b] = wq
    return out
