"""Pictures of certified results (the ``plot`` extra: matplotlib, imported where a figure is drawn).

One module per capability: ``singularity`` (cells), ``workspace`` (pavings and arcs, volume
slabs), ``trajectory`` (margins along a path); ``figure`` gets matplotlib.
"""
from .singularity import plot_cells
from .trajectory import plot_margins
from .workspace import plot_section, plot_volume

__all__ = ["plot_cells", "plot_margins", "plot_section", "plot_volume"]
