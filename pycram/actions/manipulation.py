"""Picking up and placing objects, with recovery the CRAM way.

`PickUp(object=cup)`: the object is taken from the belief (searched for when not believed);
``('to_reach', object)`` chooses the standing pose, the arm and the grasp. One attempt drives
there, looks at the object again, grasps (pre-grasp, grasp, close), lifts and carries. Recovery:

- the standing pose cannot be driven to, the arm cannot reach, or the gripper closed on nothing:
  the next standing pose (``next_solution()``) -- at most `STANDING_POSES` per perception;
- the object moved since it was perceived (seen again more than `MOVED` away): location reasoning
  again, for the new pose -- at most `PICK_ROUNDS` perceptions;
- the object is gone from where it was believed: it is searched for again.

After its attempts it raises `ObjectOutOfReach` (no standing pose at all) or `GraspFailed` (with
every attempt's failure in ``attempts``). Success is checked from the sensors: the gripper's
measured opening after closing and after lifting (an empty gripper closes to almost 0).

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

Top grasps (bowls and plates, by the rim) follow the tool poses location reasoning validated,
the tool pointing down; an object held from the top is put down with the same grasp's place
sequence. Every attempt is a task of its own (kind ``attempt``), so the task tree shows each
recovery.
"""

from __future__ import annotations

import logging
import math
import weakref
from dataclasses import dataclass
from functools import partial
from typing import Any

from pycram.core.expressions import State, pursue
from pycram.designators.action import ActionDesignator
from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import (
    GraspFailed,
    GripperEmpty,
    NavigationFailure,
    ObjectNotVisible,
    ObjectOutOfReach,
    ObjectSlipped,
    PlacingFailed,
    PlanFailure,
)
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot
from pycram.reasoning.locations.targets import KnownObject
from pycram.world.belief import PerceivedObject
from pycram.world.objects import OBJECT_TYPES, Grasp, object_type

from .core import (
    RECOVERABLE,
    ActionParameterError,
    _description,
    action_plan,
    arm_name,
    arms,
    attempt,
    base_pose_fluent,
    best_effort,
    gripper_of,
    gripper_opening,
    make_action,
    motion,
    opening_fluent,
    solutions,
    unwrap,
)
from .search import search_for

__all__ = [
    "PickUp",
    "Place",
    "Held",
    "held_objects",
    "PICK_ROUNDS",
    "STANDING_POSES",
    "MOVED",
    "PLACE_SPOTS",
    "PLACE_TOLERANCE",
    "HELD_FRACTION",
    "executable_grasps",
    "resting_problem",
    "RESTING_SLACK",
    "FOOTPRINT_SLACK",
]

log = logging.getLogger("pycram.actions")

#: Perceptions of the object per pick-up (the object moved or was lost in between).
PICK_ROUNDS = 3
#: Standing poses tried per perception.
STANDING_POSES = 2
#: The object counts as moved when seen again farther than this [m] from where it was planned for
#: -- or than `MOVED_FRACTION` of its footprint radius, for wide objects: the perceived centre of
#: a plate or bowl depends on the view (its far rim hidden by its near one), by up to ~5 cm.
MOVED = 0.03
MOVED_FRACTION = 0.5
#: Spots tried per placing (spots without a standing pose to place from included), and standing
#: poses per spot.
PLACE_SPOTS = 8
PLACE_STANDING_POSES = 2
#: Picking from a drawer that is not far enough out: it is pulled to this much [m] short of its
#: slide's end.
WIDE_MARGIN = 0.03
#: Picking from a drawer: it is pulled out until the object's footprint is this far [m] out from
#: under the furniture (the hand is wider than the object, and the handles of the drawers above
#: stick out 4 cm).
OUT_FROM_UNDER = 0.12
#: A surface named as a placing target: spots near the side facing the robot, this far in [m].
NEAR_SIDE_INSET = 0.15
#: A placed object must be seen this close [m] (horizontally) to its spot.
PLACE_TOLERANCE = 0.05
#: A placed object measured taller than it is by more than this [m] does not rest on the surface.
RESTING_SLACK = 0.05
#: ... and one measured wider than its standing footprint by more than this [m] lies on its side.
FOOTPRINT_SLACK = 0.02
#: The gripper holds the object when its opening is at least this fraction of the grasp's opening.
HELD_FRACTION = 0.5
#: Looks at an object that should be in view before the action believes what they tell: it is
#: looked at again while it is missed but not believed gone yet (`BeliefState.misses_to_gone`).
LOOKS_TO_CONFIRM = 3
#: After picking up or putting down at a surface, the base backs straight away from it by this
#: much [m] before it drives on: the arm in its carry pose still reaches ~0.65 m ahead, over the
#: surface, and the path planner keeps only the base off a counter the arms reach over -- driving
#: along the counter from there, the carried plate swept a milk carton over (measured: PR2,
#: set-table seed 31 with faults; the carton was then picked up lying and could not be placed).
BACK_AWAY = 0.3
#: The named torso position objects are carried at (a robot without a torso keeps its own).
CARRY_TORSO = "up"


