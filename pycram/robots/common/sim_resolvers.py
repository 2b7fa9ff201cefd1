"""Designator resolvers of the simulated robots, parametrised by a robot's description module.

The robot packages (:mod:`pycram.robots.pr2`, :mod:`pycram.robots.tiago`) register these on
their :class:`~pycram.robots.common.sim_modules.SimRobot`. All robot numbers (arm names, torso heights,
named joint configurations, where the base stands to reach a point, approach offsets) are read
from the description module; this file holds only the geometry that turns them into commands.

Motion resolver (thesis ch. 4.2.1): :func:`make_motion_resolver` returns ``f(designator) ->
list`` of solution dictionaries, each with a ``'cmd'`` key understood by the process modules of
:mod:`pycram.robots.common.sim_modules`:

=============================  ==================================================================
designator type                solution
=============================  ==================================================================
``moving``                     ``{'cmd': 'navigate', 'pose': Pose2D (map), 'frame': 'map', 'wait'}``
``cancelling_movement``        ``{'cmd': 'stop_base'}``
``pointing_head``              ``{'cmd': 'point_head', 'point': (x, y, z) map, 'track': not wait}``
``setting_torso``              ``{'cmd': 'set_torso', 'height': m}``
``setting_gripper``            ``{'cmd': 'set_gripper', 'gripper', 'opening': m, 'effort': N|None}``
``setting_arm_configuration``  ``{'cmd': 'move_arm', 'arm', 'positions', 'configuration'}``
``setting_arm_joints``         ``{'cmd': 'move_arm', 'arm', 'positions'}``
``reaching``                   ``{'cmd': 'reach', 'arm', 'position', 'orientation', 'tolerance',
                               'phase', 'target'}``
``subscribing_pose``           ``{'cmd': 'subscribe', 'source': 'base_pose', 'fl'}``
``subscribing_gripper``        ``{'cmd': 'subscribe', 'source': 'gripper_opening', 'gripper', 'fl'}``
``detecting``                  ``{'cmd': 'perceive', 'object': type, belief name, designator or None}``
=============================  ==================================================================

``arm`` / ``gripper`` in a solution is always the *physical* name (``description.ARMS``); a
designator may use any name of ``description.ARM_ALIASES`` (``'left'``, ``'right'``, ``'0'``,
``'1'``). Invalid values raise ``ValueError`` naming the valid choices (reported by the
designator as ``ResolverError``).

``reaching`` and ``moving`` in the ``base_footprint`` frame depend on the base pose at the
time the designator is first referenced -- the process module references it when it starts
executing it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, cast

from pycram.world.environment import FURNITURE_TOPS
from pycram.world.types import Pose2D, Vec3, yaw_to_quat

__all__ = [
    "make_motion_resolver",
    "make_to_reach_generator",
    "physical_arm",
    "physical_gripper",
    "approach_target",
    "REACH_GRASPS",
    "base_pose_to_reach",
    "make_location_generator",
    "known_objects_of",
]


def _choices(mapping: Any) -> list[str]:
    return sorted({str(k) for k in mapping})


def physical_arm(description: Any, name: Any) -> str:
    """The physical arm that serves a request for arm ``name`` (``ValueError`` if none)."""
    try:
        return description.ARM_ALIASES[name]
    except (KeyError, TypeError):
        raise ValueError(
            f"{description.NAME} has no arm {name!r}; available: {_choices(description.ARM_ALIASES)}"
        ) from None


def physical_gripper(description: Any, name: Any) -> str:
    """The physical gripper that serves a request for gripper ``name`` (``ValueError`` if none)."""
    try:
        return description.GRIPPER_ALIASES[name]
    except (KeyError, TypeError):
        raise ValueError(
            f"{description.NAME} has no gripper {name!r}; available: {_choices(description.GRIPPER_ALIASES)}"
        ) from None


def _pose2d(value: Any) -> Pose2D:
    if isinstance(value, Pose2D):
        return value
    if hasattr(value, "x") and hasattr(value, "y") and hasattr(value, "yaw"):
        return Pose2D(float(value.x), float(value.y), float(value.yaw))
    try:
        x, y, yaw = value
        return Pose2D(float(x), float(y), float(yaw))
    except (TypeError, ValueError):
        raise ValueError(f"a base pose is a Pose2D or (x [m], y [m], yaw [rad]), got {value!r}") from None


def _point(value: Any) -> tuple[float, float, float]:
    try:
        x, y, z = value
        return (float(x), float(y), float(z))
    except (TypeError, ValueError):
        raise ValueError(f"a point is [x, y, z] in [m], got {value!r}") from None


def _relative_to(base: Pose2D, pose: Pose2D) -> Pose2D:
    """``pose`` given in the frame of the base at ``base``, in the map frame."""
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    return Pose2D(base.x + c * pose.x - s * pose.y, base.y + s * pose.x + c * pose.y, base.yaw + pose.yaw)


def base_goal_in_map(world: Any, pose: Any, frame: Any = None) -> Pose2D:
    """A base goal ``pose`` given in ``frame`` (``'map'``, the default, or ``'base_footprint'``:
    relative to the base pose now) as a ``Pose2D`` in the map frame."""
    pose = _pose2d(pose)
    frame = frame or "map"
    if frame == "base_footprint":
        return _relative_to(world.base_pose.get_value(), pose)
    if frame != "map":
        raise ValueError(f"unknown frame {frame!r}; available: map, base_footprint")
    return pose


def on_free_floor(world: Any, x: float, y: float) -> bool:
    """``True`` iff the base may stand at (x, y) [m, map]: on the floor of ``world``'s environment
    and off its furniture (``Environment.is_free_floor``). Goals of ``moving`` and the base poses
    of ``to_reach`` must lie there; this is the one place resolvers ask."""
    return bool(world.environment.is_free_floor(x, y))


def describe_free_floor(world: Any) -> str:
    """``the free floor of thesis-kitchen (x in [-0.45, 3] m, y in [-0.9, 3.5] m, off the furniture)``
    (for messages)."""
    env = world.environment
    areas = "; ".join(f"x in [{x0:g}, {x1:g}] m, y in [{y0:g}, {y1:g}] m" for x0, y0, x1, y1 in env.floor)
    return f"the free floor of {env.name} ({areas}, off the furniture)"


#: How the tool meets its target in the ``reaching`` motion (the ``grasp`` key): along the base's
#: heading with the fingers opening horizontally (``'front'``, the default) or vertically
#: (``'front_vertical'``: for horizontal bars such as drawer handles), or from above
#: (``'top'``: the tool points down, the fingers open across the base's heading).
REACH_GRASPS = ("front", "front_vertical", "top")


def approach_target(
    description: Any, base: Pose2D, target: Sequence[float], phase: str | None, grasp: str | None = None
) -> tuple[tuple[float, float, float], tuple[float, ...]]:
    """Tool position [m, map] and orientation (w, x, y, z) for ``phase`` of reaching ``target``.

    The approach direction is the base's heading (``grasp`` ``'front'``/``'front_vertical'``,
    see `REACH_GRASPS`): the tool points along it and is moved ``back`` [m] against it and
    ``up`` [m] per ``description.APPROACH_OFFSETS[phase]`` (no offset without a phase). From the
    ``'top'`` the tool points down and both offsets lift it.
    """
    x, y, z = _point(target)
    if phase is None:
        back, up = 0.0, 0.0
    else:
        offsets = description.APPROACH_OFFSETS
        if phase not in offsets:
            raise ValueError(f"unknown reaching phase {phase!r}; available: {sorted(offsets)}")
        back, up = offsets[phase]
    grasp = grasp or "front"
    if grasp not in REACH_GRASPS:
        raise ValueError(f"unknown reaching grasp {grasp!r}; available: {', '.join(REACH_GRASPS)}")
    if grasp == "top":
        return (x, y, z + back + up), _quat_down(base.yaw)
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    orientation = yaw_to_quat(base.yaw)
    if grasp == "front_vertical":
        orientation = _quat_multiply(orientation, (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0))
    return (x - c * back, y - s * back, z + up), orientation


def _quat_down(yaw: float) -> tuple[float, float, float, float]:
    """Tool x pointing down, tool y across `yaw` (about z by `yaw`, then about y by 90 deg)."""
    cz, sz, c, s = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(math.pi / 4), math.sin(math.pi / 4)
    return (cz * c, -sz * s, cz * s, sz * c)


def _quat_multiply(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float, float]:
    """The rotation `a` then `b` (in `a`'s frame): Hamilton product a * b, (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def make_motion_resolver(world: Any, description: Any) -> Callable[[Any], list]:
    """The motion-designator resolver of the robot of ``description`` in ``world``."""
    d = description

    def arm_configuration(arm: str, name: Any) -> tuple[float, ...]:
        configurations = d.ARM_CONFIGURATIONS[arm]
        if name not in configurations:
            raise ValueError(f"{d.NAME} {arm} arm has no configuration {name!r}; available: {sorted(configurations)}")
        return tuple(configurations[name])

    def torso_height(position: Any) -> float:
        if isinstance(position, str):
            if position not in d.TORSO_POSITIONS:
                raise ValueError(
                    f"unknown torso position {position!r}; available: {sorted(d.TORSO_POSITIONS)} or a height in [m]"
                )
            return float(d.TORSO_POSITIONS[position])
        low, high = d.TORSO["range"]
        height = float(position)
        if not low <= height <= high:
            raise ValueError(f"torso height {height} m outside [{low}, {high}] m")
        return height

    def gripper_opening(position: Any) -> float:
        fraction = float(position)
        if not 0.0 <= fraction <= 1.0:
            raise ValueError(f"gripper position is a fraction open in [0, 1], got {position!r}")
        return fraction

    def motion_resolver(desig: Any) -> list:
        solutions = []
        wait = desig.prop_value("wait") is not False
        if desig.check_constraints([("type", "moving"), "pose"]):
            pose = base_goal_in_map(world, desig.prop_value("pose"), desig.prop_value("frame"))
            solutions.append(
                desig.make_dictionary([("cmd", "navigate"), ("pose", pose), ("frame", "map"), ("wait", wait)])
            )
        if desig.check_constraints([("type", "cancelling_movement")]):
            solutions.append(desig.make_dictionary([("cmd", "stop_base")]))
        if desig.check_constraints([("type", "pointing_head"), "coordinates"]):
            frame = desig.prop_value("frame") or "map"
            if frame != "map":
                raise ValueError(f"pointing_head supports the frame 'map', got {frame!r}")
            solutions.append(
                desig.make_dictionary(
                    [
                        ("cmd", "point_head"),
                        ("point", _point(desig.prop_value("coordinates"))),
                        ("frame", "map"),
                        ("track", not wait),
                    ]
                )
            )
        if desig.check_constraints([("type", "setting_torso"), "position"]):
            solutions.append(
                desig.make_dictionary([("cmd", "set_torso"), ("height", torso_height(desig.prop_value("position")))])
            )
        if desig.check_constraints([("type", "setting_gripper"), "gripper", "position"]):
            gripper = physical_gripper(d, desig.prop_value("gripper"))
            spec = d.GRIPPERS[gripper]
            opening = gripper_opening(desig.prop_value("position")) * spec["max_opening"]
            effort = desig.prop_value("max_effort")
            solutions.append(
                desig.make_dictionary(
                    [
                        ("cmd", "set_gripper"),
                        ("gripper", gripper),
                        ("opening", opening),
                        ("effort", None if effort is None else float(effort)),
                    ]
                )
            )
        if desig.check_constraints([("type", "setting_arm_configuration"), "arm", "configuration"]):
            arm = physical_arm(d, desig.prop_value("arm"))
            name = desig.prop_value("configuration")
            solutions.append(
                desig.make_dictionary(
                    [
                        ("cmd", "move_arm"),
                        ("arm", arm),
                        ("positions", arm_configuration(arm, name)),
                        ("configuration", name),
                    ]
                )
            )
        if desig.check_constraints([("type", "setting_arm_joints"), "arm", "positions"]):
            arm = physical_arm(d, desig.prop_value("arm"))
            positions = tuple(float(v) for v in desig.prop_value("positions"))
            joints = d.ARMS[arm]["joints"]
            if len(positions) != len(joints):
                raise ValueError(
                    f"the {d.NAME} {arm} arm has {len(joints)} joints {joints}, got {len(positions)} positions"
                )
            solutions.append(desig.make_dictionary([("cmd", "move_arm"), ("arm", arm), ("positions", positions)]))
        if desig.check_constraints([("type", "reaching"), "arm", "target"]):
            arm = physical_arm(d, desig.prop_value("arm"))
            phase = desig.prop_value("phase")
            target = _point(desig.prop_value("target"))
            explicit = desig.prop_value("orientation")
            if explicit is not None:
                if len(explicit) != 4:
                    raise ValueError(f"reaching: orientation must be a quaternion (w, x, y, z), got {explicit!r}")
                position, orientation = target, tuple(float(v) for v in explicit)
            else:
                position, orientation = approach_target(
                    d, world.base_pose.get_value(), target, phase, desig.prop_value("grasp")
                )
            tolerance = d.REACH_TOLERANCE.get(phase, d.REACH_TOLERANCE["default"])
            solutions.append(
                desig.make_dictionary(
                    [
                        ("cmd", "reach"),
                        ("arm", arm),
                        ("position", position),
                        ("orientation", orientation),
                        ("tolerance", tolerance),
                        ("phase", phase),
                        ("target", target),
                        ("contact", bool(desig.prop_value("contact"))),
                        ("joints", _joint_guess(desig.prop_value("joints"), d.ARMS[arm]["joints"])),
                    ]
                )
            )
        if desig.check_constraints([("type", "subscribing_pose"), "fl"]):
            solutions.append(desig.make_dictionary([("cmd", "subscribe"), ("source", "base_pose"), "fl"]))
        if desig.check_constraints([("type", "subscribing_gripper"), "gripper", "fl"]):
            solutions.append(
                desig.make_dictionary(
                    [
                        ("cmd", "subscribe"),
                        ("source", "gripper_opening"),
                        ("gripper", physical_gripper(d, desig.prop_value("gripper"))),
                        "fl",
                    ]
                )
            )
        if desig.check_constraints([("type", "detecting")]):
            solutions.append(desig.make_dictionary([("cmd", "perceive"), "object"]))
        return solutions

    motion_resolver.__qualname__ = f"{d.NAME}_motion_resolver"
    return motion_resolver


# --------------------------------------------------------------------------- locations


def _counter_normal(environment: Any, x: float, y: float) -> tuple[float, float] | None:
    """Outward normal (towards the free floor) of the counter or table edge nearest to (x, y),
    or None when (x, y) is on no counter or table of ``environment`` (its description)."""
    best: tuple[float, tuple[float, float]] | None = None
    for surface in environment.surfaces_of_kind(*FURNITURE_TOPS):
        if not surface.contains(x, y, -1e-6):
            continue
        for (ax, ay), _, n in surface.edges():
            distance = (ax - x) * n[0] + (ay - y) * n[1]  # to the edge's line, along its normal
            edge_x, edge_y = x + distance * n[0], y + distance * n[1]
            if not environment.is_free_floor(edge_x + 0.3 * n[0], edge_y + 0.3 * n[1]):
                continue
            if best is None or distance < best[0]:
                best = (distance, n)
    return None if best is None else best[1]


def base_pose_to_reach(
    description: Any,
    point: Sequence[float],
    arm: str,
    current: Pose2D | None = None,
    extra_standoff: float = 0.0,
    environment: Any = None,
) -> Pose2D:
    """The base pose from which ``arm`` reaches ``point`` [m, map].

    The base faces the counter or table of ``environment`` (a description) the point lies on
    (heading against the edge's outward normal); off them, or without an environment, it faces
    the point from the ``current`` base position. The point
    is then at ``description.REACH_POINT_IN_BASE[arm]`` (+ ``extra_standoff`` [m] ahead) in the
    base frame.
    """
    x, y, _ = _point(point)
    normal = None if environment is None else _counter_normal(environment, x, y)
    if normal is not None:
        yaw = math.atan2(-normal[1], -normal[0])
    elif current is not None:
        yaw = math.atan2(y - current.y, x - current.x)
    else:
        raise ValueError(f"{_point(point)} is on no counter and no current base pose is known")
    ahead, left = description.REACH_POINT_IN_BASE[arm]
    ahead += extra_standoff
    c, s = math.cos(yaw), math.sin(yaw)
    return Pose2D(x - c * ahead + s * left, y - s * ahead - c * left, yaw)


def make_to_reach_generator(world: Any, description: Any) -> Callable[[Any], Any]:
    """Location generator for ``('to_reach', [x, y, z])`` (optionally ``('arm', a)``).

    Yields base poses (``Pose2D``, map frame) from which the arm (default
    ``description.DEFAULT_ARM``) reaches the point: the best one first, then the same with the
    base 5 cm further back, 5 cm closer and 10 cm further back -- each only if it lies on the
    environment's free floor (:func:`on_free_floor`). Raises ``NoSolutionError`` saying why when
    none does (the point is outside the environment, or too far from the floor). Returns
    ``None`` for other location designators.
    """
    d = description

    def to_reach(desig: Any) -> list[Pose2D] | None:
        if not desig.check_constraints(["to_reach"]):
            return None
        point = _point(desig.prop_value("to_reach"))
        if not all(math.isfinite(v) for v in point):
            raise ValueError(f"the point to reach must be finite [m], got {point}")
        arm = physical_arm(d, desig.prop_value("arm") or d.DEFAULT_ARM)
        current = world.base_pose.get_value()
        candidates = [
            base_pose_to_reach(d, point, arm, current, extra, world.environment) for extra in (0.0, 0.05, -0.05, 0.10)
        ]
        poses = [pose for pose in candidates if on_free_floor(world, pose.x, pose.y)]
        if not poses:
            from pycram.designators.core import NoSolutionError

            where = (
                "outside the environment"
                if not on_free_floor(world, point[0], point[1])
                and _counter_normal(world.environment, point[0], point[1]) is None
                else "out of reach"
            )
            best = candidates[0]
            raise NoSolutionError(
                f"Cannot resolve {desig!r}: the point {point} [m, map] is {where}: the "
                f"{d.NAME} {arm} arm would reach it from (x={best.x:.2f}, y={best.y:.2f}), but "
                f"the base can only stand on {describe_free_floor(world)}",
                designator=desig,
            )
        return poses

    to_reach.__qualname__ = f"{d.NAME}_to_reach"
    return to_reach


def known_objects_of(belief: Any) -> list:
    """The objects the robot believes in (``belief``: its
    :class:`pycram.world.belief.BeliefState`; gone ones left out) as
    ``pycram.locations.KnownObject``s: name, type, believed centre, and the footprint and height of
    the object's type. Reasoning knows only what was perceived, never the simulator's truth.
    """
    from pycram.reasoning.locations import KnownObject
    from pycram.world.objects import OBJECT_TYPES

    known = []
    for obj in belief.objects():
        if getattr(obj, "gone", False) or obj.pose is None:
            continue
        radius = half_height = None
        size = obj.properties.get("size")
        if obj.type not in OBJECT_TYPES and size is not None:  # e.g. the thesis demo's mug: as measured
            radius, half_height = 0.5 * math.hypot(size[0], size[1]), 0.5 * size[2]
        position = cast(Vec3, tuple(float(v) for v in obj.pose[:3]))
        known.append(KnownObject(obj.name, obj.type, position, float(getattr(obj, "yaw", 0.0)), radius, half_height))
    return known


def _joint_guess(value: Any, joints: Sequence[str]) -> tuple[float, ...] | None:
    """`reaching`'s ``joints`` as a tuple of one position per joint of the arm (None when not
    given). Raises ``ValueError`` naming the arm's joints for a wrong count."""
    if value is None:
        return None
    positions = tuple(float(v) for v in value)
    if len(positions) != len(joints):
        raise ValueError(f"reaching: joints must give {len(joints)} positions {tuple(joints)}, got {len(positions)}")
    return positions


def held_objects_by_arm(description: Any, belief: Any) -> dict[str, str]:
    """arm -> the name of the object its gripper holds as `belief` has it (its ``in_hand``:
    gripper -> object), for the arms of the robot of `description` that hold one."""
    in_hand = dict(getattr(belief, "in_hand", {}) or {})
    held = {arm: in_hand.get(spec["gripper"]) for arm, spec in description.ARMS.items()}
    return {arm: obj.name for arm, obj in held.items() if obj is not None}


def make_location_generator(
    world: Any, description: Any, belief: Any, prospection: Callable[[], Any] | None = None
) -> Callable[[Any], Any]:
    """The location generator of the robot of `description` in `world` (a simulated world, or
    any object with the environment's description as ``environment``): the general reasoning of
    :mod:`pycram.locations` (``to_reach``, ``to_see``, ``to_open``, ``on``, ``in``), with
    prospection of the world the robot believes in (`prospection()`; by default
    ``world.prospection(belief)``) and the objects of the robot's ``belief`` as known objects.
    Returns ``None`` for designators outside that vocabulary."""
    from pycram.reasoning.locations import LocationReasoner, RobotGeometry

    def of_world() -> Any:
        make = getattr(world, "prospection", None)
        if make is None:
            raise LookupError(f"{world!r} offers no prospection")
        return make(belief)

    reasoner = LocationReasoner(
        RobotGeometry.from_description(description),
        lambda: world.environment,
        prospection or of_world,
        lambda: known_objects_of(belief),
        container_states=lambda: dict(getattr(belief, "container_states", {})),
        holding=lambda: held_objects_by_arm(description, belief),
    )

    def locations(desig: Any) -> Any:
        return reasoner.generator(desig)

    locations.__qualname__ = f"{description.NAME}_locations"
    locations.reasoner = reasoner  # type: ignore[attr-defined]
    return locations
