"""Running a conformance check of one robot: every check in order, each timed, none aborting the run.

`run_robot_check` runs the checks of :mod:`pycram.apps.robot_check` for a registered robot and
returns a :class:`~pycram.apps.robot_check.results.CheckReport`:

a. ``description``: the robot's description validates
   (:func:`pycram.world.robot_registry.robot_description`); ``world``: the simulated world of the
   fixed scene builds with the robot in it and the robot loads
   (:class:`~pycram.apps.robot_check.scene.CheckScene`);
b. ``motion: TYPE``: every motion type of the robot's vocabulary
   (:mod:`~pycram.apps.robot_check.motions`);
c. ``reach: ARM arm``: each arm's reach envelope (:mod:`~pycram.apps.robot_check.reach`);
d. ``camera sees a test object`` (:mod:`~pycram.apps.robot_check.camera`);
e. ``action: TYPE``: each action of the library in a fresh world of the scene
   (:mod:`~pycram.apps.robot_check.actions`);
f. ``set-table seed N``: the set-table scenario on development seeds
   (:mod:`~pycram.apps.robot_check.set_table`).

The **short form** (``short=True``) runs a-d, one action (transporting) and no set-table seed:
it takes seconds per robot, so the test suite runs it for every registered robot. The full
form runs everything (one to two minutes per robot, most of it set-table).

A check that raises is a ``FAIL`` whose detail is the failure's type, reason and first line; the
checks after it still run (those that need what failed are ``SKIP`` with that reason). Only an
unknown robot name raises (`UnknownRobotError`, listing the registered robots), before anything
runs.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from functools import partial
from typing import Any

from pycram.apps.robot_check.results import (
    FAIL,
    PASS,
    SKIP,
    CheckFailed,
    CheckReport,
    CheckResult,
    CheckSkipped,
)

__all__ = ["FORMS", "run_robot_check", "describe_error", "describe_robot"]

log = logging.getLogger("pycram.robot_check")

#: The forms of a check run.
FORMS = ("full", "short")
#: The longest detail [characters] an error gives a row.
_MAX_DETAIL = 300


def describe_error(error: BaseException) -> str:
    """A failure in one line: its type (a process module's failure unwrapped into the typed
    failure it carries), its reason if it has one, and the first line of its message."""
    from pycram.actions.core import unwrap

    inner = unwrap(error)
    reason = getattr(inner, "reason", None)
    lines = str(inner).strip().splitlines()
    text = type(inner).__name__ + (f" ({reason})" if isinstance(reason, str) and reason else "")
    if lines:
        text += f": {lines[0]}"
    return text if len(text) <= _MAX_DETAIL else text[: _MAX_DETAIL - 1] + "…"


def describe_robot(description: Any) -> str:
    """The robot in one line: arms (with their joint counts), grippers, base kind, URDF."""
    arms = ", ".join(f"{a} ({len(s['joints'])} joints)" for a, s in description.ARMS.items())
    kind = description.BASE.get("kind", "omnidirectional")
    return f"arms {arms}; grippers {', '.join(description.GRIPPERS)}; {kind} base; {description.URDF}"


class _Run:
    """One run: appends rows to `report`, telling `on_start` and `on_result`."""

    def __init__(
        self,
        report: CheckReport,
        on_start: Callable[[str], None] | None,
        on_result: Callable[[CheckResult], None] | None,
    ) -> None:
        self.report, self.on_start, self.on_result = report, on_start, on_result

    def add(self, result: CheckResult) -> CheckResult:
        self.report.results.append(result)
        log.info("%s: %s %s", result.check, result.result, result.detail)
        if self.on_result is not None:
            self.on_result(result)
        return result

    def skip(self, group: str, check: str, why: str) -> CheckResult:
        return self.add(CheckResult(group, check, SKIP, why))

    def row(
        self, group: str, check: str, body: Callable[[], Any], clock: Callable[[], float] | None = None
    ) -> CheckResult:
        """Run `body` as the check `check`: it returns (detail, data) or (detail, data, sim time
        [s]); `CheckFailed` / `CheckSkipped` / any other exception give FAIL / SKIP / FAIL.
        `clock` reads the simulated time [s] of the world it runs in."""
        if self.on_start is not None:
            self.on_start(check)
        wall0 = time.perf_counter()
        sim0 = clock() if clock is not None else None
        result, detail, data, sim = PASS, "", {}, None
        try:
            out = body()
            detail, data = out[0], out[1]
            if len(out) > 2:
                sim = out[2]
        except CheckFailed as failed:
            result, detail, data = FAIL, failed.detail, failed.data
            sim = failed.data.get("sim_time") if isinstance(failed.data.get("sim_time"), (int, float)) else None
        except CheckSkipped as skipped:
            result, detail = SKIP, str(skipped)
        except Exception as error:  # a conformance run reports every failure and goes on
            result, detail = FAIL, describe_error(error)
            log.debug("%s failed", check, exc_info=True)
        wall = time.perf_counter() - wall0
        if sim is None and clock is not None and sim0 is not None:
            try:
                sim = clock() - sim0
            except Exception:  # noqa: BLE001 - a closed world has no time to read
                sim = None
        return self.add(CheckResult(group, check, result, detail, sim, wall, data))


def run_robot_check(
    robot: str,
    *,
    short: bool = False,
    on_start: Callable[[str], None] | None = None,
    on_result: Callable[[CheckResult], None] | None = None,
) -> CheckReport:
    """Check the registered robot `robot` (see the module docstring); the short form with
    `short`. `on_start(check)` is called before each check runs, `on_result(result)` after
    each. Raises `pycram.world.robot_registry.UnknownRobotError` for a name that is not
    registered (the message lists the registered robots); every other problem is a row."""
    from pycram.world.robot_registry import robot_description, robot_package

    robot_package(robot)  # an unknown name raises here, naming the registered robots
    report = CheckReport(robot, "short" if short else "full")
    run = _Run(report, on_start, on_result)
    started = time.perf_counter()
    try:
        described = run.row("description", "description validates", lambda: _describe(robot_description(robot)))
        if described.failed:
            for group in ("world", "motions", "reach", "camera", "actions", "set-table"):
                run.skip(group, group, "needs a valid description")
            return report
        _world_checks(run, robot, short)
        _action_checks(run, robot, short)
        _set_table_checks(run, robot, short)
    finally:
        report.wall_time = time.perf_counter() - started
    return report


def _describe(description: Any) -> tuple[str, dict]:
    data = {
        "arms": {a: list(s["joints"]) for a, s in description.ARMS.items()},
        "grippers": list(description.GRIPPERS),
        "base": description.BASE.get("kind", "omnidirectional"),
        "urdf": description.URDF,
    }
    return describe_robot(description), data


def _open_scene(run: _Run, robot: str, check: str) -> Any:
    """The scene, opened as the row `check` (None if that failed)."""
    from pycram.apps.robot_check.scene import ENVIRONMENT, START, CheckScene

    holder: list[Any] = []

    def body() -> tuple[str, dict]:
        scene = CheckScene.open(robot)
        holder.append(scene)
        modules = list(getattr(scene.robot, "process_modules", {}))
        detail = f"{ENVIRONMENT} with a {robot} at {START[0]:.1f}, {START[1]:.1f} m"
        if modules:
            detail += f"; process modules: {', '.join(modules)}"
        return detail, {"process_modules": modules}

    row = run.row("world", check, body)
    return holder[0] if not row.failed and holder else None


def _world_checks(run: _Run, robot: str, short: bool) -> None:
    """a (the world), b (motions), c (reach), d (camera) in one world of the scene."""
    from pycram.apps.robot_check.camera import camera_sees_test_object
    from pycram.apps.robot_check.motions import motion_cases

    scene = _open_scene(run, robot, "world builds, robot loads")
    if scene is None:
        for group in ("motions", "reach", "camera"):
            run.skip(group, group, "needs the world")
        return
    try:
        with scene.robot:
            for name, case, why in motion_cases(scene.robot.motion_types):
                if case is None:
                    run.skip("motions", f"motion: {name}", why)
                else:
                    run.row("motions", f"motion: {name}", partial(case, scene), scene.sim_time)
            _reach_checks(run, scene, short)
            run.row("camera", "camera sees a test object", partial(camera_sees_test_object, scene), scene.sim_time)
    finally:
        scene.close()


def _reach_checks(run: _Run, scene: Any, short: bool) -> None:
    from pycram.apps.robot_check.reach import COUNTER_HEIGHT, SHORT_STEP, STEP, reach_envelope
    from pycram.apps.robot_check.scene import START
    from pycram.execution.robot import current_prospection

    step = SHORT_STEP if short else STEP
    for arm in scene.description.ARMS:

        def body(arm: str = arm) -> tuple[str, dict]:
            envelope = reach_envelope(current_prospection(), scene.description, START, step, arms=[arm])[arm]
            data = envelope.as_dict()
            data["step"] = step
            if envelope.at_height(COUNTER_HEIGHT)[0] == 0:
                raise CheckFailed(
                    f"reaches nothing at counter height ({COUNTER_HEIGHT} m): {envelope.describe()}", data
                )
            return envelope.describe(), data

        run.row("reach", f"reach: {arm} arm", body, scene.sim_time)


def _action_checks(run: _Run, robot: str, short: bool) -> None:
    """e: the action cases in a fresh world of the scene."""
    from pycram.apps.robot_check.actions import ActionState, action_cases

    cases = action_cases(short)
    scene = _open_scene(run, robot, "world for the actions")
    if scene is None:
        for name, _, _ in cases:
            run.skip("actions", f"action: {name}", "needs the world")
        return
    state = ActionState()
    try:
        with scene.robot:
            for name, case, why in cases:
                if case is None:
                    run.skip("actions", f"action: {name}", why)
                else:
                    run.row("actions", f"action: {name}", partial(case, scene, state), scene.sim_time)
    finally:
        scene.close()
    if short:
        run.skip("actions", "action: the others", "short form: one action only (the full form runs every action)")


def _set_table_checks(run: _Run, robot: str, short: bool) -> None:
    """f: set-table seeds (full form only)."""
    from pycram.apps.robot_check.set_table import SEEDS, set_table_seed

    if short:
        run.skip(
            "set-table",
            "set-table seeds",
            f"short form: seeds {', '.join(map(str, SEEDS))} run in the full form only (9-54 s of wall time each)",
        )
        return
    for seed in SEEDS:
        run.row("set-table", f"set-table seed {seed}", partial(set_table_seed, robot, seed))
