"""The 15 Cayley–Menger rotation polynomials of a query, fast and with a proved error bound: how long?

The Bernstein test of the rotation (sections "the Bernstein test as a node rule" and "the rotation
alone by Bernstein expansion" of docs/benchmarks.md) needs, per query (robot and leg lengths), the
coefficients of the 15 polynomials CM·|q|^8, homogeneous of degree 8 in the quaternion q (165
coefficients each).  The studies took them exactly from sympy (3 to 11 s a robot): far too slow per
query.  This script computes them in float, midpoint-radius, with the a-priori rounding bound of
``intervals.midrad.product_midrad`` (Higham 2002 eq. 3.5; Rump 1999), as a chain of matrix products:

- the 10 entries of each quadruple's Cayley–Menger matrix, |q|²·d²_mn = (|Δa|² + |Δb|²)|q|² −
  2 Δaᵀ R̃(q) Δb and ρ_m²|q|², as quadratic forms in q (10 coefficients; R̃ = |q|² R, homogeneous);
- each of the 130 monomials of the determinant in those entries (coefficients ±1, ±2, ±4) as the
  product e1·e2·e3·e4 of forms: an outer product, then a 0/1 matrix from monomial pairs to the
  monomials of the product (10×10 → 35, 35×10 → 84, 84×10 → 165), batched over quadruples and terms;
- the signed sum over the 130 terms (one more product, by the integer coefficients).

The robot's decimals and the lengths enter as float enclosures (one ulp each way); the exact
polynomials (sympy, from the same floats' decimal expansions as rationals) check that every exact
coefficient lies in its enclosure, and the relative radius says how tight it is.

    python benchmarks/fk_cm_coefficients.py [--robot seed002 dietmaier] [--repeat 20]

About 20 s a robot (the exact sympy reference); the timed part is printed per query.  A study: the
solver does not use it yet.
"""
from __future__ import annotations

import argparse
from fractions import Fraction
import itertools
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fk_cayley_menger import QUADS, ROBOTS                                           # noqa: E402
from fk_rotation_bernstein import cayley_menger_terms, homogeneous_cm, read_robot   # noqa: E402

from intervals.midrad import ETA, U, product_midrad, upper                                   # noqa: E402


def monomials(d):
    """Exponent tuples of the degree-d monomials in 4 variables, and their index."""
    out = [e for e in itertools.product(range(d + 1), repeat=4) if sum(e) == d]
    return out, {e: i for i, e in enumerate(out)}


MONO = {d: monomials(d) for d in (2, 4, 6, 8)}


def pair_map(d1, d2):
    """The pairs of monomials of degrees d1 and d2 (flattened i·n2 + j), sorted by the monomial of their
    product: (order, starts of each product monomial's run, the longest run)."""
    (m1, _), (m2, _), (_, idx) = MONO[d1], MONO[d2], MONO[d1 + d2]
    target = np.array([idx[tuple(x + y for x, y in zip(e1, e2))] for e1 in m1 for e2 in m2])
    order = np.argsort(target, kind="stable")
    starts = np.searchsorted(target[order], np.arange(len(idx)))
    return order, starts, int(np.max(np.bincount(target)))


T4, T6, T8 = pair_map(2, 2), pair_map(4, 2), pair_map(6, 2)


def quadratic_forms():
    """Coefficient vectors (10) of |q|² and of the 9 entries of R̃(q) = |q|² R(q)."""
    _, idx = MONO[2]

    def form(terms):
        v = np.zeros(len(idx))
        for c, (i, j) in terms:
            e = [0, 0, 0, 0]
            e[i] += 1
            e[j] += 1
            v[idx[tuple(e)]] += c
        return v
    n2 = form([(1, (i, i)) for i in range(4)])
    R = [[form([(1, (0, 0)), (1, (1, 1)), (-1, (2, 2)), (-1, (3, 3))]), form([(2, (1, 2)), (-2, (0, 3))]),
          form([(2, (1, 3)), (2, (0, 2))])],
         [form([(2, (1, 2)), (2, (0, 3))]), form([(1, (0, 0)), (-1, (1, 1)), (1, (2, 2)), (-1, (3, 3))]),
          form([(2, (2, 3)), (-2, (0, 1))])],
         [form([(2, (1, 3)), (-2, (0, 2))]), form([(2, (2, 3)), (2, (0, 1))]),
          form([(1, (0, 0)), (-1, (1, 1)), (-1, (2, 2)), (1, (3, 3))])]]
    return n2, np.array(R)


