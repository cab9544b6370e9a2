"""The constraint families of a trajectory, one module each, behind one protocol (``base``).

``FAMILIES`` is their order: the columns of a trajectory's margins and states follow it.
"""
from .determinant import Determinant
from .interference import Interference
from .joints import Joints
from .legs import LegLengths

FAMILIES = (LegLengths, Joints, Interference, Determinant)

__all__ = ["FAMILIES", "LegLengths", "Joints", "Interference", "Determinant"]
