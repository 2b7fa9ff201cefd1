"""Closing a drawer (`_close_drawer`): pushed home from a standing pose that reaches the whole
push, to `PUSH_BEYOND` [m] past closed (`pycram.actions.handles`). A drawer far out may leave no
such pose (the base keeps clear of the drawer as it is): then it is pushed in as far as it goes
from a pose reaching its handle where it is, and the whole push is sought again -- stages while
each gains at least `MIN_PUSH_GAIN` [m], at most `CONTAINER_ATTEMPTS`. Raises the last stage's
typed failure, `ContainerStuck` when it is still open after every stage.

Opening a drawer is one handle attempt (`pycram.actions.handles`) from a standing pose that
reaches the whole pull (`pycram.actions.containers`).
"""

from __future__ import annotations

import logging
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.execution.failures import ContainerFailure, ContainerStuck, ObjectOutOfReach

from .container_poses import CONTAINER_ATTEMPTS, _standing_poses, _try_poses
from .handles import _move_handle

__all__ = ["MIN_PUSH_GAIN"]

log = logging.getLogger("pycram.actions")

#: A stage of closing a drawer (`_close_drawer`) counts as progress when it pushes it in this far [m].
MIN_PUSH_GAIN = 0.05


def _close_drawer(designator: ActionDesignator, belief: Any, container: Any, arm: str | None) -> float:
    """Push the drawer `container` home from a standing pose that reaches the whole push (to
    `DRAWER_PUSH_BEYOND` past closed: checking only where the handle is found poses from which
    the arm could not push it home). A drawer far out may leave no such pose (the base keeps
    clear of the drawer as it is): then it is pushed in as far as it goes from a pose reaching
    its handle where it is, and the whole push is sought again -- stages while each gains at least
    `MIN_PUSH_GAIN`, at most `CONTAINER_ATTEMPTS`. Raises the last stage's typed failure."""
    move = partial(_move_handle, belief=belief, container=container, goal=0.0)
    for _stage in range(CONTAINER_ATTEMPTS):
        start = belief.container_states.get(container.name, 0.0)
        try:
            return _try_poses("closing", designator, container, _standing_poses(container, arm, 0.0, True), move)
        except (ContainerFailure, ObjectOutOfReach) as whole:
            if belief.container_states.get(container.name, 0.0) < start - MIN_PUSH_GAIN:
                continue  # it went part of the way in: seek the whole push again from there
            log.info("%s: no pose pushes it home from %.2f m: pushing it in part of the way", container.name, start)
            try:
                return _try_poses(
                    "closing",
                    designator,
                    container,
                    _standing_poses(container, arm, min(start, container.limits[1])),
                    move,
                )
            except (ContainerFailure, ObjectOutOfReach):
                if belief.container_states.get(container.name, 0.0) >= start - MIN_PUSH_GAIN:
                    raise whole from None  # neither way moved it
    measured = belief.container_states.get(container.name, 0.0)
    raise ContainerStuck(
        f"closing {container.name!r}: still open {measured:.2f} m after {CONTAINER_ATTEMPTS} stages of pushing",
        container.name,
        designator,
    )
