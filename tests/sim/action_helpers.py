"""Helpers of the action tests: the apartment with chosen objects at chosen spots, a robot on it,
and judging results with the simulator's truth (never given to the plans)."""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from functools import partial
from typing import Any

from sim_helpers import ok, tilt

from pycram import robots
from pycram.actions.handling import BACK_AWAY
from pycram.sim import World
from pycram.world.objects import object_type

#: Where the robot starts: in the middle of the apartment, facing the counter.
START = (2.0, 1.5, math.pi / 2)
#: Spots of the tests, (surface, (x, y)) [m]: free, reachable places on each kind of surface.
COUNTER = ("counter", (1.0, 4.55))
TABLE = ("table", (4.3, 1.7))
CABINET = ("cabinet top", (0.3, 3.0))
T = 60.0


@contextmanager
def apartment_with(
    robot_name: str, objects: dict[str, tuple[str, tuple[float, float]]], base_pose: tuple[float, float, float] = START
) -> Iterator[tuple[World, Any]]:
    """The apartment with `objects` (name -> (surface, (x, y))) standing upright, every other
    object of the scene taken aside, and the robot `robot_name` active on it."""
    names = list(objects)
    world = World(robot_name, environment="apartment", objects=names, seed=1, base_pose=base_pose)
    try:
        for name, (surface, xy) in objects.items():
            put(world, name, surface, xy)
        robot = robots.load(robot_name, world)
        try:
            with robot:
                yield world, robot
        finally:
            robot.shutdown()
    finally:
        world.close()


def put(world: World, name: str, surface: str, xy: tuple[float, float]) -> None:
    """Stand object `name` (an object type's name in these scenes) upright at `xy` on `surface`."""
    height = world.environment.surface(surface).height
    ok(world.move_item(name, (xy[0], xy[1], height + object_type(name).half_height + 0.002)))


def rests_upright_at(
    world: World, name: str, surface: str, xy: tuple[float, float] | None = None, tolerance: float = 0.05
) -> bool:
    """True when `name` stands upright (< 20 deg) on `surface` (within `tolerance` [m] of `xy`)."""
    pose = world.item_poses.get_value()[name]
    x, y, z = pose.position
    env_surface = world.environment.surface(surface)
    on_it = env_surface.contains(x, y, 0.0) and abs(z - object_type(name).half_height - env_surface.height) < 0.03
    near = xy is None or math.dist((x, y), xy) <= tolerance
    return on_it and near and tilt(pose.orientation) < math.radians(20)


def holding(world: World) -> set[str]:
    """The items the robot's grippers hold (simulator truth)."""
    return {s.holding for s in (f.get_value() for f in world.gripper_states.values()) if s and s.holding}


def run_as_task(body: Any) -> tuple[Any, Any]:
    """Run `body()` as a task of its own; returns (its result, the task), so that a test looks
    only at the tasks this body started. Re-raises what the body raised."""
    from pycram.runtime import current_task, run_subtask

    holder: list[Any] = []

    def scoped() -> Any:
        holder.append(current_task())
        return body()

    return run_subtask("test body", scoped), holder[0]


def tasks_named(root: Any, prefix: str) -> list[Any]:
    """The tasks below `root` whose names start with `prefix`, in start order."""
    return [t for t in root.walk() if str(t.name).startswith(prefix)]


def held_fluent(world: World, item: str) -> Any:
    """A fluent over the world's gripper states: True while a gripper holds `item`, else None."""
    from pycram.fluent import Fluent

    held = Fluent(lambda: True if item in holding(world) else None)
    for f in world.gripper_states.values():
        f.add_child(held)
    return held


class OnceHolding:
    """Runs `action(world)` in a thread of its own once the robot holds `item` and its base has
    moved `distance` [m] from where it grasped it (a person acting while the robot carries: the
    default is farther than the base backs away from the surface as part of picking up,
    `BACK_AWAY`). Waits on fluents only; `join()` returns what the action returned."""

    def __init__(self, world: World, item: str, action: Any, distance: float = BACK_AWAY + 0.3) -> None:
        self.world, self.item, self.action, self.distance = world, item, action, distance
        self.done = threading.Event()
        self.result: Any = None
        self._thread = threading.Thread(target=self._run, daemon=True, name=f"person taking {item}")
        self._thread.start()

    def _run(self) -> None:
        from pycram.fluent import Fluent

        if not held_fluent(self.world, self.item).wait_for(600.0):
            self.done.set()
            return
        start = self.world.base_pose.get_value()
        away = Fluent(
            lambda: (
                True
                if math.hypot(
                    self.world.base_pose.get_value().x - start.x, self.world.base_pose.get_value().y - start.y
                )
                > self.distance
                else None
            )
        )
        self.world.base_pose.add_child(away)
        if away.wait_for(600.0):
            self.result = self.action(self.world)
        self.done.set()

    def join(self, timeout: float = 60.0) -> Any:
        assert self.done.wait(timeout), "the person never acted"
        return self.result


