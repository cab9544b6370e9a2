"""Constant-orientation workspace (seed 004): certified sections and volumes.

- ``annuli``: the leg annuli of one orientation and the domain of a section;
- ``paving``: the engine's paving of a section or of z-slabs (area brackets);
- ``boundary``: the exact boundary (arcs, area, perimeter);
- ``section``: ``workspace_section``; ``volume``: ``workspace_volume``.

Results hold data (``to_json()``, ``certificate()``, checked by ``proofs.workspace``); their
pictures are drawn by ``certkin.plots``.  The soundness argument is in ``docs/soundness.md``.
"""
from .annuli import Legs, leg_data, section_domain
from .boundary import Boundary, exact_boundary
from .paving import Paving
from .section import SectionResult, workspace_section
from .volume import VolumeResult, workspace_volume

__all__ = ["workspace_section", "workspace_volume", "SectionResult", "VolumeResult", "section_domain",
           "exact_boundary", "Boundary", "Paving", "Legs", "leg_data"]
