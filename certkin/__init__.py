"""certkin: certified answers about parallel robots.

The path of data: ``robots`` (model, equations) -> ``engine`` (branch and
bound over boxes) -> the solvers (``singularity``, ``fk``, ``trajectory``)
-> result objects -> ``certificates`` -> the independent checker ``proofs``.
"""
from .errors import InputError, RobotFileError
from .robots import load_robot, robot_from_dict
from .singularity import certify_singularity_free

__version__ = "0.1.0"

__all__ = ["InputError", "RobotFileError", "load_robot", "robot_from_dict", "certify_singularity_free",
           "__version__"]
