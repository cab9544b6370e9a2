"""Batch interval evaluators of generated code: the code ``intervals.compiler`` writes from sympy
expressions, run on whole batches of boxes (``Interval``), on ``autodiff.Dual`` inputs (Jacobian
enclosures) or on ``polynomial.Poly`` inputs (polynomials in t).

An ``Evaluator`` is built from that code's text and its constants (enclosures computed by the
compiler), so a compiled model kept on disk runs without sympy (``certkin.robots.models``); its
guarantees are the compiler's (``intervals.compiler``, ``docs/soundness.md``).
"""
from __future__ import annotations

import numpy as np

from . import autodiff
from . import elementary as el
from . import polynomial as pl
from .interval import Interval, pown, sqr, stack

CHUNK = 8192  # rows per block: keeps the temporaries of one block in cache


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


class Evaluator:
    """A batch evaluator of m expressions in d variables (and fixed parameters): ``source`` defines
    ``_f(v, p)`` returning the m values, ``constants`` names its constant enclosures."""

    def __init__(self, source: str, constants: dict, n_variables: int, n_parameters: int):
        self.source, self.constants = source, dict(constants)
        self.n_variables, self.n_parameters = n_variables, n_parameters
        self._fns = {}
        code = compile(source, "<certkin-compiled>", "exec")
        for dual in (False, True, "poly"):
            ns = _namespace(dual)
            ns.update(self.constants)
            exec(code, ns)
            self._fns[dual] = ns["_f"]

    def _params(self, params):
        if params is None:
            params = []
        if len(params) != self.n_parameters:
            raise ValueError(f"expected {self.n_parameters} parameter values, got {len(params)}")
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
            v = [b[..., i] for i in range(self.n_variables)]
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
        d = self.n_variables
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
