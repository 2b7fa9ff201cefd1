"""The action framework: typed constructors, the plan registry, and what every action plan uses.

An action is a plan registered under an action type (`action_plan`), and a typed constructor
that builds its `ActionDesignator` (`make_action`)::

    @action_plan("parking_arms")
    def park(designator): ...

    def ParkArms() -> ActionDesignator:
        return make_action("parking_arms")

`perform(ParkArms())` resolves the designator through `resolve_action` (one entry of the global
`ActionDesignator.resolvers`, added when `pycram.actions` is imported) to the registered plan and
runs it as a task named ``perform parking_arms``. A robot or a world may still register its own
plan for a type before the library's (their resolvers are asked first).

The helpers below are what the action plans share: the active robot's arms and grippers (from
its description: data, never code of a robot package), motions by keyword, a gripper's measured
opening, unwrapping a process module's failure into the typed failure it carries, and running
one attempt of an action as a task of its own so that the task tree shows every recovery.

A plan may give the drives of the action library a companion (`while_driving`): within its
block, every drive (a ``moving`` motion in the map frame, through `motion`) runs as
``pursue(drive, job)``, so a plan can look around while any action drives -- the head is free
then -- without the actions knowing about it.
"""

from __future__ import annotations

import logging
import weakref
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from pycram.core.expressions import State, pursue
from pycram.core.fluent import Fluent
from pycram.core.runtime.task_variables import TaskVariable
from pycram.designators.action import ActionDesignator
from pycram.designators.core import DesignatorError, NoSolutionError, PropertyError
from pycram.designators.motion import MotionDesignator
from pycram.designators.object import ObjectDesignator
from pycram.execution.failures import PlanFailure
from pycram.execution.perform import perform
from pycram.execution.process_module import ProcessModuleError, ProcessModuleFailure
from pycram.execution.robot import current_robot
from pycram.world.objects import APPROACHES, OBJECT_TYPES

__all__ = [
    "ACTION_PLANS",
    "ActionParameterError",
    "RECOVERABLE",
    "action_plan",
    "make_action",
    "check_grasp",
    "check_object_type",
    "resolve_action",
    "motion",
    "while_driving",
    "arms",
    "arm_name",
    "gripper_name",
    "gripper_of",
    "gripper_opening",
    "opening_fluent",
    "base_pose_fluent",
    "unwrap",
    "attempt",
    "best_effort",
    "solutions",
]

log = logging.getLogger("pycram.actions")

#: Action type -> plan(designator): the plans of the action library.
ACTION_PLANS: dict[str, Callable[[ActionDesignator], Any]] = {}

#: Errors an action's recovery may handle (evaporation and programming errors always pass).
RECOVERABLE = (PlanFailure, ProcessModuleError, DesignatorError)


class ActionParameterError(PropertyError):
    """An action designator's parameter is missing or invalid. Names the action, the key and,
    where there are any, the valid values."""

    def __init__(self, action: str, key: str, message: str, choices: Any = None) -> None:
        text = f"{action}: parameter {key!r}: {message}"
        if choices:
            text += f" (valid: {', '.join(map(str, choices))})"
        super().__init__(text)
        self.action, self.key, self.choices = action, key, list(choices or ())


def action_plan(action_type: str) -> Callable[[Callable[[ActionDesignator], Any]], Callable[[ActionDesignator], Any]]:
    """Register the decorated function as the library's plan for `action_type`."""

    def register(plan: Callable[[ActionDesignator], Any]) -> Callable[[ActionDesignator], Any]:
        ACTION_PLANS[action_type] = plan
        return plan

    return register


def make_action(action_type: str, **parameters: Any) -> ActionDesignator:
    """An `ActionDesignator` of `action_type` with the parameters that are not None (a parameter
    left None is chosen by resolution)."""
    properties = [("type", action_type)]
    properties += [(key, value) for key, value in parameters.items() if value is not None]
    return ActionDesignator(properties)