class KnockOverOnceLetGo:
    """Lays `item` on its side on `surface`, where it stands, once the robot has held it, let go
    and moved the tool of `arm` more than `distance` [m] away from it (a person knocking it over
    right after it was put down). Waits on fluents only; `join()` is True when it acted."""

    def __init__(self, world: World, item: str, arm: str, surface: str, distance: float = 0.12) -> None:
        self.world, self.item, self.arm, self.surface, self.distance = world, item, arm, surface, distance
        self.done = threading.Event()
        self.acted = False
        self._thread = threading.Thread(target=self._run, daemon=True, name=f"person knocking over {item}")
        self._thread.start()

    def _run(self) -> None:
        from pycram.fluent import Fluent

        w = self.world
        if held_fluent(w, self.item).wait_for(600.0):

            def let_go_and_away() -> bool | None:
                if self.item in holding(w):
                    return None
                tool = w.tool_poses.get_value()[self.arm].position
                item = w.item_poses.get_value()[self.item].position
                return True if math.dist(tool, item) > self.distance else None

            away = Fluent(let_go_and_away)
            w.tool_poses.add_child(away)
            if away.wait_for(600.0):
                x, y, _ = w.item_poses.get_value()[self.item].position
                lying = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # 90 deg about x
                z = w.environment.surface(self.surface).height + object_type(self.item).lying_height / 2 + 0.002
                ok(w.move_item(self.item, (x, y, z), lying))
                self.acted = True
        self.done.set()

    def join(self, timeout: float = 60.0) -> bool:
        assert self.done.wait(timeout), "the person never acted"
        return self.acted


class _CameraDouble:
    """Base of the test doubles of the world's perception: while installed (``with``), every
    look goes through `look(original, *args, **kwargs)`, which returns the command handle."""

    world: World

    def look(self, original: Any, *args: Any, **kwargs: Any) -> Any:
        raise NotImplementedError

    def __enter__(self) -> Any:
        original = self._original = self.world.detect
        self.world.detect = partial(self.look, original)  # type: ignore[method-assign]
        return self

    def __exit__(self, *exc: Any) -> None:
        self.world.detect = self._original  # type: ignore[method-assign]


class MissingDetections(_CameraDouble):
    """Makes the world's perception miss every object (a detector that misses, as the
    ``missed`` fault does at random) in the next `misses` looks for which `when()` is True;
    looks are counted in `missed` (their reports). Install with ``with MissingDetections(...)``."""

    def __init__(self, world: World, misses: int, when: Any = lambda: True) -> None:
        self.world, self.misses, self.when = world, misses, when
        self.missed: list[Any] = []
        #: Every look's report (missed or not), in order.
        self.reports: list[Any] = []
        self.looks = 0

    def look(self, original: Any, *args: Any, **kwargs: Any) -> Any:
        from pycram.backends.sim.perception import PerceptionFaults

        self.looks += 1
        if len(self.missed) >= self.misses or not self.when():
            handle = original(*args, **kwargs)
            self.reports.append(ok(handle))
            return handle
        saved, self.world.perception_faults = self.world.perception_faults, PerceptionFaults(miss_probability=1.0)
        try:
            handle = original(*args, **kwargs)
            report = ok(handle)
        finally:
            self.world.perception_faults = saved
        self.missed.append(report)
        self.reports.append(report)
        return handle


class HiddenBehindRaisedArm(_CameraDouble):
    """Test double of a camera whose view of `item` the robot's own raised arm blocks: while a
    tool of the robot is higher than `height` [m] (an arm raised to carry), looks report no `item`
    and something `near` [m] in front of the camera everywhere -- so the belief holds `item`
    hidden, not missed. Looks so rewritten are counted in `hidden`. Install with ``with``."""

    def __init__(self, world: World, item: str, height: float = 1.0, near: float = 0.3) -> None:
        self.world, self.item, self.height, self.near = world, item, height, near
        self.hidden = 0

    def look(self, original: Any, *args: Any, **kwargs: Any) -> Any:
        import dataclasses

        import numpy as np

        from pycram.backends.sim.handle import CommandHandle

        handle = original(*args, **kwargs)
        if max(p.position[2] for p in self.world.tool_poses.get_value().values()) <= self.height:
            return handle
        outcome = handle.wait(T)
        report = outcome.value
        view = dataclasses.replace(report.view, depth=np.full_like(report.view.depth, self.near))
        report = dataclasses.replace(
            report, detections=tuple(d for d in report.detections if d.type != self.item), view=view
        )
        self.hidden += 1
        rewritten = CommandHandle("detect (behind the raised arm)", lambda h: None)
        rewritten.result.set_value(dataclasses.replace(outcome, value=report))
        return rewritten
