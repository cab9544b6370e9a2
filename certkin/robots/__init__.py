"""Robots: exact geometry, symbolic models, robot files and user values.

- ``base``: what every model shares (exact geometry, the compiled evaluators of det(A), leg
  lengths, platform points); ``planar``, ``spherical``, ``gough``: one module per kind;
- ``files``: ``load_robot(path)`` and ``robot_from_dict(data)`` (every field validated, errors
  name the file and the field);
- ``poses``: numbers, poses, boxes, leg lengths and orientations from user values.
"""
from .base import Robot
from .files import KINDS, as_robot, load_robot, robot_from_dict
from .gough import GoughStewart
from .planar import Planar3RPR
from .spherical import Spherical3DOF, Spherical3DOFTiltTorsion

__all__ = ["Robot", "Planar3RPR", "Spherical3DOF", "Spherical3DOFTiltTorsion", "GoughStewart", "KINDS", "as_robot", "load_robot",
           "robot_from_dict"]
