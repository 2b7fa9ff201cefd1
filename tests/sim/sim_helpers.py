"""Helpers of the simulation tests: waiting on handles, recording fluents, watching the camera.

Every wait here is on a command handle or a fluent (with a time-out); nothing sleeps and hopes.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from pycram.backends.sim.controllers import Controller
from pycram.fluent import Fluent

T = 60.0  # generous simulated-time limit for a single command [s]


def settle(world: Any, seconds: float) -> None:
    """Wait until `seconds` of simulated time have passed (physics settles)."""
    t = world.sim_time.get_value() + seconds
    assert (world.sim_time >= t).wait_for(seconds + 10.0)


def tilt(orientation: Any) -> float:
    """Angle [rad] between the z axis of a body with `orientation` (w, x, y, z) and the vertical."""
    w, x, y, z = orientation
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y))))


def ok(handle: Any, timeout: float = T) -> Any:
    """Wait for a command handle; assert it succeeded; return its value."""
    out = handle.wait(timeout)
    assert out is not None, f"{handle} did not end within {timeout} s"
    assert out.succeeded, out
    return out.value


def to_map(base: Any, dx: float, dy: float, dz: float) -> tuple[float, float, float]:
    """A point given in the robot's base frame (x ahead, y left, z up) [m] in the map frame."""
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    return (base.x + c * dx - s * dy, base.y + s * dx + c * dy, dz)


def facing_quat(yaw: float) -> tuple[float, float, float, float]:
    """Quaternion (w, x, y, z) of a rotation by `yaw` [rad] about z."""
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


class Recorder(Fluent):
    """Records the value of `source` every time it is published (in the publishing thread)."""

    def __init__(self, source: Fluent) -> None:
        super().__init__(None)
        self.source = source
        self.samples: list[Any] = []
        source.add_child(self)

    def pulse(self) -> None:
        self.samples.append(self.source.get_value())
        super().pulse()


class _Trigger(Fluent):
    def __init__(self, predicate: Callable[[], bool], fluents: Iterable[Fluent]) -> None:
        super().__init__(None)
        self.predicate, self.event = predicate, threading.Event()
        for f in fluents:
            f.add_child(self)
        self.pulse()

    def pulse(self) -> None:
        if not self.event.is_set() and self.predicate():
            self.event.set()
        super().pulse()


def wait_wall(predicate: Callable[[], bool], fluents: Iterable[Fluent], timeout: float = 60.0) -> bool:
    """Wait until `predicate()` holds, re-checked whenever one of `fluents` is published, for at
    most `timeout` [s of wall time] (independent of whichever PyCRAM clock is active)."""
    from pycram.core.runtime.lockstep import current_lockstep

    trigger = _Trigger(predicate, fluents)
    lockstep = current_lockstep()
    if lockstep is None:
        return trigger.event.wait(timeout)
    with lockstep.watching():  # a lock-step world runs on while this thread waits by wall time
        return trigger.event.wait(timeout)


class ViewMonitor(Controller):
    """Test probe run in the simulation thread: every control tick, the angle [deg] between the
    head camera's view axis and `point`, with the base's planar speed [m/s] and the time [s]."""

    channel = "test:view-monitor"

    def __init__(self, point: Iterable[float]) -> None:
        self.point = np.asarray(list(point), float)
        self.samples: list[tuple[float, float, float]] = []

    def update(self, eng: Any, t: float) -> None:
        d, cam = eng.data, eng.camera
        forward = -d.cam_xmat[cam].reshape(3, 3)[:, 2]
        to = self.point - d.cam_xpos[cam]
        to /= np.linalg.norm(to)
        angle = math.degrees(math.acos(float(np.clip(forward @ to, -1.0, 1.0))))
        speed = math.hypot(float(d.qvel[eng.base_dof[0]]), float(d.qvel[eng.base_dof[1]]))
        self.samples.append((t, speed, angle))
        return None
