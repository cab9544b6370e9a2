"""certkin: certified answers about parallel robots.

The path of data: ``robots`` (model, equations) -> ``engine`` (branch and
bound over boxes) -> the solvers (``singularity``, ``fk``, ``trajectory``)
-> result objects -> ``certificates`` -> the independent checker ``proofs``.
"""
from .errors import InputError, RobotFileError
from .robots import load_robot, robot_from_dict
from .singularity import certify_singularity_free
from .fk import forward_kinematics, track_sequence
from .trajectory import verify_trajectory, verify_trajectories
from .planning import plan

__version__ = "0.1.0"

__all__ = ["InputError", "RobotFileError", "load_robot", "robot_from_dict", "certify_singularity_free",
           "forward_kinematics", "track_sequence", "verify_trajectory", "verify_trajectories", "plan", "__version__"]
