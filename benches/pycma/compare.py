"""Evaluations pycma's CMA-ES needs to reach f <= 1e-8 on trm's test functions.

Same functions, starts (1,...,1; Rosenbrock 0,...,0), sigma0 = 0.5 and default population as
`cargo xtask optimise --algo cmaes`. Writes benches/pycma/reference.json, which the trm-optim
test `cmaes_matches_pycma_median_evaluations` reads. Run:

    python3 -m venv /tmp/cmaenv && /tmp/cmaenv/bin/pip install cma==4.5.0 numpy
    /tmp/cmaenv/bin/python benches/pycma/compare.py
"""

import json
import os
import statistics
import warnings

warnings.filterwarnings("ignore")
import cma  # noqa: E402
import numpy as np  # noqa: E402

RUNS = 21
DIM = 10
TARGET = 1e-8


def ellipsoid(x):
    d = len(x)
    return sum(10 ** (6 * i / (d - 1)) * x[i] ** 2 for i in range(d))


FUNCTIONS = {
    "sphere": (lambda x: float(np.sum(np.asarray(x) ** 2)), 1.0),
    "ellipsoid": (ellipsoid, 1.0),
    "cigar": (lambda x: x[0] ** 2 + 1e6 * sum(v * v for v in x[1:]), 1.0),
    "discus": (lambda x: 1e6 * x[0] ** 2 + sum(v * v for v in x[1:]), 1.0),
    "rosenbrock": (
        lambda x: sum(100 * (x[i + 1] - x[i] ** 2) ** 2 + (1 - x[i]) ** 2 for i in range(len(x) - 1)),
        0.0,
    ),
}


def run(f, x0, seed):
    es = cma.CMAEvolutionStrategy(
        [x0] * DIM,
        0.5,
        {"ftarget": TARGET, "seed": seed, "verbose": -9, "maxfevals": 200000, "tolflatfitness": 10**9},
    )
    while not es.stop():
        xs = es.ask()
        es.tell(xs, [f(x) for x in xs])
    return es.countevals if es.best.f <= TARGET else None


def main():
    out = {"cma_version": cma.__version__, "dim": DIM, "runs": RUNS, "target": TARGET, "functions": {}}
    for name, (f, x0) in FUNCTIONS.items():
        evals = [run(f, x0, seed) for seed in range(1, RUNS + 1)]
        ok = sorted(e for e in evals if e is not None)
        out["functions"][name] = {
            "successes": len(ok),
            "median_evaluations": statistics.median(ok) if ok else None,
            "evaluations": evals,
        }
        print(f"{name:12} successes {len(ok)}/{RUNS} median {out['functions'][name]['median_evaluations']}")
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "reference.json")
    with open(path, "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")


if __name__ == "__main__":
    main()
