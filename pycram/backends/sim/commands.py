"""How a command travels between the callers of a `World` and its simulation thread.

`CommandQueue` is the base of `World` and of its groups of commands: a caller queues a
`Controller` (`submit`) and gets its `CommandHandle` at once; the simulation thread starts the
queued controllers (`_drain_inbox`), a newer controller on the same `channel` (part of the robot)
preempting the older one, and ends them (`_end`): succeeded, failed, cancelled or preempted. It
also checks the names a command is given (arms, grippers, cameras) before anything is queued.

Thread-safety: `submit`, `cancel` and the name checks may be called from any thread; `_drain_inbox`
and `_end` only from the simulation thread.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from pycram.core.runtime.clock import ManualClock
from pycram.world.environment import Environment
from pycram.world.types import Outcome

from .camera import FollowView
from .controllers import Controller, Instant
from .engine import Engine
from .errors import UnknownNameError, WorldClosedError
from .handle import CommandHandle
from .scene import Scene

if TYPE_CHECKING:
    from pycram.world.robot_description import RobotDescription

# (the world's logger: these messages keep the name they were logged under before the split)
_log = logging.getLogger("pycram.backends.sim.world")


class CommandQueue:
    """The command queue of a `World` (set up by `World.__init__`): submitting, starting,
    preempting, cancelling and ending commands."""

    scene: Scene
    description: RobotDescription
    environment: Environment
    _engine: Engine
    _inbox: queue.SimpleQueue
    _lock: threading.Lock
    _closed: bool
    _stop: threading.Event
    _active: dict[str, tuple[Controller, CommandHandle]]
    _finished: list[tuple[CommandHandle, Outcome]]
    clock: ManualClock

    def submit(self, ctrl: Controller, name: str) -> CommandHandle:
        """Queue a controller for the simulation thread; returns its handle at once."""
        handle = CommandHandle(name, self._cancel)
        with self._lock:
            if self._closed or self._stop.is_set():
                raise WorldClosedError(f"world is closed; cannot run {name}")
            self._inbox.put(("start", ctrl, handle))
        return handle

    def _cancel(self, handle: CommandHandle) -> None:
        with self._lock:
            if not self._closed:
                self._inbox.put(("cancel", None, handle))

    def _call(self, name: str, fn: Callable[..., Any], *args: Any) -> CommandHandle:
        return self.submit(Instant(fn, *args), name)

    def _drain_inbox(self) -> None:
        eng = self._engine
        batch = []
        while True:
            try:
                batch.append(self._inbox.get_nowait())
            except queue.Empty:
                break
        # Lock-step: the commands sent while the simulation stood still all start at one
        # simulated instant, in the order they were sent -- one plan thread ran at a time, in
        # task order (`pycram.core.runtime.lockstep`), so that order is the same in every run.
        for kind, ctrl, handle in batch:
            if kind == "cancel":
                for channel, (_ctrl, h) in list(self._active.items()):
                    if h is handle:
                        self._end(channel, Outcome(False, "cancelled", "cancelled"), stop=True)
                continue
            try:
                if ctrl.channel is not None and ctrl.channel in self._active:
                    self._end(ctrl.channel, Outcome(False, "preempted", f"preempted by {handle.name}"), stop=False)
                out = ctrl.start(eng)
            except Exception as exc:  # a bad command must not kill the world
                _log.exception("command %s failed to start", handle.name)
                out = Outcome(False, "error", f"{type(exc).__name__}: {exc}")
            if out is not None:
                if not out.succeeded:
                    ctrl.stop(eng)
                self._finished.append((handle, out))
            elif ctrl.channel is None:
                self._finished.append((handle, Outcome(True, "succeeded")))
            else:
                self._active[ctrl.channel] = (ctrl, handle)

    def _end(self, channel: str, outcome: Outcome, stop: bool) -> None:
        ctrl, handle = self._active.pop(channel)
        if stop or not outcome.succeeded:
            ctrl.stop(self._engine)
        self._finished.append((handle, outcome))

    def cancel(self, part: str) -> CommandHandle:
        """Cancel whatever runs on `part` ("base", "torso", "head", "arm:<arm>", "gripper:<g>")."""

        def fn(eng: Engine) -> bool:
            if part in self._active:
                self._end(part, Outcome(False, "cancelled", "cancelled"), stop=True)
                return True
            return False

        return self._call(f"cancel:{part}", fn)

    def _check_arm(self, arm: str) -> str:
        if arm not in self.description.ARMS:
            raise UnknownNameError("arm", arm, self.description.ARMS)
        return arm

    def _check_gripper(self, gripper: str) -> str:
        if gripper not in self.description.GRIPPERS:
            raise UnknownNameError("gripper", gripper, self.description.GRIPPERS)
        return gripper

    def _check_camera(self, camera: str | FollowView) -> None:
        """Raise for a camera name the scene does not have, or a `FollowView` of unknown bodies."""
        if isinstance(camera, FollowView):
            camera.check(self.scene.model)
        else:
            self.scene.camera(camera)


__all__ = ["CommandQueue"]
