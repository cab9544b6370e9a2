"""The Cayley-Menger rule of forward-kinematics leaves (code 11, docs/certificates.md; docs/soundness.md §12).

For four legs of a 6-6 Gough-Stewart robot (``QUADS``), F(q) = CM·|q|^8, CM the Cayley-Menger determinant of the
centres a_m − R(q) b_m and p, is a form of degree 8 in q that vanishes at every posture; ``forms`` encloses its 165
coefficients.  ``proved_empty`` proves for a batch of leaves that F has no zero on the quaternion box Q: Q_k misses 0,
Y holds q/q_k, and the 729 Bernstein coefficients of F(·/q_k) on a box holding Y have one sign."""
from __future__ import annotations

import itertools
from math import comb

import numpy as np

from .arith import Iv, dn, pmatmul, up

QUADS = list(itertools.combinations(range(6), 4))
MONO = {d: [e for e in itertools.product(range(d + 1), repeat=4) if sum(e) == d] for d in (2, 4, 8)}
PAIRS = list(itertools.combinations_with_replacement(range(10), 2))       # products x_A of two CM entries
GAMMA, ETA = 2.0 ** -45, 2.0 ** -1000        # ≥ γ_n (n ≤ 128), ≥ the underflow terms (§12)
OTHERS = np.array([[i for i in range(4) if i != k] for k in range(4)])    # chart k: the q_i, i ≠ k


def _cm_pairs():
    """CM = Σ C[A, B] x_A x_B over pairs A, B of its 10 entries (d01 .. d23, L0 .. L3): Leibniz, 720 terms."""
    D = list(itertools.combinations(range(4), 2))
    entry = lambda i, j: None if i == j else -1 if not (i and j) else (  # noqa: E731
        5 + min(i, j) if max(i, j) == 5 else D.index((min(i, j) - 1, max(i, j) - 1)))
    C = np.zeros((len(PAIRS), len(PAIRS)))
    for perm in itertools.permutations(range(6)):
        vs = [entry(i, j) for i, j in enumerate(perm)]
        if None not in vs:                                   # 4 entries, and the border's 1 · 1
            v = sorted(x for x in vs if x >= 0)
            C[PAIRS.index(tuple(v[:2])), PAIRS.index(tuple(v[2:]))] += (-1) ** sum(
                perm[i] > perm[j] for i, j in itertools.combinations(range(6), 2))
    return C


def _table(da, db):
    """Per monomial of a product of forms of degrees da, db: the flat indices i·n_b + j making it (−1: none)."""
    at, nb = {e: t for t, e in enumerate(MONO[da + db])}, len(MONO[db])
    lists = [[] for _ in at]
    for (i, ea), (j, eb) in itertools.product(enumerate(MONO[da]), enumerate(MONO[db])):
        lists[at[tuple(np.add(ea, eb))]].append(i * nb + j)
    return np.array([v + [-1] * (max(map(len, lists)) - len(v)) for v in lists])


def _rtilde():
    """The coefficients (3, 3, 10) of R̃(q) on ``MONO[2]``, by polarisation at 0/1 points."""
    rt = lambda q0, q1, q2, q3: np.array([  # noqa: E731
        [q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3]])
    one = np.eye(4, dtype=np.int64)
    return np.stack([rt(*(one[i] + one[j])) - (rt(*one[i]) + rt(*one[j]) if i != j else 3 * rt(*one[i]))
                     for i, j in ([k for k in range(4) for _ in range(e[k])] for e in MONO[2])], -1)


