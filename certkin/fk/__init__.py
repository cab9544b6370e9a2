"""Forward kinematics: every real assembly mode for given leg lengths, each proved unique.

The path of a query, one module each:

- ``system``: the equations of every robot kind (platform origin and rotation unknowns), with
  ``rotation`` (enclosures of R b_i) and ``stacked`` (the same enclosures in fewer operations);
- ``contract``: the forward-backward (HC4) contraction, with ``kernels`` (its machine-code twin
  and the other hot loops);
- ``step``: Krawczyk, slope and Hansen-Sengupta steps, the position sweep, the root enclosure;
- ``search``: the branch-and-bound problem that decides boxes with those steps;
- ``tracking``: the posture near a previous one, proved directly (it reports what it could not
  prove);
- ``api``: ``forward_kinematics`` and ``track_sequence``: tracking first, the search on the rest;
- ``result``: ``FKResult``, which ``certkin.certificates`` writes.
"""
from .api import forward_kinematics, track_sequence
from .result import FKResult
from .system import FKSystem, fk_system

__all__ = ["forward_kinematics", "track_sequence", "FKResult", "FKSystem", "fk_system"]