@dataclass
class Held:
    """An object in a gripper: the believed `object`, the `arm` and `gripper`, and the `grasp`."""

    object: PerceivedObject
    arm: str
    gripper: str
    grasp: Grasp

    @property
    def held_opening(self) -> float:
        """Below this measured opening [m] the gripper holds nothing."""
        return HELD_FRACTION * self.grasp.opening


_holding: weakref.WeakKeyDictionary[Any, dict[str, Held]] = weakref.WeakKeyDictionary()


def held_objects() -> dict[str, Held]:
    """What the active robot's grippers hold, as far as its actions know (arm -> `Held`)."""
    return _holding.setdefault(current_robot(), {})


# -- constructors -------------------------------------------------------------------------------


def PickUp(object: Any, arm: str | None = None, grasp: str | None = None) -> ActionDesignator:
    """Pick up `object` (an object designator, or a believed object) with `arm` (None: the
    reasoning chooses) and `grasp` (an approach such as ``'side'`` or ``'+y'``; None: any the
    robot can execute). Returns a `Held`."""
    return make_action("picking_up", object=object, arm=arm, grasp=grasp)


def Place(object: Any, target: Any, arm: str | None = None) -> ActionDesignator:
    """Put the held `object` (a `Held`, or the object designator / believed object picked up) at
    `target`: a location designator such as ``('on', 'table')``, a `Spot`, a point (x, y, z)
    [m, map: the object's centre] or a surface's name. Returns the believed object."""
    return make_action("placing", object=object, target=target, arm=arm)


# -- helpers --------------------------------------------------------------------------------------


def executable_grasps(type_name: str, requested: str | None = None) -> list[Grasp]:
    """The grasps of an object type that picking up can execute with the active robot: the
    horizontal approaches, and ``top`` when its ``reaching`` motion takes a tool orientation
    (then the tool follows the poses location reasoning validated)."""
    types = getattr(current_robot(), "motion_types", None) or {}
    reaching = types.get("reaching")
    top_ok = reaching is not None and any(k.name == "orientation" for k in reaching.all_keys())
    grasps = [g for g in object_type(type_name).grasps if top_ok or g.approach != "top"]
    if requested is not None:
        grasps = [g for g in grasps if g.approach == requested]
    return grasps


def carry_configuration(arm: str, grasp: Grasp) -> str:
    """The named arm configuration to carry an object held with `grasp` in: ``carry_top`` (the
    tool pointing down, the object level) for top grasps of rims and across an axis (bowls,
    plates, spoons) when the robot's description has it, else ``carry`` -- also for the top grasp
    of a cup's or mug's body (out of a drawer): carried in ``carry_top`` and put down on the
    table, the PR2's cup ended tilted 75 deg (measured), in ``carry`` upright."""
    named = getattr(_description(), "ARM_CONFIGURATIONS", {}).get(arm, {})
    body = grasp.across == "radial" and grasp.radius == 0.0
    return "carry_top" if grasp.approach == "top" and not body and "carry_top" in named else "carry"


def _reach(arm: str, location: Any, index: int, phase: str, point: list[float] | None) -> None:
    """Reach phase `phase` of a sequence: the `index`-th validated tool pose of `location` when
    it has them (top grasps: the tool's orientation matters), else `point` with the phase's
    offset along the base's heading."""
    poses = getattr(location, "tool_poses", ())
    if location.grasp == "top" and len(poses) > index:
        position, orientation = poses[index]
        motion(type="reaching", arm=arm, target=list(position), orientation=list(orientation), phase=phase)
    else:
        motion(type="reaching", arm=arm, target=point, phase=phase)


