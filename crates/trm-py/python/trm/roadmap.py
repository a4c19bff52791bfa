"""Task-relevant roadmaps: built by E-TRM, saved, loaded, repaired for a new world, and run
through scenarios of moving worlds (trm-roadmap)."""

from ._trm import Roadmap, run_scenario

__all__ = ["Roadmap", "run_scenario"]
