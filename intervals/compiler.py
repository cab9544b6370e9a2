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

import numpy as np
import sympy as sp

from . import autodiff
from . import elementary as el
from . import polynomial as pl
from .interval import Interval, pown, sqr, stack

_FUNCTIONS = {
    sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.atan: "atan", sp.exp: "exp",
    sp.log: "log", sp.Abs: "abs", sp.atan2: "atan2",
}

CHUNK = 8192  # rows per block: keeps the temporaries of one block in cache


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


def _unsupported(name):
    def fn(*args):
        raise NotImplementedError(f"{name} of a polynomial in t is not supported")
    return fn


def _poly_namespace():
    """Functions for ``polynomial.Poly`` variables (polynomials in t ∈ [0, 1])."""
    ns = {name: _unsupported(name) for name in ("tan", "atan", "atan2", "exp", "log", "abs", "sqrt", "min", "max")}
    ns.update(sin=pl.sin, cos=pl.cos, sqr=pl.sqr, pown=pl.pown, pi=el.pi)
    return ns


def _namespace(dual):
    if dual == "poly":
        return _poly_namespace()
    src = autodiff if dual else el
    ns = {name: getattr(src, name) for name in ("sin", "cos", "tan", "atan", "atan2", "exp", "log", "abs", "sqrt")}
    ns.update(min=el.min, max=el.max, pi=el.pi)
    ns["sqr"] = autodiff.sqr if dual else sqr
    ns["pown"] = autodiff.pown if dual else pown
    return ns


class CompiledExprs:
    """A batch evaluator of m expressions in d variables (and fixed parameters)."""

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
        self.source = src
        self._fns = {}
        for dual in (False, True, "poly"):
            ns = _namespace(dual)
            ns.update(printer.constants)
            exec(compile(src, "<certkin-compiled>", "exec"), ns)
            self._fns[dual] = ns["_f"]

    def _params(self, params):
        if params is None:
            params = []
        if len(params) != len(self.parameters):
            raise ValueError(f"expected {len(self.parameters)} parameter values, got {len(params)}")
        return [p if isinstance(p, Interval) else Interval(p) for p in params]

    def _blocks(self, box: Interval):
        n = box.shape[0] if box.ndim > 1 else None
        if n is None or n <= CHUNK:
            yield slice(None)
            return
        for start in range(0, n, CHUNK):
            yield slice(start, min(start + CHUNK, n))

    @staticmethod
    def _broadcast(out, shape):
        """Expressions that do not depend on the variables come back 0-d: broadcast them."""
        fixed = []
        for o in out:
            if not isinstance(o, Interval):
                o = Interval(o)
            fixed.append(Interval.from_bounds(np.broadcast_to(o.lo, shape), np.broadcast_to(o.hi, shape)))
        return fixed

    def __call__(self, box: Interval, params=None) -> Interval:
        """Enclosures of the m expressions over a batch of boxes (..., d) -> (..., m)."""
        params = self._params(params)
        box = box if isinstance(box, Interval) else Interval(box)
        parts = []
        for blk in self._blocks(box):
            b = box[blk]
            v = [b[..., i] for i in range(len(self.variables))]
            out = self._broadcast(self._fns[False](v, params), b.shape[:-1])
            parts.append(stack(out, axis=-1))
        if len(parts) == 1:
            return parts[0]
        return Interval.from_bounds(np.concatenate([p.lo for p in parts]), np.concatenate([p.hi for p in parts]))

    def evaluate(self, variables, params=None) -> list:
        """The m expressions at prebuilt variable values (``Interval``, ``autodiff.Dual`` or
        ``polynomial.Poly``, one per variable, any common shape); returns a list of m values
        (constants come back unbroadcast).  Polynomial variables support + − × and sin/cos of
        degree-1 arguments (NotImplementedError otherwise)."""
        if any(isinstance(v, pl.Poly) for v in variables):
            return self._fns["poly"](list(variables), self._params(params))
        dual = any(isinstance(v, autodiff.Dual) for v in variables)
        return self._fns[dual](list(variables), self._params(params))

    def jacobian(self, box: Interval, params=None):
        """(values (..., m), Jacobian enclosure (..., m, d)) over a batch of boxes."""
        params = self._params(params)
        box = box if isinstance(box, Interval) else Interval(box)
        d = len(self.variables)
        vals, jacs = [], []
        for blk in self._blocks(box):
            b = box[blk]
            out = self._fns[True](autodiff.Dual.variables(b), params)
            vs, gs = [], []
            for o in out:
                if not isinstance(o, autodiff.Dual):
                    o = autodiff.Dual.variables(b)[0].lift(o if isinstance(o, Interval) else Interval(o))
                vs.append(Interval.from_bounds(np.broadcast_to(o.value.lo, b.shape[:-1]), np.broadcast_to(o.value.hi, b.shape[:-1])))
                gs.append(Interval.from_bounds(np.broadcast_to(o.grad.lo, b.shape[:-1] + (d,)),
                                        np.broadcast_to(o.grad.hi, b.shape[:-1] + (d,))))
            vals.append(stack(vs, axis=-1))
            jacs.append(stack(gs, axis=-2))
        if len(vals) == 1:
            return vals[0], jacs[0]
        cat = lambda xs: Interval.from_bounds(np.concatenate([x.lo for x in xs]), np.concatenate([x.hi for x in xs]))
        return cat(vals), cat(jacs)


def compile_exprs(exprs, variables, parameters=()) -> CompiledExprs:
    """Compile sympy expressions in ``variables`` (box coordinates) and ``parameters``."""
    return CompiledExprs(exprs, variables, parameters)