def believed_object(action: str, wanted: Any) -> PerceivedObject:
    """The believed object `wanted` stands for; an object designator the belief does not
    satisfy is searched for."""
    if isinstance(wanted, Held):
        return wanted.object
    if isinstance(wanted, PerceivedObject):
        return wanted
    if isinstance(wanted, str):
        wanted = ObjectDesignator(type=wanted)
    if not isinstance(wanted, ObjectDesignator):
        raise ActionParameterError(
            action, "object", f"needs an object designator, a believed object or a type name, got {wanted!r}"
        )
    return _search(wanted)


def _search(description: ObjectDesignator) -> PerceivedObject:
    """`search_for`, opening closed drawers with the `Open` action, one at a time."""
    from .containers import opening_one_at_a_time

    found: PerceivedObject = search_for(description, open_container=opening_one_at_a_time())
    return found


def _search_again(wanted: Any, obj: PerceivedObject) -> PerceivedObject:
    """Search for the object again (a fresh designator: the old one is equated to what was lost)."""
    description = wanted.copy() if isinstance(wanted, ObjectDesignator) else ObjectDesignator(type=obj.type)
    assert isinstance(description, ObjectDesignator)
    return _search(description)


def _grasp_point(obj: PerceivedObject, grasp: Grasp, heading: float) -> list[float]:
    """The tool point [m, map] of a horizontal `grasp` of `obj`, approached along `heading` [rad]."""
    return list(grasp.side_point(obj.pose, object_type(obj.type).half_height, heading))


def _pose_text(location: Any) -> str:
    return f"({location.x:.2f}, {location.y:.2f})"


class _ObjectMoved(PlanFailure):
    """Internal: the object was seen elsewhere than planned for (perceive and reason again)."""

    default_reason = "object_moved"


def _let_go_and_retract(arm: str, gripper: str, point: list[float] | None, location: Any = None) -> None:
    """Best effort after a failed grasp: open the gripper, back off, arm up for driving."""

    def retreat() -> None:
        if location is not None and location.grasp == "top":
            _reach(arm, location, 0, "pre_grasp", point)  # straight up, as it came
        elif point:
            motion(type="reaching", arm=arm, target=point, phase="retreat")

    best_effort(
        "clean-up after a failed grasp",
        lambda: motion(type="setting_gripper", gripper=gripper, position=1),
        retreat,
        lambda: motion(type="setting_arm_configuration", arm=arm, configuration="carry"),
    )
    back_away("a failed grasp")


def back_away(why: str, distance: float = BACK_AWAY) -> None:
    """Best effort: drive the base `distance` [m] straight back (a planned drive, so it stops
    short of anything behind it rather than touching it); a failure is logged, not raised (the
    object is held or down already)."""
    best_effort(
        f"backing away after {why}",
        lambda: motion(type="moving", pose=(-distance, 0.0, 0.0), frame="base_footprint"),
    )


def _arm_to_drive(arm: str, configuration: str) -> None:
    """Move `arm` to `configuration` before driving; blocked where the robot stands (beside the
    furniture it just worked at: the TIAGo's arm against the cupboard's side after pushing its
    door shut, 5 of 200 faulted set-table seeds), the base backs away `BACK_AWAY` and it tries
    once more (raising that failure)."""
    try:
        motion(type="setting_arm_configuration", arm=arm, configuration=configuration)
    except RECOVERABLE as error:
        if getattr(unwrap(error), "reason", None) != "blocked":
            raise
        log.info("the %s arm is blocked on its way to %s: backing away first (%s)", arm, configuration, unwrap(error))
        back_away(f"the {arm} arm was blocked")
        motion(type="setting_arm_configuration", arm=arm, configuration=configuration)


