"""Forward-mode automatic differentiation over mpmath ``iv`` intervals.

A ``Dual`` carries an interval value and its partial derivatives, kept in a
dict {variable index: interval} (absent means exactly 0).  Evaluated over a
box, every derivative interval encloses the true partial derivative at
every point of the box: each operation applies the exact differentiation
rule with interval arithmetic.  Only what the models need is defined:
+, −, ×, sin, cos.

mpmath's ``ivmpf`` does not defer to other types, so an ``ivmpf`` must never
be the left operand of a ``Dual``: ``lift`` turns constants into ``Dual``
with no derivatives, and the models lift their geometry before use.
"""
from __future__ import annotations

from mpmath import iv


class Dual:
    __slots__ = ("v", "d")

    def __init__(self, v, d=None):
        self.v = v
        self.d = d or {}

    def __add__(self, o):
        if not isinstance(o, Dual):
            return Dual(self.v + o, self.d)
        d = dict(self.d)
        for k, g in o.d.items():
            d[k] = d[k] + g if k in d else g
        return Dual(self.v + o.v, d)

    __radd__ = __add__

    def __neg__(self):
        return Dual(-self.v, {k: -g for k, g in self.d.items()})

    def __sub__(self, o):
        if not isinstance(o, Dual):
            return Dual(self.v - o, self.d)
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if not isinstance(o, Dual):
            return Dual(self.v * o, {k: g * o for k, g in self.d.items()})
        d = {k: g * o.v for k, g in self.d.items()}
        for k, g in o.d.items():
            d[k] = d[k] + self.v * g if k in d else self.v * g
        return Dual(self.v * o.v, d)

    __rmul__ = __mul__


def lift(x):
    """A constant as a ``Dual`` with zero derivatives (ints and Duals unchanged)."""
    return x if isinstance(x, (Dual, int)) else Dual(x)


def variables(intervals):
    """The independent variables x_i over the given intervals (∂x_i/∂x_i = 1)."""
    return [Dual(x, {i: iv.mpf(1)}) for i, x in enumerate(intervals)]


def sin(x):
    if isinstance(x, Dual):
        c = iv.cos(x.v)
        return Dual(iv.sin(x.v), {k: c * g for k, g in x.d.items()})
    return iv.sin(x)


def cos(x):
    if isinstance(x, Dual):
        s = -iv.sin(x.v)
        return Dual(iv.cos(x.v), {k: s * g for k, g in x.d.items()})
    return iv.cos(x)


def gradient(y, n: int):
    """(value, [∂y/∂x_0, ..., ∂y/∂x_{n-1}]) of a ``Dual`` result."""
    zero = iv.mpf(0)
    if not isinstance(y, Dual):
        return y, [zero] * n
    return y.v, [y.d.get(i, zero) for i in range(n)]
