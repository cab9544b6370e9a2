"""Jobs for exhaustive campaigns (``certkin jobs grid``), so nobody writes a million lines by hand.

Every generated value is an exact decimal text, so a job asks exactly what it prints:

- ``fk_jobs``: the grid of leg lengths ``"L1=a:b:n,L2=...,L3=c"`` (n values from a to b, ends
  included; a single value fixes a leg);
- ``cell_jobs``: the box ``"x=a:b,..."`` cut into ``n`` cells per varying variable, one
  ``singular`` job per cell; neighbouring cells share their cut texts, so the cells cover the box
  exactly;
- ``trajectory_jobs``: start and goal poses from ``"x=a:b,...,z=520,psi=85deg,..."``: ranges with a
  count (``a:b:n``) make a grid (every start with every goal), ranges without one are drawn at
  random (``count`` pairs, numpy's generator seeded with ``seed``, values rounded to ``decimals``
  places and kept inside their range).

Cut points that are not short decimals are rounded to ``DIGITS`` significant digits (the ends of a
range are kept exactly).  Errors name the option (``--lengths``, ``--box``, ``--from``, ``--to``).
"""
from __future__ import annotations

from decimal import Context, Decimal, InvalidOperation, ROUND_HALF_EVEN
from fractions import Fraction
import itertools
import math
import re

import numpy as np

from ..errors import InputError, clip, shown
from ..robots.poses import exact_value
from .jobs import MAX_JOBS

DIGITS = 15
MAX_MAGNITUDE = 10 ** 12    # as every user value (``robots.poses``)


def _number(text: str, option: str, name: str) -> tuple[Fraction, str]:
    """(exact value, unit suffix '' or 'deg') of one decimal text."""
    t = text.strip()
    unit = "deg" if t.lower().endswith("deg") else ""
    core = t[:-3].strip() if unit else t
    try:
        d = Decimal(core)
    except InvalidOperation:
        raise InputError(option, name, f"not a plain decimal number: {shown(text)}") from None
    if not d.is_finite():
        raise InputError(option, name, f"not a finite number: {shown(text)}")
    if abs(d) > MAX_MAGNITUDE:
        raise InputError(option, name, f"{clip(t)} is out of range (at most 1e+12 in magnitude)")
    return Fraction(d), unit


def decimal(value: Fraction, digits: int = DIGITS) -> str:
    """The decimal text of a fraction: exact when it has at most ``digits`` digits, else rounded."""
    d = Context(prec=digits, rounding=ROUND_HALF_EVEN).divide(Decimal(value.numerator), Decimal(value.denominator))
    text = format(d.normalize(), "f")
    return "0" if text in ("-0", "") else text


def _spec(spec: str, names, option: str) -> dict:
    """``{name: [texts of its parts]}`` of ``"a=lo:hi:n,..."``, every one of ``names`` given once."""
    items = {}
    for part in [p.strip() for p in (spec or "").split(",") if p.strip()]:
        name, eq, rng = part.partition("=")
        name = name.strip()
        if not eq:
            raise InputError(option, part, "expected name=value, name=lo:hi or name=lo:hi:n")
        if name not in names:
            raise InputError(option, name, f"unknown name (expected {', '.join(names)})")
        if name in items:
            raise InputError(option, name, "given twice")
        items[name] = [s.strip() for s in rng.split(":")]
        if len(items[name]) > 3 or not all(items[name]):
            raise InputError(option, name, f"expected value, lo:hi or lo:hi:n, got {shown(rng)}")
    missing = [n for n in names if n not in items]
    if missing:
        raise InputError(option, missing[0], "missing (give a value or a range for each)")
    return items


def _range(parts, option, name):
    """(lo, hi, count or None, unit) of a value or range."""
    lo, unit = _number(parts[0], option, name)
    hi, unit_hi = _number(parts[1], option, name) if len(parts) > 1 else (lo, unit)
    if unit != unit_hi:
        raise InputError(option, name, "both ends need the same unit")
    if lo > hi:
        raise InputError(option, name, f"lower end {clip(parts[0])} exceeds upper end {clip(parts[1])}")
    count = None
    if len(parts) == 3:
        count = int(parts[2]) if re.fullmatch(r"[0-9]+", parts[2]) else 0     # (int() takes ' 3', '+2', '1_0', '٣')
        if count < 1 or count > MAX_JOBS:
            raise InputError(option, name, f"expected a positive count of values, at most {MAX_JOBS}, got {shown(parts[2])}")
    elif len(parts) == 1:
        count = 1
    if count is not None and count > 1 and lo == hi:
        raise InputError(option, name, f"{count} values of a range of one value would be {count} identical jobs: "
                                       f"give the value alone ({name}={parts[0]})")
    return lo, hi, count, unit


def _values(lo, hi, n, unit, ends, option="", name=""):
    """n values from lo to hi, ends included (their texts ``ends`` kept exactly); n = 1: the midpoint.
    Values that ``DIGITS`` digits cannot tell apart (a range too narrow for n of them) are refused:
    they would be the same job twice."""
    if n == 1:
        return [ends[0] if lo == hi else decimal((lo + hi) / 2) + unit]
    out = [decimal(lo + (hi - lo) * k / (n - 1)) + unit for k in range(n)]
    out[0], out[-1] = ends
    if len({exact_value(v) for v in out}) < n:
        raise InputError(option, name, f"{n} values from {ends[0]} to {ends[1]} repeat when written with {DIGITS} "
                                       "significant digits: take fewer values or a wider range")
    return out


def _end_texts(parts):
    """The texts of the two ends of a value (``v``) or range (``lo:hi``, ``lo:hi:n``)."""
    return parts[0], parts[1] if len(parts) > 1 else parts[0]


