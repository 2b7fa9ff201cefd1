"""The ``to_see`` vocabulary: base poses from which the head camera sees a target.

``('to_see', t)`` is answered with `BaseLocation`s from which at least half of ``t`` is in the
camera's view and unoccluded (`Prospection.visible`), the base facing ``t``. Layers: occupancy
and a viewing ring (`VIEW_RING` [m]: preferred distance, spread, nearest, farthest).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

from .costmap import Costmap, FloorGrid, occupancy_layer, ring_layer
from .search import NO_WAY_IN, CandidateSearch, _ranked
from .solutions import BaseLocation

__all__ = ["SeeVocabulary", "VIEW_RING"]

#: Viewing ring for ``to_see`` [m]: preferred distance, spread, nearest, farthest.
VIEW_RING = (1.3, 0.5, 0.6, 3.0)


class SeeVocabulary(CandidateSearch):
    """Answers ``to_see`` (see the module docstring)."""

    # ------------------------------------------------------------------ to_see
    def to_see(self, desig: Any) -> Iterator[BaseLocation]:
        target = self._target(desig.prop_value("to_see"))
        env = self.environment()
        grid = FloorGrid.of(env)
        preferred, sigma, low, high = VIEW_RING
        costmap = Costmap(
            grid,
            {
                "occupancy": occupancy_layer(env, grid, self._base_radius),
                "view": ring_layer(grid, target.position, preferred, sigma, low, high),
            },
        )
        self.last_costmaps = {"view": costmap}
        what = target.name if target.kind == "object" and target.name else target.position

        def validate(cell: tuple) -> tuple[BaseLocation | None, tuple[str, str | None] | None]:
            cost, _, _, r, c = cell
            x, y = costmap.xy(r, c)
            yaw = math.atan2(target.position[1] - y, target.position[0] - x)
            prosp = self.prospection()
            arrival = self.arrival_configuration(prosp)
            if prosp.in_collision((x, y, yaw), arrival, self.carried(), objects=True):
                return None, ("in collision", None)
            if self.cannot_drive_in(prosp, (x, y, yaw), arrival):
                return None, (NO_WAY_IN, None)
            seen = prosp.visible(what, (x, y, yaw), 0.5, arrival)
            if seen:
                return BaseLocation(x, y, yaw, cost=cost, visible=seen.fraction), None
            if seen.in_view < 0.5:
                return None, ("out of the camera's view", None)
            return None, ("occluded", seen.occluders[0] if seen.occluders else None)

        cells = _ranked(costmap, 0, None)
        return self._search(desig, cells, validate, "to_see", target, {"view": costmap})
