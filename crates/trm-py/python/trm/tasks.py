"""Problems: a task spec's costs and constraints, solved by NGIK; costs written in Python
(trm-tasks)."""

from ._trm import Problem

__all__ = ["Problem"]
