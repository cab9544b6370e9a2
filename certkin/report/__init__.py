"""Self-contained HTML reports for a certification file, one module per capability.

One page per run (``page``): the robot (exact data), the question, the verdict and its evidence
summary, and a picture when matplotlib is available (embedded as a data URI, so the file stands
alone).
"""
from .fk import fk_report
from .plan import plan_report
from .singularity import singularity_report
from .trajectory import trajectory_report
from .workspace import workspace_report

__all__ = ["singularity_report", "fk_report", "trajectory_report", "plan_report", "workspace_report"]