def _look_again(obj: PerceivedObject, point: Any = None) -> bool:
    """Point the head at the believed object (or at `point` [m, map]) and look; True when it was
    seen. The belief is refreshed, or counts a miss when the object should have been seen (not
    hidden, e.g. by the robot's own arm) and was not: then the robot looks again, until the
    object is seen or has been missed as often in a row as the belief needs to hold it gone
    (`BeliefState.misses_to_gone`: one missed detection is no proof that the object is not
    there), at most `LOOKS_TO_CONFIRM` looks."""
    belief = getattr(current_robot(), "belief", None)
    needed = int(getattr(belief, "misses_to_gone", 1))
    seen_before, missed_before = obj.times_seen, obj.misses
    target = list(obj.pose if point is None else point)
    for _ in range(LOOKS_TO_CONFIRM):
        misses = obj.misses
        motion(type="pointing_head", coordinates=target)
        motion(type="detecting", object=obj.type)
        if obj.times_seen > seen_before:
            return True
        if obj.misses == misses or obj.misses - missed_before >= needed:
            return False  # hidden from this view (looking again will not tell), or missed enough
    return False


def _grasp_from(location: Any, obj: PerceivedObject, grasp: Grasp) -> Held:
    """One pick-up attempt from the standing pose `location` (see the module's description)."""
    arm = location.arm
    gripper = gripper_of(arm)
    planned = tuple(obj.pose)
    motion(type="setting_gripper", gripper=gripper, position=1)
    # raised over the furniture; for a top grasp with the tool pointing down (``carry_top``),
    # which also keeps the arm out of the camera's view of a flat object (measured: the PR2's
    # ``carry`` gripper hid 12 of a spoon's 15 cm, its centre was seen 6 cm off)
    # a deep object (the cereal box) reaches out towards the robot: the raised arm, 0.6 m ahead,
    # bumped it while the base drove up (measured: the TIAGo's, 1 in 4 runs), so the arm is parked
    deep = grasp.approach != "top" and grasp.radius > 0.0
    _arm_to_drive(arm, "park" if deep else carry_configuration(arm, grasp))
    # another arm that holds nothing is parked: raised to carry, it stands over the counter beside
    # the object and swept a milk carton over as the base drove up (measured: the PR2's)
    for other in arms():
        if other != arm and other not in held_objects():
            best_effort(
                f"parking the empty {other} arm",
                partial(motion, type="setting_arm_configuration", arm=other, configuration="park"),
            )
    motion(type="moving", pose=location)
    torso = getattr(location, "torso", None)
    if torso is not None:  # e.g. in a low drawer: the sequence was validated at another torso height
        # only once there: a torso lowered where the robot stood would sweep its raised arm over
        # the table or counter beside it
        motion(type="setting_torso", position=torso)
    seen = _look_again(obj)
    if not seen and not obj.gone and not deep:
        # hidden from this view -- by the robot's own arm, raised to carry, whose gripper stands
        # just in front of the object here. The pose believed may then come from a partial view
        # from elsewhere (measured: the TIAGo's, a milk carton believed from a 1.5-cm sliver of
        # it, 3.5 cm off: the fingers knocked it over), so the arm is parked for a look
        log.info("grasping %s: hidden from the standing pose; parking the %s arm to look", obj.name, arm)
        motion(type="setting_arm_configuration", arm=arm, configuration="park")
        _look_again(obj)
        if not obj.gone:
            motion(type="setting_arm_configuration", arm=arm, configuration=carry_configuration(arm, grasp))
    if obj.gone:
        raise ObjectNotVisible(f"{obj.name} is no longer where it was believed ({_xyz(planned)})", obj, "lost")
    moved = max(MOVED, MOVED_FRACTION * object_type(obj.type).footprint_radius)
    if math.dist(obj.pose, planned) > moved:
        raise _ObjectMoved(f"{obj.name} moved from {_xyz(planned)} to {_xyz(obj.pose)}", obj)
    poses: Any = getattr(location, "tool_poses", ())
    if location.grasp == "top" and len(poses) > 1:  # validated for where the object was then
        off = abs(math.dist(poses[1][0][:2], obj.pose[:2]) - grasp.radius)
        if off > moved:
            raise _ObjectMoved(f"{obj.name} is {off:.2f} m off the grasp planned for it", obj)
    point = _grasp_point(obj, grasp, location.yaw)
    try:
        if grasp.approach != "top" and grasp.radius:
            # a deep object (a cereal box) reaches towards the robot: the raised gripper would
            # swing into it on its way to the pre-grasp pose (measured: the TIAGo knocked the
            # cereal box over), so it comes to a pose `radius` farther back first -- where the
            # arm reaches that close to the body (the PR2's often does not: then straight on)
            c, s = math.cos(location.yaw), math.sin(location.yaw)
            back = [point[0] - grasp.radius * c, point[1] - grasp.radius * s, point[2]]
            try:
                motion(type="reaching", arm=arm, target=back, phase="pre_grasp")
            except RECOVERABLE as error:
                log.info("grasping %s: no pose farther back first (%s)", obj.name, unwrap(error))
        _reach(arm, location, 0, "pre_grasp", point)
        _reach(arm, location, 1, "grasp", point)
        opening = float(motion(type="setting_gripper", gripper=gripper, position=0))
    except RECOVERABLE:
        _let_go_and_retract(arm, gripper, point, location)
        raise
    held = Held(obj, arm, gripper, grasp)
    if opening < held.held_opening:
        _let_go_and_retract(arm, gripper, point, location)
        if not _look_again(obj):  # closed on nothing where it was believed, and not seen there: gone
            belief = getattr(current_robot(), "belief", None)
            if belief is not None:
                belief.lost(obj)
            raise ObjectNotVisible(
                f"the {gripper} gripper closed on nothing: {obj.name} is no longer at {_xyz(planned)}", obj, "lost"
            )
        raise GraspFailed(
            f"the {gripper} gripper closed on nothing at {_xyz(point)} (opening {opening * 1000:.1f} mm)", obj
        )
    # in hand from now on: a look while it is lifted (e.g. a plan's look for the next object)
    # must not take it for another object standing in the air
    belief = getattr(current_robot(), "belief", None)
    if belief is not None:
        belief.picked_up(obj, gripper)
    try:
        _reach(arm, location, 2, "lift", point)
        motion(type="setting_arm_configuration", arm=arm, configuration=carry_configuration(arm, grasp))
        back_away(f"picking up {obj.name}")
        # carried with the torso up (`CARRY_TORSO`), once backed away from the furniture: from a
        # drawer, picked with the torso low, the PR2's carried cup hung 4 cm above the table top
        # and the hand swept the plate set there 13 cm aside as the base drove up (measured:
        # set-table seeds 8, 12, the cup in drawer 2)
        best_effort(
            f"raising the torso to carry {obj.name}", partial(motion, type="setting_torso", position=CARRY_TORSO)
        )
        opening = gripper_opening(gripper)
        if opening < held.held_opening:
            raise ObjectSlipped(f"{obj.name} slipped out of the {gripper} gripper while lifting it away", obj)
    except BaseException:
        if belief is not None:
            belief.released(obj)
        raise
    return held


