"""Reachability as a scene-generation filter: where *some* standing pose of a robot reaches.

A scene generator that wants tasks a robot can do at all (issue 32: "start spots anywhere on the
open surfaces where some standing pose can reach it") draws a spot uniformly and keeps it only
where `ReachabilityFilter` says a standing pose exists. The filter decides by reasoning, never by
trying the task: it asks the robot's own location reasoning (`LocationReasoner`, ``to_reach``)
in prospection built from the environment's description alone -- the robot at its initial
configuration, the containers closed (or, for a target inside one, opened as far as `Open` opens
it), no objects -- whether some base pose, named torso height (the one the robot starts with and
every higher one), arm and grasp of the object's type executes the whole grasp (or place)
sequence without touching the furniture. Asked without `neighbours`, other objects in the scene
do not change the answer.

`graspable` answers for a spot inside a container too (the container opened as `Open` opens
it; no spot inside a container that no standing pose opens, `openable`: the PR2 opens no drawer
whose handle is 0.22 m above the floor), and -- to judge as the robot's reasoning will once it
has seen the scene -- with other objects counted as believed ones, the object's turn as
perception reports it and a margin for how far off perception measures it (`draw_spot(...,
among_placed=True)`, used by set-table's ``anywhere`` starts; the other scenes of the task suite
do not ask for it yet).

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
import threading
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from functools import partial
from typing import Any

from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.world.belief import BeliefState, PerceivedObject, support_of
from pycram.world.environment import Environment, Surface
from pycram.world.objects import object_type
from pycram.world.scenes import EDGE_MARGIN, GAP, Placement

__all__ = ["ReachabilityFilter", "draw_spot", "perceived_yaw", "PLACE_SPOTS", "MAX_DRAWS", "PERCEPTION_MARGIN"]

#: Spots of a target checked by `ReachabilityFilter.placeable` (solutions of ``on``/``in``, kept
#: `pycram.reasoning.locations.search.SPACING` apart; in a container nearest its front first)
#: before it says none can be placed on.
PLACE_SPOTS = 20
#: Draws `draw_spot` makes before it gives up on finding a free, reachable spot.
MAX_DRAWS = 400
#: How far off [m] a spot must still be graspable for `draw_spot(..., among_placed=True)`: about
#: how far off perception measures an object's centre.
PERCEPTION_MARGIN = 0.01


class ReachabilityFilter:
    """Whether some standing pose of `robot` grasps an object at a spot, or places one on a
    target, in `environment` (a name or a description) -- see the module docstring.

    Built once (a world is opened only to compile the robot's prospection and closed at once:
    no simulation runs afterwards); every answer is computed on prospection's scratch copies."""

    def __init__(self, robot: str, environment: str | Environment = "apartment") -> None:
        from pycram.actions.containers import DOOR_OPENING, DRAWER_OPENING
        from pycram.reasoning.locations import LocationReasoner, RobotGeometry
        from pycram.robots.common.sim_resolvers import known_objects_of
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
            #: The belief each reasoner's prospection is built from (empty but for `neighbours`
            #: while a question about a spot among other objects is answered).
            self._beliefs: dict[str | None, BeliefState] = {}
            for container in [None, *self.openings]:  # None: every container closed
                belief = BeliefState(self.environment)
                if container is not None:
                    belief.container_states[container] = self.openings[container]
                self._beliefs[container] = belief
                self._reasoners[container] = LocationReasoner(
                    geometry,
                    _constant(self.environment),
                    _constant(world.prospection(belief)),
                    partial(known_objects_of, belief),
                    container_states=_constant(dict(belief.container_states)),
                )
        finally:
            world.close()
        self._placeable: dict[tuple[str, str], tuple[bool, str]] = {}
        self._openable: dict[str, tuple[bool, str]] = {}
        self._lock = threading.Lock()

    def _first(self, container: str | None, properties: list[tuple[str, Any]]) -> Any:
        """The first solution of the designator of `properties` (NoSolutionError when none)."""
        generator = self._reasoners[container].generator(LocationDesignator(properties))
        for solution in generator:
            return solution
        raise NoSolutionError(f"no solution for {properties!r}")

    def graspable(
        self,
        type_name: str,
        position: Sequence[float],
        yaw: float = 0.0,
        support: str | None = None,
        neighbours: Sequence[Placement] = (),
        as_perceived: bool = False,
        margin: float = 0.0,
    ) -> tuple[bool, str]:
        """Whether some standing pose grasps an upright `type_name` object standing with its
        centre at `position` [m] turned by `yaw` [rad]; with the pose found, or why none is.

        On an open surface (`support` None or not inside a container) every container is
        closed; on the inside `support` of a container (`position` as it stands with the
        container closed) the container is opened as `Open` opens it (`openings`: a drawer's
        inside slides out with it) and the others are closed. `neighbours` (placements of other
        objects, e.g. those of the scene drawn so far) are counted as the robot's location
        reasoning counts the objects it believes in: as obstacles of its standing poses and
        arm motions, each believed where it stands (in an opened drawer: slid out with it). With
        `as_perceived`, the object's turn is the one perception measures (`perceived_yaw`: none
        for a round object, a box's up to the symmetry of its top), as the robot's reasoning gets
        it -- a cup's answer does not depend on which way it was drawn turned. With a `margin`
        [m], the object must be graspable also where it would stand that far off in each of the
        four directions along the map's axes (a spot on the edge of the robot's reach is not
        reached from a pose perceived a few millimetres off)."""
        from pycram.reasoning.locations import KnownObject

        container = self._container_of(support)
        if container is not None:
            opens, why = self.openable(container)
            if not opens:  # the object inside is out of reach however reachable it is once open
                return False, f"no standing pose opens {container}: {why}"
        turn = perceived_yaw(type_name, yaw) if as_perceived else float(yaw)
        x, y, z = self._as_opened(container, support, position)
        points = [(x, y, z)]
        if margin > 0.0:
            points += [(x + dx * margin, y + dy * margin, z) for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))]
        found = []
        with self._lock, self._believing(container, neighbours):
            for point in points:
                target = KnownObject(type_name, type_name, point, turn)
                try:
                    found.append(self._first(container, [("to_reach", target)]))
                except NoSolutionError as error:
                    off = "" if point == points[0] else f" {margin * 100:.0f} cm off"
                    return False, off.strip() + (": " if off else "") + str(error).split(": ", 1)[-1]
        return True, _describe(found[0])

    def openable(self, container: str) -> tuple[bool, str]:
        """Whether some standing pose opens `container` (closed, nothing else believed) as far
        as `Open` opens it (`openings`): ``to_open`` of the robot's location reasoning; with the
        pose found, or why none is (e.g. a drawer whose handle is too low for the arm). Cached."""
        with self._lock:
            if container not in self._openable:
                try:
                    location = self._first(None, [("to_open", container), ("opening", self.openings[container])])
                    self._openable[container] = (True, _describe(location))
                except NoSolutionError as error:
                    self._openable[container] = (False, str(error).split(": ", 1)[-1])
            return self._openable[container]

    def _container_of(self, support: str | None) -> str | None:
        """The container whose inside `support` is (None for an open surface or None)."""
        if support is None:
            return None
        container = self.environment.container_of(support)
        return None if container is None else container.name

    def _as_opened(
        self, container: str | None, support: str | None, position: Sequence[float]
    ) -> tuple[float, float, float]:
        """Where a point on `support` stands [m] once `container` is opened as in `openings`: a
        drawer's inside slides out along its opening direction; a door's shelves stay."""
        x, y, z = _xyz(position)
        if container is None:
            return (x, y, z)
        body = self.environment.container(container)
        if body.kind != "drawer" or support not in {s.name for s in body.interior}:
            return (x, y, z)
        dx, dy = body.opening_direction
        q = self.openings[container]
        return (x + dx * q, y + dy * q, z)

    @contextmanager
    def _believing(self, container: str | None, neighbours: Sequence[Placement]) -> Iterator[None]:
        """The belief of `container`'s reasoner holding `neighbours` (as perceived objects at
        their spots, as `_as_opened` moves them) while the block runs; empty again after."""
        belief = self._beliefs[container]
        added: list[str] = []
        try:
            for other in neighbours:
                x, y, z = self._as_opened(container, other.support, other.position)
                otype = object_type(other.type)
                axis = other.yaw + (math.pi / 2 if otype.shape == "box" and otype.size[1] > otype.size[0] else 0.0)
                name = f"{other.type}-{sum(1 for n in added if n.rsplit('-', 1)[0] == other.type) + 1}"
                belief.add(PerceivedObject(name, other.type, (x, y, z), {"axis": axis, "on": other.support}))
                added.append(name)
            yield
        finally:
            for name in added:
                belief.remove(name)

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


