"""trm from Python: task-relevant roadmaps for high-DOF robots.

NumPy arrays in and out, batch-first: a configuration is an ``(n,)`` array, a batch
``(N, n)``, and results gain the leading ``N`` axis. Long calls (``Problem.solve``,
``Roadmap.build``, ``Planner.plan``, batched kinematics and collision) release the GIL. Errors
are :class:`TrmError` (a ``ValueError``) with trm's located messages: file, place, fix.

One submodule per concept, as the Rust crates are split (``trm.kinematics``,
``trm.collision``, ``trm.tasks``, ``trm.optim``, ``trm.roadmap``, ``trm.plan``,
``trm.taskmap``, ``trm.wholebody``, ``trm.viewer``); every name is also here, at the top.

>>> import trm
>>> robot = trm.Robot.icub()
>>> robot.fk(robot.posture("home")).shape[1:]
(4, 4)
"""

from . import collision, kinematics, optim, plan, roadmap, taskmap, tasks, viewer, wholebody
from ._trm import TrmError, __version__
from .collision import CollisionModel, World, fit_proxies
from .kinematics import Robot
from .optim import ALGORITHMS, Optimizer, compare_optimisers, minimize, minimize_constrained
from .plan import MotionPlanRequest, Planner, benchmark_mbm, generate_mbm
from .roadmap import Roadmap, run_scenario
from .taskmap import TaskMap, reach_grasp
from .tasks import Problem
from .viewer import view
from .wholebody import stand_up

#: the submodules, one per concept
SUBMODULES = (kinematics, collision, tasks, optim, roadmap, plan, taskmap, wholebody, viewer)

__all__ = ["__version__", "TrmError"] + [name for m in SUBMODULES for name in m.__all__]
