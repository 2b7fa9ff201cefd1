"""Check e: each action of the action library, performed on the robot in the fixed scene.

The cases (`ACTION_CASES`) run in this order in one fresh world of the scene
(:mod:`pycram.apps.robot_check.scene`), each ``perform``-ing the library's action designator as a
plan would, and are judged with the simulator's truth:

- ``parking_arms``: every arm within `JOINT_TOLERANCE` of its ``park`` configuration;
- ``moving_torso``: ``up``, the torso joint within 1 cm of it;
- ``setting_gripper``: the default arm's gripper fully open (at least 80 % of its opening);
- ``navigating``: to the apartment's place in front of the counter, within 5 cm;
- ``looking_at``: the counter;
- ``detecting``: the test object, believed within 3 cm of where it stands;
- ``searching``: the test object (an object designator), found;
- ``picking_up``: what the search found, then held by a gripper;
- ``placing``: the held object on `PLACE_TARGET`, standing upright there and let go;
- ``transporting``: the object (an object designator: searched for, picked up, placed) from
  where it is to the other surface (the counter or `PLACE_TARGET`), upright there;
- ``opening`` / ``closing``: `CONTAINER`, open at least `OPEN_AT_LEAST` / closed to at most
  `CLOSED_AT_MOST` (its slide's truth).

An action type of the library (``pycram.actions.ACTION_PLANS``) without a case is skipped with
that reason. The short form runs `SHORT_ACTION` alone, from the start: after parking the arms
and raising the torso, the test object from the counter to `PLACE_TARGET`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pycram.apps.robot_check.results import CheckFailed, CheckSkipped
from pycram.apps.robot_check.scene import (
    CONTAINER,
    PLACE_TARGET,
    TEST_OBJECT,
    TRANSPORT_TARGET,
    VIEWPOINT,
    CheckScene,
    holding,
    rests_on,
)

__all__ = [
    "ACTION_CASES",
    "SHORT_ACTION",
    "JOINT_TOLERANCE",
    "OPEN_AT_LEAST",
    "CLOSED_AT_MOST",
    "ActionState",
    "action_cases",
]

#: A parked arm's joints lie this close [rad] to its ``park`` configuration.
JOINT_TOLERANCE = 0.05
#: An opened container is open at least this far [m for a drawer, rad for a door].
OPEN_AT_LEAST = 0.15
#: A closed container is open at most this far [m or rad].
CLOSED_AT_MOST = 0.03
#: The action of the short form.
SHORT_ACTION = "transporting"

ActionCase = Callable[[CheckScene, "ActionState"], tuple[str, dict]]


@dataclass
class ActionState:
    """What one action case leaves for the next: the believed test object, the grasp held."""

    found: Any = None
    held: Any = None


def _parking_arms(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import ParkArms
    from pycram.designator import perform

    perform(ParkArms())
    joints = scene.world.joint_states.get_value().position
    errors = {}
    for arm, spec in scene.description.ARMS.items():
        park = scene.description.ARM_CONFIGURATIONS[arm].get("park")
        if park is None:
            raise CheckFailed(f"arm {arm!r} has no 'park' configuration (ParkArms needs one)")
        errors[arm] = max(abs(joints[j] - q) for j, q in zip(spec["joints"], park, strict=True))
        if errors[arm] > JOINT_TOLERANCE:
            raise CheckFailed(f"the {arm} arm is {errors[arm]:.3f} rad from 'park' (> {JOINT_TOLERANCE})")
    return "every arm parked (" + ", ".join(f"{a} {e:.3f} rad off" for a, e in errors.items()) + ")", errors


def _moving_torso(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import MoveTorso
    from pycram.designator import perform

    d = scene.description
    perform(MoveTorso("up"))
    height = scene.world.joint_states.get_value().position[d.TORSO["joint"]]
    error = abs(height - d.TORSO_POSITIONS["up"])
    if error > 0.01:
        raise CheckFailed(f"the torso stands at {height:.3f} m, 'up' is {d.TORSO_POSITIONS['up']:.3f} m")
    return f"up: {height:.3f} m", {"height": height}


def _setting_gripper(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import SetGripper
    from pycram.designator import perform

    d = scene.description
    gripper = d.ARMS[d.DEFAULT_ARM]["gripper"]
    perform(SetGripper(gripper, 1.0))
    opening = scene.world.gripper_states[gripper].get_value().opening
    if opening < 0.8 * d.GRIPPERS[gripper]["max_opening"]:
        raise CheckFailed(f"the {gripper} gripper opened {opening * 1000:.0f} mm only")
    return f"{gripper} open {opening * 1000:.0f} mm", {"opening": opening}


def _navigating(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Navigate
    from pycram.designator import perform

    perform(Navigate(VIEWPOINT))
    goal = scene.world.environment.place(VIEWPOINT).pose
    base = scene.world.base_pose.get_value()
    distance = math.hypot(base.x - goal[0], base.y - goal[1])
    if distance > 0.05:
        raise CheckFailed(f"the base stands {distance:.2f} m from {VIEWPOINT!r}")
    return f"to {VIEWPOINT!r}, {distance * 1000:.0f} mm off", {"distance": distance}


def _looking_at(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import LookAt
    from pycram.designator import perform

    error = perform(LookAt(TRANSPORT_TARGET))
    return f"at the {TRANSPORT_TARGET}", {"error": error}


def _believed_within(scene: CheckScene, seen: Any, tolerance: float = 0.03) -> float:
    truth = scene.world.item_poses.get_value()[TEST_OBJECT].position
    error = math.dist(seen.pose, truth)
    if error > tolerance:
        raise CheckFailed(f"{seen.name} is believed {error * 100:.1f} cm from where it stands")
    return error


def _detecting(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Detect
    from pycram.designator import perform

    seen = perform(Detect(TEST_OBJECT))
    if not seen:
        raise CheckFailed(f"no {TEST_OBJECT} seen")
    error = _believed_within(scene, seen[0])
    return f"{seen[0].name}, {error * 1000:.0f} mm from where it stands", {"error": error}


def _searching(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Search
    from pycram.designator import ObjectDesignator, perform

    state.found = perform(Search(ObjectDesignator(type=TEST_OBJECT)))
    error = _believed_within(scene, state.found)
    return f"found {state.found.name}", {"error": error}


def _picking_up(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import PickUp
    from pycram.designator import ObjectDesignator, perform

    target = state.found if state.found is not None else ObjectDesignator(type=TEST_OBJECT)
    state.held = perform(PickUp(target))
    held = holding(scene.world)
    if TEST_OBJECT not in held:
        raise CheckFailed(f"PickUp succeeded but the grippers hold {sorted(held) or 'nothing'}")
    return f"{TEST_OBJECT} held by the {state.held.arm} arm ({state.held.grasp.approach} grasp)", {
        "arm": state.held.arm,
        "approach": state.held.grasp.approach,
    }


def _placing(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Place
    from pycram.designator import perform

    if state.held is None:
        raise CheckSkipped("nothing held: picking_up did not succeed")
    perform(Place(state.held, PLACE_TARGET))
    state.held = None
    return _judge_on(scene, PLACE_TARGET)


def _judge_on(scene: CheckScene, surface: str) -> tuple[str, dict]:
    ok, where = rests_on(scene.world, TEST_OBJECT, surface)
    if TEST_OBJECT in holding(scene.world):
        raise CheckFailed(f"the {TEST_OBJECT} is still held, at {where}")
    if not ok:
        raise CheckFailed(f"the {TEST_OBJECT} does not stand on the {surface}: {where}")
    return f"upright on the {surface} at {where}", {"where": where}


def _transporting(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Transport
    from pycram.designator import ObjectDesignator, perform

    on_counter, _ = rests_on(scene.world, TEST_OBJECT, TRANSPORT_TARGET)
    target = PLACE_TARGET if on_counter else TRANSPORT_TARGET
    perform(Transport(ObjectDesignator(type=TEST_OBJECT), target))
    detail, data = _judge_on(scene, target)
    return f"to the {target}: {detail}", data


def _transporting_from_the_start(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import MoveTorso, ParkArms
    from pycram.designator import perform

    perform(ParkArms())
    perform(MoveTorso("up"))
    detail, data = _transporting(scene, state)
    return f"{detail} (after parking the arms, torso up)", data


def _container_opening(scene: CheckScene) -> float:
    return float(scene.world.container_states.get_value()[CONTAINER])


def _opening(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Open
    from pycram.designator import perform

    measured = perform(Open(CONTAINER))
    opening = _container_opening(scene)
    if opening < OPEN_AT_LEAST:
        raise CheckFailed(f"{CONTAINER} is open {opening:.3f} only (< {OPEN_AT_LEAST})")
    return f"{CONTAINER} open {opening:.3f} (measured {float(measured):.3f})", {"opening": opening}


def _closing(scene: CheckScene, state: ActionState) -> tuple[str, dict]:
    from pycram.actions import Close
    from pycram.designator import perform

    perform(Close(CONTAINER))
    opening = _container_opening(scene)
    if opening > CLOSED_AT_MOST:
        raise CheckFailed(f"{CONTAINER} is still open {opening:.3f} (> {CLOSED_AT_MOST})")
    return f"{CONTAINER} closed ({opening:.3f} open)", {"opening": opening}


#: The case of each action type, in the order they run: ``case(scene, state) -> (detail, data)``.
ACTION_CASES: dict[str, ActionCase] = {
    "parking_arms": _parking_arms,
    "moving_torso": _moving_torso,
    "setting_gripper": _setting_gripper,
    "navigating": _navigating,
    "looking_at": _looking_at,
    "detecting": _detecting,
    "searching": _searching,
    "picking_up": _picking_up,
    "placing": _placing,
    "transporting": _transporting,
    "opening": _opening,
    "closing": _closing,
}


def action_cases(short: bool = False) -> list[tuple[str, ActionCase | None, str]]:
    """The action cases to run: ``(action type, case or None, why skipped)``. The full form has
    every case, then the library's action types without one (None); the short form only
    `SHORT_ACTION`, from the start."""
    if short:
        return [(SHORT_ACTION, _transporting_from_the_start, "")]
    from pycram.actions import ACTION_PLANS

    out: list[tuple[str, ActionCase | None, str]] = [(name, case, "") for name, case in ACTION_CASES.items()]
    out += [
        (name, None, "no conformance case for this action yet") for name in ACTION_PLANS if name not in ACTION_CASES
    ]
    return out
