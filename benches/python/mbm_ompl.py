"""OMPL's RRTConnect on MotionBenchMaker problems, for the side-by-side table of
`cargo xtask benchmark-mbm`: the same scenes, requests and robot (models/panda-mbm: URDF,
collision meshes, the SRDF's disabled pairs), collision checked by coal through Pinocchio (an
independent implementation of meshes and primitives), edges checked at the same 1/32 rad step,
OMPL's standard simplification. Prints the same per-family table: valid, solved, median and
p95 time (ms), median path length (rad).

OMPL runs through its Python bindings, so every state check crosses into Python: its times
include that overhead (state it when quoting them).

Run (PyPI: `python3 -m pip install ompl pin pyyaml numpy`):
    python3 benches/python/mbm_ompl.py SET_DIR [--per-family N] [--time-limit 10] [--seed 0]
where SET_DIR holds one folder per family (unpack benches/mbm/panda_problems.tar.bz2).
"""

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import coal
import yaml
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

ROOT = Path(__file__).resolve().parents[2]
MODEL = ROOT / "models" / "panda-mbm"
RESOLUTION = 1.0 / 32.0


def vec(v, keys):
    return [float(v[k]) for k in keys] if isinstance(v, dict) else [float(x) for x in v]


def pose(p):
    t = vec(p.get("position", [0, 0, 0]), "xyz")
    q = vec(p.get("orientation", [0, 0, 0, 1]), "xyzw")
    quat = pin.Quaternion(q[3], q[0], q[1], q[2])
    quat.normalize()
    return pin.SE3(quat.matrix(), np.array(t))


def robot():
    model = pin.buildModelFromUrdf(str(MODEL / "panda.urdf"))
    collision = pin.buildGeomFromUrdf(
        model, str(MODEL / "panda.urdf"), pin.GeometryType.COLLISION, package_dirs=[str(MODEL)]
    )
    collision.addAllCollisionPairs()
    pin.removeCollisionPairs(model, collision, str(MODEL / "panda.srdf"))
    return model, collision


def with_scene(model, robot_geometry, scene):
    geometry = robot_geometry.copy()
    robot_ids = list(range(len(geometry.geometryObjects)))
    for o in scene["world"]["collision_objects"]:
        base = pose(o["pose"]) if "pose" in o else pin.SE3.Identity()
        for k, (prim, p) in enumerate(zip(o["primitives"], o["primitive_poses"])):
            d = [float(x) for x in prim["dimensions"]]
            kind = str(prim["type"]).lower()
            shape = {
                "box": lambda: coal.Box(d[0], d[1], d[2]),
                "sphere": lambda: coal.Sphere(d[0]),
                "cylinder": lambda: coal.Cylinder(d[1], d[0]),
            }[kind]()
            obj = pin.GeometryObject(f"{o['id']}/{k}", 0, 0, base * pose(p), shape)
            i = geometry.addGeometryObject(obj)
            for r in robot_ids:
                geometry.addCollisionPair(pin.CollisionPair(r, i))
    return geometry, geometry.createData()


def solve(model, robot_geometry, scene, request, time_limit, seed):
    geometry, gdata = with_scene(model, robot_geometry, scene)
    data = model.createData()
    names = [c["joint_name"] for c in request["goal_constraints"][0]["joint_constraints"]]
    goal = [float(c["position"]) for c in request["goal_constraints"][0]["joint_constraints"]]
    js = request["start_state"]["joint_state"]
    start_by_name = dict(zip(js["name"], js["position"]))
    start = [float(start_by_name[n]) for n in names]
    idx = [model.joints[model.getJointId(n)].idx_q for n in names]
    q = pin.neutral(model)
    checks = [0]

    def free(values):
        checks[0] += 1
        for i, v in zip(idx, values):
            q[i] = v
        return not pin.computeCollisions(model, data, geometry, gdata, q, True)

    low = [model.lowerPositionLimit[i] for i in idx]
    high = [model.upperPositionLimit[i] for i in idx]
    inside = lambda v: all(lo - 1e-9 <= x <= hi + 1e-9 for x, lo, hi in zip(v, low, high))
    if not (inside(start) and inside(goal) and free(start) and free(goal)):
        return dict(valid=False, solved=False, seconds=0.0, length=0.0)
    space = ob.RealVectorStateSpace(len(names))
    bounds = ob.RealVectorBounds(len(names))
    for k in range(len(names)):
        bounds.setLow(k, low[k])
        bounds.setHigh(k, high[k])
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    d = len(names)

    class Valid(ob.StateValidityChecker):
        def isValid(self, state):
            return free([state[k] for k in range(d)])

    checker = Valid(si)
    ss.setStateValidityChecker(checker)
    si.setStateValidityCheckingResolution(RESOLUTION / space.getMaximumExtent())
    ss.setPlanner(og.RRTConnect(si))
    s, g = space.allocState(), space.allocState()
    for k in range(d):
        s[k], g[k] = start[k], goal[k]
    ss.setStartAndGoalStates(s, g)
    started = time.perf_counter()
    solved = bool(ss.solve(time_limit)) and ss.haveExactSolutionPath()
    if solved:
        ss.simplifySolution()
    seconds = time.perf_counter() - started
    length = ss.getSolutionPath().length() if solved else 0.0
    return dict(valid=True, solved=solved, seconds=seconds, length=length)


def quantile(values, q):
    if not values:
        return None
    values = sorted(values)
    return values[max(1, math.ceil(q * len(values))) - 1]


def row(name, outcomes):
    valid = [o for o in outcomes if o["valid"]]
    solved = [o for o in valid if o["solved"]]
    times = [o["seconds"] * 1e3 for o in solved]
    fmt = lambda v: "—" if v is None else f"{v:.2f}"
    rate = 100.0 * len(solved) / max(1, len(valid))
    return (
        f"| {name} | {len(valid)}/{len(outcomes)} | {len(solved)}/{len(valid)} ({rate:.1f} %) | "
        f"{fmt(quantile(times, 0.5))} | {fmt(quantile(times, 0.95))} | "
        f"{fmt(quantile([o['length'] for o in solved], 0.5))} |"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("set", type=Path)
    parser.add_argument("--per-family", type=int, default=None)
    parser.add_argument("--time-limit", type=float, default=10.0)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if not args.set.is_dir():
        sys.exit(f"{args.set}: not a folder of family folders (unpack the .tar.bz2 first)")
    ou.setLogLevel(ou.LOG_ERROR)
    ou.RNG.setSeed(args.seed + 1)  # once: OMPL's sampler is seeded before its first use
    model, robot_geometry = robot()
    families = sorted(p for p in args.set.iterdir() if p.is_dir())
    if len(families) == 1 and not list(families[0].glob("scene*.yaml")):
        families = sorted(p for p in families[0].iterdir() if p.is_dir())
    print("OMPL RRTConnect + simplifySolution (Python bindings), coal via Pinocchio\n")
    print("| family | valid | solved | median ms | p95 ms | median length (rad) |")
    print("|---|---|---|---|---|---|")
    everything = []
    for family in families:
        scenes = sorted(family.glob("scene*.yaml"))[: args.per_family]
        outcomes = []
        for scene_path in scenes:
            request_path = family / scene_path.name.replace("scene", "request")
            scene = yaml.safe_load(scene_path.read_text())
            request = yaml.safe_load(request_path.read_text())
            outcomes.append(solve(model, robot_geometry, scene, request, args.time_limit, args.seed))
        print(row(family.name, outcomes), flush=True)
        everything += outcomes
    print(row("all", everything))


if __name__ == "__main__":
    main()
