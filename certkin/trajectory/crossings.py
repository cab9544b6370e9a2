"""Where to cut a t-interval: float estimates of where a polynomial changes sign (a heuristic for the
search's cuts, never a proof)."""
from __future__ import annotations

import numpy as np


def midpoint(p):
    """The float midpoint coefficients of an interval polynomial."""
    return 0.5 * (p.lo + p.hi)


def derivative(c):
    """Coefficients of p' (float, last axis), same length (last coefficient 0)."""
    return np.concatenate([c[..., 1:] * np.arange(1, c.shape[-1]), np.zeros(c.shape[:-1] + (1,))], -1)


def float_mul(a, b):
    """Float product of coefficient arrays (last axis), at most 16 coefficients."""
    out = np.zeros(np.broadcast_shapes(a.shape[:-1], b.shape[:-1]) + (a.shape[-1] + b.shape[-1] - 1,))
    for i in range(a.shape[-1]):
        out[..., i:i + b.shape[-1]] += a[..., i:i + 1] * b
    if np.any(out[..., 16:] != 0):
        raise ValueError("polynomial of degree above 15")
    return out[..., :16]


def crossing_points(coefficients, tlo, thi, iterations: int = 60, radii=None):
    """Float estimates of a sign change of each polynomial (rows of ``coefficients``, (M, m),
    NaN rows allowed) inside [tlo, thi]: Newton in the bracket, regula falsi where a Newton step
    leaves it (until the steps stop moving, at most ``iterations``); NaN when the values at the
    two ends have the same sign.  With ``radii`` (the coefficients' uncertainty),
    also an estimate of the estimate's error, (Σ r_k |t|^k + 2⁻⁴⁸ Σ |c_k t^k|) / |p'(t)|.
    A heuristic for cutting boxes, not a proof."""
    coefficients = np.asarray(coefficients, dtype=np.float64)
    m, n = coefficients.shape
    c = np.where(np.isnan(coefficients), 0.0, coefficients)
    a = np.broadcast_to(np.asarray(tlo, dtype=np.float64), (m,))
    b = np.broadcast_to(np.asarray(thi, dtype=np.float64), (m,))
    k = np.arange(n, dtype=np.float64)
    dc = c[:, 1:] * k[1:]

    def powers(x):                      # x^0, ..., x^(n−1) by repeated products
        out = np.empty((len(x), n))
        out[:, 0] = 1.0
        if n > 1:
            out[:, 1:] = x[:, None]
            np.cumprod(out[:, 1:], axis=1, out=out[:, 1:])
        return out

    fa = np.einsum("ij,ij->i", powers(a), c)
    fb = np.einsum("ij,ij->i", powers(b), c)
    bracket = (np.sign(fa) * np.sign(fb) < 0) & ~np.isnan(coefficients[:, 0])
    rows = np.nonzero(bracket)[0]           # only the bracketed rows are iterated
    c, dc, a, b, fa, fb = c[rows], dc[rows], a[rows], b[rows], fa[rows], fb[rows]
    with np.errstate(all="ignore"):
        x = a - fa * (b - a) / (fb - fa)                                           # regula falsi start
    x = np.where((x > a) & (x < b), x, 0.5 * (a + b))
    for _ in range(iterations if len(rows) else 0):
        xp = powers(x)
        f = np.einsum("ij,ij->i", xp, c)
        df = np.einsum("ij,ij->i", xp[:, :-1], dc)
        same = np.sign(f) == np.sign(fa)
        a, fa = np.where(same, x, a), np.where(same, f, fa)
        b, fb = np.where(same, b, x), np.where(same, fb, f)
        with np.errstate(all="ignore"):
            newton = x - f / df
            secant = a - fa * (b - a) / (fb - fa)
        previous = x
        x = np.where((newton > a) & (newton < b), newton,
                     np.where((secant > a) & (secant < b), secant, 0.5 * (a + b)))
        x = np.where(f == 0, previous, x)
        if np.all(np.abs(x - previous) <= 2.0 ** -50 * np.abs(x)):
            break
    t = np.full(m, np.nan)
    t[rows] = x
    if radii is None:
        return t
    xp = np.abs(powers(x))
    err = np.full(m, np.nan)
    with np.errstate(all="ignore"):
        err[rows] = (np.einsum("ij,ij->i", xp, radii[rows]) + 2.0 ** -48 * np.einsum("ij,ij->i", xp, np.abs(c))) \
            / np.abs(np.einsum("ij,ij->i", xp[:, :-1], dc))
    return t, err
