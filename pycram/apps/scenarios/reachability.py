"""Reachability as a scene-generation filter: where *some* standing pose of a robot reaches.

A scene generator that wants tasks a robot can do at all (issue 32: "start spots anywhere on the
open surfaces where some standing pose can reach it") draws a spot uniformly and keeps it only
where `ReachabilityFilter` says a standing pose exists. The filter decides by reasoning, never by
trying the task: it asks the robot's own location reasoning (`LocationReasoner`, ``to_reach``)
in prospection built from the environment's description alone -- the robot at its initial
configuration, the containers closed (or, for a target inside one, opened as far as `Open` opens
it), no objects -- whether some base pose, named torso height (the one the robot starts with and
every higher one), arm and grasp of the object's type executes the whole grasp (or place)
sequence without touching the furniture. Prospection ignores objects for these checks, so other
objects in the scene do not change the answer.

This is knowledge of the scene's generator, not of the robot: the robot still starts knowing
nothing, and no plan may ask this filter. Benchmarks also use it to judge a failure: an
`ObjectOutOfReach` is *true* when the filter finds no standing pose either.

    reach = ReachabilityFilter("pr2", "apartment")
    ok, why = reach.graspable("cup", (1.3, 4.7, 0.945), yaw=0.3)
    ok, why = reach.placeable("milk", "fridge")   # a surface's or a container's name
    spot, drawn = draw_spot(rng, environment, "cup", ["counter", "table"], placed, reach)

Costs: a spot that some pose reaches answers in ~0.01-0.5 s, one that none reaches in ~1 s (every
candidate of the reasoning is checked); `placeable` checks at most `PLACE_SPOTS` spots once per
object type and target (cached).
"""

from __future__ import annotations

import math
import random
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.world.belief import BeliefState, support_of
from pycram.world.environment import Environment, Surface
from pycram.world.objects import object_type
from pycram.world.scenes import EDGE_MARGIN, GAP, Placement

__all__ = ["ReachabilityFilter", "draw_spot", "PLACE_SPOTS", "MAX_DRAWS"]

#: Spots of a target checked by `ReachabilityFilter.placeable` (solutions of ``on``/``in``, kept
#: `pycram.reasoning.locations.search.SPACING` apart; in a container nearest its front first)
#: before it says none can be placed on.
PLACE_SPOTS = 20
#: Draws `draw_spot` makes before it gives up on finding a free, reachable spot.
MAX_DRAWS = 400


class ReachabilityFilter:
    """Whether some standing pose of `robot` grasps an object at a spot, or places one on a
    target, in `environment` (a name or a description) -- see the module docstring.

    Built once (a world is opened only to compile the robot's prospection and closed at once:
    no simulation runs afterwards); every answer is computed on prospection's scratch copies."""

    def __init__(self, robot: str, environment: str | Environment = "apartment") -> None:
        from pycram.actions.containers import DOOR_OPENING, DRAWER_OPENING
        from pycram.reasoning.locations import LocationReasoner, RobotGeometry
        from pycram.sim import World
        from pycram.world.robot_registry import robot_description

        self.robot = robot
        world = World(robot, environment=environment, activate_clock=False)
        try:
            self.environment: Environment = world.environment
            geometry = RobotGeometry.from_description(robot_description(robot))
            #: How far each container is opened for the question about a target inside it.
            self.openings = {
                c.name: (DOOR_OPENING if c.kind == "door" else DRAWER_OPENING) for c in self.environment.containers
            }
            self._reasoners: dict[str | None, Any] = {}
            for container in [None, *self.openings]:  # None: every container closed
                belief = BeliefState(self.environment)
                if container is not None:
                    belief.container_states[container] = self.openings[container]
                self._reasoners[container] = LocationReasoner(
                    geometry,
                    _constant(self.environment),
                    _constant(world.prospection(belief)),
                    container_states=_constant(dict(belief.container_states)),
                )
        finally:
            world.close()
        self._placeable: dict[tuple[str, str], tuple[bool, str]] = {}

    def _first(self, container: str | None, properties: list[tuple[str, Any]]) -> Any:
        """The first solution of the designator of `properties` (NoSolutionError when none)."""
        generator = self._reasoners[container].generator(LocationDesignator(properties))
        for solution in generator:
            return solution
        raise NoSolutionError(f"no solution for {properties!r}")

    def graspable(self, type_name: str, position: Sequence[float], yaw: float = 0.0) -> tuple[bool, str]:
        """Whether some standing pose grasps an upright `type_name` object standing with its
        centre at `position` [m] turned by `yaw` [rad] on an open surface (containers closed);
        with the pose found, or why none is."""
        from pycram.reasoning.locations import KnownObject

        target = KnownObject(type_name, type_name, _xyz(position), float(yaw))
        try:
            location = self._first(None, [("to_reach", target)])
        except NoSolutionError as error:
            return False, str(error).split(": ", 1)[-1]
        return True, _describe(location)

    def placeable(self, type_name: str, target: str) -> tuple[bool, str]:
        """Whether some standing pose puts an upright `type_name` object down on the surface or
        inside the container `target` (a drawer or door opened as `Open` opens it: `openings`),
        at one of its first `PLACE_SPOTS` free spots (in a container: nearest its front first);
        with the spot and pose, or why not."""
        key = (type_name, target)
        if key not in self._placeable:
            self._placeable[key] = self._check_placeable(type_name, target)
        return self._placeable[key]

    def _check_placeable(self, type_name: str, target: str) -> tuple[bool, str]:
        container = target if target in self.openings else None
        asks: list[list[tuple[str, Any]]]
        if container is None:
            asks = [[("on", target), ("for", type_name)]]
        else:  # nearest the front (the door's or the drawer's body) first
            body = self.environment.container(target)
            front: tuple[str, Any] = ("near", body.body.center)
            if body.kind == "drawer":  # its inside as it is open
                asks = [[("in", target), ("for", type_name), front]]
            else:  # each shelf: ``in`` gives the spots of the lowest shelf first (SPACING is in x, y)
                asks = [[("on", s.name), ("for", type_name), front] for s in body.interior]
        why = []
        for properties in asks:
            ok, answer = self._placeable_on(container, type_name, properties)
            if ok:
                return True, answer
            why.append(f"{properties[0][1]}: {answer}")
        return False, "; ".join(why)

    def _placeable_on(
        self, container: str | None, type_name: str, properties: list[tuple[str, Any]]
    ) -> tuple[bool, str]:
        from pycram.reasoning.locations import KnownObject

        why = "no free spot"
        try:
            generator = self._reasoners[container].generator(LocationDesignator(properties))
            for number, spot in enumerate(generator):
                if number >= PLACE_SPOTS:
                    break
                standing = KnownObject(f"{type_name} at the spot", type_name, _xyz(spot))
                try:
                    location = self._first(container, [("to_reach", standing), ("action", "place")])
                except NoSolutionError as error:
                    why = str(error).split(": ", 1)[-1]
                    continue
                x, y, z = (float(v) for v in spot)
                return True, f"at ({x:.2f}, {y:.2f}, {z:.2f}) on {spot.surface} from {_describe(location)}"
        except NoSolutionError as error:
            return False, str(error).split(": ", 1)[-1]
        return False, f"none of its first {PLACE_SPOTS} spots (the last: {why})"


