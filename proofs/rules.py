"""The leaf rules: each re-proves sign(det A) = s on a box.

A rule returns the sign it proved on the whole box (1 or −1), or 0 when its
enclosures do not decide.

- ``natural``: the interval extension of det(A) over the box.
- ``centred``: the mean-value form det(m) + Σ ∂det/∂x_i(box)·(x_i − m), with m
  a float point of the box (the midpoint up to rounding: any point of the
  box makes the form an enclosure), intersected with the natural extension
  that the gradient pass yields for free.
- ``monotone`` with flags m_i ∈ {−1, 0, 1}: for every m_i ≠ 0 the enclosure of
  ∂det/∂x_i on the box must have sign m_i (≥ 0 or ≤ 0 is enough: det is then
  monotone in x_i along every segment parallel to axis i, which stays in the
  box); then the extreme value of det on the box is attained on the face
  x_i = the bound that minimises det (s = 1) or maximises it (s = −1), and
  the sign of det on that face (natural, then centred enclosure) is the
  sign on the box.

``prove`` applies a leaf's rule.  When the checker's own enclosure does not
decide the whole leaf (its arithmetic differs from the producer's), it
bisects the leaf, up to ``MAX_DEPTH`` levels, and applies the same rule to
every piece: the pieces cover the leaf, so they prove the same statement.
A rule that proves the opposite sign on a box (or on a face inside it)
refutes the leaf at once.
"""
from __future__ import annotations

from mpmath import iv

from .numbers import sign
from .report import Rejected

MAX_DEPTH = 6


class NotProved(Exception):
    pass


def _midpoint(box):
    return [min(max(0.5 * lo + 0.5 * hi, lo), hi) for lo, hi in box]


def natural(robot, box, s, flags):
    return sign(robot.det(box))


def centred(robot, box, s, flags):
    D, grad = robot.det_gradient(box)
    m = _midpoint(box)
    form = robot.det([(x, x) for x in m])
    for g, (lo, hi), x in zip(grad, box, m):
        if lo != hi:
            form = form + g * (iv.mpf([lo, hi]) - iv.mpf(x))
    return sign(form) or sign(D)


def monotone(robot, box, s, flags):
    D, grad = robot.det_gradient(box)
    if sign(D) == -s:
        return -s
    for f, g in zip(flags, grad):
        if (f > 0 and (g >= 0) is not True) or (f < 0 and (g <= 0) is not True):
            return 0  # the stated monotonicity is not proved (on this box)
    if sign(D) == s:
        return s
    face = [(lo, lo) if f * s > 0 else (hi, hi) if f else (lo, hi) for f, (lo, hi) in zip(flags, box)]
    return natural(robot, face, s, None) or centred(robot, face, s, None)


RULES = {"natural": natural, "centred": centred, "monotone": monotone}


def parse(leaf: dict, dims: int, where: str):
    """(rule function, flags) of a leaf; rejects an unknown rule or malformed flags."""
    name = leaf.get("leaf")
    if name not in RULES:
        raise Rejected(f"{where}: unknown rule {name!r} (known: {', '.join(RULES)})")
    flags = None
    if name == "monotone":
        flags = leaf.get("monotone")
        if (not isinstance(flags, list) or len(flags) != dims
                or any(isinstance(f, bool) or f not in (-1, 0, 1) for f in flags)):
            raise Rejected(f"{where}: 'monotone' must be {dims} values in -1, 0, 1")
    return RULES[name], flags


def prove(robot, rule, box, s, flags, scale, depth=MAX_DEPTH) -> int:
    """Prove sign(det A) = s on ``box`` with ``rule``; returns the number of boxes used.

    ``scale`` (the claim's box widths) picks the dimension to bisect: the
    widest relative to it.  Raises ``NotProved`` with the reason.
    """
    got = rule(robot, box, s, flags)
    if got == s:
        return 1
    if got == -s:
        raise NotProved(f"det(A) has sign {got} on [{_show(box)}], not {s}")
    cut = _bisect(box, scale) if depth > 0 else None
    if cut is None:
        raise NotProved(f"sign {s} not proved on [{_show(box)}]"
                        + (f" (also after bisecting {MAX_DEPTH} levels)" if depth < MAX_DEPTH else ""))
    return sum(prove(robot, rule, part, s, flags, scale, depth - 1) for part in cut)


def _bisect(box, scale):
    order = sorted((i for i, w in enumerate(scale) if w > 0),
                   key=lambda i: (box[i][1] - box[i][0]) / scale[i], reverse=True)
    for i in order:
        lo, hi = box[i]
        mid = 0.5 * lo + 0.5 * hi
        if lo < mid < hi:
            return ([*box[:i], (lo, mid), *box[i + 1:]], [*box[:i], (mid, hi), *box[i + 1:]])
    return None


def _show(box):
    return ", ".join(f"{lo!r}:{hi!r}" for lo, hi in box)
