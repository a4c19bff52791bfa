"""NGIK with a cost written in Python: the right palm reaches above the cup (specs/reach_point.ron)
while a NumPy term keeps the elbow away from the torso.

    python crates/trm-py/examples/ngik_with_a_python_cost.py
"""

from pathlib import Path

import numpy as np

import trm

ROOT = Path(__file__).resolve().parents[3]

problem = trm.Problem.load(str(ROOT / "specs" / "reach_point.ron"))


def elbow_out(q, frames):
    """Squared shortfall of the elbow's distance from the body's mid-plane (y = 0) below 20 cm."""
    y = frames["r_elbow_1"][:, 1, 3]
    return np.maximum(0.0, 0.2 - np.abs(y)) ** 2


problem.add_cost(elbow_out, weight=20.0, label="elbow out", frames=["r_elbow_1"])
solution = problem.solve(seed=1, max_evals=4000)
print(f"cost {solution['cost']:.4f} after {solution['evaluations']} evaluations")
for label, weight, value in solution["breakdown"]:
    print(f"  {label:<40} {weight:>6.2f} × {value:.5f}")
assert solution["breakdown"][-1][0] == "elbow out"
