"""Planning through maps, completed by a sampling planner; MotionBenchMaker sets generated and
benchmarked (trm-plan)."""

from ._trm import Planner, benchmark_mbm, generate_mbm

__all__ = ["Planner", "benchmark_mbm", "generate_mbm"]
