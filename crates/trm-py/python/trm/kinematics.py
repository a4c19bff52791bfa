"""Robot models: URDF + model description, forward kinematics, postures (trm-kinematics)."""

from ._trm import Robot

__all__ = ["Robot"]
