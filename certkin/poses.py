"""Poses and boxes from user text, enclosed exactly.

``parse_pose("-69,-50,500,85deg,10deg,0", robot)`` and
``parse_box("x=-20:20,y=-20:20,phi=0:0.7853981634", robot)``.  Values are
exact decimals (an angle may carry ``deg``); each becomes the outward float
enclosure of its exact value, so a certified box always contains the box
the user wrote.  A bound may be given once (``phi=0.5``) to fix a
coordinate.  Errors raise ``InputError`` naming the option and the field.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from intervals import Interval

from .errors import InputError
from .robots.base import parse_number


def _value(text, robot, name, option):
    try:
        return parse_number(text, option, name, angle=name in robot.angle_names)
    except InputError as exc:
        raise InputError(option, name, exc.problem) from None


def parse_pose(text, robot, option="--pose") -> tuple[Interval, list[str]]:
    """(d,) enclosure of a pose and its exact texts."""
    parts = [p.strip() for p in text.split(",")] if isinstance(text, str) else list(text)
    names = robot.pose_names
    if len(parts) != len(names):
        raise InputError(option, "", f"expected {len(names)} comma-separated values ({','.join(names)}), got {len(parts)}")
    ivs, texts = [], []
    for name, p in zip(names, parts):
        iv, t = _value(p, robot, name, option)
        ivs.append(iv)
        texts.append(str(t))
    return Interval._raw(np.array([float(i.lo) for i in ivs]), np.array([float(i.hi) for i in ivs])), texts


def parse_box(spec, robot, option="--box") -> tuple[Interval, dict]:
    """(d,) box enclosing the user's box, and the exact texts {name: [lo, hi]}.

    ``spec`` is a string ``"x=a:b,y=c:d,..."`` or a dict ``{name: (a, b)}``.
    Every pose variable of the robot must be given.
    """
    if isinstance(spec, str):
        items = {}
        for part in [p.strip() for p in spec.split(",") if p.strip()]:
            if "=" not in part:
                raise InputError(option, part, "expected name=lo:hi")
            name, rng = (s.strip() for s in part.split("=", 1))
            if name in items:
                raise InputError(option, name, "given twice")
            bounds = rng.split(":")
            if len(bounds) == 1:
                bounds = [bounds[0], bounds[0]]
            if len(bounds) != 2 or not all(b.strip() for b in bounds):
                raise InputError(option, name, f"expected lo:hi, got {rng!r}")
            items[name] = (bounds[0].strip(), bounds[1].strip())
    elif isinstance(spec, dict):
        items = {}
        for k, v in spec.items():
            if isinstance(v, (list, tuple)) and len(v) == 2:
                items[k] = (v[0], v[1])
            else:
                items[k] = (v, v)
    else:
        raise InputError(option, "", "expected 'name=lo:hi,...' or a mapping")
    for name in items:
        if name not in robot.pose_names:
            raise InputError(option, name, f"{robot.kind} robots have no variable {name!r} "
                                           f"(their pose is {','.join(robot.pose_names)})")
    missing = [n for n in robot.pose_names if n not in items]
    if missing:
        raise InputError(option, missing[0], "missing (every pose variable needs a range or a value)")
    lo, hi, texts = [], [], {}
    for name in robot.pose_names:
        a, b = items[name]
        ia, ta = _value(a, robot, name, option)
        ib, tb = _value(b, robot, name, option)
        if float(ia.lo) > float(ib.hi) or (_exact(ta) is not None and _exact(tb) is not None and _exact(ta) > _exact(tb)):
            raise InputError(option, name, f"lower bound {ta} exceeds upper bound {tb}")
        lo.append(float(ia.lo))
        hi.append(float(ib.hi))
        texts[name] = [str(ta), str(tb)]
    return Interval._raw(np.array(lo), np.array(hi)), texts


def _exact(text):
    try:
        return Fraction(str(text))
    except (ValueError, ZeroDivisionError):
        return None
