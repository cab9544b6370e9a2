"""Determinant enclosures: Laplace expansion, and preconditioned elimination for n >= 4.

``det(M)``: cofactor (Laplace) expansion along the rows, with the minors of
the lower rows memoised by their column set (a 6×6 costs 192 products, not
720 terms × 5).  It uses only +, − and ×, so it works for ``iv`` intervals
and for ``ad.Dual`` numbers alike (gradients).

``det_interval(M)`` (``iv`` entries): for n >= 4 the Laplace expansion of a
wide interval matrix overestimates badly, so we also enclose det by
elimination after preconditioning (Rump, "Verification methods", Acta
Numerica 2010, sec. 10): a float LU factorisation with partial pivoting of
the midpoint matrix gives a permutation P and a unit lower-triangular X ≈
L⁻¹ whose diagonal is exactly 1, so det(X P M) = ±det(M) exactly; Y = X P M
is enclosed in ``iv`` and eliminated without pivoting: det Y is the product
of the pivots, valid when no pivot used as a divisor contains 0.  The
preconditioner is computed here, in floats; any X of that form is correct,
its quality only affects the width.
"""
from __future__ import annotations

from mpmath import iv


def det(M):
    n = len(M)
    memo = {}

    def minor(cols):
        # determinant of rows n-len(cols) .. n-1 restricted to the columns ``cols``
        if len(cols) == 1:
            return M[n - 1][cols[0]]
        if cols not in memo:
            r = n - len(cols)
            total = None
            for k, j in enumerate(cols):
                term = M[r][j] * minor(cols[:k] + cols[k + 1:])
                total = term if total is None else (total - term if k % 2 else total + term)
            memo[cols] = total
        return memo[cols]

    return minor(tuple(range(n)))


def det_interval(M):
    """Enclosure of det over an ``iv`` interval matrix (the tighter of two enclosures for n >= 4)."""
    D = det(M)
    if len(M) < 4:
        return D
    E = _det_elimination(M)
    if E is None:
        return D
    lo, hi = max(D.a, E.a), min(D.b, E.b)
    return iv.mpf([lo, hi])


def _float_lu(A):
    """Partial-pivoting LU of a float matrix: (row order, unit lower L as lists)."""
    n = len(A)
    U = [row[:] for row in A]
    L = [[0.0] * n for _ in range(n)]
    order = list(range(n))
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(U[i][k]))
        U[k], U[p] = U[p], U[k]
        L[k], L[p] = L[p], L[k]
        order[k], order[p] = order[p], order[k]
        piv = U[k][k] or 1.0
        for i in range(k + 1, n):
            f = U[i][k] / piv
            L[i][k] = f
            for j in range(k, n):
                U[i][j] -= f * U[k][j]
    for i in range(n):
        L[i][i] = 1.0
    return order, L


def _unit_lower_inverse(L):
    """Approximate inverse of a unit lower-triangular matrix, exactly unit lower triangular."""
    n = len(L)
    X = [[0.0] * n for _ in range(n)]
    for i in range(n):
        X[i][i] = 1.0
        for j in range(i):
            X[i][j] = -sum(L[i][k] * X[k][j] for k in range(j, i))
    return X


def _det_elimination(M):
    n = len(M)
    mid = [[float(e.mid) for e in row] for row in M]
    order, L = _float_lu(mid)
    X = _unit_lower_inverse(L)
    sign = _permutation_sign(order)
    PM = [M[i] for i in order]
    Y = [[sum((iv.mpf(X[i][k]) * PM[k][j] for k in range(i + 1)), iv.mpf(0)) for j in range(n)] for i in range(n)]
    d = iv.mpf(1)
    for k in range(n):
        piv = Y[k][k]
        d = d * piv
        if k == n - 1:
            break
        if (piv > 0) is not True and (piv < 0) is not True:
            return None  # a divisor may be 0: elimination proves nothing
        for i in range(k + 1, n):
            f = Y[i][k] / piv
            for j in range(k + 1, n):
                Y[i][j] = Y[i][j] - f * Y[k][j]
    return d if sign > 0 else -d


def _permutation_sign(order):
    sign, seen = 1, [False] * len(order)
    for i in range(len(order)):
        if not seen[i]:
            j, length = i, 0
            while not seen[j]:
                seen[j] = True
                j = order[j]
                length += 1
            if length % 2 == 0:
                sign = -sign
    return sign
