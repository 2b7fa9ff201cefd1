"""Interventions in a `World`: what a person, fault injection and tests do to it -- take an
item away, hand one over, move one, place and remove obstacles, make a drawer or door stuck,
push or pull a container.

Each returns a `CommandHandle` at once; the change happens in the simulation thread. Units:
metres, newtons, seconds of simulated time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

from pycram.world.types import Vec3

from .commands import CommandQueue
from .container_push import ContainerPush
from .controllers import GiveItem
from .engine import Engine
from .environment_builder import OBSTACLE_PARKING
from .errors import UnknownNameError
from .handle import CommandHandle


class Interventions(CommandQueue):
    """The interventions in a `World` (a part of it: `World` inherits them)."""

    def take_item(
        self, gripper: str | None = None, item: str | None = None, to: Sequence[float] | None = None
    ) -> CommandHandle:
        """Take an item away, as a person would: out of `gripper` (the item it holds) or `item` by name.

        The item goes to `to` [m] or aside onto the floor beyond the environment. The gripper keeps
        its command, so a closed gripper closes fully. Value: the item's name (None if nothing).
        """
        if gripper is not None:
            self._check_gripper(gripper)
        if item is not None:
            self.scene.item(item)

        def fn(eng: Engine) -> str | None:
            name = item
            if name is None and gripper is not None:
                name = eng.grippers[gripper].holding
            if name is None:
                return None
            eng.set_item_pose(name, cast(Vec3, tuple(to)) if to is not None else eng.aside_position(name))
            return name

        return self._call("take_item", fn)

    def give_item(self, item: str, gripper: str, close: bool = True, timeout: float = 5.0) -> CommandHandle:
        """Hand `item` into `gripper` (opened first if needed) and hold it there until it is grasped.

        With `close` the person closes the gripper on the item; without, the robot must close
        its gripper (e.g. a `setting_gripper` motion) within `timeout` [s of simulated time].
        The command succeeds once the gripper holds the item and fails with "timeout" otherwise.
        """
        self.scene.item(item)
        self._check_gripper(gripper)
        arm = next(a for a, s in self.description.ARMS.items() if s["gripper"] == gripper)
        return self.submit(GiveItem(item, gripper, arm, close, timeout), "give_item")

    def move_item(
        self, item: str, position: Sequence[float], orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0)
    ) -> CommandHandle:
        """Put `item` at `position` [m] / `orientation` (w, x, y, z), releasing any grasp."""
        self.scene.item(item)
        return self._call("move_item", lambda eng: eng.set_item_pose(item, tuple(position), tuple(orientation)))

    def place_obstacle(self, x: float, y: float) -> CommandHandle:
        """Put a 0.3 x 0.3 x 1 m box on the floor centred at (x, y) [m]; value: its name."""

        def fn(eng: Engine) -> str:
            free = [n for n in eng.obstacles if n not in eng.obstacles_used]
            if not free:
                raise RuntimeError(f"all {len(eng.obstacles)} obstacles are in use")
            name = free[0]
            eng.obstacles_used.add(name)
            eng.place_obstacle(name, x, y)
            return name

        return self._call("place_obstacle", fn)

    def remove_obstacle(self, name: str) -> CommandHandle:
        """Take the obstacle `name` away again."""

        def fn(eng: Engine) -> None:
            if name not in eng.obstacles:
                raise UnknownNameError("obstacle", name, eng.obstacles)
            eng.obstacles_used.discard(name)
            eng.remove_obstacle(name, OBSTACLE_PARKING)

        return self._call("remove_obstacle", fn)

    def set_container_stuck(self, container: str, stuck: bool = True) -> CommandHandle:
        """Fault: make the drawer or door `container` stuck where it is (or free it again).

        A stuck container does not move however hard it is pulled (it is held by a constraint).
        """
        self.environment.container(container)

        def fn(eng: Engine) -> None:
            eng.furniture.set_stuck(eng.data, container, stuck)

        return self._call("set_container_stuck", fn)

    def push_container(
        self, container: str, force: Sequence[float], duration: float, point: Sequence[float] | None = None
    ) -> CommandHandle:
        """A person's hand pushes or pulls `container` with `force` [N, map frame] for `duration`
        [s of simulated time], at its handle (default) or at `point` [m, map frame] on it.

        Value: the container's joint position at the end [m or rad]. The container moves only as
        far as the force overcomes its friction; it keeps moving briefly (damped) afterwards.
        """
        self.environment.container(container)
        return self.submit(ContainerPush(container, force, duration, point), f"push:{container}")


__all__ = ["Interventions"]
