"""What every robot model shares: exact geometry, symbolic model, compiled evaluators.

A model is written once with sympy (leg vectors, Jacobians A and B in the
seed 003 form A ṫ + B ρ̇ = 0, det(A)) with the geometry as *symbols*; the
expressions are compiled once per kind by ``intervals.compiler`` and then
evaluated on batches of boxes with the robot's exact geometry enclosed as
parameter intervals.
"""
from __future__ import annotations

from fractions import Fraction
from functools import cached_property

import numpy as np
import sympy as sp

from intervals import Interval, linalg, sqrt
from intervals.autodiff import Dual
from intervals.compiler import compile_exprs

from .poses import parse_number

_COMPILED: dict = {}  # (kind, n_legs, what) -> CompiledExprs, shared by robots of one kind


def det3(M):
    """Cofactor expansion of a 3x3 sympy matrix, left unexpanded.

    Keeping the products of the (short) entries instead of the expanded
    polynomial makes far fewer interval operations and tighter enclosures.
    """
    return (M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
            - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
            + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))


class Robot:
    """A parallel robot with exact geometry.  Subclasses define the symbolic model.

    Attributes: ``kind``, ``name``, ``base``/``platform`` (exact decimal
    strings), ``limits`` (dict), ``home`` (exact texts of a reference pose),
    ``pose_names`` (the pose variables, in order), ``angle_names``.
    """

    kind = ""
    n_legs = 0
    dim = 0
    pose_names: tuple[str, ...] = ()
    angle_names: frozenset = frozenset()

    def __init__(self, name, base, platform, limits=None, home=None, source=""):
        self.name = name
        self.base = [tuple(p) for p in base]
        self.platform = [tuple(p) for p in platform]
        self.limits = limits or {}
        self.home = list(home) if home is not None else None
        self.source = source

    # ----- symbolic model (written by each kind) -----------------------------
    @classmethod
    def symbols(cls):
        """(pose symbols, geometry symbols) of the symbolic model of this kind."""
        raise NotImplementedError

    @classmethod
    def symbolic_model(cls) -> dict:
        """Sympy expressions: ``legs`` (leg vectors), ``A``, ``B`` (matrices), ``points`` (world B_i)."""
        raise NotImplementedError

    # ----- exact data ------------------------------------------------------
    def geometry_texts(self) -> list[str]:
        """The geometry parameters, as exact texts, in ``symbols()[1]`` order."""
        return [c for p in self.base for c in p] + [c for p in self.platform for c in p]

    @cached_property
    def parameters(self) -> list[Interval]:
        return [Interval(t) for t in self.geometry_texts()]

    def to_dict(self) -> dict:
        """The exact robot data (for certificates and reports)."""
        d = {"name": self.name, "kind": self.kind,
             "base": [list(p) for p in self.base], "platform": [list(p) for p in self.platform]}
        if self.limits:
            d["limits"] = self.limits
        return d

    # ----- compiled evaluators ---------------------------------------------
    @property
    def model_name(self) -> str:
        """The name of the equations in certificates (``docs/certificates.md``)."""
        return self.kind

    @classmethod
    def compiled(cls, what: str):
        key = (cls.__name__, what)
        if key not in _COMPILED:
            pose, geom = cls.symbols()
            model = cls.symbolic_model()
            if what == "det":
                exprs = [model["det"]]
            elif what == "A":
                exprs = list(model["A"])
            elif what == "legs_sq":
                exprs = [sum(c ** 2 for c in leg) for leg in model["legs"]]
            elif what == "R":
                exprs = list(model["R"])
            elif what == "points":
                exprs = [c for p in model["points"] for c in p]
            elif what == "leg_vectors":   # l_i padded to 3 coordinates, then R row by row if modelled
                exprs = [c for leg in model["legs"] for c in (list(leg) + [0] * (3 - len(leg)))]
                if "R" in model:
                    exprs += list(model["R"])
            else:
                raise KeyError(what)
            _COMPILED[key] = compile_exprs(exprs, pose, geom)
        return _COMPILED[key]

    @classmethod
    def rigid_legs(cls) -> bool:
        """Whether the model's leg vectors are l_i = C + R b_i − a_i (C the position variables,
        a_i, b_i the base and platform geometry), checked symbolically once per kind."""
        key = (cls.__name__, "rigid_legs")
        if key not in _COMPILED:
            pose, geom = cls.symbols()
            model = cls.symbolic_model()
            ok = "R" in model and cls.dim == 3
            if ok:
                R = sp.Matrix(model["R"]).reshape(3, 3)
                C = [v for v in pose if str(v) not in cls.angle_names]
                C = sp.Matrix(C + [0] * (3 - len(C)))
                n = cls.n_legs
                for i, leg in enumerate(model["legs"]):
                    a, b = sp.Matrix(geom[3 * i:3 * i + 3]), sp.Matrix(geom[3 * n + 3 * i:3 * n + 3 * i + 3])
                    ok = ok and all(sp.expand(x - y) == 0 for x, y in zip(leg, C + R * b - a))
            _COMPILED[key] = bool(ok)
        return _COMPILED[key]

    def _box(self, boxes) -> Interval:
        b = boxes if isinstance(boxes, Interval) else Interval(np.asarray(boxes, dtype=np.float64))
        if b.shape[-1] != len(self.pose_names):
            raise ValueError(f"{self.kind} poses have {len(self.pose_names)} coordinates {self.pose_names}")
        return b

    def det_enclosure(self, boxes) -> Interval:
        """Enclosure of det(A) over each box of a batch (..., d) -> (...)."""
        b = self._box(boxes)
        if "det" in self.symbolic_model():
            return self.compiled("det")(b, self.parameters)[..., 0]
        A = self.compiled("A")(b, self.parameters)
        n = self.n_legs
        return linalg.det(A.reshape(*A.shape[:-1], n, n))

    def det_gradient(self, boxes):
        """(det enclosure (...), gradient enclosure (..., d)) over each box.

        Without a symbolic det(A) (Gough-Stewart), the compiled entries of A
        and their gradients feed a Laplace expansion on ``autodiff.Dual``
        numbers (``linalg.laplace_det``).
        """
        b = self._box(boxes)
        if "det" in self.symbolic_model():
            v, j = self.compiled("det").jacobian(b, self.parameters)
            return v[..., 0], j[..., 0, :]
        vals, jac = self.compiled("A").jacobian(b, self.parameters)
        n, d = self.n_legs, len(self.pose_names)
        M = [[Dual(vals[..., i * d + j], jac[..., i * d + j, :]) for j in range(d)] for i in range(n)]
        D = linalg.laplace_det(M)
        return D.value, D.grad

    def leg_lengths_squared(self, boxes) -> Interval:
        """Enclosures of rho_i^2 over each box (..., n_legs)."""
        return self.compiled("legs_sq")(self._box(boxes), self.parameters)

    def leg_lengths(self, boxes) -> Interval:
        """Enclosures of rho_i over each box (..., n_legs)."""
        return sqrt(self.leg_lengths_squared(boxes))

    def platform_points(self, boxes) -> Interval:
        """World coordinates of the B_i over each box (..., n_legs, dim)."""
        p = self.compiled("points")(self._box(boxes), self.parameters)
        return p.reshape(*p.shape[:-1], self.n_legs, self.dim)

    def jacobian_A(self, boxes) -> Interval:
        """Enclosure of the matrix A over each box (..., n_legs, d)."""
        a = self.compiled("A")(self._box(boxes), self.parameters)
        return a.reshape(*a.shape[:-1], self.n_legs, len(self.pose_names))

    # ----- float helpers (not rigorous: for sampling and display) ------------
    @property
    def _float_funcs(self):
        """(squared leg lengths, A) as float functions of (pose, geometry): lambdified once per kind."""
        key = (type(self).__name__, "float")
        if key not in _COMPILED:
            pose, geom = self.symbols()
            model = self.symbolic_model()
            legs = sp.lambdify(list(pose) + list(geom), [sum(c ** 2 for c in l) for l in model["legs"]], "numpy")
            A = sp.lambdify(list(pose) + list(geom), model["A"].tolist(), "numpy")
            _COMPILED[key] = (legs, A)
        return _COMPILED[key]

    def leg_lengths_float(self, pose) -> np.ndarray:
        """Leg lengths at float poses (..., d) -> (..., n) by plain float arithmetic (not certified)."""
        pose = np.asarray(pose, dtype=np.float64)
        g = [float(Fraction(t)) for t in self.geometry_texts()]
        legs, _ = self._float_funcs
        vals = legs(*np.moveaxis(pose, -1, 0), *g)
        return np.sqrt(np.stack(np.broadcast_arrays(*vals), axis=-1))

    def jacobian_float(self, pose) -> np.ndarray:
        """The matrix A at float poses (..., d) -> (..., n, d) (not certified)."""
        pose = np.asarray(pose, dtype=np.float64)
        g = [float(Fraction(t)) for t in self.geometry_texts()]
        _, A = self._float_funcs
        entries = A(*np.moveaxis(pose, -1, 0), *g)
        M = np.array([[np.broadcast_to(np.asarray(e, dtype=np.float64), pose.shape[:-1]) for e in row] for row in entries])
        return np.moveaxis(M, (0, 1), (-2, -1))

    def det_float(self, pose) -> np.ndarray:
        """det(A) at float poses (not certified)."""
        return np.linalg.det(self.jacobian_float(pose))

    def pose_box(self, pose) -> Interval:
        """An (d,) Interval from a pose given as numbers, exact texts or intervals."""
        items = []
        for name, v in zip(self.pose_names, pose):
            if isinstance(v, Interval):
                items.append(v)
            else:
                items.append(parse_number(v, "pose", name, angle=name in self.angle_names)[0])
        return Interval.from_bounds(np.array([float(i.lo) for i in items]), np.array([float(i.hi) for i in items]))

    def home_box(self) -> Interval | None:
        return None if self.home is None else self.pose_box(self.home)

    def __repr__(self):
        return f"<{type(self).__name__} {self.name!r} ({self.kind}, {self.n_legs} legs)>"
