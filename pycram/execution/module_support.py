"""What the process modules of every backend share: checking a command, formatting values for
log lines and failure messages, cancelling a running command, and the answer of a
``detecting`` motion.

Used by the simulator's modules (:mod:`pycram.robots.common.sim_modules`) and the ROS backend's
(:mod:`pycram.backends.ros.modules`), so that one backend never imports the other's.
"""

from __future__ import annotations

import logging
from typing import Any

from pycram.designators.object import ObjectDesignator
from pycram.execution.process_module import ProcessModule

__all__ = ["format_values", "format_pose2d", "check_command", "cancel_running_handle", "seen_objects"]

logger = logging.getLogger(__name__)


def format_values(values: Any) -> str:
    """``(1.000, 2.000)``: numbers to 3 decimals, anything else as its ``repr``."""
    try:
        return "(" + ", ".join(f"{float(v):.3f}" for v in values) + ")"
    except TypeError:
        return repr(values)


def format_pose2d(pose: Any) -> str:
    """``(x=1.000, y=2.000, yaw=0.000)`` of a 2D pose; ``?`` for ``None``."""
    if pose is None:
        return "?"
    return f"(x={pose.x:.3f}, y={pose.y:.3f}, yaw={pose.yaw:.3f})"


def cancel_running_handle(module: Any, designator: Any) -> None:
    """The cancel hook of a module that keeps its running command's handle in ``module._handle``
    (a simulator command, a ROS goal: anything with ``name``, ``done`` and ``cancel()``): cancel
    it -- unless ``designator`` was evaporated while still queued, when the running command
    belongs to another caller."""
    current = module.current
    if current is None or current.designator is not designator:
        return
    handle, module._handle = module._handle, None
    if handle is not None and not handle.done:
        logger.info("%s: cancelling %s", module.name, handle.name)
        handle.cancel()


def seen_objects(update: Any, wanted: Any, stamp: float) -> list[Any]:
    """What a ``detecting`` motion returns, on every backend: the believed objects seen in one
    look (``update``, a :class:`pycram.world.belief.BeliefUpdate`), most visible first,
    restricted by ``wanted`` when given -- a type or belief name, or an object designator, whose
    best match is then recorded with ``designator.perceived(obj, timestamp=stamp)`` (``stamp``
    [s]: the look's time)."""
    seen = sorted(update.seen, key=lambda o: -int(o.properties.get("pixels", 0)))
    if wanted is None:
        return seen
    if isinstance(wanted, ObjectDesignator):
        matching = [obj for obj in seen if wanted.matches(obj)]
        if matching:
            wanted.perceived(matching[0], timestamp=stamp)
        return matching
    return [obj for obj in seen if wanted in (obj.name, obj.type)]


def check_command(module: ProcessModule, solution: Any, *expected: str) -> None:
    """Raise ``ValueError`` unless ``solution`` is a command dict whose ``cmd`` is one of ``expected``."""
    if not isinstance(solution, dict) or solution.get("cmd") not in expected:
        raise ValueError(f"{module.name} executes commands {list(expected)}, got solution {solution!r}")
