"""trm's roadmap planner side by side with OMPL's RRTConnect and PRM on the 41-DOF iCub.

The 16 reach queries of trm's `plan` bench (benches/benches/plan.rs): from the spec's start to
every 97th node of a 400-point map of specs/reach.ron (seed 0), given to every planner as that
node's posture. trm plans through its map; OMPL plans in the same active joint space with trm's
collision check (self and world) as its state-validity checker, edges checked at trm's
0.05 rad step, and its standard path simplification. PRM keeps its roadmap from query to query (it is a multi-query planner, as trm's
map is). Prints a table: success rate, median and 95th-percentile time per query, joint-space
path length, clearance (smallest distance to collision along the path, sampled every 0.05 rad).

With `--world W.ron` (e.g. specs/worlds/reach_with_box.ron, the map's table plus a box it
never saw) every planner checks that world instead: trm re-checks its map lazily, OMPL plans
from scratch; queries whose goal posture collides there are left out for all planners.

Run (release wheel installed, README "trm from Python"; `python3 -m pip install ompl`):
    python3 benches/python/ompl_compare.py [--world W.ron] [--time-limit 5] [--points 400]
"""

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

import trm

ROOT = Path(__file__).resolve().parents[2]
SPEC = str(ROOT / "specs" / "reach.ron")
STEP = 0.05


def path_length(path):
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def clearance(problem, path, world):
    """Smallest clearance along the path, sampled every STEP radians."""
    worst = np.inf
    for a, b in zip(path[:-1], path[1:]):
        n = max(1, int(np.ceil(np.abs(b - a).max() / STEP)))
        for u in np.linspace(0.0, 1.0, n + 1):
            worst = min(worst, problem.clearance(a + u * (b - a), world))
    return worst


def trm_queries(problem, roadmap, postures, active, world):
    planner = trm.Planner(roadmap, world)
    out = []
    for goal in postures:
        started = time.perf_counter()
        try:
            plan = planner.plan(goal, posture=True)
        except trm.TrmError:
            out.append((False, time.perf_counter() - started, None))
            continue
        out.append((True, time.perf_counter() - started, plan["positions"][:, active]))
    return out


def ompl_queries(problem, start, postures, kind, time_limit, world):
    from ompl import base as ob
    from ompl import geometric as og

    lower, upper = problem.bounds
    d = len(lower)
    space = ob.RealVectorStateSpace(d)
    bounds = ob.RealVectorBounds(d)
    for i in range(d):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    si = setup.getSpaceInformation()

    class Valid(ob.StateValidityChecker):
        calls = 0
        seconds = 0.0

        def isValid(self, state):
            started = time.perf_counter()
            free = bool(problem.is_collision_free(np.array([state[i] for i in range(d)]), world))
            Valid.calls += 1
            Valid.seconds += time.perf_counter() - started
            return free

    checker = Valid(si)
    setup.setStateValidityChecker(checker)
    si.setStateValidityCheckingResolution(STEP / space.getMaximumExtent())
    planner = og.RRTConnect(si) if kind == "RRTConnect" else og.PRM(si)
    setup.setPlanner(planner)
    out = []
    for goal in postures:
        a, b = space.allocState(), space.allocState()
        for i in range(d):
            a[i], b[i] = float(start[i]), float(goal[i])
        if kind == "PRM":
            planner.clearQuery()  # keep the roadmap, forget the last start and goal
        else:
            setup.clear()
        setup.setStartAndGoalStates(a, b)
        started = time.perf_counter()
        status = setup.solve(time_limit)
        solved = setup.haveExactSolutionPath()
        if solved:
            setup.simplifySolution()
        elapsed = time.perf_counter() - started
        if not solved:
            out.append((False, elapsed, None))
            continue
        p = setup.getSolutionPath()
        path = np.array([[p.getState(k)[i] for i in range(d)] for k in range(p.getStateCount())])
        out.append((True, elapsed, path))
    per_query = Valid.calls / max(1, len(postures))
    print(
        f"OMPL {kind}: {per_query:.0f} state checks per query, "
        f"{Valid.seconds / max(1, Valid.calls) * 1e6:.1f} µs each through the Python callback"
    )
    return out


def row(name, problem, results, world):
    ok = [r for r in results if r[0]]
    times = np.array([r[1] for r in results]) * 1e3
    lengths = [path_length(r[2]) for r in ok]
    clear = [clearance(problem, r[2], world) for r in ok]
    med = lambda v: f"{np.median(v):.3f}" if len(v) else "—"  # noqa: E731
    return (
        f"| {name} | {len(ok)}/{len(results)} | {np.median(times):.1f} | {np.percentile(times, 95):.1f} "
        f"| {med(lengths)} | {med(clear)} |"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time-limit", type=float, default=5.0, help="OMPL's limit per query, s")
    parser.add_argument("--points", type=int, default=400, help="points of trm's map")
    parser.add_argument("--world", help="a world (RON) to plan in instead of the map's")
    args = parser.parse_args()
    world = trm.World.load(args.world) if args.world else None
    problem = trm.Problem.load(SPEC)
    started = time.perf_counter()
    roadmap = trm.Roadmap.build(SPEC, points=args.points, seed=0)
    built = time.perf_counter() - started
    motors = problem.robot.motor_names
    active = [motors.index(n) for n in problem.active_names]
    n = len(roadmap)
    nodes = [(k * 97) % n for k in range(16)]
    nodes = [i for i in nodes if problem.is_collision_free(roadmap.postures[i], world)]
    postures = roadmap.postures[nodes]
    start = problem.start
    print(
        f"iCub, {len(active)} active motors, {len(nodes)} queries (of 16) in "
        f"{args.world or 'the map world'}; trm map: {n} points, "
        f"{roadmap.info()['edges']} edges, built in {built:.1f} s (once, before the queries)"
    )
    lines = [
        "| planner | solved | median ms/query | p95 ms/query | median path length (rad) | median clearance (m) |",
        "|---|---|---|---|---|---|",
        row(
            "trm roadmap (A* + shortcuts)",
            problem,
            trm_queries(problem, roadmap, postures, active, world),
            world,
        ),
    ]
    for kind in ["RRTConnect", "PRM"]:
        results = ompl_queries(problem, start, postures, kind, args.time_limit, world)
        lines.append(row(f"OMPL {kind}", problem, results, world))
    print("\n".join(lines))
    sys.stdout.flush()
    # nanobind reports OMPL's binding objects still alive at exit; nothing to act on here
    os._exit(0)


if __name__ == "__main__":
    main()
