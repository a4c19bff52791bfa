"""Planning through maps, completed by a sampling planner; MotionBenchMaker sets generated and
benchmarked (trm-plan)."""

from ._trm import MotionPlanRequest, Planner, benchmark_mbm, generate_mbm

__all__ = ["MotionPlanRequest", "Planner", "benchmark_mbm", "generate_mbm"]