def _xyz(p: Any) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"


# -- picking up -----------------------------------------------------------------------------------


@action_plan("picking_up")
def picking_up(designator: ActionDesignator) -> Held:
    from .containers import Open

    wanted = designator.prop_value("object")
    if wanted is not None:
        # in a drawer pulled out only part of the way, the object may still be under the furniture
        obj = believed_object("picking_up", wanted)
        needed = _wider_opening(obj, as_far_as_needed=True)
        if needed is not None:
            log.info("%s is behind the door or under the furniture of %s: opening it", obj.name, obj.properties["in"])
            perform(Open(obj.properties["in"], opening=needed))
            _look_again(obj)
    try:
        return _pick_up(designator)
    except ObjectOutOfReach:
        # still out of reach: the drawer all the way out (the object farther from the furniture)
        obj = believed_object("picking_up", designator.prop_value("object"))
        wider = _wider_opening(obj)
        if wider is None:
            raise
        log.info("%s is out of reach in %s: opening it further", obj.name, obj.properties["in"])
        perform(Open(obj.properties["in"], opening=wider))
        _look_again(obj)
        return _pick_up(designator)


def _wider_opening(obj: PerceivedObject, as_far_as_needed: bool = False) -> float | None:
    """How far [m] to pull out the drawer `obj` lies in: near the slide's end, or -- with
    `as_far_as_needed` -- just so far that the object is `OUT_FROM_UNDER` out from under the
    furniture (its footprint past the closed drawer's front). Behind a door (a cupboard's, the
    fridge's) believed open less than `DOOR_USEFUL`: `DOOR_OPENING` [rad] (the object was seen
    inside, and the door was closed since or stuck part way). None when it is in no container or
    the container is (about) that far open already."""
    from .containers import DOOR_OPENING, DOOR_USEFUL

    name = obj.properties.get("in")
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if not name or belief is None or environment is None or obj.pose is None:
        return None
    container = environment.container(name)
    if container.kind == "door":
        return DOOR_OPENING if abs(float(belief.container_states.get(name, 0.0))) < DOOR_USEFUL else None
    if container.kind != "drawer":
        return None
    wide = container.limits[1] - WIDE_MARGIN
    now = float(belief.container_states.get(name, 0.0))
    goal = wide
    if as_far_as_needed:
        radius = object_type(obj.type).footprint_radius if obj.type in OBJECT_TYPES else 0.05
        out = container.along_slide(obj.pose[0], obj.pose[1]) - radius - container.front  # [m] past the front now
        goal = min(container.limits[1], now + OUT_FROM_UNDER - out)
    return goal if now < goal - WIDE_MARGIN else None