def _constant(value: Any) -> Callable[[], Any]:
    """A function returning `value` (what `LocationReasoner` asks for its inputs)."""
    return lambda: value


def _xyz(point: Sequence[float]) -> tuple[float, float, float]:
    return (float(point[0]), float(point[1]), float(point[2]))


def _describe(location: Any) -> str:
    torso = getattr(location, "torso", None)
    return (
        f"({location.x:.2f}, {location.y:.2f}, {math.degrees(location.yaw):.0f} deg), "
        f"{location.arm} arm, {location.grasp} grasp" + (f", torso {torso}" if torso else "")
    )


def draw_spot(
    rng: random.Random,
    environment: Environment,
    type_name: str,
    surfaces: Sequence[str],
    placed: Sequence[Placement],
    reach: ReachabilityFilter | None = None,
    name: str | None = None,
    max_draws: int = MAX_DRAWS,
) -> tuple[Placement | None, Counter[tuple[str, bool]]]:
    """A spot for an upright `type_name` object drawn uniformly from the union of the open
    `surfaces` (surface names; a surface lying on another, e.g. a cooker on the counter, counts
    once), fully on a surface (`EDGE_MARGIN`), clear of the `placed` objects (`GAP`) and -- with
    `reach` -- where some standing pose grasps it. The object is named `name` (default: its
    type) and supported by the smallest of `surfaces` under it (a cooker rather than its counter).

    Returns the placement (None after `max_draws` draws) and what the reachability check said
    about the free spots drawn: (surface name, reachable) -> count."""
    otype = object_type(type_name)
    radius = otype.footprint_radius
    listed = [environment.surface(s) for s in surfaces]
    weights = [s.area for s in listed]
    checked: Counter[tuple[str, bool]] = Counter()
    for _ in range(max_draws):
        surface = rng.choices(listed, weights)[0]
        x0, y0, x1, y1 = surface.bounds
        x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
        yaw = rng.uniform(-math.pi, math.pi)
        under = [s for s in listed if s.contains(x, y)]
        if not surface.contains(x, y) or rng.random() >= 1.0 / len(under):
            continue  # outside the drawn surface's polygon, or a point two listed surfaces share
        support = _support(environment, x, y, under)
        if not any(s.contains(x, y, radius + EDGE_MARGIN) for s in listed if abs(s.height - support.height) < 1e-6):
            continue
        container = environment.container_of(support.name)
        candidate = Placement(
            name or type_name,
            otype.name,
            support.name,
            None if container is None else container.name,
            (x, y, support.height + otype.half_height + 0.001),
            yaw,
            radius,
        )
        if any(candidate.overlaps(other, GAP) for other in placed):
            continue
        if reach is not None:
            ok, _ = reach.graspable(type_name, candidate.position, yaw)
            checked[(support.name, ok)] += 1
            if not ok:
                continue
        return candidate, checked
    return None, checked


def _support(environment: Environment, x: float, y: float, under: list[Surface]) -> Surface:
    """The surface of `under` an object at (x, y) stands on: the highest, of equally high ones
    the smallest (as `pycram.world.belief.support_of` says)."""
    top = max(s.height for s in under)
    found = support_of(environment, x, y, top)
    if found is not None and found in under:
        return found
    return min((s for s in under if s.height == top), key=lambda s: s.area)
