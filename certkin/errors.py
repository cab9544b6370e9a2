"""Typed errors for bad input.  The CLI prints ``str(error)`` and exits 2.

A user's value echoed in a message goes through ``shown`` (plain values, cut to ``SHOWN`` characters):
``base[0]: expected 2 coordinates, got [3.78, 4.34, 1]``, never ``[Decimal('3.78'), ...]`` nor the
100 000 characters of a value pasted by mistake.
"""
from __future__ import annotations

from decimal import Decimal
from fractions import Fraction

SHOWN = 60          # characters of a user's value in a message at most (its start and end, "..." between)


class InputError(ValueError):
    """Bad user input: a robot file, a pose, a box, a job line.

    The message names the source (file name or option) and the field:
    ``robot.toml: limits.leg_length[2]: min 5 exceeds max 3``.  A field longer than ``SHOWN``
    characters (a user's text taken for a name) is cut in the message, not in ``field``.
    """

    def __init__(self, source: str, field: str, problem: str):
        self.source = source
        self.field = field
        self.problem = problem
        where = f"{source}: " if source else ""
        where += f"{clip(str(field))}: " if field and field != source else ""     # (not "z: z: ...")
        super().__init__(where + problem)


class RobotFileError(InputError):
    """A robot file that cannot be loaded, or describes a degenerate robot."""


def clip(text: str, limit: int = SHOWN) -> str:
    """``text`` if at most ``limit`` characters, else its start and end with ``...`` between.

    >>> clip("1234567890" * 10, 20)
    '123456789...34567890'
    """
    if len(text) <= limit:
        return text
    head = (limit - 3 + 1) // 2
    return text[:head] + "..." + text[len(text) - (limit - 3 - head):]


def shown(value, limit: int = SHOWN) -> str:
    """A user's value in a message: a text quoted as Python writes it (``'0x10'``), a number as its
    plain text (a ``Decimal`` or a ``Fraction`` too), lists and tables with their items shown so,
    ``nothing`` for None; cut by ``clip``.  Lists nested to any depth are written without recursion.

    >>> shown([Decimal("3.78"), Decimal("4.34"), 1])
    '[3.78, 4.34, 1]'
    >>> shown({"x": [Fraction(1, 3), None]})
    "{'x': [1/3, nothing]}"
    """
    parts, todo = [], [value]
    while todo:
        v = todo.pop()
        if isinstance(v, _Text):
            parts.append(v.text)
        elif isinstance(v, str):
            parts.append(repr(v))
        elif v is None:
            parts.append("nothing")
        elif isinstance(v, bool):
            parts.append(str(v).lower())
        elif isinstance(v, (int, float, Decimal, Fraction)):
            parts.append(str(v))
        elif isinstance(v, (list, tuple, dict)):
            items = [(_Text(f"{shown(k, limit)}: "), w) for k, w in v.items()] if isinstance(v, dict) else \
                [(w,) for w in v]
            seq = [_Text("{" if isinstance(v, dict) else "[")]
            for i, item in enumerate(items):
                seq.extend(((_Text(", "),) if i else ()) + item)
            seq.append(_Text("}" if isinstance(v, dict) else "]"))
            todo.extend(reversed(seq))
        elif callable(getattr(v, "tolist", None)):      # a numpy array or scalar: its Python values
            todo.append(v.tolist())
        else:
            parts.append(str(v))
    return clip("".join(parts), limit)


class _Text:
    """A piece of punctuation of a value being shown (not itself a value)."""
    __slots__ = ("text",)

    def __init__(self, text: str):
        self.text = text
