"""The checker's verdict: ``Report`` (what was proved, or the step that failed) and ``Rejected``."""
from __future__ import annotations

from dataclasses import dataclass, field


class Rejected(Exception):
    """Raised with the name of the first step that does not re-verify."""

    def __init__(self, step: str):
        super().__init__(step)
        self.step = step


class Unreadable(ValueError):
    """The file is not a certificate at all (not JSON, not a ZIP with a JSON header): exit code 2."""


@dataclass
class Report:
    """``ok``; ``step`` names the first failing step ("" when ok); ``checked`` counts what was
    re-verified (claims, undecided, leaves, pieces, solutions, contractions, witnesses);
    ``proved`` holds one line per claim group saying what was proved; ``about`` the robot and
    the question (name, geometry SHA-256, problem)."""

    ok: bool
    step: str = ""
    checked: dict = field(default_factory=dict)
    proved: list = field(default_factory=list)
    about: dict = field(default_factory=dict)
    progress: object = field(default=None, repr=False)

    def __bool__(self) -> bool:
        return self.ok

    def summary(self) -> str:
        """The step when rejected, else what was re-verified (no "OK:" prefix)."""
        if not self.ok:
            return self.step
        c = self.checked
        return f"{(n := c.get('claims', 0))} claim{'s' * (n != 1)}, {c.get('leaves', 0)} leaves re-verified" + "".join(
            f", {c[k]} {what}" for k, what in (("solutions", "solutions proved unique"), ("witnesses", "witness pairs"),
                                               ("undecided", "undecided (nothing claimed)")) if c.get(k))

    def __str__(self) -> str:
        return ("OK: " if self.ok else "REJECTED: ") + self.summary()

    def lines(self) -> list:
        """The full account printed by ``certkin check``: robot, question, verdicts, result; any character of
        the certificate that is not printable (a newline, a terminal escape, a bidi control) escaped."""
        a = self.about
        out = [f"robot: {a.get('robot')} ({a.get('kind')}), geometry SHA-256 {a.get('geometry_sha256')}"] * (a.get("robot") is not None)
        out += [f"robot file: {a['robot_file']}: same geometry"] if a.get("robot_file") else []
        out += ([f"question: {a['question']}"] if a.get("question") else []) + [f"proved: {p}" for p in self.proved] * self.ok
        return ["".join(c if c.isprintable() else ascii(c)[1:-1] for c in line) for line in out + [str(self)]]

    def to_json(self) -> dict:
        return {"ok": self.ok, "step": self.step, "checked": self.checked, "proved": self.proved, **self.about}
