"""Pictures of certified results (matplotlib, imported where a figure is drawn).

One module per capability: ``singularity`` (cells), ``workspace`` (pavings and arcs, volume
slabs), ``trajectory`` (margins along a path, one panel per constraint family), ``robot`` (the
robot at some poses), ``batch`` (a campaign); ``figure`` gets matplotlib.
"""
from .batch import plot_campaign
from .robot import plot_robot
from .singularity import plot_cells
from .trajectory import plot_margins
from .workspace import plot_section, plot_volume

__all__ = ["plot_campaign", "plot_cells", "plot_margins", "plot_robot", "plot_section", "plot_volume"]
