"""Self-contained HTML pages of robots, worlds, paths and maps (trm-view)."""

from ._trm import view

__all__ = ["view"]
