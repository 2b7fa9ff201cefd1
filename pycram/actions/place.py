"""Placing a held object, with recovery the CRAM way.

`Place(object, target)`: the object held (the result of `PickUp`, or the believed object or
designator that was picked up) is put at `target` -- a location designator (``('on', 'table')``),
a `Spot`, a point or a surface's name. Each attempt drives to a standing pose from which the arm
places there, lowers the object until the place pose or until it touches down (the arm is
blocked), lets go, retreats, and looks: the object must be seen within `PLACE_TOLERANCE` of
the spot, and standing on the surface (`resting_problem`): not measured taller than it is
(reason ``'not_resting'``: still held, or on something), nor lying (``'toppled'``). A look
that does not see the object or sees it not standing is taken again with the arm parked
before it is believed (the arm may hide the object; a look may miss it). While the base
drives, the gripper's opening is watched: an object slipping out raises `ObjectSlipped` at
once (`pursue`). Raises `GripperEmpty` when the gripper
holds nothing, `PlacingFailed` / `ObjectOutOfReach` after its attempts.

An object held from the top (bowls and plates, by the rim) is put down with the same grasp's
place sequence, the tool pointing down; one picked up lying on its side with a planned grasp
(`pycram.reasoning.grasps`) is put down as it hangs in the hand, lying (not counted as
toppled). The belief turns a put-down object by as much as the hand turned it since the grasp
(`Held.hand_turn`). Every attempt is a task of its own (kind ``attempt``),
so the task tree shows each recovery. The object let go of is removed from
`pycram.actions.held`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import replace
from functools import partial
from typing import Any

from pycram.core.expressions import State, pursue
from pycram.designators.action import ActionDesignator
from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import GripperEmpty, ObjectOutOfReach, ObjectSlipped, PlacingFailed, PlanFailure
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot
from pycram.reasoning.locations.targets import KnownObject
from pycram.world.belief import PerceivedObject, support_of
from pycram.world.environment import Surface
from pycram.world.objects import FOOTPRINT_SLACK, SIDE, Grasp, object_type

from .core import (
    RECOVERABLE,
    ActionParameterError,
    action_plan,
    arm_name,
    attempt,
    base_pose_fluent,
    best_effort,
    gripper_opening,
    make_action,
    motion,
    opening_fluent,
    solutions,
    unwrap,
)
from .handling import _look_again, _pose_text, _reach, _xyz, carry_configuration
from .held import Held, fingers_yaw, held_objects
from .pick_up import PickUp, executable_grasps

__all__ = [
    "Place",
    "PLACE_SPOTS",
    "PLACE_TOLERANCE",
    "resting_problem",
    "RESTING_SLACK",
    "FOOTPRINT_SLACK",
    "REGRASP_INSET",
]

log = logging.getLogger("pycram.actions")

#: Spots tried per placing (spots without a standing pose to place from included), and standing
#: poses per spot.
PLACE_SPOTS = 8
PLACE_STANDING_POSES = 2
#: A surface named as a placing target: spots near the side facing the robot, this far in [m].
NEAR_SIDE_INSET = 0.15
#: A placed object must be seen this close [m] (horizontally) to its spot.
PLACE_TOLERANCE = 0.05
#: A placed object measured taller than it is by more than this [m] does not rest on the surface.
RESTING_SLACK = 0.05


def Place(object: Any, target: Any, arm: str | None = None, regrasp: bool = True) -> ActionDesignator:
    """Put the held `object` (a `Held`, or the object designator / believed object picked up) at
    `target`: a location designator such as ``('on', 'table')``, a `Spot`, a point (x, y, z)
    [m, map: the object's centre] or a surface's name. With `regrasp`, an object that no
    standing pose puts at the target with the grasp it is held with, but another grasp of its
    type does, is put down within reach and taken again with that grasp (`regrasping`).
    Returns the believed object."""
    return make_action("placing", object=object, target=target, arm=arm, regrasp=None if regrasp else False)


def _held_for(designator: ActionDesignator) -> Held:
    wanted = designator.prop_value("object")
    arm = arm_name("placing", designator.prop_value("arm"))
    holding = held_objects()
    if isinstance(wanted, Held):
        return wanted
    candidates = [h for a, h in holding.items() if arm is None or a == arm]
    if isinstance(wanted, ObjectDesignator):
        candidates = [h for h in candidates if wanted.matches(h.object)]
    elif isinstance(wanted, PerceivedObject):
        candidates = [h for h in candidates if h.object is wanted]
    elif isinstance(wanted, str):
        candidates = [h for h in candidates if wanted in (h.object.type, h.object.name)]
    if not candidates:
        raise GripperEmpty(
            f"placing: no gripper holds {wanted!r} (holding: "
            f"{', '.join(f'{a}: {h.object.name}' for a, h in holding.items()) or 'nothing'})",
            designator,
        )
    return candidates[0]


def _believed_environment() -> Any:
    """The environment description the active robot's belief holds (None: it knows none)."""
    return getattr(getattr(current_robot(), "belief", None), "environment", None)


def _tool_point(spot: tuple[float, float, float], half: float, grasp: Grasp) -> list[float]:
    """Where the tool is [m, map] when an object of half height `half` [m] held with `grasp`
    stands with its centre at `spot`."""
    return [spot[0], spot[1], spot[2] - half + grasp.height]


def _near_side(surface_name: str) -> tuple[float, float, float] | None:
    """A point on the surface 0.15 m in from its edge nearest to the robot (None when the
    environment does not know the surface)."""
    environment = _believed_environment()
    if environment is None:
        return None
    try:
        surface = environment.surface(surface_name)
    except KeyError:
        return None
    here = base_pose_fluent().get_value()
    x0, y0, x1, y1 = surface.bounds
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    if here is None:
        return (cx, cy, surface.height)
    x, y = min(max(here.x, x0), x1), min(max(here.y, y0), y1)
    inset = min(NEAR_SIDE_INSET, (x1 - x0) / 2, (y1 - y0) / 2)
    x = min(max(x, x0 + inset), x1 - inset)
    y = min(max(y, y0 + inset), y1 - inset)
    return (x, y, surface.height)


def _spots(target: Any, held: Held) -> Any:
    """The spots `target` stands for, best first. A surface's name means: on that surface, near
    its side facing the robot (within easy reach of every arm); a location designator ``on`` or
    ``in`` something without ``for`` means spots for the held object's type."""
    if isinstance(target, str):
        near = _near_side(target)
        target = LocationDesignator(
            [("on", target), ("for", held.object.type)] + ([("near", near)] if near is not None else [])
        )
    if isinstance(target, LocationDesignator):
        if target.prop_value("for") is None and (target.prop_value("on") or target.prop_value("in")):
            # spots for this object: its centre above the surface, room for its footprint (without
            # ``for`` a spot is a point of the surface itself)
            target = target.copy([("for", held.object.type)])
        return solutions(target)
    if hasattr(target, "position"):
        return [tuple(target.position)]
    return [tuple(float(v) for v in target)]


def _drive_watching(location: Any, held: Held) -> None:
    """Drive to `location`; raise `ObjectSlipped` as soon as the gripper is measured empty."""
    fluent = opening_fluent(held.gripper)
    dropped = fluent < held.held_opening
    errors: list[BaseException] = []

    def watch() -> None:
        dropped.wait_for()
        raise ObjectSlipped(f"{held.object.name} fell out of the {held.gripper} gripper while driving", held.object)

    state = pursue(lambda: motion(type="moving", pose=location), watch, errors=errors, name="drive, holding")
    if state.get_value() is not State.SUCCEEDED:
        raise errors[0] if errors else PlanFailure("driving with the object did not succeed")


def _look_over(spot: tuple[float, float, float]) -> None:
    """Look at `spot` once (best effort): the base could not drive to a standing pose reasoning
    offered, so the world differs from the belief there -- e.g. a door swung back since it was
    opened. The look measures the containers in view and the objects there, and the next
    standing pose is resolved against that belief."""
    log.info("placing: no way to the standing pose; looking at %s again", _xyz(spot))
    best_effort(
        "looking at the spot",
        lambda: motion(type="pointing_head", coordinates=list(spot)),
        lambda: motion(type="detecting"),
    )


def _place_locations(held: Held, spot: tuple[float, float, float], point: list[float]) -> LocationDesignator:
    """Standing poses to put the held object at `spot`: for an object held from the top, the
    place sequence of that top grasp for the object standing at the spot (the tool keeps
    pointing down); else the tool point `point`, approached along the base's heading."""
    if held.grasp.approach == "top":
        standing = KnownObject(f"{held.object.name} at the spot", held.object.type, spot)
        # a type's own top grasp by its name; a planned one (`pycram.reasoning.grasps`: e.g. a
        # carton picked up lying) as it is held, so the object is put down as it hangs in the hand
        own = held.grasp in object_type(held.object.type).grasps
        grasp: Any = "top" if own else held.grasp
        return LocationDesignator([("to_reach", standing), ("arm", held.arm), ("grasp", grasp), ("action", "place")])
    return LocationDesignator([("to_reach", tuple(point)), ("arm", held.arm), ("action", "place")])


def _place_at(location: Any, held: Held, spot: tuple[float, float, float], point: list[float]) -> PerceivedObject:
    arm, gripper, obj = held.arm, held.gripper, held.object
    # picked up lying on its side (the belief keeps the size measured before it was grasped):
    # it is put down as it hangs in the hand, lying -- that is no toppling
    lying = obj.lying_axis is not None
    if held.grasp.approach != "top" and held.grasp.radius:  # held off its centre, towards the robot
        r = held.grasp.radius
        point = [point[0] - r * math.cos(location.yaw), point[1] - r * math.sin(location.yaw), point[2]]
    motion(type="setting_arm_configuration", arm=arm, configuration=carry_configuration(arm, held.grasp))
    torso = getattr(location, "torso", None)
    if torso is not None:  # validated at another torso height (e.g. lowered for a drawer before):
        # set before driving -- the arm raised to carry stands over the table at the goal, and with
        # the torso still low the robot would not fit there (measured: TIAGo, goal_in_collision)
        motion(type="setting_torso", position=torso)
    arrival = getattr(location, "arrival", ())
    if arrival:  # validated with the object lifted clear of the furniture there
        motion(type="setting_arm_joints", arm=arm, positions=list(arrival))
    _drive_watching(location, held)
    if gripper_opening(gripper) < held.held_opening:
        raise ObjectSlipped(f"{obj.name} is no longer in the {gripper} gripper", obj)
    _reach(arm, location, 0, "pre_place", point)
    try:
        _reach(arm, location, 1, "place", point)
    except RECOVERABLE as error:
        if getattr(unwrap(error), "reason", None) != "blocked":
            raise
        log.info("placing %s: touched down before the place pose (%s)", obj.name, unwrap(error))
    motion(type="setting_gripper", gripper=gripper, position=1)
    held_objects().pop(arm, None)
    belief = getattr(current_robot(), "belief", None)
    if belief is not None:
        belief.put_down(obj, spot, held.hand_turn(fingers_yaw(location)))  # it turned with the hand
    try:
        _reach(arm, location, 2, "retreat", point, obj)  # the fingers may still touch it
    except RECOVERABLE as error:  # the object is down: backing off is best effort
        log.info("placing %s: retreat: %s", obj.name, unwrap(error))
    motion(type="setting_arm_configuration", arm=arm, configuration="carry")
    # looks that miss the object in view are taken again until the belief holds it gone; a look
    # the arm hides it from leaves the put-down pose believed (parking the arm next to the
    # object just put down knocked it over: the TIAGo's cup, measured)
    _look_again(obj, spot)
    problem = None if obj.gone else resting_problem(obj, lying)
    if obj.gone or problem is not None:
        # the arm in its carry pose may hide the object (or its top), and looks may miss what is
        # there (missed detections): park the arm and look again before believing the looks
        why = "not seen" if problem is None else problem[1]
        log.info("placing %s: %s; parking the %s arm and looking again", obj.name, why, arm)
        motion(type="setting_arm_configuration", arm=arm, configuration="park")
        _look_again(obj, spot)
        problem = None if obj.gone else resting_problem(obj, lying)
    if problem is not None:
        reason, why = problem
        raise PlacingFailed(f"{obj.name} does not rest upright at {_xyz(spot)}: {why}", obj, reason)
    if obj.gone or math.dist(obj.pose[:2], spot[:2]) > PLACE_TOLERANCE:
        where = "not seen there after letting go" if obj.gone else f"seen at {_xyz(obj.pose)}"
        raise PlacingFailed(f"{obj.name} is not at its target {_xyz(spot)}: {where}", obj, "not_at_target")
    return obj


def _lost_from_gripper(held: Held, park: bool = False) -> None:
    """The gripper was measured empty: it holds nothing any more, and the object is not where
    the belief last had it (where it was picked up) -- a search must find it. With `park`
    (lost on the way, the base stopped in the open), the empty arm is parked: raised in its
    carry pose it stands in front of the head camera, and the search that follows did not see
    the object on the counter ahead (measured: the PR2's, a cup 0.8 m ahead unseen in six
    looks). Parking is best effort."""
    held_objects().pop(held.arm, None)
    belief = getattr(current_robot(), "belief", None)
    if belief is not None:
        belief.lost(held.object)
    if park:
        best_effort(
            f"park the empty {held.arm} arm",
            lambda: motion(type="setting_arm_configuration", arm=held.arm, configuration="park"),
        )


def resting_problem(obj: PerceivedObject, lying: bool = False) -> tuple[str, str] | None:
    """Why the measured `obj` does not stand upright on its surface -- ``('toppled', why)`` or
    ``('not_resting', why)`` -- or None when its measured height fits. With `lying` (it was put
    down lying, as it was picked up) only ``'not_resting'`` is a problem.

    Perception measures an object's height from the surface it is over to its top. Taller than
    the object by more than `RESTING_SLACK`: it does not rest on the surface (still in the
    gripper, or on something). Wider than its standing footprint by more than `FOOTPRINT_SLACK`:
    it lies on its side (a cup seen from above). For types whose standing and lying heights
    differ clearly (`ObjectType.topples_visibly`: milk, cereal, mug): nearer the lying than the
    standing height means toppled. Something between the camera and the object's top (the robot's own arm in
    its carry pose) makes a standing object look short: `Place` looks again with the arm parked
    before it believes either."""
    kind = object_type(obj.type)
    size = obj.properties.get("size")
    if not size or obj.properties.get("on") is None:
        return None
    measured = float(size[2])
    if measured > kind.height + RESTING_SLACK:
        return "not_resting", (
            f"its top is measured {measured * 100:.0f} cm above the {obj.properties['on']}, "
            f"a {kind.name} is {kind.height * 100:.0f} cm tall (still held, or on something)"
        )
    if lying:
        return None
    wide = max(float(size[0]), float(size[1]))
    if wide > 2.0 * kind.footprint_radius + FOOTPRINT_SLACK:
        return "toppled", (
            f"measured {wide * 100:.0f} cm across, standing it is at most "
            f"{2 * kind.footprint_radius * 100:.0f} cm across"
        )
    if kind.topples_visibly and measured < (kind.height + kind.lying_height) / 2.0:
        return "toppled", (
            f"measured {measured * 100:.0f} cm tall, {kind.height * 100:.0f} cm standing, "
            f"at most {kind.lying_height * 100:.0f} cm toppled over"
        )
    return None


@action_plan("placing")
def placing(designator: ActionDesignator) -> PerceivedObject:
    target = designator.prop_value("target")
    if target is None:
        raise ActionParameterError("placing", "target", "missing: where to put the object")
    held = _held_for(designator)
    if gripper_opening(held.gripper) < held.held_opening:
        _lost_from_gripper(held)
        raise GripperEmpty(f"the {held.gripper} gripper holds nothing ({held.object.name} was in it)", designator)
    half = object_type(held.object.type).half_height
    attempts: list[str] = []
    tried: list[tuple[float, float, float]] = []
    last: BaseException | None = None
    try:
        for spot_number, spot in enumerate(_spots(target, held), start=1):
            if spot_number > PLACE_SPOTS:
                break
            spot = tuple(float(v) for v in spot)
            tried.append(spot)
            point = _tool_point(spot, half, held.grasp)
            locations = _place_locations(held, spot, point)
            try:
                for pose_number, location in enumerate(solutions(locations), start=1):
                    if pose_number > PLACE_STANDING_POSES:
                        break
                    try:
                        placed: PerceivedObject = attempt(
                            f"place {held.object.name} at {_xyz(spot)} from {_pose_text(location)}",
                            partial(_place_at, location, held, spot, point),
                        )
                    except RECOVERABLE as error:
                        cause = last = unwrap(error)
                        attempts.append(f"at {_xyz(spot)} from {_pose_text(location)}: {cause}")
                        if isinstance(cause, ObjectSlipped):
                            _lost_from_gripper(held, park=True)
                        if isinstance(cause, (ObjectSlipped, PlacingFailed)):
                            raise cause from error
                        if getattr(cause, "reason", None) == "no_path":
                            _look_over(spot)
                        if held.arm not in held_objects():  # let go already: nothing to retry with
                            raise PlacingFailed(
                                f"{held.object.name} was let go at {_xyz(spot)}, then: {cause}",
                                designator,
                                attempts=attempts,
                            ) from error
                    else:
                        return placed
            except NoSolutionError as error:
                attempts.append(f"at {_xyz(spot)}: {error}")
                last = error
    except NoSolutionError as error:
        raise ObjectOutOfReach(
            f"no spot at {target!r} for {held.object.name}: {error}", designator, attempts=attempts
        ) from error
    message = f"could not place {held.object.name} at {target!r}: " + "; ".join(attempts)
    if last is None or isinstance(last, NoSolutionError):
        if designator.prop_value("regrasp") is not False:
            for spot in tried:
                grasp = _grasp_reaching(held, spot)
                if grasp is not None:
                    return regrasping(held, spot, grasp, message)
        raise ObjectOutOfReach(message, designator, attempts=attempts) from last
    raise PlacingFailed(message, designator, getattr(last, "reason", None), attempts) from last


# -- regrasping: another grasp for a target the held grasp does not reach ------------------------

#: Put down for a regrasp this far [m] in from the surface's edge (then taken from that side).
REGRASP_INSET = 0.15


def _grasp_reaching(held: Held, spot: tuple[float, float, float]) -> Grasp | None:
    """Another grasp of the held object's type (one the robot executes) with which some standing
    pose puts it at `spot` -- asked of location reasoning, nothing moves; None when there is
    none, and for an object held with a grasp planned for it (lying on its side: it is put down
    as it hangs in the hand)."""
    if held.grasp not in object_type(held.object.type).grasps:
        return None
    half = object_type(held.object.type).half_height
    for grasp in executable_grasps(held.object.type):
        if grasp.approach == held.grasp.approach:
            continue
        other = replace(held, grasp=grasp)
        point = _tool_point(spot, half, grasp)
        try:
            next(iter(solutions(_place_locations(other, spot, point))))
        except (NoSolutionError, StopIteration):
            continue
        return grasp
    return None


def _surface_under(spot: tuple[float, float, float], half: float) -> Surface | None:
    """The open surface (no furniture over it) an object of half height `half` [m] stands on
    with its centre at `spot` (`support_of`, within 5 cm of its bottom), None when the
    environment knows none there."""
    environment = _believed_environment()
    if environment is None:
        return None
    bottom = spot[2] - half
    surface = support_of(environment, spot[0], spot[1], bottom)
    if surface is None or surface.clearance != math.inf or abs(bottom - surface.height) >= 0.05:
        return None
    return surface


def _edge_points(surface: Surface, spot: tuple[float, float, float]) -> list[tuple[float, float, float]]:
    """Points `REGRASP_INSET` in from each edge of `surface`, across from `spot`, nearest first:
    where an object is put down to be taken again from that side."""
    points = []
    for a, b, n in surface.edges():
        dx, dy = b[0] - a[0], b[1] - a[1]
        t = min(max(((spot[0] - a[0]) * dx + (spot[1] - a[1]) * dy) / (dx * dx + dy * dy), 0.0), 1.0)
        x, y = a[0] + t * dx - REGRASP_INSET * n[0], a[1] + t * dy - REGRASP_INSET * n[1]
        if surface.contains(x, y):
            points.append((x, y, surface.height))
    return sorted(points, key=lambda p: math.dist(p[:2], spot[:2]))


def regrasping(held: Held, spot: tuple[float, float, float], grasp: Grasp, why: str) -> PerceivedObject:
    """Put the held object down within reach on the surface under `spot` (near one of its edges,
    the nearest to the spot first), take it again with `grasp`'s approach (`PickUp`: a
    horizontal grasp from any side, or from the top) and place it at `spot`. Measured: a
    cereal box the PR2 took from the top, as it stood, reaches no spot 0.45 m in on the table
    that way, from the side it does. Raises `ObjectOutOfReach` (with `why`, the failed
    placing) when it cannot be put down anywhere within reach -- it is still held then; the
    failures of the pick-up and of the placing after it as they are."""
    obj = held.object
    kind = object_type(obj.type)
    surface = _surface_under(spot, kind.half_height)
    if surface is None:
        raise ObjectOutOfReach(f"{why}; no surface under {_xyz(spot)} to put it down on and take it again", obj)
    approach = "top" if grasp.approach == "top" else SIDE
    log.info(
        "placing %s: held %s it reaches no spot; putting it down to take it %s", obj.name, held.grasp.approach, approach
    )
    down: PerceivedObject | None = None
    failures = []
    for point in _edge_points(surface, spot):
        near = LocationDesignator([("on", surface.name), ("for", obj.type), ("near", point)])
        try:
            down = perform(Place(held, near, arm=held.arm, regrasp=False))
            break
        except ObjectOutOfReach as error:
            failures.append(str(error))
    if down is None:
        raise ObjectOutOfReach(f"{why}; regrasping: put down nowhere on {surface.name}: {'; '.join(failures)}", obj)
    again: Held = perform(PickUp(down, arm=held.arm, grasp=approach))
    placed: PerceivedObject = perform(Place(again, spot, arm=again.arm, regrasp=False))
    return placed
