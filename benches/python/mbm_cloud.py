"""MotionBenchMaker as point clouds through Python's door, as a user with a depth camera plans:
one `trm.Planner` for the robot; per problem its scene loaded (the allowed-collision matrix),
then the world replaced by the problem's cloud given as a NumPy array (`World.add_points`,
`Planner.set_world`) and its request planned (`plan_request`). The clouds are the very points
`trm benchmark-mbm SET --cloud 10000` planned among (its `peer-problems.txt`), so the table
compares with that run's `results.csv` problem by problem: solved counts, the planner's median
and p95 time, the median wall time of the Python call, and the cloud's build as Python pays it
(`add_points` + `set_world`: the exact object and the screen's grid).

Run (the wheel installed: `python3 -m maturin build --release -m crates/trm-py/Cargo.toml`
and `pip install` the wheel it writes):
    trm benchmark-mbm benches/mbm/panda_problems.tar.bz2 \\
        --model models/panda-mbm/panda_spherized.ron --cloud 10000 --out-dir /tmp/clouds
    python3 benches/python/mbm_cloud.py benches/mbm/panda_problems.tar.bz2 \\
        /tmp/clouds/peer-problems.txt --model models/panda-mbm/panda_spherized.ron \\
        --benchmark /tmp/clouds/results.csv
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np
import trm

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mbm_planner import quantile  # noqa: E402
from mbm_set import by_family, problems, unpacked  # noqa: E402


def clouds(path):
    """{(family, index): (points (N, 3), radius)} of a `peer-problems.txt` whose every problem
    holds one cloud (what `benchmark-mbm --cloud` writes)."""
    out = {}
    with open(path) as f:
        lines = f.read().splitlines()
    i, key = 0, None
    while i < len(lines):
        words = lines[i].split()
        i += 1
        if not words:
            continue
        if words[0] == "problem":
            key = (words[1], int(words[2]))
        elif words[0] == "cloud":
            n, radius = int(words[1]), float(words[2])
            block = " ".join(lines[i:i + n])
            points = np.array(block.split(), dtype=np.float64).reshape(n, 3)
            out[key] = (points, radius)
            i += n
        elif words[0] in ("box", "sphere", "cylinder", "capsule"):
            sys.exit(f"{path}:{i}: a {words[0]}: give the peer file of a --cloud run")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("set", type=Path)
    ap.add_argument("peer_problems", type=Path)
    ap.add_argument("--model", required=True)
    ap.add_argument("--benchmark", type=Path, help="the --cloud run's results.csv, to compare")
    ap.add_argument("--per-family", type=int)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-samples", type=int, default=1_000_000)
    args = ap.parse_args()

    root = unpacked(args.set)
    by_problem = clouds(args.peer_problems)
    robot = trm.Robot.load(args.model)
    all_problems = list(problems(root))
    planner = trm.Planner(robot, request=str(all_problems[0][3]))

    rows, counts = [], {}
    for family, number, scene, request in all_problems:
        seen = counts.setdefault(family, 0)
        if args.per_family is not None and seen >= args.per_family:
            continue
        counts[family] = seen + 1
        if (family, number) not in by_problem:
            sys.exit(f"{args.peer_problems}: no cloud for {family} {number}")
        points, radius = by_problem[(family, number)]
        read = trm.MotionPlanRequest.load(str(request))
        planner.load_scene(str(scene))
        t0 = time.perf_counter()
        world = trm.World()
        world.add_points("scene", points, radius)
        planner.world = world
        t1 = time.perf_counter()
        row = {"family": family, "problem": number, "valid": True, "solved": False,
               "build": t1 - t0}
        try:
            r = planner.plan_request(read, seed=args.seed, max_samples=args.max_samples)
            row.update(solved=True, seconds=r["seconds"], length=r["length"])
        except trm.TrmError as e:
            message = str(e)
            row["valid"] = "collides" not in message and "outside its limits" not in message
        row["call"] = time.perf_counter() - t1
        rows.append(row)

    bench = {}
    if args.benchmark:
        with open(args.benchmark) as f:
            for r in csv.DictReader(f):
                bench[(r["family"], int(r["problem"]))] = r
    print("| family | valid | solved | median ms | p95 ms | median call ms | median build ms "
          "| median length (rad) | benchmark solved | benchmark median ms | same length |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    med = lambda v: quantile(v, 0.5)  # noqa: E731
    for family, sel, valid, solved in by_family(rows):
        ms = [1e3 * r["seconds"] for r in solved]
        call = [1e3 * r["call"] for r in solved]
        build = [1e3 * r["build"] for r in sel]
        length = [r["length"] for r in solved]
        ours = [bench.get((r["family"], r["problem"])) for r in sel]
        b_solved = [b for b in ours if b and b["solved"] == "true"]
        b_ms = [1e3 * float(b["seconds"]) for b in b_solved]
        same = sum(
            1 for r in solved
            if (b := bench.get((r["family"], r["problem"]))) and b["solved"] == "true"
            and abs(float(b["length"]) - r["length"]) < 1e-3
        )
        print(f"| {family} | {len(valid)}/{len(sel)} | {len(solved)}/{len(valid)} | "
              f"{med(ms):.2f} | {quantile(ms, 0.95):.2f} | {med(call):.2f} | {med(build):.2f} | "
              f"{med(length):.2f} | {len(b_solved) if bench else '—'} | "
              f"{med(b_ms):.2f} | {same}/{len(solved)} |")


if __name__ == "__main__":
    main()