def _pick_up(designator: ActionDesignator) -> Held:
    wanted = designator.prop_value("object")
    if wanted is None:
        raise ActionParameterError("picking_up", "object", "missing: what to pick up")
    arm = arm_name("picking_up", designator.prop_value("arm"))
    requested_grasp = designator.prop_value("grasp")
    obj = believed_object("picking_up", wanted)
    grasps = executable_grasps(obj.type, requested_grasp)
    if not obj.properties.get("in"):
        # on an open surface: from the torso height it carries at (``'up'``), not one left low by
        # a drawer opened before -- the arm going to its carry pose with the torso low swept the
        # milk carton it held into the counter's edge and off (measured: the PR2, set-table with
        # the cup in drawer 2, seed 6); location reasoning may still choose another height
        motion(type="setting_torso", position=CARRY_TORSO)
    if not grasps:
        available = [g.approach for g in object_type(obj.type).grasps]
        raise GraspFailed(
            f"the robot cannot execute a grasp {requested_grasp or ''} of a {obj.type} "
            f"(its grasps: {', '.join(available)}; from the top only when the robot's reaching "
            f"motion takes a tool orientation)",
            designator,
            "no_executable_grasp",
        )
    by_approach = {g.approach: g for g in grasps}
    attempts: list[str] = []
    last: BaseException | None = None
    for _ in range(PICK_ROUNDS):
        properties: list[tuple[str, Any]] = [("to_reach", obj)]
        if arm is not None:
            properties.append(("arm", arm))
        if requested_grasp is not None:
            properties.append(("grasp", requested_grasp))
        tried = 0
        perceive_again = False
        try:
            for location in solutions(LocationDesignator(properties)):
                grasp = by_approach.get(location.grasp)
                if grasp is None:
                    continue
                tried += 1
                try:
                    held: Held = attempt(
                        f"grasp {obj.name} from {_pose_text(location)} with the {location.arm} arm "
                        f"({location.grasp} grasp)",
                        partial(_grasp_from, location, obj, grasp),
                    )
                except RECOVERABLE as error:
                    cause = last = unwrap(error)
                    attempts.append(f"from {_pose_text(location)}: {cause}")
                    if isinstance(cause, ObjectNotVisible):
                        obj = _search_again(wanted, obj)
                        perceive_again = True
                    elif isinstance(cause, _ObjectMoved):
                        perceive_again = True
                    if perceive_again:
                        break
                    if tried >= STANDING_POSES:
                        break
                    continue
                held_objects()[held.arm] = held
                log.info("picked up %s with the %s arm", obj.name, held.arm)
                return held
        except NoSolutionError as error:
            if not attempts:
                raise ObjectOutOfReach(
                    f"no standing pose from which the robot can grasp {obj!r}: {error}",
                    designator,
                    attempts=[str(error)],
                ) from error
            attempts.append(str(error))
            last = error
        if not perceive_again and tried == 0 and not attempts:
            raise ObjectOutOfReach(f"no standing pose with a grasp the robot can execute for {obj!r}", designator)
        if not perceive_again:
            break
    message = f"could not pick up {obj!r} after {len(attempts)} attempts: " + "; ".join(attempts)
    if isinstance(last, NavigationFailure) and all("drive" in a or "path" in a for a in attempts):
        raise ObjectOutOfReach(message, designator, "no_drivable_pose", attempts) from last
    raise GraspFailed(message, designator, getattr(last, "reason", None), attempts) from last


# -- placing --------------------------------------------------------------------------------------


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


