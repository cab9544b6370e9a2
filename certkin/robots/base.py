"""What every robot model shares: exact geometry, symbolic model, compiled evaluators, float helpers.

A model is written once with sympy (``robots.symbolic``: leg vectors,
Jacobians A and B in the seed 003 form A ṫ + B ρ̇ = 0, det(A)) with the
geometry as *symbols*; the expressions are compiled once per kind by
``intervals.compiler`` (kept on disk, ``robots.models``) and then
evaluated on batches of boxes with the robot's exact geometry enclosed as
parameter intervals.  The symbolic module is loaded on first use
(``models.symbolic()``): reading a robot file, forward kinematics, poses and
a compiled model found on disk do not import sympy.

The float helpers (``leg_lengths_float``, ``jacobian_float``,
``rotation_float``) are plain numpy formulas of each kind, for guesses,
sampling and input checks, never for proofs; tests compare them with the
symbolic model.
"""
from __future__ import annotations

from fractions import Fraction
from functools import cached_property

import numpy as np

from intervals import Interval, linalg, sqrt
from intervals.autodiff import Dual

from ..errors import InputError
from . import models
from .poses import parse_number


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
    geometry_letters = ("a", "b")           # symbol prefixes of the base and platform coordinates
    symbolic_det = False                    # whether the model has a short symbolic det(A) (else A only)

    def __init__(self, name, base, platform, limits=None, home=None, source=""):
        self.name = name
        self.base = [tuple(p) for p in base]
        self.platform = [tuple(p) for p in platform]
        self.limits = limits or {}
        self.home = list(home) if home is not None else None
        self.source = source

    # ----- symbolic model (robots.symbolic) -----------------------------------
    @classmethod
    def geometry_names(cls) -> tuple[str, ...]:
        """Names of the geometry parameters, base points then platform points (``a1x a1y ...``)."""
        coords = "xyz"[:cls.dim]
        return tuple(f"{which}{i}{c}" for which in cls.geometry_letters for i in range(1, cls.n_legs + 1)
                     for c in coords)

    @classmethod
    def symbols(cls):
        """(pose symbols, geometry symbols) of the symbolic model of this kind."""
        return models.symbolic().symbols(cls)

    @classmethod
    def symbolic_model(cls) -> dict:
        """Sympy expressions: ``legs`` (leg vectors), ``A``, ``B`` (matrices), ``points`` (world B_i),
        ``det`` and ``R`` where the kind has them."""
        return models.symbolic().model(cls)

    # ----- exact data ------------------------------------------------------
    def geometry_texts(self) -> list[str]:
        """The geometry parameters, as exact texts, in ``symbols()[1]`` order."""
        return [c for p in self.base for c in p] + [c for p in self.platform for c in p]

    @cached_property
    def parameters(self) -> list[Interval]:
        out = []
        for name, points in (("base", self.base), ("platform", self.platform)):
            for i, point in enumerate(points):
                try:
                    out += [Interval(t) for t in point]
                except (ValueError, TypeError) as exc:   # (a robot changed after it was read: its points unchecked)
                    raise InputError("robot", f"{name}[{i}]", f"{exc}: a robot's points are exact decimals (change "
                                                             "the robot file and read it again)") from None
        return out

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
        """The compiled interval evaluator of ``what``: det, A, legs_sq, R, points, leg_vectors
        (``robots.models``: compiled once, then kept on disk)."""
        return models.compiled(cls, what)

    @classmethod
    def model_parts(cls) -> frozenset:
        """The names of the parts of the symbolic model (``symbolic_model()``'s keys), without sympy
        when they are on disk (``robots.models``)."""
        return models.parts(cls)

    @classmethod
    def rigid_legs(cls) -> bool:
        """Whether the model's leg vectors are l_i = C + R b_i − a_i (checked symbolically once)."""
        return models.rigid_legs(cls)

    def _box(self, boxes) -> Interval:
        b = boxes if isinstance(boxes, Interval) else Interval(np.asarray(boxes, dtype=np.float64))
        if b.shape[-1] != len(self.pose_names):
            raise ValueError(f"{self.kind} poses have {len(self.pose_names)} coordinates {self.pose_names}")
        return b

    def det_enclosure(self, boxes) -> Interval:
        """Enclosure of det(A) over each box of a batch (..., d) -> (...)."""
        b = self._box(boxes)
        if self.symbolic_det:
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
        if self.symbolic_det:
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

    # ----- float helpers (not rigorous: for guesses, sampling and input checks) ------------
    @cached_property
    def float_geometry(self) -> tuple[np.ndarray, np.ndarray]:
        """(base, platform) points as floats (n_legs, dim): the nearest floats of the exact decimals."""
        return (np.array([[float(Fraction(c)) for c in p] for p in self.base]),
                np.array([[float(Fraction(c)) for c in p] for p in self.platform]))

    def rotation_float(self, pose) -> np.ndarray:
        """The platform rotation at float poses (..., d) -> (..., dim, dim) (not certified)."""
        raise NotImplementedError

    def leg_vectors_float(self, pose) -> np.ndarray:
        """Leg vectors l_i = B_i − A_i at float poses (..., d) -> (..., n, dim) (not certified)."""
        raise NotImplementedError

    def leg_lengths_float(self, pose) -> np.ndarray:
        """Leg lengths at float poses (..., d) -> (..., n) by plain float arithmetic (not certified)."""
        legs = self.leg_vectors_float(np.asarray(pose, dtype=np.float64))
        return np.sqrt(np.sum(legs * legs, axis=-1))

    def jacobian_float(self, pose) -> np.ndarray:
        """The matrix A at float poses (..., d) -> (..., n, d) (not certified)."""
        raise NotImplementedError

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
