"""Self-contained HTML reports a reviewer can file, one module per capability (``page``: the
common layout: verdict first, robot table and drawing, question and assumptions, evidence, figures,
certificate with its SHA-256 and re-check command, version and date)."""
from .batch import batch_report
from .fk import fk_report
from .plan import plan_report
from .singularity import singularity_report
from .trajectory import trajectory_report
from .workspace import workspace_report

__all__ = ["batch_report", "fk_report", "plan_report", "singularity_report", "trajectory_report",
           "workspace_report"]
