"""The protocol of a constraint family, and what every family shares.

A family is one kind of constraint of one robot (``leg-length``, ``joints``, ``interference``,
``singularity``), with one column per instance (a leg, a joint facet or cone, a pair of legs,
det(A)).  ``Constraints`` (``trajectory.constraints``) selects the families, gives each its
columns (``columns``), and asks each, over a batch of t-intervals, for its margins and states.
A family has

- ``constraint``: its name; ``missing(robot)``: why the robot's file does not allow it (None
  when it does); ``build(robot, base)``: the family of a robot; ``instances``: one ``Instance``
  per column;
- ``uses_lengths``: its margins need the leg lengths ρ over the intervals;
- ``key`` and ``functions(pose)``: the name of its functions of the pose (``trajectory.pose``) in
  a path evaluator and those functions (None: it has none); ``polynomials(...)``: the same as
  polynomials in t (``PolyPath``);
- ``margins(path, rho, upper)``: (lo, hi, state) arrays (N, its columns) over the intervals of the
  path evaluator ``path`` (``trajectory.evaluate``); a state is ``SATISFIED`` or ``VIOLATED``
  (proved on the whole interval) or ``UNKNOWN``;
- ``crossings(polys, put)``: per column, polynomials whose sign changes mark where the state may
  change (candidates 0 and 1) or where the margin has an extremum (candidate 2), from the
  family's polynomials: hints for cutting intervals, never proofs;
- ``sign_only``: its margin is a sign to keep along the path (det(A)), not a margin to refine.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SATISFIED, VIOLATED, UNKNOWN = 1, -1, 0


@dataclass(frozen=True)
class Instance:
    """One scalar constraint: its kind, the legs it concerns and a short detail."""

    constraint: str
    legs: tuple
    detail: str = ""

    def to_json(self) -> dict:
        d = {"constraint": self.constraint, "legs": list(self.legs)}
        if self.detail:
            d["detail"] = self.detail
        return d


def states(lo, hi):
    """SATISFIED where the margin's lower bound is ≥ 0, VIOLATED where its upper bound is < 0."""
    return np.where(lo >= 0, SATISFIED, np.where(hi < 0, VIOLATED, UNKNOWN)).astype(np.int8)


def cached(robot, key, build):
    """Per-robot data derived from its geometry and limits, built once per value of the limits
    (the geometry does not change after loading; the limits are a plain dict a caller may edit)."""
    cache = robot.__dict__.setdefault("_trajectory_cache", {})
    key = (key, repr(robot.limits))
    if key not in cache:
        cache[key] = build()
    return cache[key]


class Family:
    """The defaults of the protocol (see the module docstring)."""

    constraint = ""
    key: str | None = None
    uses_lengths = False
    sign_only = False
    columns = slice(0, 0)

    @staticmethod
    def missing(robot) -> str | None:
        return None

    @staticmethod
    def partial(robot) -> str | None:
        """What of the family the robot file gives no limits for, when it is checked only in part."""
        return None

    @classmethod
    def build(cls, robot, base):
        """The family of ``robot`` (``base``: the base points A_i as three (n,) enclosures)."""
        return cls(robot)

    def functions(self, pose):
        return None

    def polynomials(self, pose, linear=None, P0=None, var=None):
        """The functions as polynomials in t on the rows of ``pose`` (polynomial leg vectors); a
        family whose functions are not of the leg vectors alone uses ``linear`` and ``P0``
        (constant orientation) or ``var`` (the pose coordinates as polynomials)."""
        return self.functions(pose)

    def margins(self, path, rho, upper):
        raise NotImplementedError

    def crossings(self, polys, put):
        pass
