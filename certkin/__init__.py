"""certkin: certified answers about parallel robots.

The path of data: ``robots`` (models, robot files, user values) -> the
capabilities (``singularity``, ``fk``, ``trajectory``, ``workspace``), each
deciding boxes with the one branch-and-bound ``engine`` -> result objects ->
``certificates`` -> the independent checker ``proofs``; ``report`` and
``plots`` present results, and ``cli`` is the command line
(``docs/architecture.md``).
"""
from .engine import Budget
from .errors import InputError, RobotFileError
from .robots import load_robot, robot_from_dict
from .singularity import certify_singularity_free
from .fk import forward_kinematics, track_sequence
from .trajectory import plan, verify_trajectory, verify_trajectories

__version__ = "0.1.0"

__all__ = ["Budget", "InputError", "RobotFileError", "load_robot", "robot_from_dict", "certify_singularity_free",
           "forward_kinematics", "track_sequence", "verify_trajectory", "verify_trajectories", "plan", "__version__"]
