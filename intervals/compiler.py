"""Compile sympy expressions into vectorised interval evaluators.

A robot model is written once symbolically; ``compile_exprs`` turns a list
of expressions into Python code that runs on a whole batch of boxes at once:

    ev = compile_exprs([x**2 + y, sin(x)*y], variables=[x, y])
    values = ev(box)                      # box: Interval (N, 2) -> (N, 2)
    values, jac = ev.jacobian(box)        # jac: (N, 2, 2)

Guarantees: the generated code applies only enclosing operations of
``intervals`` (``sqr`` for squares, ``pown`` for other integer powers,
outward-rounded + - * /, rigorous elementary functions), and every numeric
constant is enclosed from its exact value (a sympy ``Rational`` as a
fraction, ``pi`` by the rigorous π enclosure, a sympy ``Float`` by its exact
binary value).  Common subexpressions are computed once (``sympy.cse``).
The same code run on ``autodiff.Dual`` inputs gives the Jacobian enclosure.
"""
from __future__ import annotations

from fractions import Fraction

import sympy as sp

from .evaluator import Evaluator
from .interval import Interval

_FUNCTIONS = {
    sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.atan: "atan", sp.exp: "exp",
    sp.log: "log", sp.Abs: "abs", sp.atan2: "atan2",
}


class _Printer:
    """Turns a sympy expression tree into a Python expression string."""

    def __init__(self, names):
        self.names = dict(names)
        self.constants: dict[str, Interval] = {}

    def const(self, value) -> str:
        key = f"_c{len(self.constants)}"
        self.constants[key] = value
        return key

    def number(self, e) -> str:
        if e.is_Integer or e.is_Rational:
            return self.const(Interval(Fraction(int(e.p), int(e.q))))
        if e is sp.pi:
            return "pi"
        if e.is_Float:
            mpf = e._mpf_
            sign, man, exp_, _ = mpf
            q = Fraction(int(man)) * (Fraction(2) ** int(exp_)) * (-1 if sign else 1)
            return self.const(Interval(q))
        if e is sp.E:
            return f"exp({self.const(Interval(1))})"
        raise NotImplementedError(f"constant {e!r} cannot be enclosed")

    def __call__(self, e) -> str:
        if e in self.names:
            return self.names[e]
        if e.is_Number or e is sp.pi or e is sp.E:
            return self.number(e)
        if e.is_Symbol:
            raise KeyError(f"unbound symbol {e} (declare it as a variable or parameter)")
        if e.is_Add:
            plus, minus = [], []
            for a in e.args:
                coeff, rest = a.as_coeff_Mul()
                if coeff.is_Number and coeff < 0:
                    minus.append(self(-a))
                else:
                    plus.append(self(a))
            if not plus:
                out = "(-" + minus.pop(0)
            else:
                out = "(" + " + ".join(plus)
            for m in minus:
                out += " - " + m
            return out + ")"
        if e.is_Mul:
            coeff, rest = e.as_coeff_Mul()
            factors = [self(a) for a in sp.Mul.make_args(rest)]
            body = " * ".join(factors)
            if coeff == 1:
                return "(" + body + ")"
            if coeff == -1:
                return "(-(" + body + "))"
            return "(" + self.number(coeff) + " * " + body + ")"
        if e.is_Pow:
            base, ex = e.args
            b = self(base)
            if ex.is_Integer:
                n = int(ex)
                if n == 2:
                    return f"sqr({b})"
                if n == -1:
                    return f"({self.const(Interval(1))} / {b})"
                if n < 0:
                    return f"({self.const(Interval(1))} / pown({b}, {-n}))"
                return f"pown({b}, {n})"
            if ex == sp.Rational(1, 2):
                return f"sqrt({b})"
            if ex == sp.Rational(-1, 2):
                return f"({self.const(Interval(1))} / sqrt({b}))"
            return f"exp({self(ex)} * log({b}))"
        if isinstance(e, (sp.Min, sp.Max)):
            fn = "min" if isinstance(e, sp.Min) else "max"
            out = self(e.args[0])
            for a in e.args[1:]:
                out = f"{fn}({out}, {self(a)})"
            return out
        for cls, name in _FUNCTIONS.items():
            if isinstance(e, cls):
                return f"{name}(" + ", ".join(self(a) for a in e.args) + ")"
        raise NotImplementedError(f"cannot compile {type(e).__name__}: {e}")


class CompiledExprs(Evaluator):
    """The evaluator of m sympy expressions in d variables (and fixed parameters); ``exprs``,
    ``variables`` and ``parameters`` as given."""

    def __init__(self, exprs, variables, parameters=()):
        self.exprs = [sp.sympify(e) for e in exprs]
        self.variables = list(variables)
        self.parameters = list(parameters)
        names = {v: f"v[{i}]" for i, v in enumerate(self.variables)}
        names.update({p: f"p[{i}]" for i, p in enumerate(self.parameters)})
        replacements, reduced = sp.cse(self.exprs, optimizations="basic")
        printer = _Printer(names)
        lines = []
        for k, (sym, sub) in enumerate(replacements):
            code = printer(sub)
            printer.names[sym] = f"t{k}"
            lines.append(f"    t{k} = {code}")
        outs = [printer(r) for r in reduced]
        src = "def _f(v, p):\n" + "\n".join(lines) + ("\n" if lines else "")
        src += "    return [" + ", ".join(outs) + "]\n"
        super().__init__(src, printer.constants, len(self.variables), len(self.parameters))


def compile_exprs(exprs, variables, parameters=()) -> CompiledExprs:
    """Compile sympy expressions in ``variables`` (box coordinates) and ``parameters``."""
    return CompiledExprs(exprs, variables, parameters)
