"""trm's trajectory timing beside `toppra` (Pham and Pham's TOPP-RA, the `toppra` package) on
MotionBenchMaker Panda paths, under MoveIt's Panda limits (panda_joint_limits.yaml here):

* per path, trm's duration on its blended path and toppra's on the same path (a cubic spline
  through trm's samples of it, parametrised by arc length), and their ratio;
* trm's blended duration beside its stop-at-every-waypoint duration (`max_deviation=0`: the
  same path, at rest at each waypoint, time-optimal per segment) under the same limits.

Run (the wheel installed, `pip install toppra`):
    python3 benches/timing/toppra_compare.py benches/mbm/panda_problems.tar.bz2 \\
        --model models/panda-mbm/panda_spherized.ron --paths 100
"""

import argparse
import math
import statistics
import sys
from pathlib import Path

import numpy as np
import toppra as ta
import toppra.algorithm as algo
import toppra.constraint as constraint

import trm

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
from mbm_set import problems, unpacked  # noqa: E402
LIMITS = HERE / "panda_joint_limits.yaml"
VELOCITY = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]
ACCELERATION = [3.75, 1.875, 2.5, 3.125, 3.75, 5.0, 5.0]


def toppra_duration(points):
    """toppra's time-optimal duration along a cubic spline through `points` (arc-length
    parametrised), MoveIt's Panda limits, 1000 grid points."""
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    keep = np.concatenate([[True], steps > 1e-9])
    points = points[keep]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    path = ta.SplineInterpolator(s, points)
    vlim = np.array([[-v, v] for v in VELOCITY])
    alim = np.array([[-a, a] for a in ACCELERATION])
    pc_vel = constraint.JointVelocityConstraint(vlim)
    pc_acc = constraint.JointAccelerationConstraint(alim)
    grid = np.linspace(0, s[-1], 1001)
    instance = algo.TOPPRA([pc_vel, pc_acc], path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    result = instance.compute_trajectory(0, 0)
    return None if result is None else result.duration


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("set", type=Path)
    ap.add_argument("--model", required=True)
    ap.add_argument("--paths", type=int, default=100)
    ap.add_argument("--max-deviation", type=float, default=0.2)
    args = ap.parse_args()
    all_problems = list(problems(unpacked(args.set)))
    if not all_problems:
        sys.exit(f"{args.set}: no MotionBenchMaker problems")
    # spread the paths over the families
    step = max(1, len(all_problems) // args.paths)
    chosen = all_problems[::step][: args.paths]
    robot = trm.Robot.load(args.model)
    planner = trm.Planner(robot, request=str(chosen[0][3]))
    arm = [robot.motor_names.index(n) for n in planner.joint_names]
    ratios, blend_vs_stop, waypoints = [], [], []
    print("family,trm_s,toppra_s,ratio,stop_s,blend_over_stop,waypoints")
    for family, _, scene, request in chosen:
        planner.load_scene(str(scene))
        planner.set_timing(joint_limits=str(LIMITS), max_deviation=args.max_deviation)
        try:
            blended = planner.plan_request(str(request))
        except Exception as e:  # an invalid problem: skip, say so
            print(f"# {request}: {e}", file=sys.stderr)
            continue
        planner.set_timing(joint_limits=str(LIMITS), max_deviation=0.0)
        stopping = planner.plan_request(str(request))
        trm_s = float(blended["times"][-1])
        stop_s = float(stopping["times"][-1])
        theirs = toppra_duration(np.asarray(blended["positions"])[:, arm])
        ratio = trm_s / theirs if theirs else math.nan
        ratios.append(ratio)
        blend_vs_stop.append(trm_s / stop_s)
        waypoints.append(len(blended["waypoints"]))
        print(f"{family},{trm_s:.4f},{theirs:.4f},{ratio:.4f},{stop_s:.4f},{trm_s / stop_s:.4f},{waypoints[-1]}")
    print(
        f"# {len(ratios)} paths (median {statistics.median(waypoints)} waypoints): "
        f"trm / toppra median {statistics.median(ratios):.4f} "
        f"(min {min(ratios):.4f}, max {max(ratios):.4f}); "
        f"blended / stop-at-every-waypoint median {statistics.median(blend_vs_stop):.3f}"
    )


if __name__ == "__main__":
    main()
