"""MotionBenchMaker problems (MoveIt scenes, joint goals) solved by trm's RRT-Connect, one per
family of the Panda sample in the repository, each path re-checked.

    python crates/trm-py/examples/motionbenchmaker.py
"""

from pathlib import Path

import trm

ROOT = Path(__file__).resolve().parents[3]

result = trm.benchmark_mbm(
    str(ROOT / "crates" / "trm-mbm" / "tests" / "fixtures" / "mbm"),
    str(ROOT / "models" / "panda-mbm" / "panda.ron"),
    per_family=1,
    verify=True,
)
print(result["table"])
assert all(r["outcome"]["solved"] and r["verified"] for r in result["runs"] if r["outcome"]["valid"])
