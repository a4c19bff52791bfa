"""Task maps of grasps on an object, explored and used as a cost; reaching motions toward them
(trm-taskmap)."""

from ._trm import TaskMap, reach_grasp

__all__ = ["TaskMap", "reach_grasp"]
