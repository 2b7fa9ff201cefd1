"""The put-away plan: every grocery into one of the containers it belongs in, then every door
closed -- `pycram.apps.scenarios.common.plan.put_away`, robot-agnostic."""

from __future__ import annotations

from pycram.apps.scenarios.common.plan import put_away

__all__ = ["put_away"]
