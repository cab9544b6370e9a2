"""Typed errors for bad input.  The CLI prints ``str(error)`` and exits 2."""
from __future__ import annotations


class InputError(ValueError):
    """Bad user input: a robot file, a pose, a box, a job line.

    The message names the source (file name or option) and the field:
    ``robot.toml: limits.leg_length[2]: min 5 exceeds max 3``.
    """

    def __init__(self, source: str, field: str, problem: str):
        self.source = source
        self.field = field
        self.problem = problem
        where = f"{source}: " if source else ""
        where += f"{field}: " if field else ""
        super().__init__(where + problem)


class RobotFileError(InputError):
    """A robot file that cannot be loaded, or describes a degenerate robot."""
