"""Black-box optimisers (xNES, CMA-ES, (1+1)-CMA-ES with constraints, SIR, Nelder-Mead…) and the
Table III comparison (trm-optim)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

from ._trm import ALGORITHMS, Optimizer, TrmError, compare_optimisers, minimize_constrained

__all__ = ["ALGORITHMS", "Optimizer", "compare_optimisers", "minimize", "minimize_constrained"]


if TYPE_CHECKING:
    import numpy.typing as npt

    from ._trm import Array


def minimize(
    fun: Callable[[Array], float] | Callable[[Array], npt.ArrayLike],
    x0: npt.ArrayLike,
    sigma: float,
    algo: str = "xnes",
    seed: int = 0,
    max_evals: int = 10_000,
    batch: bool = False,
) -> tuple[Array, float, int]:
    """Minimises ``fun`` from ``x0`` (step ``sigma``) with a trm-optim algorithm.

    ``fun`` takes one point ``(d,)`` and returns a float or, with ``batch=True``, takes the
    whole population ``(λ, d)`` and returns ``(λ,)`` values (``inf`` for a point that cannot
    be evaluated; NaN is an error naming the point). Returns ``(best_x, best_f, evaluations)``.
    """
    import numpy as np

    opt = Optimizer(algo, x0, sigma, seed=seed, max_evals=max_evals)
    while not opt.done:
        xs = opt.ask()
        if batch:
            values = np.asarray(fun(xs), dtype=float)
        else:
            values = np.array([fun(x) for x in xs], dtype=float)
        bad = np.flatnonzero(np.isnan(values) | (values == -np.inf))
        if bad.size:
            i = int(bad[0])
            raise TrmError(
                f"fun returned {values[i]} at x = {xs[i].tolist()} (evaluation {opt.evaluations + i + 1}): "
                "return a number, or inf for a point that cannot be evaluated"
            )
        opt.tell(values)
    return opt.best_x, opt.best_f, opt.evaluations
