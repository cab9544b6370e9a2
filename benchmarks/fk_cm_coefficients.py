"""The 15 Cayley–Menger rotation polynomials of a query, fast and with a proved error bound: how long?

The Bernstein test of the rotation (sections "the Bernstein test as a node rule" and "the rotation
alone by Bernstein expansion" of docs/benchmarks.md) needs, per query (robot and leg lengths), the
coefficients of the 15 polynomials CM·|q|^8, homogeneous of degree 8 in the quaternion q (165
coefficients each).  The studies took them exactly from sympy (3 to 11 s a robot): far too slow per
query.  This script times the solver's own computation (``certkin.fk.cayley_menger.forms``, once a study
of this script): float, midpoint-radius, with the a-priori rounding bound of
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

About 20 s a robot (the exact sympy reference); the timed part is printed per query.
"""
from __future__ import annotations

import argparse
from fractions import Fraction
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fk_cayley_menger import ROBOTS                                   # noqa: E402
from fk_rotation_bernstein import homogeneous_cm, read_robot         # noqa: E402

from certkin.fk.cayley_menger import MONO, forms                       # noqa: E402
from intervals import Interval                                        # noqa: E402


def enclose(values, shape):
    """Float enclosures (one ulp each way) of exact rationals, as an Interval of ``shape``."""
    m = np.array([float(v) for v in values]).reshape(shape)
    return Interval.from_bounds(np.nextafter(m, -np.inf), np.nextafter(m, np.inf))


def exact_vectors(polys):
    """The exact coefficients (15, 165) as Fractions, in ``MONO[8]`` order."""
    idx = {e: i for i, e in enumerate(MONO[8][0])}
    out = np.full((len(polys), len(idx)), Fraction(0), dtype=object)
    for k, p in enumerate(polys):
        for mono, c in p.terms():
            out[k, idx[tuple(mono)]] = Fraction(int(c.numerator), int(c.denominator))
    return out


def run(name, repeat):
    a, b, rho = read_robot(name)
    A, B = enclose([x for row in a for x in row], (6, 3)), enclose([x for row in b for x in row], (6, 3))
    L = enclose([x * x for x in rho], (6,))
    spent = []
    for _ in range(repeat):
        t0 = time.process_time()
        m, r = forms(A, B, L)
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