N2, RT = quadratic_forms()


def enclose(values):
    """Float midpoint-radius enclosures of exact rationals (the radius one ulp)."""
    m = np.array([float(v) for v in values])
    return m, np.spacing(np.abs(m))


def entries(a, b, rho):
    """Midpoint-radius coefficient vectors (15, 10, 10) of the 10 entries of each quadruple's matrix:
    the 6 |q|²d²_mn (pairs of the quadruple, in order), then the 4 ρ_m²|q|²."""
    am, ar = enclose([x for row in a for x in row])
    bm, br = enclose([x for row in b for x in row])
    rm, rr = enclose(rho)
    am, ar, bm, br = am.reshape(6, 3), ar.reshape(6, 3), bm.reshape(6, 3), br.reshape(6, 3)
    mid, rad = np.zeros((15, 10, 10)), np.zeros((15, 10, 10))
    for k, quad in enumerate(QUADS):
        for e, (m, n) in enumerate(itertools.combinations(quad, 2)):
            dam, dar = am[m] - am[n], ar[m] + ar[n] + np.spacing(np.abs(am[m] - am[n]))
            dbm, dbr = bm[m] - bm[n], br[m] + br[n] + np.spacing(np.abs(bm[m] - bm[n]))
            s, sr = product_midrad(np.concatenate([dam, dbm])[None], np.concatenate([dar, dbr])[None],
                                   np.concatenate([dam, dbm])[:, None], np.concatenate([dar, dbr])[:, None])
            # Δaᵀ R̃ Δb = Σ_ij Δa_i Δb_j R̃_ij: outer product, then the forms (exact integers)
            o, orad = product_midrad(dam[:, None], dar[:, None], dbm[None], dbr[None])
            lin, lrad = product_midrad(o.reshape(1, 9), orad.reshape(1, 9), RT.reshape(9, 10), None)
            mid[k, e] = s[0, 0] * N2 - 2.0 * lin[0]           # (N2's coefficients are 0 or 1: exact products)
            rad[k, e] = upper(np.abs(N2) * sr[0, 0] + 2.0 * lrad[0] + np.spacing(np.abs(mid[k, e])), 4)
        for e, m in enumerate(quad):
            r2, r2r = product_midrad(rm[m:m + 1, None], rr[m:m + 1, None], rm[None, m:m + 1], rr[None, m:m + 1])
            mid[k, 6 + e] = r2[0, 0] * N2
            rad[k, 6 + e] = r2r[0, 0] * np.abs(N2)
    return mid, rad


def times(am, ar, bm, br, T):
    """The products of forms a·b (batched over the leading axes), midpoint-radius: every pair's product
    (one rounding each), then the sums of the pairs of each product monomial (``np.add.reduceat``, at most
    ``longest`` terms): |error| <= the radii's part + gamma_(longest+1) Σ|am bm| (Higham 2002, eq. 3.5),
    bounded by ``upper``."""
    order, starts, longest = T
    shape = am.shape[:-1]
    pm = (am[..., :, None] * bm[..., None, :]).reshape(*shape, -1)[..., order]
    aa, ab = np.abs(am), np.abs(bm)
    pa = (aa[..., :, None] * ab[..., None, :]).reshape(*shape, -1)[..., order]
    pr = (aa[..., :, None] * br[..., None, :] + ar[..., :, None] * (ab + br)[..., None, :]).reshape(*shape, -1)[..., order]
    mid = np.add.reduceat(pm, starts, axis=-1)
    bound = np.add.reduceat(pr, starts, axis=-1) + (longest + 2) * U * np.add.reduceat(pa, starts, axis=-1)
    return mid, upper(bound, 4 * longest + 8) + longest * ETA


