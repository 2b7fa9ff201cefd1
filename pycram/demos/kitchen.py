"""`pycram demo`: the thesis demo in the simulated kitchen, headless, with pictures.

Builds the kitchen with the chosen robot and the item at the chosen position, activates the
robot and the kitchen's location resolvers, runs `kitchen_plan.fetch_and_place` while showing
live progress, then prints the task tree, writes snapshots, an animation, the task-tree SVG and
the timeline PNG to the output folder, and returns 0 only when the item rests on cooker #1.
"""

from __future__ import annotations

import logging
import os
import random
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

log = logging.getLogger("pycram.demo")

#: A run that has not ended after this much wall time is evaporated and reported as failed [s].
WALL_TIME_LIMIT = 110.0


@dataclass
class DemoOptions:
    robot: str = "pr2"
    output: Path | None = None
    item_at: int = 1
    steal: int = 0
    seed: int = 0
    realtime: bool = False
    interactive: bool = False
    db: str | None = None
    record: bool = True
    quiet: bool = False


@dataclass
class DemoResult:
    """What a demo run produced: exit code, message, counts and where the pictures are."""

    exit_code: int
    message: str
    output: Path
    run_id: Any = None
    sim_time: float = 0.0
    wall_time: float = 0.0
    failed_grasps: int = 0
    recoveries: int = 0
    item_on_cooker_1: bool = False
    files: list[Path] = field(default_factory=list)
    tree_text: str = ""

    @property
    def speed_factor(self) -> float:
        return self.sim_time / self.wall_time if self.wall_time > 0 else 0.0


def default_output(robot: str) -> Path:
    return Path("output") / f"demo-{robot}"


def run_demo(options: DemoOptions) -> DemoResult:
    """Run the demo once; never raises for plan failures (they are in the result)."""
    if options.item_at not in (0, 1, 2, 3):
        raise ValueError(f"--item-at must be 0 (no item) or a position 1, 2 or 3, not {options.item_at}")
    if options.robot not in ("pr2", "tiago"):
        raise ValueError(f"--robot must be 'pr2' or 'tiago', not {options.robot!r}")
    output = Path(options.output) if options.output else default_output(options.robot)
    output.mkdir(parents=True, exist_ok=True)

    from pycram import robots as robot_packages
    from pycram.demos import kitchen_plan as plan
    from pycram.demos.kitchen_world import (
        ITEM_NAME,
        SLOTS,
        START_POSE,
        Helper,
        KitchenFacts,
        Operator,
        Thief,
        operator_resolver,
    )
    from pycram.runtime import current_task, format_task_tree
    from pycram.sim import COUNTER_HEIGHT, ItemSpec, Pose2D, World

    rng = random.Random(options.seed)
    mug = ItemSpec(ITEM_NAME, "mug", "cylinder", (0.03, 0.05), 0.25,
                   (*SLOTS[options.item_at], None) if options.item_at else (5.0, 5.0, None), (0.85, 0.2, 0.15, 1))
    items = [mug] if options.item_at else []
    started_wall = time.monotonic()
    world = World(options.robot, items, base_pose=START_POSE, realtime=options.realtime)
    result = DemoResult(exit_code=1, message="", output=output)
    recorder = _start_recorder(options, plan_name="kitchen demo (fetch and place)")
    thief = None
    try:
        robot = robot_packages.load(options.robot, world)
        helper = Helper(world, interactive=options.interactive)
        gripper_of = _gripper_mapper(world)
        operator = Operator(helper, gripper_of)
        robot.add_process_module("operator", operator)
        robot.process_module_resolvers.append(operator_resolver(operator))
        facts = KitchenFacts(mug.half_height, COUNTER_HEIGHT, Pose2D(*START_POSE))
        thief = Thief(world, helper, plan.phase, plan.goal, gripper_of(plan.GRIPPER), options.steal, rng)
        if recorder is not None:
            recorder.set_run_info(robot=options.robot)
            for fluent in (plan.phase, world.base_pose):
                recorder.watch(fluent, fluent.name, max_rate_hz=5.0)
        world.start_recording("overview", fps=8.0, width=480, height=360)
        world.snapshot(output / "start.png")
        result.files.append(output / "start.png")
        plan.forget_state()
        outcome: dict[str, Any] = {}

        def run_plan() -> None:
            outcome["root"] = current_task()
            try:
                with robot, facts:
                    outcome["state"] = plan.fetch_and_place()
            except BaseException as error:  # evaporated on the wall-time limit, or a bug
                outcome["error"] = error

        runner = threading.Thread(target=run_plan, name="pycram-demo-plan", daemon=True)
        thief.start()
        runner.start()
        _show_progress(runner, world, plan, thief, started_wall, options.quiet, outcome)
        if runner.is_alive():
            result.message = f"the demo did not end within {WALL_TIME_LIMIT:.0f} s of wall time"
            root = outcome.get("root")
            if root is not None:
                for task in list(root.children):
                    task.evaporate()
            runner.join(10.0)
        thief.stop()
        root = outcome.get("root")
        plan_task = root.children[-1] if root is not None and root.children else None
        result.tree_text = format_task_tree(plan_task) if plan_task is not None else ""
        result.failed_grasps = _count(plan_task, lambda t: t.kind == "step" and _failed(t) and "GraspFailed" in _error(t))
        result.recoveries = _count(plan_task, lambda t: t.kind == "attempt" and "RetryRequested" in _error(t))
        result.sim_time = world.sim_time.get_value()
        result.item_on_cooker_1 = _item_on_cooker_1(world, ITEM_NAME, COUNTER_HEIGHT) if items else False
        world.snapshot(output / "end.png")
        result.files.append(output / "end.png")
        world.stop_recording(output / "run.gif")
        result.files.append(output / "run.gif")
        if result.item_on_cooker_1:
            result.exit_code, result.message = 0, "the item rests on cooker #1"
        elif not result.message:
            result.message = _failure_message(outcome)
    finally:
        if thief is not None:
            thief.stop()
        world.close()
        result.wall_time = time.monotonic() - started_wall
        if recorder is not None:
            result.run_id = recorder.finish("succeeded" if result.exit_code == 0 else "failed")
            result.files.extend(_write_run_pictures(result.run_id, output, recorder))
    return result


