"""Determinant by Laplace (cofactor) expansion along the rows, with shared minors.

det(M) = Σ_j (−1)^j M[0][j] det(M without row 0 and column j), applied
recursively; the minors of the lower rows are memoised by their column set,
so a 6×6 matrix costs 192 products instead of 6! = 720 terms × 5.  For 3×3 it
is the usual cofactor expansion along the first row.  Only +, − and × are
used, so it works for ``iv`` intervals (each operation encloses) and for
``ad.Dual`` numbers alike, and needs no division or pivot choice.
"""
from __future__ import annotations


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
