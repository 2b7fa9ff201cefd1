"""The serve plan: each requested object to the table at the seat, next to each other --
`pycram.apps.scenarios.common.plan.serve`, robot-agnostic (``('on', 'table')``, ``('near', the
seat or the object served before)``)."""

from __future__ import annotations

from pycram.apps.scenarios.common.plan import serve

__all__ = ["serve"]
