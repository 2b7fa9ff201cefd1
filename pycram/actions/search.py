"""Searching for an object the belief does not hold: a robot-agnostic plan.

`search_for(ObjectDesignator(type="cup"))` finds an object matching the description:

1. if the robot's belief already holds one, that is the answer;
2. it looks around from where it stands: at each likely place within `look_range` [m], nearest
   first, it points the head there and detects -- twice while nothing matching is seen
   (`LOOKS_PER_PLACE`: one look is no proof that nothing is there; a detector misses objects
   now and then);
3. it visits the likely places it has not looked at closely, nearest first -- the surfaces
   where a matching object was last seen before it was believed gone first (moved by a person
   or missed by a look, it is likely still near), places inside containers not known to be
   open last, the kinds of place the object type is most likely found on first
   (`ObjectType.found_on`: a cup in the drawers before the fridge), and of each kind the places
   an earlier search looked into without seeing a match last (`BeliefState.searched`: a second
   search, e.g. a transport's next round, does not go through the drawers it has just looked
   through before the cupboard it never reached): it drives to a standing pose in front of
   each, points the head at it and detects (as in 2.);
4. it fails with `pycram.failures.ObjectNotFound`, which names every place it looked at and
   the places it could not look into (closed containers, places it could not reach).

Likely places come from the environment's description (`Lookout`s): the surfaces of the kinds
objects of the type are found on (`ObjectType.found_on`; every surface for an unknown or
unspecified type), open surfaces seen from their free edge nearest to the robot, surfaces inside
containers seen from in front of the container. A container measured closed is opened with
`open_container(name)` when given (a plan, e.g. ``lambda name: perform(Open(name))``; the
set-table plan passes one that closes the other containers first); without one it is skipped and
reported, so objects in closed containers are then found only when the scene leaves them open.

The plan uses motion designators only (`subscribing_pose`, `moving`, `pointing_head`,
`detecting`) and the active robot's belief (`robot.belief`, a
`pycram.world.belief.BeliefState`): it runs unchanged on every robot that offers them.
A failed motion (a pose it cannot drive to, a point its head cannot turn to) skips that place;
evaporation is never caught.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

from pycram.core.fluent import Fluent
from pycram.core.runtime import as_task
from pycram.designators.core import DesignatorError
from pycram.designators.motion import MotionDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import ObjectNotFound, PlanFailure
from pycram.execution.perform import perform
from pycram.execution.process_module import ProcessModuleError
from pycram.world.belief import BeliefState, PerceivedObject
from pycram.world.environment import Environment, Surface
from pycram.world.objects import OBJECT_TYPES

from .core import motion
from .handling import park_empty_arms

__all__ = [
    "Lookout",
    "lookouts",
    "look_around",
    "search_for",
    "LOOK_RANGE",
    "LOOKS_PER_PLACE",
    "STANDOFF",
    "STAND_CLEARANCE",
]

logger = logging.getLogger(__name__)

#: Places farther than this [m] are not looked at from where the robot stands.
LOOK_RANGE = 3.0
#: How far [m] in front of a surface's edge (or a container's opened front) the robot stands.
STANDOFF = 0.9
#: A place looked at from closer than this [m] is not visited again.
CLOSE_LOOK = 1.6
#: Longest stretch [m] of an edge one look covers; longer edges get several lookouts.
LOOK_WIDTH = 1.3
#: Looks at each place while nothing matching is seen there (a detector misses objects now and
#: then: with the simulated camera's ``missed`` fault, 3 looks in 10 miss a visible object).
LOOKS_PER_PLACE = 2

_FAILURES = (PlanFailure, ProcessModuleError, DesignatorError)


@dataclass(frozen=True)
class Lookout:
    """A place to look at: `name` (the surface's, with a part number on long surfaces),
    `surface`, the `target` [m, map] to point the head at, where to `stand` (x [m], y [m],
    yaw [rad]) and the `container` the surface is inside (None for open surfaces)."""

    name: str
    surface: str
    target: tuple[float, float, float]
    stand: tuple[float, float, float]
    container: str | None = None


#: Clearance [m] of a standing pose from walls and furniture (a robot base's half diagonal).
STAND_CLEARANCE = 0.5


def _free(environment: Environment, x: float, y: float) -> bool:
    return environment.is_free_floor(x, y, margin=STAND_CLEARANCE)


def _stand_along(
    environment: Environment,
    point: tuple[float, float],
    towards: tuple[float, float],
    n: tuple[float, float],
    standoff: float,
) -> tuple[float, float] | None:
    """A free standing spot `standoff` [m] out from `point` on an edge (outward normal `n`),
    moved along the edge towards `towards` (in 0.1 m steps, at most to it) when `point` is not
    free; None when there is none."""
    span = math.dist(point, towards)
    steps = int(span / 0.1) + 1
    for k in range(steps + 1):
        f = 0.0 if span == 0.0 else min(1.0, 0.1 * k / span)
        x = point[0] + f * (towards[0] - point[0]) + standoff * n[0]
        y = point[1] + f * (towards[1] - point[1]) + standoff * n[1]
        if _free(environment, x, y):
            return (x, y)
    return None


def _surface_lookouts(
    environment: Environment, surface: Surface, near: tuple[float, float], standoff: float
) -> list[Lookout]:
    """Lookouts along the free edge of an open surface nearest to `near`."""
    options = []
    for a, b, n in surface.edges():
        mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
        if _stand_along(environment, mid, mid, n, standoff) is None:
            continue
        options.append((math.dist(near, mid), a, b, n))
    if not options:
        return []
    _, a, b, n = min(options)
    length = math.dist(a, b)
    pieces = max(1, math.ceil(length / LOOK_WIDTH))
    x0, y0, x1, y1 = surface.bounds
    inward = min(0.25, (x1 - x0 + y1 - y0) / 8)
    out = []
    mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
    for k in range(pieces):
        f = (k + 0.5) / pieces
        px, py = a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])
        stand = _stand_along(environment, (px, py), mid, n, standoff)
        if stand is None:
            continue
        name = surface.name if pieces == 1 else f"{surface.name} ({k + 1}/{pieces})"
        out.append(
            Lookout(
                name,
                surface.name,
                (px - inward * n[0], py - inward * n[1], surface.height + 0.05),
                (*stand, math.atan2(-n[1], -n[0])),
            )
        )
    return out


def lookouts(
    environment: Environment,
    type_name: str | None = None,
    near: tuple[float, float] = (0.0, 0.0),
    standoff: float = STANDOFF,
) -> list[Lookout]:
    """The places of `environment` where an object of `type_name` is likely (all surfaces when
    the type is None or unknown), with where to stand for each, nearest to `near` [m] first."""
    kinds = OBJECT_TYPES[type_name].found_on if type_name in OBJECT_TYPES else None
    out: list[Lookout] = []
    for surface in environment.all_surfaces():
        if kinds is not None and surface.kind not in kinds:
            continue
        container = environment.container_of(surface.name)
        if container is None:
            out += _surface_lookouts(environment, surface, near, standoff)
            continue
        dx, dy = container.opening_direction
        reach = container.limits[1] if container.kind == "drawer" else 0.0
        hx, hy, _ = container.handle
        stand = (hx + dx * (reach + standoff), hy + dy * (reach + standoff), math.atan2(-dy, -dx))
        if _free(environment, stand[0], stand[1]):
            cx, cy, h = surface.centroid
            out.append(Lookout(surface.name, surface.name, (cx, cy, h + 0.05), stand, container.name))
    # places seen from the same standing pose (a cabinet's drawers): the highest first -- an
    # upper drawer is opened and closed more easily than the ones below it
    return sorted(out, key=lambda lk: (math.dist(near, lk.stand[:2]), -lk.target[2]))


def _robot_belief() -> BeliefState:
    from pycram.execution.robot import current_robot

    robot = current_robot()
    belief = getattr(robot, "belief", None)
    if not isinstance(belief, BeliefState):
        raise ValueError(f"search_for needs a belief state: the active robot {robot!r} has none (pass belief=...)")
    return belief


def _believed(description: ObjectDesignator, belief: BeliefState) -> PerceivedObject | None:
    return next((o for o in belief.present() if description.matches(o)), None)


def _base_pose() -> Any:
    pose = Fluent(name="search: base pose")
    perform(MotionDesignator(type="subscribing_pose", fl=pose))
    return pose


def _target(lookout: Lookout, environment: Environment, belief: BeliefState) -> tuple[float, float, float]:
    """Where to look at: a drawer's inside moves out with the drawer (measured opening)."""
    if lookout.container is None:
        return lookout.target
    container = environment.container(lookout.container)
    q = belief.container_states.get(container.name, 0.0) if container.kind == "drawer" else 0.0
    x, y, z = lookout.target
    return (x + q * container.opening_direction[0], y + q * container.opening_direction[1], z)


def _detect(description: ObjectDesignator | None) -> list[PerceivedObject]:
    """Detect (the head already pointed); with a `description`, up to `LOOKS_PER_PLACE` times
    while nothing matching is seen: one look that shows nothing is no proof that nothing is
    there (a detector misses objects now and then)."""
    looks = 1 if description is None else LOOKS_PER_PLACE
    seen: list[PerceivedObject] = []
    for _ in range(looks):
        seen = list(perform(MotionDesignator(type="detecting", object=description)))
        if seen:
            break
    return seen


def _look(description: ObjectDesignator, target: tuple[float, float, float]) -> PerceivedObject | None:
    """Point the head at `target` and detect (`_detect`); the best match seen, or None."""
    perform(MotionDesignator(type="pointing_head", coordinates=target))
    seen = _detect(description)
    return seen[0] if seen else None


def _look_around(
    description: ObjectDesignator | None,
    places: list[Lookout],
    here: tuple[float, float],
    belief: BeliefState,
    look_range: float,
    looked: list[str],
    close: set[str],
) -> list[PerceivedObject]:
    """Look at each place within `look_range` of `here`; stop at the first match of a
    `description` (None: look at every place and return everything seen)."""
    environment = belief.environment
    if environment is None:
        raise ValueError("looking around needs a belief with an environment description")
    seen: list[PerceivedObject] = []
    for lookout in places:
        target = _target(lookout, environment, belief)
        distance = math.dist(here, target[:2])
        if distance > look_range or any(entry.startswith(lookout.name + " ") for entry in looked):
            continue
        if lookout.container is not None and belief.container_open(lookout.container) is False:
            continue
        try:
            perform(MotionDesignator(type="pointing_head", coordinates=target))
            result = _detect(description)
        except _FAILURES as failure:
            logger.info("cannot look at %s from here: %s", lookout.name, failure)
            continue
        if lookout.container is not None and not belief.container_open(lookout.container):
            continue  # it showed the door or drawer shut (or not at all): no look inside
        looked.append(f"{lookout.name} (from where it stood)")
        if distance < CLOSE_LOOK:
            close.add(lookout.name)
        seen += [obj for obj in result if obj not in seen]
        if description is not None and seen:
            break
    return seen


def _last_seen_on(description: ObjectDesignator, belief: BeliefState) -> set[str]:
    """The surfaces where an object matching `description` was last seen before it was believed
    gone."""
    gone = [
        o
        for o in belief.objects()
        if isinstance(o, PerceivedObject) and o.gone and o.pose is not None and description.matches(o)
    ]
    return {str(o.properties.get("on")) for o in gone if o.properties.get("on")}


def _last_seen_first(places: list[Lookout], description: ObjectDesignator, belief: BeliefState) -> list[Lookout]:
    """`places` with those on the surfaces where a matching object was last seen before it was
    believed gone first (a person who moved it likely put it down nearby; a missed look is
    made good there), the order kept otherwise."""
    surfaces = _last_seen_on(description, belief)
    if not surfaces:
        return places
    return sorted(places, key=lambda lookout: lookout.surface not in surfaces)


@as_task(name="look_around")
def look_around(
    description: ObjectDesignator | None = None, *, belief: BeliefState | None = None, look_range: float = LOOK_RANGE
) -> list[PerceivedObject]:
    """Look at every likely place within `look_range` [m] from where the robot stands (for the
    type of `description`, all places without one), detecting at each, without driving; stops
    at the first object matching `description`. Returns the believed objects seen (matching
    `description` when given). Runs as a task named "look_around"."""
    belief = belief if belief is not None else _robot_belief()
    if belief.environment is None:
        raise ValueError("look_around needs a belief with an environment description")
    here = _base_pose().get_value()
    type_name = None if description is None else description.prop_value("type")
    places = lookouts(belief.environment, type_name, (here.x, here.y))
    return _look_around(description, places, (here.x, here.y), belief, look_range, [], set())


@as_task(name="search_for")
def search_for(
    description: ObjectDesignator,
    *,
    belief: BeliefState | None = None,
    open_container: Callable[[str], Any] | None = None,
    look_range: float = LOOK_RANGE,
    standoff: float = STANDOFF,
) -> PerceivedObject:
    """Find an object matching `description` (see the module's description); returns the believed
    object found, to which `description` is then equated (``description.current()``).

    `belief` defaults to the active robot's; `open_container(name)` opens a container (a plan),
    when available. Raises `ObjectNotFound` naming the places looked at and those skipped, and
    `ValueError` when there is no belief to search with. Runs as a task named "search_for".
    """
    if not isinstance(description, ObjectDesignator):
        raise TypeError(f"search_for needs an ObjectDesignator, got {description!r}")
    belief = belief if belief is not None else _robot_belief()
    environment = belief.environment
    if environment is None:
        raise ValueError("search_for needs a belief with an environment description")
    known = _believed(description, belief)
    if known is not None:
        return known
    here = _base_pose().get_value()
    places = _last_seen_first(
        lookouts(environment, description.prop_value("type"), (here.x, here.y), standoff), description, belief
    )
    looked: list[str] = []
    skipped: dict[str, str] = {}
    close: set[str] = set()
    # 1. look around from where it stands
    around = _look_around(description, places, (here.x, here.y), belief, look_range, looked, close)
    if around:
        return around[0]

    # 2. visit the likely places, nearest first -- those behind a closed door or drawer last
    #    (opening is slow, and an opened drawer stands in the way), the likeliest kind first
    order = partial(
        _closed_last, environment, belief, description.prop_value("type"), _last_seen_on(description, belief)
    )
    for lookout in sorted(places, key=order):
        if lookout.name in close:
            continue
        found = _visit(description, lookout, environment, belief, open_container, looked, skipped)
        if found is not None:
            return found
    raise ObjectNotFound(description, looked, sorted(skipped.items()))


#: Other standing poses tried for a place when its own cannot be driven to (e.g. a box on the
#: floor there): this far [m] to either side of the line of sight, then this far back.
STAND_ASIDE = (0.35, 0.7)
STAND_BACK = 0.35


def _stands(lookout: Lookout, environment: Environment) -> list[tuple[float, float, float]]:
    """Where to stand to look at `lookout`: its own standing pose, then poses beside and behind
    it (`STAND_ASIDE`, `STAND_BACK`) on free floor, each facing the place's target."""
    x, y, _ = lookout.stand
    tx, ty, _ = lookout.target
    distance = math.hypot(tx - x, ty - y) or 1.0
    fx, fy = (tx - x) / distance, (ty - y) / distance  # towards the target
    offsets = [(0.0, side * aside) for aside in STAND_ASIDE for side in (1.0, -1.0)] + [(-STAND_BACK, 0.0)]
    out = [lookout.stand]
    for ahead, aside in offsets:
        px, py = x + ahead * fx - aside * fy, y + ahead * fy + aside * fx
        if _free(environment, px, py):
            out.append((px, py, math.atan2(ty - py, tx - px)))
    return out


def _drive_to_look(lookout: Lookout, environment: Environment, skipped: dict[str, str]) -> bool:
    """Drive to a standing pose to look at `lookout` from (`_stands`, the first that can be
    driven to); False, with the reason in `skipped`, when none can. Each drive runs with the
    plan's `while_driving` job, if any."""
    first: BaseException | None = None
    parked = False
    for stand in _stands(lookout, environment):
        for _ in range(2):
            try:
                motion(type="moving", pose=stand)
                return True
            except _FAILURES as failure:
                first = first or failure
                logger.info("cannot stand at (%.2f, %.2f) to look at %s: %s", stand[0], stand[1], lookout.name, failure)
            if parked or not park_empty_arms():
                break
            # an empty arm left out (raised to carry, or where a handle was let go) widens the
            # robot: the place's own standing pose, refused beside a door swung open with it,
            # is tried again with them parked (measured: the TIAGo Pro at the cupboard)
            parked = True
    skipped[lookout.name] = f"could not get there: {first}"
    return False


def _closed_last(
    environment: Environment, belief: BeliefState, type_name: str | None, last_seen: set[str], lookout: Lookout
) -> tuple[bool, bool, bool, int]:
    """Sort key of the places to visit: open places first (kept nearest first); places in
    containers not known to be open last -- where a matching object was last seen (`last_seen`)
    first among them, then those whose inside is of a kind the object type is more likely found
    on (`ObjectType.found_on`, most likely first): a person looks for a cup in the drawers
    before the fridge. Among either, places an earlier search looked into (`BeliefState.searched`:
    nothing matching was seen there, or the belief would hold it) come after the others."""
    searched = lookout.surface in belief.searched
    if lookout.container is None or belief.container_open(lookout.container) is True:
        return (False, False, searched, 0)
    kinds = OBJECT_TYPES[type_name].found_on if type_name in OBJECT_TYPES else ()
    kind = environment.surface(lookout.surface).kind
    return (True, lookout.surface not in last_seen, searched, kinds.index(kind) if kind in kinds else len(kinds))


def _visit(
    description: ObjectDesignator,
    lookout: Lookout,
    environment: Environment,
    belief: BeliefState,
    open_container: Callable[[str], Any] | None,
    looked: list[str],
    skipped: dict[str, str],
) -> PerceivedObject | None:
    container = lookout.container
    if container is not None and belief.container_open(container) is False and open_container is None:
        skipped[lookout.name] = f"{container} is closed"
        return None
    if not _drive_to_look(lookout, environment, skipped):
        return None
    opened = False  # the last look is the first since this visit opened the container
    for _ in range(2):  # a look that finds the container closed opens it and looks again
        if container is not None and belief.container_open(container) is False:
            if open_container is None:
                skipped[lookout.name] = f"{container} is closed"
                return None
            try:
                open_container(container)
            except _FAILURES as failure:
                skipped[lookout.name] = f"could not open {container}: {failure}"
                return None
            opened = True
        try:
            found = _look(description, _target(lookout, environment, belief))
            if found is None and opened and container and environment.container(container).kind == "door":
                # opening leaves the robot where it held the handle, often beside the door it
                # swung open, which then hides the shelf (measured: the TIAGo Pro at the
                # cupboard): it looks again from the place's own standing pose. (A drawer is
                # looked into from where it was pulled out: from the standing pose, farther
                # back, its walls hide what lies inside.)
                opened = False
                if _drive_to_look(lookout, environment, {}):
                    found = _look(description, _target(lookout, environment, belief))
        except _FAILURES as failure:
            skipped[lookout.name] = f"could not look at it: {failure}"
            return None
        if found is not None:
            looked.append(lookout.name)
            return found
        if container is None or belief.container_open(container) is not False:
            looked.append(lookout.name)
            belief.looked_into(lookout.surface)
            return None
    looked.append(lookout.name)
    return None