def check_grasp(action: str, grasp: Any) -> str | None:
    """`grasp` when it is None or an approach of `pycram.world.objects.APPROACHES`; otherwise
    `ActionParameterError` naming the valid approaches (whether the object's type has that
    grasp is decided when the object is known: `GraspFailed`, reason ``no_executable_grasp``)."""
    if grasp is None:
        return None
    if not isinstance(grasp, str) or grasp not in APPROACHES:
        raise ActionParameterError(action, "grasp", f"no grasp approach {grasp!r}", APPROACHES)
    return grasp


def check_object_type(action: str, wanted: Any, key: str = "object", names_too: bool = False) -> None:
    """Refuse at once an object given by a type nobody knows: a type name (a string; with
    `names_too` a string may also be a believed object's name, and is not checked) or an
    object designator's ``type``. `ActionParameterError` names the known types
    (`pycram.world.objects.OBJECT_TYPES`); anything else passes."""
    type_name = wanted if isinstance(wanted, str) and not names_too else None
    if isinstance(wanted, ObjectDesignator):
        type_name = wanted.prop_value("type")
    if isinstance(type_name, str) and type_name not in OBJECT_TYPES:
        raise ActionParameterError(action, key, f"unknown object type {type_name!r}", sorted(OBJECT_TYPES))


def resolve_action(designator: ActionDesignator) -> Any:
    """Action resolver: the library's plan for the designator's type (None for other types)."""
    return ACTION_PLANS.get(designator.prop_value("type"))


#: The job bound by `while_driving` (None: drives run alone).
_DRIVING_JOB: TaskVariable[Callable[[], Any] | None] = TaskVariable("while_driving", default=None)


@contextmanager
def while_driving(job: Callable[[], Any]) -> Iterator[None]:
    """Within the block (in the calling task and every task it starts), each drive of the base
    through `motion` -- a ``moving`` motion in the map frame, i.e. without a ``frame`` -- runs
    as ``pursue(drive, job)``: `job` starts with the drive and is evaporated as soon as the
    drive ends (its ``finally`` blocks run; a head motion it started is cancelled), so the drive
    returns, or raises its own failure, exactly as it would alone. `job` may return early (the
    drive then goes on alone); its recoverable failures (`RECOVERABLE`) are logged, never
    raised. `job` must use only what a drive leaves free (the head, perception): it must not
    drive (drives inside it run without a companion) or move an arm."""
    with _DRIVING_JOB.bound(job):
        yield


def _companion(job: Callable[[], Any]) -> Callable[[], None]:
    def look_while_driving() -> None:
        with _DRIVING_JOB.bound(None):  # no companion for the companion's own motions
            try:
                job()
            except RECOVERABLE as error:
                log.info("while driving: %s", unwrap(error))
            Fluent(None, name="until the drive ends").wait_for()  # evaporated when the drive ends

    return look_while_driving


def motion(**properties: Any) -> Any:
    """Perform a motion designator made of `properties`; return the process module's result.

    A drive (``type='moving'`` without ``frame``) inside a `while_driving` block runs with that
    block's job alongside (``pursue``); it raises what the drive alone raises."""
    job = _DRIVING_JOB.get()
    if job is None or properties.get("type") != "moving" or "frame" in properties:
        return perform(MotionDesignator(**properties))
    errors: list[BaseException] = []

    def drive() -> Any:
        return perform(MotionDesignator(**properties))

    state = pursue(drive, _companion(job), errors=errors, name="drive, looking around")
    if state.get_value() is not State.SUCCEEDED:
        raise errors[0] if errors else PlanFailure(f"the drive to {properties.get('pose')!r} did not succeed")
    return state.result


def _description() -> Any:
    robot = current_robot()
    description = getattr(robot, "description", None)
    if description is None:
        raise PlanFailure(
            f"the action library needs an active robot with a description (arms, grippers); active robot: {robot!r}"
        )
    return description


def arms() -> list[str]:
    """The active robot's arms, its default arm first (a one-armed robot has one)."""
    d = _description()
    names = list(d.ARMS)
    default = d.DEFAULT_ARM
    return [default] + [a for a in names if a != default]


