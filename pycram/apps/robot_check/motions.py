"""Check b: every motion designator type of the robot's vocabulary, performed on the robot.

One case per motion type (`MOTION_CASES`), run in this order in the scene's world with the robot
active (``with scene.robot``), each through ``perform(MotionDesignator(...))`` as a plan would:

- ``subscribing_pose`` / ``subscribing_gripper``: the subscribed fluent follows the base pose /
  each gripper's opening (compared with the simulator's truth);
- ``setting_torso``: each named torso position and the middle of the range, ending ``up``
  (the joint error each returns within `TORSO_TOLERANCE`);
- ``setting_arm_configuration``: every named configuration of every arm, ending in the first
  (the joint error within `JOINT_TOLERANCE`);
- ``setting_arm_joints``: each arm to its second named configuration's joints and back;
- ``setting_gripper``: each gripper fully open (at least `OPEN_FRACTION` of its maximum
  opening) and closed on nothing (at most `CLOSED_OPENING`);
- ``pointing_head``: two points ahead (the remaining angle within `HEAD_TOLERANCE`);
- ``moving``: forward `FORWARD` [m], a turn on the spot of `TURN` [rad] and back -- each reached
  within `BASE_TOLERANCE` / `YAW_TOLERANCE` -- then `SIDEWAYS` [m] to the left, which a
  differential drive may refuse: refused with a typed failure or done counts, anything else
  fails; then back to the start pose (map frame);
- ``cancelling_movement``: a drive of `FORWARD` m started without waiting is stopped once the
  base has moved: the drive ends cancelled, short of its goal;
- ``reaching``: each arm's tool to the point its description says it reaches
  (``REACH_POINT_IN_BASE``) at `REACH_HEIGHT`, within the description's tolerance, then back to
  the first named configuration;
- ``detecting``: one look folded into the belief (a list of perceived objects).

A motion type of the vocabulary without a case here is skipped with that reason; a case whose
type the robot's vocabulary lacks is skipped too.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from pycram.apps.robot_check.results import CheckFailed
from pycram.apps.robot_check.scene import CheckScene

__all__ = [
    "MOTION_CASES",
    "motion_cases",
    "FORWARD",
    "TURN",
    "SIDEWAYS",
    "BASE_TOLERANCE",
    "YAW_TOLERANCE",
    "JOINT_TOLERANCE",
    "TORSO_TOLERANCE",
    "HEAD_TOLERANCE",
    "OPEN_FRACTION",
    "CLOSED_OPENING",
    "REACH_HEIGHT",
    "refusal",
]

#: The forward drive [m] of ``moving`` and ``cancelling_movement``.
FORWARD = 0.3
#: The turn on the spot [rad] of ``moving``.
TURN = 0.5
#: The sideways move [m] of ``moving`` (to the left; a differential drive may refuse it).
SIDEWAYS = 0.2
#: A base goal counts as reached within this distance [m] ...
BASE_TOLERANCE = 0.05
#: ... and this heading difference [rad].
YAW_TOLERANCE = 0.05
#: A joint motion's remaining error [rad] must be at most this.
JOINT_TOLERANCE = 0.02
#: The torso's remaining error [m] must be at most this.
TORSO_TOLERANCE = 0.01
#: The angle [rad] between the camera's view and the point looked at must be at most this (2 deg).
HEAD_TOLERANCE = math.radians(2.0)
#: Fully open, a gripper opens at least this fraction of its maximum opening.
OPEN_FRACTION = 0.8
#: Closed on nothing, a gripper's opening is at most this [m].
CLOSED_OPENING = 0.005
#: Height [m] of the point each arm reaches (0.1 m above the counter).
REACH_HEIGHT = 1.0


def _motion(**properties: Any) -> Any:
    from pycram.designator import MotionDesignator, perform

    return perform(MotionDesignator(**properties))


def _angle(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def _in_map(base: Any, dx: float, dy: float) -> tuple[float, float]:
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    return base.x + c * dx - s * dy, base.y + s * dx + c * dy


def refusal(error: BaseException) -> str | None:
    """How a motion was refused cleanly: the typed failure's name and reason (a plan failure, a
    process module's failure or a designator's error, unwrapped), or None for any other error."""
    from pycram.actions.core import RECOVERABLE, unwrap

    if not isinstance(error, RECOVERABLE):
        return None
    inner = unwrap(error)
    reason = getattr(inner, "reason", None)
    first = str(inner).splitlines()[0] if str(inner) else ""
    return f"{type(inner).__name__}" + (f" ({reason})" if reason else "") + (f": {first[:160]}" if first else "")


def _subscribing_pose(scene: CheckScene) -> tuple[str, dict]:
    from pycram.fluent import Fluent

    fl = Fluent(name="robot-check pose")
    _motion(type="subscribing_pose", fl=fl)
    believed, truth = fl.get_value(), scene.world.base_pose.get_value()
    if believed is None:
        raise CheckFailed("the subscribed fluent has no value")
    error = math.hypot(believed.x - truth.x, believed.y - truth.y)
    if error > 0.01:
        raise CheckFailed(f"the subscribed pose is {error:.3f} m from the base's")
    return f"follows the base pose ({truth.x:.2f}, {truth.y:.2f}) m", {"error": error}


def _subscribing_gripper(scene: CheckScene) -> tuple[str, dict]:
    from pycram.fluent import Fluent

    parts = []
    data = {}
    for gripper in scene.description.GRIPPERS:
        fl = Fluent(name=f"robot-check {gripper} opening")
        _motion(type="subscribing_gripper", gripper=gripper, fl=fl)
        value, truth = fl.get_value(), scene.world.gripper_states[gripper].get_value().opening
        if not isinstance(value, (int, float)) or abs(value - truth) > 0.005:
            raise CheckFailed(f"{gripper}: the subscribed opening is {value!r}, the gripper's {truth:.3f} m")
        parts.append(f"{gripper} {value * 1000:.0f} mm")
        data[gripper] = value
    return "follows " + ", ".join(parts), data


def _setting_torso(scene: CheckScene) -> tuple[str, dict]:
    d = scene.description
    low, high = d.TORSO["range"]
    names = [n for n in d.TORSO_POSITIONS if n != "up"] + (["up"] if "up" in d.TORSO_POSITIONS else [])
    targets: list[Any] = [names[0]] if names else []
    targets += [round((low + high) / 2, 3)] + names[1:]
    errors = {}
    for target in targets:
        error = float(_motion(type="setting_torso", position=target))
        errors[str(target)] = error
        if abs(error) > TORSO_TOLERANCE:
            raise CheckFailed(f"torso to {target!r}: {abs(error) * 1000:.1f} mm off (> {TORSO_TOLERANCE * 1000:.0f})")
    worst = max(map(abs, errors.values()))
    return f"to {', '.join(str(t) for t in targets)} (max error {worst * 1000:.1f} mm)", {"errors": errors}


def _first_configuration(scene: CheckScene, arm: str) -> str:
    return next(iter(scene.description.ARM_CONFIGURATIONS[arm]))


def _setting_arm_configuration(scene: CheckScene) -> tuple[str, dict]:
    parts, data = [], {}
    for arm, configurations in scene.description.ARM_CONFIGURATIONS.items():
        names = list(configurations) + [_first_configuration(scene, arm)]
        worst = 0.0
        for name in names:
            error = float(_motion(type="setting_arm_configuration", arm=arm, configuration=name))
            data[f"{arm}/{name}"] = error
            if abs(error) > JOINT_TOLERANCE:
                raise CheckFailed(f"{arm} arm to {name!r}: {abs(error):.3f} rad off (> {JOINT_TOLERANCE})")
            worst = max(worst, abs(error))
        parts.append(f"{arm}: {', '.join(configurations)} (max error {worst:.3f} rad)")
    return "; ".join(parts), data


def _setting_arm_joints(scene: CheckScene) -> tuple[str, dict]:
    parts, data = [], {}
    for arm, configurations in scene.description.ARM_CONFIGURATIONS.items():
        names = list(configurations)
        targets = [names[1 % len(names)], names[0]]
        for name in targets:
            error = float(_motion(type="setting_arm_joints", arm=arm, positions=tuple(configurations[name])))
            data[f"{arm}/{name}"] = error
            if abs(error) > JOINT_TOLERANCE:
                raise CheckFailed(f"{arm} arm to the joints of {name!r}: {abs(error):.3f} rad off")
        parts.append(f"{arm}: joints of {' and '.join(targets)}")
    return "; ".join(parts), data


def _setting_gripper(scene: CheckScene) -> tuple[str, dict]:
    parts, data = [], {}
    for gripper, spec in scene.description.GRIPPERS.items():
        opened = float(_motion(type="setting_gripper", gripper=gripper, position=1.0))
        if opened < OPEN_FRACTION * spec["max_opening"]:
            raise CheckFailed(
                f"{gripper} opened {opened * 1000:.0f} mm of {spec['max_opening'] * 1000:.0f} mm "
                f"(< {OPEN_FRACTION:.0%})"
            )
        closed = float(_motion(type="setting_gripper", gripper=gripper, position=0.0))
        if closed > CLOSED_OPENING:
            raise CheckFailed(f"{gripper} closed on nothing stays {closed * 1000:.1f} mm open")
        data[gripper] = {"open": opened, "closed": closed}
        parts.append(f"{gripper} open {opened * 1000:.0f} mm, closed {closed * 1000:.1f} mm")
    return "; ".join(parts), data


def _pointing_head(scene: CheckScene) -> tuple[str, dict]:
    base = scene.world.base_pose.get_value()
    errors = []
    for ahead, left, z in ((1.0, 0.0, 0.9), (1.5, 0.5, 1.2)):
        x, y = _in_map(base, ahead, left)
        error = float(_motion(type="pointing_head", coordinates=(x, y, z)))
        errors.append(error)
        if error > HEAD_TOLERANCE:
            raise CheckFailed(f"looking at ({x:.2f}, {y:.2f}, {z:.2f}): {math.degrees(error):.1f} deg off")
    return f"2 points ahead (max {math.degrees(max(errors)):.2f} deg off)", {"errors": errors}


def _check_reached(what: str, reached: Any, goal: tuple[float, float, float]) -> None:
    distance = math.hypot(reached.x - goal[0], reached.y - goal[1])
    turn = abs(_angle(reached.yaw - goal[2]))
    if distance > BASE_TOLERANCE or turn > YAW_TOLERANCE:
        raise CheckFailed(
            f"{what}: the base ended {distance:.3f} m and {math.degrees(turn):.1f} deg from its goal "
            f"({goal[0]:.2f}, {goal[1]:.2f}, {goal[2]:.2f})"
        )


def _moving(scene: CheckScene) -> tuple[str, dict]:
    world = scene.world
    start = world.base_pose.get_value()
    parts = []
    steps = (("forward", (FORWARD, 0.0, 0.0)), ("turn left", (0.0, 0.0, TURN)), ("turn right", (0.0, 0.0, -TURN)))
    for what, relative in steps:
        base = world.base_pose.get_value()
        goal = (*_in_map(base, relative[0], relative[1]), base.yaw + relative[2])
        reached = _motion(type="moving", pose=relative, frame="base_footprint")
        _check_reached(what, reached, goal)
    parts.append(f"forward {FORWARD} m, turned {TURN} rad and back")
    base = world.base_pose.get_value()
    goal = (*_in_map(base, 0.0, SIDEWAYS), base.yaw)
    data: dict[str, Any] = {}
    try:
        reached = _motion(type="moving", pose=(0.0, SIDEWAYS, 0.0), frame="base_footprint")
    except Exception as error:  # a typed refusal is fine, anything else is not
        why = refusal(error)
        if why is None:
            raise
        parts.append(f"sideways refused: {why}")
        data["sideways"] = f"refused: {why}"
    else:
        _check_reached("sideways", reached, goal)
        parts.append(f"sideways {SIDEWAYS} m done")
        data["sideways"] = "done"
    reached = _motion(type="moving", pose=(start.x, start.y, start.yaw))
    _check_reached("back to the start", reached, (start.x, start.y, start.yaw))
    parts.append("back to the start (map)")
    return "; ".join(parts), data


def _cancelling_movement(scene: CheckScene) -> tuple[str, dict]:
    from pycram.execution.process_module import ProcessModuleStatus
    from pycram.fluent import Fluent

    world = scene.world
    start = world.base_pose.get_value()
    goal = _in_map(start, FORWARD, 0.0)
    pose = Fluent(name="robot-check pose")
    _motion(type="subscribing_pose", fl=pose)
    drive = _motion(type="moving", pose=(FORWARD, 0.0, 0.0), frame="base_footprint", wait=False)
    moving = Fluent(
        lambda: True if math.hypot(pose.get_value().x - start.x, pose.get_value().y - start.y) > 0.05 else None
    )
    pose.add_child(moving)
    if not moving.wait_for(timeout=30.0):
        drive.cancel()
        raise CheckFailed("the drive started without waiting did not move the base 5 cm within 30 s")
    stopped = _motion(type="cancelling_movement")
    try:
        drive.wait(timeout=30.0)
    except Exception:  # noqa: S110 - a cancelled drive raises; its status is checked below
        pass
    status = drive.status.get_value()
    if status is not ProcessModuleStatus.CANCELLED:
        raise CheckFailed(f"the stopped drive ended {status.value}, not cancelled")
    short = math.hypot(goal[0] - stopped.x, goal[1] - stopped.y)
    if short < 0.01:
        raise CheckFailed("the base reached the goal of the stopped drive")
    _motion(type="moving", pose=(start.x, start.y, start.yaw))
    return f"stopped {short:.2f} m short of its goal; the drive ended cancelled", {"short": short}


def _reaching(scene: CheckScene) -> tuple[str, dict]:
    d = scene.description
    base = scene.world.base_pose.get_value()
    tolerance = float(d.REACH_TOLERANCE.get("default", 0.01)) + 0.005
    parts, data = [], {}
    for arm in d.ARMS:
        ahead, left = d.REACH_POINT_IN_BASE[arm]
        target = (*_in_map(base, ahead, left), REACH_HEIGHT)
        reached = _motion(type="reaching", arm=arm, target=target)
        error = math.dist(reached.position, target)
        data[arm] = {"target": target, "error": error}
        if error > tolerance:
            raise CheckFailed(
                f"{arm} arm: the tool ended {error * 1000:.0f} mm from the target (> {tolerance * 1000:.0f})"
            )
        _motion(type="setting_arm_configuration", arm=arm, configuration=_first_configuration(scene, arm))
        parts.append(
            f"{arm} to ({ahead:.2f}, {left:.2f}, {REACH_HEIGHT:.2f}) m in the base frame, {error * 1000:.0f} mm off"
        )
    return "; ".join(parts), data


def _detecting(scene: CheckScene) -> tuple[str, dict]:
    seen = _motion(type="detecting")
    if not isinstance(seen, list):
        raise CheckFailed(f"detecting returned {type(seen).__name__}, not a list of perceived objects")
    names = [getattr(o, "name", str(o)) for o in seen]
    return f"one look: {len(seen)} object(s) seen" + (f" ({', '.join(names)})" if names else ""), {"seen": names}


#: The case of each motion type, in the order they run: ``case(scene) -> (detail, data)``.
MOTION_CASES: dict[str, Callable[[CheckScene], tuple[str, dict]]] = {
    "subscribing_pose": _subscribing_pose,
    "subscribing_gripper": _subscribing_gripper,
    "setting_torso": _setting_torso,
    "setting_arm_configuration": _setting_arm_configuration,
    "setting_arm_joints": _setting_arm_joints,
    "setting_gripper": _setting_gripper,
    "pointing_head": _pointing_head,
    "moving": _moving,
    "cancelling_movement": _cancelling_movement,
    "reaching": _reaching,
    "detecting": _detecting,
}


def motion_cases(vocabulary: Any) -> list[tuple[str, Callable[[CheckScene], tuple[str, dict]] | None, str]]:
    """The motion cases to run for a robot whose vocabulary (``robot.motion_types``) is
    `vocabulary`: ``(type, case or None, why skipped)``; the vocabulary's types without a case
    come last, with None."""
    out: list[tuple[str, Callable[[CheckScene], tuple[str, dict]] | None, str]] = []
    for name, case in MOTION_CASES.items():
        if name in vocabulary:
            out.append((name, case, ""))
        else:
            out.append((name, None, "not in the robot's motion vocabulary"))
    for name in vocabulary:
        if name not in MOTION_CASES:
            out.append((name, None, "no conformance case for this motion type yet"))
    return out
