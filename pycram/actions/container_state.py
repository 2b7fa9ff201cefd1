"""How open a container is, as the robot knows it: perception measures a drawer's opening [m]
or a door's angle [rad] whenever its handle is in view (the belief's ``container_states``; the
environment's description says only where the containers are and how they move).

The thresholds say when a measurement counts as closed or open: a drawer closed below
`CLOSED`, opened within `OPEN_TOLERANCE` of its goal or at least `USEFUL_OPENING` out; a door
closed below `DOOR_CLOSED`, opened within `DOOR_TOLERANCE` of its goal or at least
`DOOR_USEFUL` open. `believed_open` reads the belief; `_measure` looks at a handle to measure it
now, `_look_at_neighbours` at the handles within `NEIGHBOUR_RADIUS` [m] of one.
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

from pycram.execution.failures import ContainerFailure
from pycram.execution.robot import current_robot

from .core import best_effort, motion

__all__ = ["NEIGHBOUR_RADIUS", "believed_open"]

#: A drawer counts as closed below this opening [m], as opened when within this of its goal --
#: or at least `USEFUL_OPENING` [m] out (enough to look and reach in).
CLOSED, OPEN_TOLERANCE, USEFUL_OPENING = 0.03, 0.06, 0.15
#: A door counts as closed below this angle [rad] (4 deg), as opened when within this of its
#: goal -- or at least `DOOR_USEFUL` [rad] open (60 deg: enough to look and reach in).
DOOR_CLOSED, DOOR_TOLERANCE, DOOR_USEFUL = math.radians(4), math.radians(10), math.radians(60)
#: After a hand worked a drawer, the containers whose handles are within this distance [m] of
#: its handle are looked at too: an arm going up from a low drawer can catch the handle of one
#: above and pull it out unnoticed (the TIAGo, closing drawer 1: drawer 3 left 6 cm out in 16 of
#: 200 faulted seeds). The apartment's stacked drawers are 0.26 m apart.
NEIGHBOUR_RADIUS = 0.6


def _environment() -> Any:
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if environment is None:
        raise ContainerFailure("opening and closing need a robot whose belief knows the environment")
    return belief, environment


def _measure(belief: Any, container: Any, expected: float | None = None) -> float | None:
    """Look at the handle; the opening [m or rad] perception measured (None when these looks did
    not measure it: an older value of the belief is no measurement).

    With `expected` (where the container should be now, far from where it is believed to be) the
    head looks there first and then where it was believed to be: perception measures the
    container whenever its handle is in view, so the belief ends with what was seen."""
    believed = belief.container_states.get(container.name, 0.0)
    before = belief.container_stamps.get(container.name)
    looks = [believed]
    if expected is not None and abs(expected - believed) > DOOR_TOLERANCE:
        looks.insert(0, expected)
    for q in looks:
        # standing close, the head may not turn all the way: it looks as near as it can
        best_effort(
            "looking at a handle",
            partial(motion, type="pointing_head", coordinates=list(container.handle_position(q))),
        )
        motion(type="detecting")
    if belief.container_stamps.get(container.name) == before:  # not measured by these looks
        return None
    return float(belief.container_states[container.name])


def believed_open(name: str) -> bool | None:
    """Whether the current robot believes the container `name` open: a drawer measured out
    `CLOSED` [m] or more, a door `DOOR_CLOSED` [rad] or more -- the thresholds `Close` pushes
    below. None when it was never measured (or the robot has no belief of the environment)."""
    belief: Any = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if environment is None or name not in belief.container_states:
        return None
    closed = CLOSED if environment.container(name).kind == "drawer" else DOOR_CLOSED
    return abs(belief.container_states[name]) >= closed


def _look_at_neighbours(belief: Any, container: Any) -> None:
    """Look at the handles of the containers within `NEIGHBOUR_RADIUS` of `container`'s (best
    effort): the belief ends with how far each is open now, so that one pulled out by the arm
    is closed again."""
    _, environment = _environment()
    here = container.handle_position(belief.container_states.get(container.name, 0.0))
    for other in environment.containers:
        there = other.handle_position(belief.container_states.get(other.name, 0.0))
        if other.name != container.name and math.dist(here, there) <= NEIGHBOUR_RADIUS:
            best_effort(f"looking at the handle of {other.name}", partial(_measure, belief, other))
