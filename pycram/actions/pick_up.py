"""Picking up an object, with recovery the CRAM way.

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

An object in a drawer not pulled out far enough, or behind a door not open far enough, is made
reachable first with the `Open` action. Top grasps (bowls and plates, by the rim) follow the
tool poses location reasoning validated, the tool pointing down. So do grasps planned from the
object's measured shape and pose (`pycram.reasoning.grasps`: an object lying on its side, a
box turned far from square; the location's ``grasp_candidate``), with their tool orientations,
moved along with the object by as much as a look from the standing pose saw it move. Every attempt is a task of its
own (kind ``attempt``), so the task tree shows each recovery. The object picked up is recorded
in `pycram.actions.held`.
"""

from __future__ import annotations

import logging
import math
from functools import partial
from typing import Any

from pycram.designators.action import ActionDesignator
from pycram.designators.core import NoSolutionError
from pycram.designators.location import LocationDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import (
    GraspFailed,
    NavigationFailure,
    ObjectNotVisible,
    ObjectOutOfReach,
    ObjectSlipped,
    PlanFailure,
)
from pycram.execution.perform import perform
from pycram.execution.robot import current_robot
from pycram.world.belief import PerceivedObject
from pycram.world.objects import OBJECT_TYPES, Grasp, approach_matches, object_type

from .container_state import DOOR_TOLERANCE, DOOR_USEFUL
from .containers import DOOR_OPENING, Open, opening_one_at_a_time
from .core import (
    RECOVERABLE,
    ActionParameterError,
    action_plan,
    arm_name,
    attempt,
    best_effort,
    check_grasp,
    check_object_type,
    gripper_of,
    gripper_opening,
    make_action,
    motion,
    solutions,
    unwrap,
)
from .handling import _look_again, _pose_text, _reach, _xyz, back_away, carry_configuration, park_empty_arms
from .held import Held, fingers_yaw, held_objects
from .search import search_for