def arm_name(action: str, requested: Any) -> str | None:
    """The robot's name for the arm `requested` (aliases allowed; None stays None)."""
    if requested is None:
        return None
    d = _description()
    aliases = d.ARM_ALIASES
    if requested not in aliases:
        raise ActionParameterError(
            action, "arm", f"the robot has no arm {requested!r}", sorted(str(a) for a in aliases)
        )
    return str(aliases[requested])


def gripper_name(action: str, requested: Any) -> str | None:
    """The robot's name for the gripper `requested` (its ``GRIPPER_ALIASES`` allowed; None stays
    None). A gripper's names need not be its arm's (a ``'hand'`` on the arm ``'arm'``)."""
    if requested is None:
        return None
    aliases = _description().GRIPPER_ALIASES
    if requested not in aliases:
        raise ActionParameterError(
            action, "gripper", f"the robot has no gripper {requested!r}", sorted(str(a) for a in aliases)
        )
    return str(aliases[requested])


def gripper_of(arm: str) -> str:
    """The gripper mounted on `arm`."""
    return str(_description().ARMS[arm]["gripper"])


#: Sensor fluents per robot: grippers' openings by gripper name, the base pose.
_openings: weakref.WeakKeyDictionary[Any, dict[str, Fluent]] = weakref.WeakKeyDictionary()


def opening_fluent(gripper: str) -> Fluent:
    """A fluent that follows the measured opening [m] of `gripper` (a sensor:
    ``subscribing_gripper``, subscribed once per robot and gripper)."""
    robot = current_robot()
    per_robot = _openings.setdefault(robot, {})
    fluent = per_robot.get(gripper)
    if fluent is None:
        fluent = per_robot[gripper] = Fluent(name=f"{gripper} gripper opening")
        motion(type="subscribing_gripper", gripper=gripper, fl=fluent)
    return fluent


def base_pose_fluent() -> Fluent:
    """A fluent that follows the active robot's base pose (`Pose2D`, map frame; a sensor:
    ``subscribing_pose``, subscribed once per robot)."""
    robot = current_robot()
    per_robot = _openings.setdefault(robot, {})
    fluent = per_robot.get(" base pose")
    if fluent is None:
        fluent = per_robot[" base pose"] = Fluent(name="base pose")
        motion(type="subscribing_pose", fl=fluent)
    return fluent


def gripper_opening(gripper: str, timeout: float = 5.0) -> float:
    """The measured opening [m] of `gripper` (see `opening_fluent`). Raises `PlanFailure` when
    no measurement arrives within `timeout` [s of the active clock]."""
    fluent = opening_fluent(gripper)
    if not fluent.wait_for(timeout):
        raise PlanFailure(f"no measurement of the {gripper} gripper's opening within {timeout} s")
    return float(fluent.get_value())


def unwrap(error: BaseException) -> BaseException:
    """The typed failure inside a process module's failure (the error itself otherwise)."""
    while isinstance(error, ProcessModuleFailure) and error.cause is not None:
        error = error.cause
    return error


def solutions(designator: Any) -> Iterator[Any]:
    """The solutions of `designator`, best first. Unlike `Designator.solutions`, a designator
    without any solution raises its `NoSolutionError` (which says what ruled the candidates
    out); running out of further solutions ends the iteration."""
    current = designator
    yield current.reference()
    while True:
        current = current.next_solution()
        if current is None:
            return
        try:
            solution = current.reference()
        except NoSolutionError:
            return
        yield solution


def best_effort(what: str, *steps: Callable[[], Any]) -> None:
    """Run each step in turn; a step's recoverable failure is logged (`what`: of what) and the
    next step runs. For clean-up after a failed attempt (let go, back off, arm up)."""
    for step in steps:
        try:
            step()
        except RECOVERABLE as error:
            log.info("%s: %s", what, unwrap(error))


def attempt(name: str, body: Callable[[], Any]) -> Any:
    """Run `body` as a task called `name` (so the task tree shows each attempt of an action)."""
    from pycram.core.runtime import run_subtask

    return run_subtask(name, body, kind="attempt")