def grouped_sum(m, r, keys):
    """Midpoint-radius sums of the rows of (m, r) (axis 1) with equal ``keys`` (sorted): (unique keys,
    sums); the float sums' error, at most gamma_n Σ|m|, is added to the radius (``upper``)."""
    keys = np.asarray(keys)
    starts = np.concatenate([[0], np.nonzero(keys[1:] != keys[:-1])[0] + 1])
    n = int(np.max(np.diff(np.concatenate([starts, [len(keys)]]))))
    mid = np.add.reduceat(m, starts, axis=1)
    bound = np.add.reduceat(r, starts, axis=1) + (n + 1) * U * np.add.reduceat(np.abs(m), starts, axis=1)
    return keys[starts], mid, upper(bound, 2 * n + 2) + n * ETA


def cm_forms(a, b, rho, terms):
    """Midpoint-radius coefficients (15, 165) of the 15 polynomials CM·|q|^8, by a Horner scheme over the
    130 terms c e_v1 e_v2 e_v3 e_v4 (v1 <= v2 <= v3 <= v4): L = Σ c e_v4 (per v1 v2 v3), S = Σ e_v3 L (per
    v1 v2), T = Σ e_v2 S (per v1), CM = Σ e_v1 T: 3 batched products of forms instead of 3 per term."""
    em, er = entries(a, b, rho)
    rows = sorted((tuple(v for v, ev in enumerate(e) for _ in range(ev)), float(c)) for c, e in terms)
    f = np.array([v for v, _ in rows])                      # (130, 4) factors, sorted
    coef = np.array([c for _, c in rows])
    # L: the integer combinations of e_v4 (exact products by 1, 2, 4; sums bounded)
    keys3 = f[:, 0] * 100 + f[:, 1] * 10 + f[:, 2]
    k3, Lm, Lr = grouped_sum(coef[None, :, None] * em[:, f[:, 3]], np.abs(coef)[None, :, None] * er[:, f[:, 3]], keys3)
    v3 = k3 % 10
    pm, pr = times(em[:, v3], er[:, v3], Lm, Lr, T4)
    k2, Sm, Sr = grouped_sum(pm, pr, k3 // 10)
    pm, pr = times(Sm, Sr, em[:, k2 % 10], er[:, k2 % 10], T6)      # (T6: a form of degree 4 times one of 2)
    k1, Tm, Tr = grouped_sum(pm, pr, k2 // 10)
    pm, pr = times(Tm, Tr, em[:, k1], er[:, k1], T8)
    _, m, r = grouped_sum(pm, pr, np.zeros(len(k1), dtype=int))
    return m[:, 0], r[:, 0]


def exact_vectors(polys):
    """The exact coefficients (15, 165) as Fractions, in ``MONO[8]`` order."""
    _, idx = MONO[8]
    out = np.full((len(polys), len(idx)), Fraction(0), dtype=object)
    for k, p in enumerate(polys):
        for mono, c in p.terms():
            out[k, idx[tuple(mono)]] = Fraction(int(c.numerator), int(c.denominator))
    return out


def run(name, repeat):
    a, b, rho = read_robot(name)
    terms = cayley_menger_terms()
    spent = []
    for _ in range(repeat):
        t0 = time.process_time()
        m, r = cm_forms(a, b, rho, terms)
        spent.append(time.process_time() - t0)
    exact = exact_vectors(homogeneous_cm(a, b, rho))
    inside = all(abs(Fraction(float(m[k, i])) - exact[k, i]) <= Fraction(float(r[k, i]))
                 for k in range(15) for i in range(165))
    scale = np.max(np.abs(m), axis=1, keepdims=True)
    err = max(float(abs(Fraction(float(m[k, i])) - exact[k, i])) / scale[k, 0] for k in range(15) for i in range(165))
    print(f"| {name} | {1e3 * np.median(spent):.2f} | {1e3 * min(spent):.2f} | {err:.1e} | "
          f"{float(np.max(r / scale)):.1e} | {'yes' if inside else 'NO'} |", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--robot", nargs="+", default=["seed002", "dietmaier"], choices=sorted(ROBOTS))
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args()
    print("| robot | ms a query (median) | ms (least) | largest error / max coefficient | largest radius / max coefficient | every exact coefficient enclosed |")
    print("|---|---:|---:|---:|---:|---|")
    for name in args.robot:
        run(name, args.repeat)


if __name__ == "__main__":
    main()
