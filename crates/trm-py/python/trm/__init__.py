"""trm from Python: task-relevant roadmaps for high-DOF robots.

NumPy arrays in and out, batch-first: a configuration is an ``(n,)`` array, a batch
``(N, n)``, and results gain the leading ``N`` axis. Long calls (``Problem.solve``,
``Roadmap.build``, ``Planner.plan``, batched kinematics and collision) release the GIL. Errors
are :class:`TrmError` (a ``ValueError``) with trm's located messages: file, place, fix.

>>> import trm
>>> robot = trm.Robot.icub()
>>> robot.fk(robot.posture("home")).shape[1:]
(4, 4)
"""

from ._trm import (
    ALGORITHMS,
    CollisionModel,
    Optimizer,
    Planner,
    Problem,
    Roadmap,
    Robot,
    TaskMap,
    TrmError,
    World,
    __version__,
    benchmark_mbm,
    compare_optimisers,
    fit_proxies,
    generate_mbm,
    minimize_constrained,
    reach_grasp,
    run_scenario,
    stand_up,
    view,
)

__all__ = [
    "__version__",
    "ALGORITHMS",
    "CollisionModel",
    "Optimizer",
    "Planner",
    "Problem",
    "Roadmap",
    "Robot",
    "TaskMap",
    "TrmError",
    "World",
    "benchmark_mbm",
    "compare_optimisers",
    "fit_proxies",
    "generate_mbm",
    "minimize",
    "minimize_constrained",
    "reach_grasp",
    "run_scenario",
    "stand_up",
    "view",
]


def minimize(fun, x0, sigma, algo="xnes", seed=0, max_evals=10_000, batch=False):
    """Minimises ``fun`` from ``x0`` (step ``sigma``) with a trm-optim algorithm.

    ``fun`` takes one point ``(d,)`` and returns a float or, with ``batch=True``, takes the
    whole population ``(λ, d)`` and returns ``(λ,)`` values. Returns ``(best_x, best_f,
    evaluations)``.
    """
    import numpy as np

    opt = Optimizer(algo, x0, sigma, seed=seed, max_evals=max_evals)
    while not opt.done:
        xs = opt.ask()
        if batch:
            values = np.asarray(fun(xs), dtype=float)
        else:
            values = np.array([fun(x) for x in xs], dtype=float)
        opt.tell(values)
    return opt.best_x, opt.best_f, opt.evaluations
