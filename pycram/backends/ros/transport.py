"""The transport the ROS process modules talk through: actions, topics, services, a clock.

The process modules of :mod:`pycram.backends.ros.modules` never import a middleware; they use a
:class:`Transport`. :class:`pycram.backends.ros.ros1.Ros1Transport` implements it with ``rospy`` and
``actionlib``; a ROS 2 transport (``rclpy``) can be added beside it without touching the modules.
Message types are named as ``'package/Type'`` strings (``'move_base_msgs/MoveBaseGoal'``); the
transport turns them into its message classes (:meth:`Transport.message`).

Guarantees (every implementation)
---------------------------------
- :meth:`ActionChannel.send` returns a :class:`GoalHandle` at once; its ``result`` fluent is
  ``None`` until the goal ended and then holds a :class:`GoalOutcome`, set exactly once.
- A goal whose action server disappears (no status from it for the transport's
  ``server_timeout`` [s of wall time]) ends with status ``'lost'``: a waiter never hangs on a
  dead robot, whatever clock the plan runs on.
- Sending to a server that is not there raises :class:`ActionServerUnavailable` after at most
  the transport's ``connect_timeout`` [s of wall time].
"""

from __future__ import annotations

import threading
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pycram.core.fluent import Fluent
from pycram.execution.failures import MotionFailure

__all__ = [
    "RosMotionFailed",
    "ActionServerUnavailable",
    "ActionServerLost",
    "GoalOutcome",
    "GoalHandle",
    "ActionChannel",
    "Subscription",
    "Publication",
    "Transport",
    "GOAL_STATUSES",
]

#: The final statuses of a goal (actionlib's terminal states, plus 'lost').
GOAL_STATUSES = ("succeeded", "aborted", "preempted", "rejected", "recalled", "lost")


class RosMotionFailed(MotionFailure):
    """A goal sent over ROS ended without success.

    Attributes: ``command`` (what was asked, readable), ``action`` (the action's name),
    ``reason`` (the robot's reason -- for the simulator bridge the simulator's outcome reason:
    ``'collision'``, ``'blocked'``, ``'unreachable'``, ``'timeout'``, ``'cancelled'`` ... --,
    otherwise the goal status: ``'aborted'``, ``'rejected'``, ``'preempted'``, ``'lost'``,
    ``'unavailable'``), ``message`` (the robot's explanation), ``outcome`` (the
    :class:`GoalOutcome`, if any).
    """

    def __init__(
        self, command: str, reason: str, message: str, action: str = "", outcome: GoalOutcome | None = None
    ) -> None:
        where = f" (action {action})" if action else ""
        super().__init__(f"{command} failed{where}: {reason}: {message}")
        self.command, self.reason, self.message, self.action, self.outcome = command, reason, message, action, outcome


class ActionServerUnavailable(RosMotionFailed):
    """No server for the action answered within the transport's ``connect_timeout``."""


class ActionServerLost(RosMotionFailed):
    """The action server vanished while it had our goal (no status for ``server_timeout`` s)."""


@dataclass(frozen=True)
class GoalOutcome:
    """How a goal ended: ``status`` (one of :data:`GOAL_STATUSES`), the server's ``result``
    message (``None`` if it sent none) and its status ``text``."""

    status: str
    result: Any = None
    text: str = ""

    @property
    def succeeded(self) -> bool:
        return self.status == "succeeded"


class GoalHandle:
    """One goal sent on an :class:`ActionChannel`. ``result`` is a fluent: ``None`` while the
    goal runs, then its :class:`GoalOutcome`. ``feedback`` holds the latest feedback message."""

    def __init__(self, action: str) -> None:
        self.action = action
        self.result = Fluent(None, name=f"{action}.result")
        self.feedback = Fluent(None, name=f"{action}.feedback")
        self._lock = threading.Lock()

    @property
    def name(self) -> str:
        return f"the goal on {self.action}"

    @property
    def done(self) -> bool:
        return self.result.get_value() is not None

    def _finish(self, outcome: GoalOutcome) -> bool:
        """Set the outcome once; later calls are ignored. True if this call set it."""
        with self._lock:
            if self.result.get_value() is not None:
                return False
            self.result.set_value(outcome)
            return True

    def cancel(self) -> None:
        """Ask the server to cancel the goal; returns at once (the outcome follows)."""
        raise NotImplementedError


class ActionChannel(ABC):
    """A client of one action server (``name``, e.g. ``'move_base'``)."""

    name: str

    @abstractmethod
    def send(self, goal: Any) -> GoalHandle:
        """Send ``goal`` (a message of the action's goal type); raises
        :class:`ActionServerUnavailable` when no server answers."""

    @abstractmethod
    def cancel_all(self) -> None:
        """Cancel every goal on the server (thesis: ``cancel_all_goals``)."""


class Subscription(ABC):
    """A live subscription to a topic, as returned by :meth:`Transport.subscribe`."""

    @abstractmethod
    def close(self) -> None:
        """Stop receiving messages (idempotent)."""


class Publication(ABC):
    """A topic this process publishes on, as returned by :meth:`Transport.advertise`."""

    @abstractmethod
    def publish(self, message: Any) -> None:
        """Send ``message``; never waits for a subscriber."""

    @abstractmethod
    def close(self) -> None:
        """Stop publishing (idempotent): subscribers lose their connection to it."""


class Transport(ABC):
    """A connection to a robot's middleware (one per process)."""

    @abstractmethod
    def action(self, name: str, action_type: str) -> ActionChannel:
        """The client of action ``name`` of type ``action_type`` (``'control_msgs/PointHead'``)."""

    @abstractmethod
    def subscribe(self, topic: str, msg_type: str, callback: Callable[[Any], None]) -> Subscription:
        """Call ``callback(message)`` (in a middleware thread) for each message on ``topic``."""

    def advertise(self, topic: str, msg_type: str) -> Publication:
        """Publish messages of ``msg_type`` on ``topic`` (default: this transport cannot publish,
        ``NotImplementedError``)."""
        raise NotImplementedError(f"{type(self).__name__} cannot publish on {topic}")

    @abstractmethod
    def message(self, msg_type: str, **fields: Any) -> Any:
        """A new message of ``msg_type`` (``'geometry_msgs/Point'``) with ``fields`` set."""

    @abstractmethod
    def duration(self, seconds: float) -> Any:
        """A message duration of ``seconds`` [s]."""

    @abstractmethod
    def time_to_seconds(self, stamp: Any) -> float:
        """A message time stamp in [s]."""

    def shutdown(self) -> None:  # noqa: B027 -- optional hook: transports without clients keep it
        """Close every client and subscription of this transport (default: nothing to close)."""