def _gripper_mapper(world: Any):
    grippers = list(world.gripper_openings)

    def gripper_of(name: str) -> str:
        if name in grippers:
            return name
        if len(grippers) == 1:  # a one-armed robot serves requests for either gripper
            return grippers[0]
        return {"0": "left", "1": "right"}.get(str(name), name)

    return gripper_of


def _item_on_cooker_1(world: Any, item: str, counter_height: float) -> bool:
    from pycram.demos.kitchen_world import PLACE_XY

    pose = world.item_poses.get_value().get(item)
    if pose is None:
        return False
    x, y, z = pose.position
    held = any(state.get_value().holding == item for state in world.gripper_states.values())
    on_top = counter_height < z < counter_height + 0.15
    return not held and on_top and ((x - PLACE_XY[0]) ** 2 + (y - PLACE_XY[1]) ** 2) ** 0.5 < 0.15


def _failed(task: Any) -> bool:
    return task.status.get_value().value == "failed"


def _error(task: Any) -> str:
    return type(task.exception).__name__ if task.exception is not None else ""


def _count(task: Any, predicate) -> int:
    return 0 if task is None else sum(1 for t in task.walk() if predicate(t))


def _failure_message(outcome: dict) -> str:
    if "error" in outcome:
        error = outcome["error"]
        return f"the plan stopped: {type(error).__name__}: {error}"
    root = outcome.get("root")
    plan_task = root.children[-1] if root is not None and root.children else None
    if plan_task is not None:
        failures = [t for t in plan_task.walk() if _failed(t) and t.exception is not None and t.kind in ("branch", "step")]
        if failures:
            deepest = failures[0]
            for task in failures:
                if type(task.exception).__name__ in ("NoItemGrasped", "ResetFailed", "ItemLost"):
                    deepest = task
            return f"{type(deepest.exception).__name__}: {deepest.exception}"
    return "the item is not on cooker #1"


def _start_recorder(options: DemoOptions, plan_name: str) -> Any:
    if not options.record:
        return None
    try:
        from pycram.trace import start_recording
    except ImportError:
        log.info("recording unavailable (pycram.trace not installed)")
        return None
    return start_recording(url=options.db, plan=plan_name)


def _write_run_pictures(run_id: Any, output: Path, recorder: Any) -> list[Path]:
    try:
        from pycram.trace.pictures import write_run_pictures
    except ImportError:
        return []
    return list(write_run_pictures(run_id, output, url=recorder.url))


def _show_progress(runner: threading.Thread, world: Any, plan: Any, thief: Any, started_wall: float,
                   quiet: bool, outcome: dict) -> None:
    """Live terminal progress until the plan thread ends or the wall-time limit passes."""
    deadline = started_wall + WALL_TIME_LIMIT

    def status_line() -> str:
        wall = time.monotonic() - started_wall
        sim = world.sim_time.get_value()
        root = outcome.get("root")
        plan_task = root.children[-1] if root is not None and root.children else None
        grasps = _count(plan_task, lambda t: t.kind == "step" and _failed(t))
        retries = _count(plan_task, lambda t: t.kind == "attempt" and _failed(t))
        return (f"step: {plan.phase.get_value():<13} failed grasps: {grasps}  recoveries: {retries}  "
                f"thefts: {thief.stolen}  sim {sim:6.1f} s  wall {wall:5.1f} s")

    if quiet:
        runner.join(max(0.0, deadline - time.monotonic()))
        return
    from rich.console import Console
    from rich.live import Live

    console = Console(stderr=True)
    with Live(status_line(), console=console, refresh_per_second=4, transient=False) as live:
        while runner.is_alive() and time.monotonic() < deadline:
            runner.join(0.25)  # refresh the status line four times a second
            live.update(status_line())


def main(robot: str = "pr2", output: str | None = None, item_at: int = 1, steal: int = 0, seed: int = 0,
         realtime: bool = False, interactive: bool = False, db: str | None = None, record: bool = True,
         quiet: bool = False) -> int:
    """Run the demo, print the task tree and a summary; return the process exit code."""
    from rich.console import Console

    logging.basicConfig(level=logging.INFO, format="%(message)s")
    os.environ.setdefault("MUJOCO_GL", "egl")
    console = Console()
    options = DemoOptions(robot, Path(output) if output else None, item_at, steal, seed, realtime,
                          interactive, db, record, quiet)
    result = run_demo(options)
    console.print("\n[bold]Task tree[/bold]")
    console.print(result.tree_text, markup=False, highlight=False)
    console.print(f"\nsimulated {result.sim_time:.1f} s in {result.wall_time:.1f} s of wall time "
                  f"({result.speed_factor:.1f}x faster than real time)")
    console.print(f"failed grasps: {result.failed_grasps}, recoveries: {result.recoveries}")
    console.print(f"pictures in {result.output.resolve()}: " + ", ".join(p.name for p in result.files))
    if result.run_id is not None:
        console.print(f"recorded as run {result.run_id} (see `pycram show {result.run_id}`)")
    colour = "green" if result.exit_code == 0 else "red"
    verdict = "SUCCESS" if result.exit_code == 0 else "FAILURE"
    console.print(f"[bold {colour}]{verdict}[/bold {colour}]: {result.message}")
    return result.exit_code