__all__ = [
    "PickUp",
    "PICK_ROUNDS",
    "STANDING_POSES",
    "MOVED",
    "CARRY_TORSO",
    "executable_grasps",
    "believed_object",
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
#: A box measured turned by more than this [rad] from the pose its grasp was chosen for, once
#: looked at from the standing pose, is planned for again (a first look from afar may measure no
#: turn: a carton turned 45 deg was then grasped across its diagonal).
TURNED = 0.2
#: Picking from a drawer that is not far enough out: it is pulled to this much [m] short of its
#: slide's end.
WIDE_MARGIN = 0.03
#: Picking from a drawer: it is pulled out until the object's footprint is this far [m] out from
#: under the furniture (the hand is wider than the object, and the handles of the drawers above
#: stick out 4 cm).
OUT_FROM_UNDER = 0.12
#: Picking from behind a door (a fridge's, a cupboard's) that no standing pose reaches into with
#: the door open as `Open` opens it: it is opened this far [rad] (92 deg; or to its limit) and
#: the grasp is planned again. The door's leaf swung further back frees the floor in front of
#: the shelves (measured: a bowl on a generated fridge's middle shelf is reached by the PR2 from
#: 1 standing pose with the door at 67 deg, from 3 at 92 deg; `procedural:46`, seed 1).
DOOR_WIDE = 1.6
#: The named torso position objects are carried at (a robot without a torso keeps its own).
CARRY_TORSO = "up"
#: Picking from a shelf behind a door: once lifted, the object is taken straight out along the
#: door's opening direction until its footprint is this far [m] past the furniture's front, and
#: only then to the carry configuration (`_withdraw`).
WITHDRAW_MARGIN = 0.05


def PickUp(object: Any, arm: str | None = None, grasp: str | None = None) -> ActionDesignator:
    """Pick up `object` (an object designator, or a believed object) with `arm` (None: the
    reasoning chooses) and `grasp` (an approach such as ``'side'`` or ``'+y'``; None: any the
    robot can execute). Returns a `Held`. An unknown grasp approach or object type raises
    `ActionParameterError` at once."""
    check_object_type("picking_up", object)
    return make_action("picking_up", object=object, arm=arm, grasp=check_grasp("picking_up", grasp))


def executable_grasps(type_name: str, requested: str | None = None) -> list[Grasp]:
    """The grasps of an object type that picking up can execute with the active robot: the
    horizontal approaches, and ``top`` when its ``reaching`` motion takes a tool orientation
    (then the tool follows the poses location reasoning validated)."""
    top_ok = _reaching_takes_orientation()
    grasps = [g for g in object_type(type_name).grasps if top_ok or g.approach != "top"]
    if requested is not None:
        grasps = [g for g in grasps if approach_matches(g.approach, requested)]
    return grasps


def _reaching_takes_orientation() -> bool:
    """Whether the active robot's ``reaching`` motion takes a tool orientation (needed for top
    grasps and for planned grasps, `pycram.reasoning.grasps`, whose tool turns from the base's
    heading)."""
    types = getattr(current_robot(), "motion_types", None) or {}
    reaching = types.get("reaching")
    return reaching is not None and any(k.name == "orientation" for k in reaching.all_keys())


def believed_object(action: str, wanted: Any) -> PerceivedObject:
    """The believed object `wanted` stands for; an object designator the belief does not
    satisfy is searched for."""
    if isinstance(wanted, Held):
        return wanted.object
    if isinstance(wanted, PerceivedObject):
        return wanted
    check_object_type(action, wanted)
    if isinstance(wanted, str):
        wanted = ObjectDesignator(type=wanted)
    if not isinstance(wanted, ObjectDesignator):
        raise ActionParameterError(
            action, "object", f"needs an object designator, a believed object or a type name, got {wanted!r}"
        )
    return _search(wanted)


def _search(description: ObjectDesignator) -> PerceivedObject:
    """`search_for`, opening closed drawers with the `Open` action, one at a time."""
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


class _ObjectMoved(PlanFailure):
    """Internal: the object was seen elsewhere than planned for (perceive and reason again)."""

    default_reason = "object_moved"


def _let_go_and_retract(
    arm: str, gripper: str, point: list[float] | None, location: Any = None, reach: Any = None
) -> None:
    """Best effort after a failed grasp: open the gripper, back off (`reach(0, phase)`: to the
    pre-grasp pose of a planned grasp), arm up for driving."""

    def retreat() -> None:
        if reach is not None:
            reach(0, "pre_grasp")
        elif location is not None and location.grasp == "top":
            _reach(arm, location, 0, "pre_grasp", point)  # straight up, as it came
        elif point:
            motion(type="reaching", arm=arm, target=point, phase="retreat")

    best_effort(
        "clean-up after a failed grasp",
        lambda: motion(type="setting_gripper", gripper=gripper, position=1),
        retreat,
        lambda: motion(type="setting_arm_configuration", arm=arm, configuration="carry"),
    )


def _arm_to_drive(arm: str, configuration: str) -> None:
    """Move `arm` to `configuration` before driving; blocked where the robot stands, or stopped
    by a contact (beside the furniture it just worked at: the TIAGo's arm against the cupboard's
    side after pushing its door shut, 5 of 200 faulted set-table seeds; a carried bowl on the milk
    carton beside it), the base backs away `BACK_AWAY` and it tries once more (raising that
    failure)."""
    try:
        motion(type="setting_arm_configuration", arm=arm, configuration=configuration)
    except RECOVERABLE as error:
        if getattr(unwrap(error), "reason", None) not in ("blocked", "collision"):
            raise
        log.info("the %s arm is blocked on its way to %s: backing away first (%s)", arm, configuration, unwrap(error))
        back_away(f"the {arm} arm was blocked")
        motion(type="setting_arm_configuration", arm=arm, configuration=configuration)


def _planned_reach(arm: str, location: Any, obj: PerceivedObject) -> Any:
    """For a location validated for a planned grasp (``location.grasp_candidate``): a function
    ``reach(index, phase, grasping=None)`` that moves the tool to the `index`-th validated tool
    pose (position and orientation), moved along with the object by as much as it was seen to
    have moved since the grasp was planned (within `MOVED`: a look from close by is the better
    measurement). None for a location of a type's own grasp."""
    candidate = getattr(location, "grasp_candidate", None)
    if candidate is None:
        return None
    poses = location.tool_poses

    def reach(index: int, phase: str, grasping: Any = None) -> None:
        (x, y, z), orientation = poses[index]
        dx, dy, dz = (a - b for a, b in zip(obj.pose, candidate.centre, strict=True))
        extra = {} if grasping is None else {"object": grasping}
        target = [x + dx, y + dy, z + dz]
        return motion(type="reaching", arm=arm, target=target, orientation=list(orientation), phase=phase, **extra)

    return reach


def _believed_container(obj: PerceivedObject) -> tuple[Any, Any] | None:
    """The active robot's belief and the container (`pycram.world.environment.Container`) `obj`
    is believed in (its ``"in"`` property); None when it is in none, or when the robot has no
    belief of the environment."""
    name = obj.properties.get("in")
    belief = getattr(current_robot(), "belief", None)
    environment = getattr(belief, "environment", None)
    if not name or environment is None:
        return None
    return belief, environment.container(name)


def _withdraw(arm: str, obj: PerceivedObject, lifted: Any) -> bool:
    """Take `obj`, held by `arm` and lifted (the tool at `lifted`, the pose the lift reached: a
    position [m, map] and orientation), out of the cupboard or fridge it stands in, straight
    along the door's opening direction until its footprint is `WITHDRAW_MARGIN` past the
    furniture's front (a ``lift`` reach: the tool's line, else planned); True when it did.
    Going to the carry configuration from inside, the held bowl met the fridge's side wall, and
    backing the base away dragged it along the wall (PR2, set-table-anywhere, ``procedural:80``
    and ``procedural:130``, seed 1; ``procedural:80`` sets the table with this). Best effort: a
    failure is logged and the pick-up goes on as before. Nothing to do (False) for an object not
    behind a door or out already, or for a lift that reports no tool pose."""
    believed = _believed_container(obj)
    position, orientation = getattr(lifted, "position", None), getattr(lifted, "orientation", None)
    if believed is None or position is None or orientation is None:
        return False
    container = believed[1]
    if container.kind != "door":  # a drawer is open above: the lift takes the object out
        return False
    dx, dy = container.opening_direction
    out = container.front + WITHDRAW_MARGIN + object_type(obj.type).footprint_radius
    distance = out - container.along_slide(obj.pose[0], obj.pose[1])
    if distance <= 0.0:
        return False
    x, y, z = (float(v) for v in position)
    target = [x + distance * dx, y + distance * dy, z]
    try:
        # a lift's line (the tool's straight line, else planned); with the orientation given, no offset
        motion(type="reaching", arm=arm, target=target, orientation=[float(v) for v in orientation], phase="lift")
    except RECOVERABLE as error:
        log.info("taking %s out of %s: %s; on to carrying it from where it is", obj.name, container.name, unwrap(error))
        return False
    return True


def _turn_between(obj: PerceivedObject, before: float, after: float) -> float:
    """How far [rad] `obj` turned between the yaws `before` and `after` [rad], up to the symmetry
    of its top (a box with a square top looks the same a quarter turn on, another box half a turn
    on; other shapes have no measured turn)."""
    otype = OBJECT_TYPES.get(obj.type)
    if otype is None or otype.shape != "box":
        return 0.0
    period = math.pi / 2 if otype.size[0] == otype.size[1] else math.pi
    return abs((after - before + period / 2) % period - period / 2)


def _grasp_from(location: Any, obj: PerceivedObject, grasp: Grasp) -> Held:
    """One pick-up attempt from the standing pose `location` (see the module's description)."""
    arm = location.arm
    candidate = getattr(location, "grasp_candidate", None)
    gripper = gripper_of(arm)
    planned = tuple(obj.pose)
    planned_yaw = obj.yaw
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
    park_empty_arms(keep=arm)
    try:
        motion(type="moving", pose=location)
    except RECOVERABLE as error:
        if deep or not isinstance(unwrap(error), NavigationFailure):
            raise
        # location reasoning checks a standing pose with the free arms tucked, as they arrive: the
        # arm raised to carry did not fit there (measured: PR2, set-table-anywhere,
        # procedural:14, seed 1, "goal_in_collision" beside a counter) -- tucked, it drives again
        log.info(
            "grasping %s: the drive with the %s arm raised failed (%s): tucked, again", obj.name, arm, unwrap(error)
        )
        motion(type="setting_arm_configuration", arm=arm, configuration="park")
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
    turned = _turn_between(obj, planned_yaw, obj.yaw)
    if turned > TURNED:  # measured turned from up close: the grasp was chosen for another turn
        raise _ObjectMoved(
            f"{obj.name} is turned {math.degrees(turned):.0f} deg from the pose its grasp was chosen for", obj
        )
    poses: Any = getattr(location, "tool_poses", ())
    if candidate is not None:  # planned for where the object was when the location was resolved
        if math.dist(obj.pose, candidate.centre) > moved:
            raise _ObjectMoved(f"{obj.name} moved from {_xyz(candidate.centre)} to {_xyz(obj.pose)}", obj)
    elif location.grasp == "top" and len(poses) > 1:  # validated for where the object was then
        off = abs(math.dist(poses[1][0][:2], obj.pose[:2]) - grasp.radius)
        if off > moved:
            raise _ObjectMoved(f"{obj.name} is {off:.2f} m off the grasp planned for it", obj)
    point = _grasp_point(obj, grasp, location.yaw)
    planned_reach = _planned_reach(arm, location, obj)

    def reach(index: int, phase: str, grasping: Any = None) -> Any:
        if planned_reach is not None:
            return planned_reach(index, phase, grasping)
        return _reach(arm, location, index, phase, point, grasping)

    try:
        if candidate is not None and grasp.approach != "top" and grasp.radius:
            # a deep object, planned: as below, along the planned tool heading and orientation
            c, s = math.cos(candidate.heading), math.sin(candidate.heading)
            (gx, gy, gz), orientation = poses[1]
            dx, dy, dz = (a - b for a, b in zip(obj.pose, candidate.centre, strict=True))
            back = [gx + dx - grasp.radius * c, gy + dy - grasp.radius * s, gz + dz]
            try:
                motion(
                    type="reaching", arm=arm, target=back, orientation=list(orientation), phase="pre_grasp", object=obj
                )
            except RECOVERABLE as error:
                log.info("grasping %s: no pose farther back first (%s)", obj.name, unwrap(error))
        elif grasp.approach != "top" and grasp.radius:
            # a deep object (a cereal box) reaches towards the robot: the raised gripper would
            # swing into it on its way to the pre-grasp pose (measured: the TIAGo knocked the
            # cereal box over), so it comes to a pose `radius` farther back first -- where the
            # arm reaches that close to the body (the PR2's often does not: then straight on)
            c, s = math.cos(location.yaw), math.sin(location.yaw)
            back = [point[0] - grasp.radius * c, point[1] - grasp.radius * s, point[2]]
            try:
                motion(type="reaching", arm=arm, target=back, phase="pre_grasp", object=obj)
            except RECOVERABLE as error:
                log.info("grasping %s: no pose farther back first (%s)", obj.name, unwrap(error))
        reach(0, "pre_grasp", obj)
        reach(1, "grasp", obj)
        opening = float(motion(type="setting_gripper", gripper=gripper, position=0))
    except RECOVERABLE:
        _let_go_and_retract(arm, gripper, point, location, planned_reach)
        raise
    held = Held(obj, arm, gripper, grasp, fingers_yaw(location))
    if opening < held.held_opening:
        _let_go_and_retract(arm, gripper, point, location, planned_reach)
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
        lifted = reach(2, "lift")
        if _withdraw(arm, obj, lifted):  # out of the doorway: the base backs away before the arm
            # moves to carry (the carry pose, fixed to the base, lay in the fridge's side wall)
            back_away(f"taking {obj.name} out of {obj.properties.get('in')}")
        # blocked on its way to carry -- the held box pressed onto the furniture it was taken
        # from (the PR2's, a cereal box from a cabinet top's back: let go, it fell) -- the base
        # backs away first and the arm tries once more
        _arm_to_drive(arm, carry_configuration(arm, grasp))
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


@action_plan("picking_up")
def picking_up(designator: ActionDesignator) -> Held:
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
    fridge's): with `as_far_as_needed`, `DOOR_OPENING` [rad] when it is believed open less than
    `DOOR_USEFUL` (the object was seen inside, and the door was closed since or stuck part way);
    else `DOOR_WIDE` (or the door's limit). None when it is in no container or the container is
    (about) that far open already."""
    believed = _believed_container(obj)
    if believed is None or obj.pose is None:
        return None
    belief, container = believed
    name = container.name
    if container.kind == "door":
        now = abs(float(belief.container_states.get(name, 0.0)))
        if as_far_as_needed:
            return DOOR_OPENING if now < DOOR_USEFUL else None
        wide = min(container.limits[1], DOOR_WIDE)
        return wide if now < wide - DOOR_TOLERANCE else None
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
    requested_grasp = check_grasp("picking_up", designator.prop_value("grasp"))
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
    # planned grasps (`pycram.reasoning.grasps`) need a tool orientation
    planned_ok = _reaching_takes_orientation()
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
                candidate = getattr(location, "grasp_candidate", None)
                if candidate is not None:
                    grasp = candidate.grasp if planned_ok else None
                else:
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
