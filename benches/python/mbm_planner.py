"""MotionBenchMaker problems through Python's door: one `trm.Planner` for the robot, each
problem's scene set on it (`load_scene`: world and allowed-collision matrix) and its request
planned (`plan_request`, the request read beforehand: `trm.MotionPlanRequest.load`), as a Python
user plans MoveIt queries. Prints, per family: valid, solved, the planner's median and p95 time
(what `trm benchmark-mbm` reports for the same problems and seed), and the median wall time of
the Python call for the path alone (`timed=False`, as the benchmark plans), without and with
reading the scene, and for the path timed as a robot would run it. Compare with `trm benchmark-mbm SET --model MODEL` on the same set: the same planner
object answers both, so solved counts and path lengths agree problem by problem.

Run (the wheel installed: `python3 -m maturin build --release -m crates/trm-py/Cargo.toml`
and `pip install` the wheel it writes):
    python3 benches/python/mbm_planner.py SET_DIR --model models/panda-mbm/panda_spherized.ron
where SET_DIR holds one folder per family (unpack benches/mbm/panda_problems.tar.bz2), or a
.tar.bz2 of one. `--csv FILE` writes one row per problem; `--certified` plans proved paths
(`certified=True`, as `trm benchmark-mbm --certified`).
"""

import argparse
import math
import sys
import time
from pathlib import Path

import trm

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mbm_set import by_family, problems, unpacked  # noqa: E402


def quantile(values, q):
    """The q-quantile (nearest rank), as `trm benchmark-mbm` reports it."""
    if not values:
        return float("nan")
    s = sorted(values)
    k = min(max(math.ceil(q * len(s)), 1), len(s))
    return s[k - 1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("set", type=Path)
    ap.add_argument("--model", required=True)
    ap.add_argument("--per-family", type=int)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-samples", type=int, default=1_000_000)
    ap.add_argument("--csv", type=Path)
    ap.add_argument("--certified", action="store_true")
    args = ap.parse_args()

    root = unpacked(args.set)

    robot = trm.Robot.load(args.model)
    all_problems = list(problems(root))
    if not all_problems:
        sys.exit(f"{args.set}: no family folders with sceneNNNN.yaml and requestNNNN.yaml")
    # one planner for the set: the first request's goal joints move, the other motors stay where
    # its start puts them (every later request is checked against that by plan_request)
    made = time.perf_counter()
    planner = trm.Planner(robot, request=str(all_problems[0][3]))
    made = time.perf_counter() - made

    rows = []
    counts = {}
    for family, number, scene, request in all_problems:
        seen = counts.setdefault(family, 0)
        if args.per_family is not None and seen >= args.per_family:
            continue
        counts[family] = seen + 1
        # the request read before the clock starts, as a user holding requests in memory does
        read = trm.MotionPlanRequest.load(str(request))
        t0 = time.perf_counter()
        planner.load_scene(str(scene))
        t1 = time.perf_counter()
        row = {"family": family, "problem": number, "valid": True, "solved": False}
        try:
            # the path alone, as the benchmark plans it
            r = planner.plan_request(read, seed=args.seed, max_samples=args.max_samples,
                                     certified=args.certified, timed=False)
            t2 = time.perf_counter()
            row.update(solved=True, seconds=r["seconds"], length=r["length"],
                       waypoints=len(r["waypoints"]), checks=r["checks"], note=r["source"])
            # and timed (time-optimal, sampled every 10 ms), as a robot would run it
            planner.plan_request(read, seed=args.seed, max_samples=args.max_samples,
                                 certified=args.certified)
            row["timed"] = time.perf_counter() - t2
        except trm.TrmError as e:
            t2 = time.perf_counter()
            message = str(e)
            row["valid"] = "collides" not in message and "outside its limits" not in message
            row["note"] = message.splitlines()[0]
        row["call"] = t2 - t1
        row["with_scene"] = t2 - t0
        rows.append(row)

    print(f"trm.Planner({Path(args.model).name}) made in {made * 1e3:.2f} ms")
    print("| family | valid | solved | median ms | p95 ms | median call ms | median call + scene ms "
          "| median timed call ms | median length (rad) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for family, sel, valid, solved in by_family(rows):
        ms = [1e3 * r["seconds"] for r in solved]
        call = [1e3 * r["call"] for r in solved]
        scene = [1e3 * r["with_scene"] for r in solved]
        timed = [1e3 * r["timed"] for r in solved]
        length = [r["length"] for r in solved]
        med = lambda v: quantile(v, 0.5)
        print(f"| {family} | {len(valid)}/{len(sel)} | {len(solved)}/{len(valid)} | "
              f"{med(ms):.2f} | {quantile(ms, 0.95):.2f} | {med(call):.2f} | {med(scene):.2f} | "
              f"{med(timed):.2f} | {med(length):.2f} |")
    if args.csv:
        keys = ["family", "problem", "valid", "solved", "seconds", "call", "with_scene",
                "timed", "length", "waypoints", "checks", "note"]
        with open(args.csv, "w") as f:
            f.write(",".join(keys) + "\n")
            for r in rows:
                f.write(",".join(str(r.get(k, "")).replace(",", ";") for k in keys) + "\n")


if __name__ == "__main__":
    main()