def _near_side(surface_name: str) -> tuple[float, float, float] | None:
    """A point on the surface 0.15 m in from its edge nearest to the robot (None when the
    environment does not know the surface)."""
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
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
    its side facing the robot (within easy reach of every arm)."""
    if isinstance(target, str):
        near = _near_side(target)
        target = LocationDesignator(
            [("on", target), ("for", held.object.type)] + ([("near", near)] if near is not None else [])
        )
    if isinstance(target, LocationDesignator):
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


def _place_locations(held: Held, spot: tuple[float, float, float], point: list[float]) -> LocationDesignator:
    """Standing poses to put the held object at `spot`: for an object held from the top, the
    place sequence of that top grasp for the object standing at the spot (the tool keeps
    pointing down); else the tool point `point`, approached along the base's heading."""
    if held.grasp.approach == "top":
        standing = KnownObject(f"{held.object.name} at the spot", held.object.type, spot)
        return LocationDesignator([("to_reach", standing), ("arm", held.arm), ("grasp", "top"), ("action", "place")])
    return LocationDesignator([("to_reach", tuple(point)), ("arm", held.arm), ("action", "place")])


def _place_at(location: Any, held: Held, spot: tuple[float, float, float], point: list[float]) -> PerceivedObject:
    arm, gripper, obj = held.arm, held.gripper, held.object
    if held.grasp.approach != "top" and held.grasp.radius:  # held off its centre, towards the robot
        r = held.grasp.radius
        point = [point[0] - r * math.cos(location.yaw), point[1] - r * math.sin(location.yaw), point[2]]
    motion(type="setting_arm_configuration", arm=arm, configuration=carry_configuration(arm, held.grasp))
    torso = getattr(location, "torso", None)
    if torso is not None:  # validated at another torso height (e.g. lowered for a drawer before):
        # set before driving -- the arm raised to carry stands over the table at the goal, and with
        # the torso still low the robot would not fit there (measured: TIAGo, goal_in_collision)
        motion(type="setting_torso", position=torso)
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
        belief.put_down(obj, spot)
    try:
        _reach(arm, location, 2, "retreat", point)
    except RECOVERABLE as error:  # the object is down: backing off is best effort
        log.info("placing %s: retreat: %s", obj.name, unwrap(error))
    motion(type="setting_arm_configuration", arm=arm, configuration="carry")
    # looks that miss the object in view are taken again until the belief holds it gone; a look
    # the arm hides it from leaves the put-down pose believed (parking the arm next to the
    # object just put down knocked it over: the TIAGo's cup, measured)
    _look_again(obj, spot)
    problem = None if obj.gone else resting_problem(obj)
    if obj.gone or problem is not None:
        # the arm in its carry pose may hide the object (or its top), and looks may miss what is
        # there (missed detections): park the arm and look again before believing the looks
        why = "not seen" if problem is None else problem[1]
        log.info("placing %s: %s; parking the %s arm and looking again", obj.name, why, arm)
        motion(type="setting_arm_configuration", arm=arm, configuration="park")
        _look_again(obj, spot)
        problem = None if obj.gone else resting_problem(obj)
    back_away(f"putting down {obj.name}")
    if problem is not None:
        reason, why = problem
        raise PlacingFailed(f"{obj.name} does not rest upright at {_xyz(spot)}: {why}", obj, reason)
    if obj.gone or math.dist(obj.pose[:2], spot[:2]) > PLACE_TOLERANCE:
        where = "not seen" if obj.gone else f"seen at {_xyz(obj.pose)}"
        raise PlacingFailed(f"{obj.name} does not rest at {_xyz(spot)}: {where}", obj)
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


def resting_problem(obj: PerceivedObject) -> tuple[str, str] | None:
    """Why the measured `obj` does not stand upright on its surface -- ``('toppled', why)`` or
    ``('not_resting', why)`` -- or None when its measured height fits.

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
    last: BaseException | None = None
    try:
        for spot_number, spot in enumerate(_spots(target, held), start=1):
            if spot_number > PLACE_SPOTS:
                break
            spot = tuple(float(v) for v in spot)
            point = [spot[0], spot[1], spot[2] - half + held.grasp.height]
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
        raise ObjectOutOfReach(message, designator, attempts=attempts) from last
    raise PlacingFailed(message, designator, getattr(last, "reason", None), attempts) from last
