"""Whole-body motions: the stand-up rollouts (trm-wholebody)."""

from ._trm import stand_up

__all__ = ["stand_up"]
