"""The verdict of the checker, and the exception that names a failing step."""
from __future__ import annotations

from dataclasses import dataclass, field


class Rejected(Exception):
    """Raised with the name of the first step that does not re-verify."""

    def __init__(self, step: str):
        super().__init__(step)
        self.step = step


@dataclass
class Report:
    """``ok``; ``step`` names the first failing step ("" when ok); ``checked`` counts what was re-verified.

    ``checked`` keys: ``claims`` (all claims), ``undecided`` (claims that claim
    nothing), ``leaves`` (tree leaves re-proved), ``solutions`` and
    ``contractions`` (forward kinematics), ``pieces`` (sub-boxes the
    checker cut leaves into when its own enclosure did not decide a whole
    leaf), ``witnesses`` (witness pairs re-proved).
    """

    ok: bool
    step: str = ""
    checked: dict = field(default_factory=dict)

    def __bool__(self) -> bool:
        return self.ok

    def summary(self) -> str:
        """The step when rejected, else what was re-verified (no "OK:" prefix)."""
        if not self.ok:
            return self.step
        c = self.checked
        text = f"{c.get('claims', 0)} claims, {c.get('leaves', 0)} leaves re-verified"
        if c.get("solutions"):
            text += f", {c['solutions']} solutions proved unique"
        if c.get("witnesses"):
            text += f", {c['witnesses']} witness pairs"
        if c.get("undecided"):
            text += f", {c['undecided']} undecided (nothing claimed)"
        return text

    def __str__(self) -> str:
        return ("OK: " if self.ok else "REJECTED: ") + self.summary()
