"""A roadmap of the iCub's reach, repaired for a world with a box in it, then run through a
scenario where objects move and goals change (repairs bounded by evaluations: reproducible).

    python crates/trm-py/examples/maps_in_a_changing_world.py
"""

from pathlib import Path

import trm

ROOT = Path(__file__).resolve().parents[3]

roadmap = trm.Roadmap.build(str(ROOT / "specs" / "reach.ron"), points=60, seed=0)
print("built:", {k: roadmap.info()[k] for k in ("points", "edges", "components")})

box = trm.World.load(str(ROOT / "specs" / "worlds" / "reach_with_box.ron"))
repaired, report = roadmap.repair(box)
print(
    f"repaired for a box: {report['blocked_nodes']} nodes blocked, "
    f"{report['added_nodes']} grown ({report['stopped_because']}); {len(repaired)} points"
)

run = trm.run_scenario(str(ROOT / "specs" / "scenarios" / "sliding_box.ron"), roadmap, repair_evaluations=500)
actions = [s["action"] if isinstance(s["action"], str) else next(iter(s["action"])) for s in run["steps"]]
print(f"scenario: {len(run['steps'])} steps, " + ", ".join(f"{a} {actions.count(a)}" for a in sorted(set(actions))))