CPAIR, T22, T44, RT, (PU, PV) = _cm_pairs(), _table(2, 2), _table(4, 4), _rtilde(), np.array(PAIRS).T
SQUARES = np.array([2 in e for e in MONO[2]], dtype=float)                # |q|² on the degree-2 monomials
BERN = np.array([[comb(i, m) * 280 // comb(8, m) for m in range(9)] for i in range(9)], dtype=float)  # 280 C(i,m)/C(8,m)
BINOM = np.array([[comb(j, m) for j in range(9)] for m in range(9)], dtype=float)                  # [m, j]: C(j, m)
J_M = np.clip(np.arange(9)[None, :] - np.arange(9)[:, None], 0, 8)                               # [m, j]: j − m
POS = np.array([[int(np.dot(np.array(e)[OTHERS[k]], (81, 9, 1))) for e in MONO[8]] for k in range(4)])


def formmul(A: Iv, B: Iv, T) -> Iv:
    """Σ_K A_K B_K for forms A (..., K, nA), B (..., K, nB), T the table of their degrees: (..., nT)."""
    p = Iv(A.lo[..., :, None], A.hi[..., :, None]) * Iv(B.lo[..., None, :], B.hi[..., None, :])
    K, n = p.shape[-3], p.shape[-2] * p.shape[-1]
    idx = np.concatenate([np.where(T < 0, -1, T + k * n) for k in range(K)], 1)
    flat = lambda x: np.concatenate([x.reshape(x.shape[:-3] + (K * n,)), np.zeros(x.shape[:-3] + (1,))], -1)[..., idx]  # noqa: E731
    return Iv(flat(p.lo), flat(p.hi)).sum(-1)


def forms(system, L: Iv) -> Iv:
    """F = CM·|q|^8 for the 15 quads: Iv (15, 165) on ``MONO[8]``; L (6,) the squared lengths."""
    if getattr(system, "cm_d", None) is None:      # d_mn|q|² per quad and pair: exact, then enclosed
        a, b = system.a_q, system.b_q
        d = [Iv.const(sum((a[m][k] - a[n][k]) ** 2 + (b[m][k] - b[n][k]) ** 2 for k in range(3)) * int(sq) - 2 * sum(
            (a[m][k] - a[n][k]) * (b[m][j] - b[n][j]) * int(RT[k, j, t]) for k in range(3) for j in range(3)))
             for quad in QUADS for m, n in itertools.combinations(quad, 2) for t, sq in enumerate(SQUARES)]
        system.cm_d = Iv(np.reshape([e.lo for e in d], (15, 6, 10)), np.reshape([e.hi for e in d], (15, 6, 10)))
    E = Iv(*(np.concatenate([d, x[np.array(QUADS)][..., None] * SQUARES], 1)      # (15, 10, 10); L_m |q|²: exact
             for d, x in ((system.cm_d.lo, L.lo), (system.cm_d.hi, L.hi))))
    P = formmul(E[:, PU][:, :, None], E[:, PV][:, :, None], T22)            # the x_A, degree 4: (15, 55, 35)
    return formmul(P, pmatmul(CPAIR, P), T44)                              # Σ_A x_A Σ_B C[A, B] x_B


def imatmul(A: Iv, X: Iv) -> Iv:
    """A X for interval matrices (inner dimension ≤ 64), midpoint-radius (Rump 1999; §12): with A ⊆ m ± r and
    X ⊆ c ± s, every A'X' lies in fl(m c) ± (|m| s + r (|c| + s) + γ |m||c| + η), rounded up."""
    (m, r), (c, s) = ((h, up(np.maximum(Z.hi - h, h - Z.lo))) for Z in (A, X) for h in [0.5 * Z.lo + 0.5 * Z.hi])
    mc = m @ c
    G = np.concatenate([np.abs(m), r], -1) @ np.concatenate([up(s + up(np.abs(c) * GAMMA)), up(np.abs(c) + s)], -2)
    t = up(up(G * (1.0 + GAMMA)) + ETA)
    return Iv(dn(mc - t), up(mc + t))


def chart_box(qlo, qhi, chart):
    """(Y: Iv (N, 3) holding q_i/q_k, i ≠ k, for every q in the boxes (N, 4); mask: Q_k strictly away from 0)."""
    qk = Iv(*(np.take_along_axis(x, chart[:, None], 1) for x in (qlo, qhi)))
    return Iv(*(np.take_along_axis(x, OTHERS[chart], 1) for x in (qlo, qhi))) / qk, (qk.lo[:, 0] > 0) | (qk.hi[:, 0] < 0)


def bernstein(F: Iv, chart, Y: Iv) -> Iv:
    """280³ × the Bernstein coefficients (degree 8 per variable) of F with q_k = 1 on a box holding Y: (N, 729).
    Per variable, x ∈ [a, a + w] (a = Y̲, w ≥ Ȳ − a rounded up): b = B diag(w^m) S(a) p, S(a)[m, j] = C(j, m) a^(j−m)."""
    N = len(chart)
    X = Iv(np.zeros((N, 729)), np.zeros((N, 729)))
    X[np.arange(N)[:, None], POS[chart]] = F
    for v in range(3):
        a, w = Y.lo[:, v], up(Y.hi[:, v] - Y.lo[:, v])
        pw = list(itertools.accumulate([np.stack([a, w], 1)] * 8, lambda p, x: p * x, initial=Iv(np.ones((N, 2)))))
        pw = Iv(np.stack([p.lo for p in pw], 1), np.stack([p.hi for p in pw], 1))    # (N, 9, 2): a^i, w^i
        M = pmatmul(BERN, (pw[:, J_M, 0] * BINOM) * pw[:, :, None, 1])
        R = imatmul(M, Iv(X.lo.reshape(N, 9, 81), X.hi.reshape(N, 9, 81)))
        X = Iv(*(x.reshape(N, 9, 9, 9).transpose(0, 2, 3, 1).reshape(N, 729) for x in (R.lo, R.hi)))  # next variable first
    return X


def combined(W, forms) -> Iv:
    """Σ_q W_q F_q per leaf: W (N, 15) exact floats, ``forms`` each leaf's F (``forms``)."""
    out = Iv(np.zeros((len(W), 165)), np.zeros((len(W), 165)))
    for F, m in ((F, np.array([f is F for f in forms])) for F in {id(F): F for F in forms}.values()):
        out[m] = imatmul(Iv(W[m], W[m]), F)
    return out


def proved_empty(F: Iv, chart, qlo, qhi):
    """(proved: F (N, 165) has no zero on the quaternion boxes [qlo, qhi] (N, 4); mask: Q_k misses 0)."""
    with np.errstate(all="ignore"):
        Y, away = chart_box(qlo, qhi, chart)
        b = bernstein(F, chart, Y)
    finite = np.all(np.isfinite(np.concatenate([Y.lo, Y.hi, b.lo, b.hi], 1)), 1)
    return away & finite & (np.all(b.lo > 0, 1) | np.all(b.hi < 0, 1)), away