def perceived_yaw(type_name: str, yaw: float) -> float:
    """The turn [rad] perception reports for an upright `type_name` object turned by `yaw` [rad]
    (as `pycram.world.belief.PerceivedObject.yaw` has it): 0 for a round object (perception
    measures no turn of a cylinder, a bowl or a plate); for a box, `yaw` up to the symmetry of
    its top -- within [-45, 45) deg for a square top, within [-90, 90) deg otherwise."""
    otype = object_type(type_name)
    if otype.shape != "box":
        return 0.0
    period = math.pi / 2 if otype.size[0] == otype.size[1] else math.pi
    return (float(yaw) + period / 2) % period - period / 2


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
    among_placed: bool = False,
) -> tuple[Placement | None, Counter[tuple[str, bool]]]:
    """A spot for an upright `type_name` object drawn uniformly from the union of `surfaces`
    (surface names: open surfaces, and insides of containers -- the spot as it is with the
    container closed; a surface lying on another at the same height, e.g. a cooker on the
    counter, counts once), fully on a surface (`EDGE_MARGIN`), under its `Surface.clearance`,
    clear of the `placed` objects (`GAP`) and -- with `reach` -- where some standing pose grasps
    it (inside a container: the container opened as `Open` opens it). With `among_placed`, the
    reachability check judges as the robot's location reasoning would once it has seen the
    objects: it counts the `placed` objects as believed objects, takes the object's turn as
    perception reports it (`perceived_yaw`), wants it reached also `PERCEPTION_MARGIN` off (a
    spot on the edge of the reach is missed from a pose perceived a little off: measured, PR2
    dev seed 13, a cup reached at its drawn spot and from nowhere 4 mm away), and keeps the spot
    only when every placed object stays graspable with the new one beside it (whatever order
    the objects are fetched in). The object is named `name` (default: its type) and supported by
    the smallest of `surfaces` under it (a cooker rather than its counter).

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
        # the listed surfaces at the drawn one's height under the point (a drawer's inside below
        # the cabinet's top is another place)
        under = [s for s in listed if abs(s.height - surface.height) < 1e-6 and s.contains(x, y)]
        if not surface.contains(x, y) or rng.random() >= 1.0 / len(under):
            continue  # outside the drawn surface's polygon, or a point two listed surfaces share
        support = _support(environment, x, y, under)
        if 2.0 * otype.half_height >= support.clearance:
            continue  # does not fit under the shelf or into the drawer
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
            neighbours = list(placed) if among_placed else []
            margin = PERCEPTION_MARGIN if among_placed else 0.0
            ok, _ = reach.graspable(type_name, candidate.position, yaw, support.name, neighbours, among_placed, margin)
            if ok and among_placed:  # the objects drawn before stay graspable beside this one
                ok = all(
                    reach.graspable(
                        other.type,
                        other.position,
                        other.yaw,
                        other.support,
                        [p for p in placed if p is not other] + [candidate],
                        as_perceived=True,
                    )[0]
                    for other in placed
                )
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