def _check_count(n: int, option: str) -> None:
    if n > MAX_JOBS:
        raise InputError(option, "", f"{n} jobs, more than {MAX_JOBS}: split the campaign")


def _ids(prefix: str, n: int):
    width = len(str(max(n - 1, 0)))
    return [f"{prefix}-{k:0{width}d}" for k in range(n)]


def fk_jobs(robot_ref, robot, spec: str, prefix: str = "fk") -> list[dict]:
    """One ``fk`` job per point of the leg-length grid ``spec`` (``L1=a:b:n,...``)."""
    names = [f"L{i + 1}" for i in range(robot.n_legs)]
    axes = []
    for name, parts in _spec(spec, names, "--lengths").items():
        lo, hi, n, unit = _range(parts, "--lengths", name)
        if unit:
            raise InputError("--lengths", name, "a leg length has no unit 'deg'")
        if n is None:
            raise InputError("--lengths", name, "expected lo:hi:n (n values) or one value")
        axes.append((lo, hi, n, parts, name))
    _check_count(math.prod(a[2] for a in axes), "--lengths")
    axes = [_values(lo, hi, n, "", _end_texts(parts), "--lengths", name) for lo, hi, n, parts, name in axes]
    points = list(itertools.product(*[axes[names.index(n)] for n in names]))
    return [{"id": i, "command": "fk", "robot": robot_ref, "lengths": ",".join(p)}
            for i, p in zip(_ids(prefix, len(points)), points)]


def cell_jobs(robot_ref, robot, spec: str, cells: int, prefix: str = "cell") -> list[dict]:
    """One ``singular`` job per cell of the box ``spec`` cut into ``cells`` parts per varying variable."""
    if cells < 1:
        raise InputError("--cells", "", f"expected a positive number of cells per side, got {cells}")
    varying = sum(len(p) > 1 and _range(p, "--box", n)[0] != _range(p, "--box", n)[1]
                  for n, p in _spec(spec, robot.pose_names, "--box").items())
    _check_count(cells ** varying, "--cells")
    axes = []
    for name in robot.pose_names:
        parts = _spec(spec, robot.pose_names, "--box")[name]
        if len(parts) > 2:
            raise InputError("--box", name, "expected lo:hi (the cells are given by --cells)")
        lo, hi, _, unit = _range(parts, "--box", name)
        if lo == hi:
            axes.append([f"{parts[0]}:{parts[-1]}"])
            continue
        cuts = _values(lo, hi, cells + 1, unit, (parts[0], parts[-1]), "--box", name)
        axes.append([f"{a}:{b}" for a, b in zip(cuts, cuts[1:])])
    points = list(itertools.product(*axes))
    return [{"id": i, "command": "singular", "robot": robot_ref,
             "box": ",".join(f"{n}={r}" for n, r in zip(robot.pose_names, p))}
            for i, p in zip(_ids(prefix, len(points)), points)]


def trajectory_jobs(robot_ref, robot, start: str, goal: str, count: int | None = None, seed: int | None = None,
                    decimals: int | None = None, prefix: str = "traj") -> list[dict]:
    """``trajectory`` jobs from a grid of start and goal poses, or ``count`` random pairs (drawn with
    ``seed``, default 0, rounded to ``decimals`` places, default 3: options of the random draw only)."""
    names = robot.pose_names
    ends = {}
    for option, spec in (("--from", start), ("--to", goal)):
        items = _spec(spec, names, option)
        ends[option] = [(_range(items[n], option, n), items[n]) for n in names]
    ranged = [r[2] for option in ends for r, parts in ends[option] if len(parts) > 1]
    random = any(c is None for c in ranged)
    if random and any(c is not None for c in ranged):
        raise InputError("--from", "", "give every range a count (a grid: lo:hi:n) or none (random pairs)")
    if random:
        if not count or count < 1:
            raise InputError("--count", "", "random start and goal poses need --count N (a positive number)")
        _check_count(count, "--count")
        rng = np.random.default_rng(0 if seed is None else seed)
        decimals = 3 if decimals is None else decimals
        poses = {o: [_random(rng, r, parts, count, decimals) for r, parts in ends[o]] for o in ends}
        pairs = [(tuple(v[k] for v in poses["--from"]), tuple(v[k] for v in poses["--to"])) for k in range(count)]
    else:
        for option, value in (("--count", count), ("--seed", seed), ("--decimals", decimals)):
            if value is not None:
                raise InputError(option, "", "every range has a count (a grid of poses): " + option +
                                 " belongs to random pairs (ranges without a count)")
        _check_count(math.prod(r[2] for o in ends for r, _ in ends[o]), "--from")
        grids = {o: list(itertools.product(*[_values(*r, _end_texts(p), o, n)
                                             for (r, p), n in zip(ends[o], names)])) for o in ends}
        pairs = list(itertools.product(grids["--from"], grids["--to"]))
    return [{"id": i, "command": "trajectory", "robot": robot_ref, "from": ",".join(a), "to": ",".join(b)}
            for i, (a, b) in zip(_ids(prefix, len(pairs)), pairs)]


def _random(rng, r, parts, count, decimals):
    """``count`` texts drawn uniformly in the range, rounded to ``decimals`` places, kept inside it."""
    lo, hi, _, unit = r
    if lo == hi:
        return [parts[0]] * count
    draws = rng.uniform(float(lo), float(hi), count)
    step = Fraction(1, 10 ** decimals)
    out = []
    for v in draws:
        q = Fraction(round(Fraction(v) / step)) * step
        q = min(max(q, lo), hi)
        out.append(parts[0] if q == lo else parts[1] if q == hi else decimal(q) + unit)
    return out
