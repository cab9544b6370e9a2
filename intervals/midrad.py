"""Midpoint-radius bounds with an a-priori rounding-error bound (docs/soundness.md, "midrad").

A float matrix product computed to nearest, in any order of summation, is within a bound that
depends only on the magnitudes of its factors (Higham 2002, eq. 3.5); evaluating that bound in
floats and widening it once (``upper``) gives a proved enclosure of the exact product of two
interval matrices in midpoint-radius form, at the cost of two float matrix products (Rump, "Fast
and parallel interval arithmetic", BIT 39, 1999).  ``linalg``'s Krawczyk and Hansen-Sengupta
operators and the robot models use these bounds; ``native`` holds their machine-code twins.
"""
from __future__ import annotations

import numpy as np

from .rounding import up

U = 2.0 ** -53          # unit roundoff of float64
ETA = 2.0 ** -1022      # smallest positive normal float64


def upper(x, k: int):
    """An upper bound of a nonnegative exact value whose float evaluation, with at most
    ``k`` roundings (+ and x of nonnegative numbers), gave ``x``:
    E <= (x + k 2^-1022)(1 + 2k u); two more roundings are covered by 2k + 6."""
    return (x + k * ETA) * (1.0 + (2 * k + 6) * U)


def midrad(lo, hi):
    """(m, r) with [lo, hi] inside [m - r, m + r] (finite endpoints)."""
    m = 0.5 * lo + 0.5 * hi
    return m, up(np.maximum(hi - m, m - lo))


def product_midrad(am, ar, bm, br):
    """Enclosure (mid, rad) of A B for every A in [am ± ar], B in [bm ± br] (float arrays;
    ``ar``/``br`` None for points).

    |A B - fl(am bm)| <= |am| br + ar (|bm| + br) + gamma_n |am||bm| + n eta (Higham 2002,
    eq. 3.5, any summation order), with gamma_n <= (n + 1) u; the right side is
    evaluated in floats and bounded by ``upper`` (k = 4n + 4 roundings).
    """
    n = am.shape[-1]
    mid = am @ bm
    abm = np.abs(bm)
    inner = (n + 1) * U * abm if br is None else (n + 1) * U * abm + br
    rad = np.abs(am) @ inner
    if ar is not None:
        rad = rad + ar @ (abm if br is None else abm + br)
    return mid, upper(rad, 4 * n + 4) + n * ETA
