"""What Python costs on top of trm's Rust FK: one configuration per call, and batches of
10 000, on the 41-motor iCub (all 75 link poses as 4 × 4 matrices). Run with the wheel
installed (README, "trm from Python"): python3 benches/python/fk_overhead.py.
Compare with `cargo bench --bench kinematics -- fk_all_links/checked/icub_upper_body`."""

import statistics
import time

import numpy as np

import trm


def median_seconds(f, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


robot = trm.Robot.icub()
rng = np.random.default_rng(0)
batch = rng.uniform(robot.lower, robot.upper, size=(10_000, robot.dof))
one = batch[0]
inner = 1000
single = median_seconds(lambda: [robot.fk(one) for _ in range(inner)], 15) / inner
many = median_seconds(lambda: robot.fk(batch), 15) / len(batch)
pose = median_seconds(lambda: [robot.frame_pose(one, "r_hand") for _ in range(inner)], 15) / inner
print(f"fk, one configuration per call:      {single * 1e6:7.2f} µs (median of 15 × {inner} calls)")
print(f"fk, batch of 10 000, per config:     {many * 1e6:7.2f} µs")
print(f"frame_pose, one frame, one config:   {pose * 1e6:7.2f} µs")
print(f"per-call overhead over the batch:    {(single - many) * 1e6:7.2f} µs")
