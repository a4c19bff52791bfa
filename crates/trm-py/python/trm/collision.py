"""Worlds of objects, a robot's collision model, and proxies fitted to its meshes
(trm-collision)."""

from ._trm import CollisionModel, World, fit_proxies

__all__ = ["CollisionModel", "World", "fit_proxies"]
