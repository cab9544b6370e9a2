"""certkin: certified answers about parallel robots.

The path of data: ``robots`` (models, robot files, user values) -> the
capabilities (``singularity``, ``fk``, ``trajectory``, ``workspace``), each
deciding boxes with the one branch-and-bound ``engine`` -> result objects ->
``certificates`` -> the independent checker ``proofs``; ``report`` and
``plots`` present results, and ``cli`` is the command line
(``docs/architecture.md``).

The capabilities are imported on first use (``certkin.forward_kinematics``
loads ``certkin.fk``, and so on), so a process pays only for what it runs.
"""
import importlib


from .allocator import keep_freed_memory
from .engine import Budget
from .errors import InputError, RobotFileError
from .robots import load_robot, robot_from_dict

__version__ = "0.1.0"

_CAPABILITIES = {"certify_singularity_free": "certkin.singularity",
                 "forward_kinematics": "certkin.fk", "track_sequence": "certkin.fk",
                 "verify_trajectory": "certkin.trajectory", "verify_trajectories": "certkin.trajectory",
                 "plan": "certkin.trajectory"}

__all__ = ["Budget", "InputError", "keep_freed_memory", "RobotFileError", "load_robot", "robot_from_dict", *_CAPABILITIES, "__version__"]


def __getattr__(name):
    """The public functions of the capabilities, each module imported when first asked for."""
    if name not in _CAPABILITIES:
        raise AttributeError(f"module 'certkin' has no attribute {name!r}")
    value = getattr(importlib.import_module(_CAPABILITIES[name]), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
