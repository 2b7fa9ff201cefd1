"""The ROS 1 transport: ``rospy`` + ``actionlib`` (Debian's packages; see scripts/install_ros.sh).

One ROS node per process (a rospy rule): :func:`ros1_transport` initialises it on first use (as
an anonymous node ``pycram_<pid>...``, without rospy's signal handlers) and returns the same
:class:`Ros1Transport` afterwards. The master is the one of ``ROS_MASTER_URI`` at that moment.

Liveness: every action client also watches its server's ``status`` topic (actionlib servers
publish it at 5 Hz). A thread of the transport waits -- on a condition, until the next deadline,
in wall time -- and ends a goal with status ``'lost'`` when its server has sent no status for
``server_timeout`` seconds (a killed driver, a dropped network link): waiters wake with
:class:`~pycram.backends.ros.transport.ActionServerLost` instead of hanging.
"""

from __future__ import annotations

import importlib
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus

from pycram.backends.ros.transport import (
    ActionChannel,
    ActionServerUnavailable,
    GoalHandle,
    GoalOutcome,
    Publication,
    Subscription,
    Transport,
)
from pycram.core.runtime.clock import ManualClock

__all__ = ["Ros1Transport", "ros1_transport", "message_class"]

logger = logging.getLogger(__name__)

_STATUS_NAMES = {
    GoalStatus.SUCCEEDED: "succeeded",
    GoalStatus.ABORTED: "aborted",
    GoalStatus.PREEMPTED: "preempted",
    GoalStatus.REJECTED: "rejected",
    GoalStatus.RECALLED: "recalled",
    GoalStatus.LOST: "lost",
}

_lock = threading.Lock()
_transport: Ros1Transport | None = None


def message_class(msg_type: str, kind: str = "msg") -> Any:
    """The class of ``'package/Type'`` (``kind`` ``'msg'`` or ``'srv'``); ``ValueError`` naming the
    type and the import error when it is not installed."""
    package, _, name = msg_type.partition("/")
    try:
        return getattr(importlib.import_module(f"{package}.{kind}"), name)
    except (ImportError, AttributeError) as e:
        raise ValueError(f"ROS {kind} type {msg_type!r} is not available ({e}); run scripts/install_ros.sh") from None


def ros1_transport(
    node_name: str = "pycram", server_timeout: float = 2.0, connect_timeout: float = 10.0
) -> Ros1Transport:
    """The process's ROS 1 transport (created, and the node initialised, on the first call)."""
    global _transport
    with _lock:
        if _transport is None:
            _transport = Ros1Transport(node_name, server_timeout, connect_timeout)
        return _transport


class _Ros1GoalHandle(GoalHandle):
    def __init__(self, action: str) -> None:
        super().__init__(action)
        self.sent = time.monotonic()
        self.client_handle: Any = None  # actionlib's ClientGoalHandle (kept: actionlib holds it weakly)

    def cancel(self) -> None:
        if self.client_handle is not None and not self.done:
            self.client_handle.cancel()


class _StatusWatchingClient(actionlib.ActionClient):
    """actionlib's client, telling us when its server's status arrives."""

    def __init__(self, ns: str, action_spec: Any, on_status: Callable[[], None]) -> None:
        self._on_status = on_status
        super().__init__(ns, action_spec)

    def _status_cb(self, msg: Any) -> None:
        super()._status_cb(msg)
        self._on_status()


class Ros1ActionChannel(ActionChannel):
    def __init__(self, transport: Ros1Transport, name: str, action_type: str) -> None:
        self.name, self.action_type = name, action_type
        self._transport = transport
        self._cond = threading.Condition()
        self.last_status = float("-inf")  # monotonic time of the server's last status message
        self._client = _StatusWatchingClient(name, message_class(action_type + "Action"), self._status_seen)

    def _status_seen(self) -> None:
        with self._cond:
            self.last_status = time.monotonic()
            self._cond.notify_all()

    def server_alive(self) -> bool:
        """True while the server's status arrives (within the transport's server time-out)."""
        return time.monotonic() - self.last_status < self._transport.server_timeout

    def _connected(self) -> bool:
        """The server is alive and connected both ways: our goal and cancel publishers reach it,
        and its result and feedback reach us (as actionlib's own check: a goal sent before the
        result topic is connected can succeed on the server and never be reported)."""
        client = self._client
        status = client.last_status_msg
        if status is None or not self.server_alive():
            return False
        server = status._connection_header["callerid"]
        return (
            client.pub_goal.impl.has_connection(server)
            and client.pub_cancel.impl.has_connection(server)
            and any(c.callerid_pub == server for c in client.result_sub.impl.connections)
            and any(c.callerid_pub == server for c in client.feedback_sub.impl.connections)
        )

    def wait_for_server(self, timeout: float) -> bool:
        """Wait at most ``timeout`` [s, wall] until the server's status arrives and it is
        connected both ways (see :meth:`_connected`). The status wakes this wait; the
        connections are re-checked every 20 ms (rospy has no event for them), within the same
        bound. Waits in slices of at most 0.1 s so that an evaporation injected into this thread
        lands promptly."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while not self._connected():
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._cond.wait(min(remaining, 0.02 if self.server_alive() else 0.1))
        return True

    def send(self, goal: Any) -> GoalHandle:
        if not self.wait_for_server(self._transport.connect_timeout):
            raise ActionServerUnavailable(
                f"send a goal to {self.name}",
                "unavailable",
                f"no action server answered within {self._transport.connect_timeout:.1f} s "
                f"(master {rosgraph_master()})",
                action=self.name,
            )
        handle = _Ros1GoalHandle(self.name)

        def transition(client_handle: Any) -> None:
            if client_handle.get_comm_state() != actionlib.CommState.DONE:
                return
            status = client_handle.get_goal_status()
            outcome = GoalOutcome(
                _STATUS_NAMES.get(status, f"status {status}"),
                client_handle.get_result(),
                client_handle.get_goal_status_text(),
            )
            if handle._finish(outcome):
                self._transport._unwatch(handle)

        def feedback(client_handle: Any, message: Any) -> None:
            handle.feedback.set_value(message)

        self._transport._watch(handle, self)
        handle.client_handle = self._client.send_goal(goal, transition, feedback)
        return handle

    def cancel_all(self) -> None:
        self._client.cancel_all_goals()


class _Topic:
    """One rospy subscriber per topic (one connection per publisher), fanning its messages out
    to every callback of this process; a closed subscription only removes its callback."""

    def __init__(self, topic: str, msg_type: str) -> None:
        self.msg_type = msg_type
        self.callbacks: list[Callable[[Any], None]] = []
        self._lock = threading.Lock()
        self._subscriber = rospy.Subscriber(topic, message_class(msg_type), self._deliver, queue_size=1)

    def _deliver(self, message: Any) -> None:
        with self._lock:
            callbacks = list(self.callbacks)
        for callback in callbacks:
            try:
                callback(message)
            except Exception:
                logger.exception("callback %r failed on a %s message", callback, self.msg_type)

    def add(self, callback: Callable[[Any], None]) -> None:
        with self._lock:
            self.callbacks.append(callback)

    def remove(self, callback: Callable[[Any], None]) -> None:
        with self._lock:
            if callback in self.callbacks:
                self.callbacks.remove(callback)


class _Ros1Subscription(Subscription):
    def __init__(self, topic: _Topic, callback: Callable[[Any], None]) -> None:
        self._topic, self._callback = topic, callback
        topic.add(callback)

    def close(self) -> None:
        self._topic.remove(self._callback)


class _Ros1Publication(Publication):
    def __init__(self, publisher: Any) -> None:
        self._publisher: Any = publisher
        self._lock = threading.Lock()

    def publish(self, message: Any) -> None:
        with self._lock:
            publisher = self._publisher
        if publisher is not None:
            publisher.publish(message)

    def close(self) -> None:
        with self._lock:
            publisher, self._publisher = self._publisher, None
        if publisher is not None:
            publisher.unregister()


def rosgraph_master() -> str:
    import rosgraph

    return rosgraph.get_master_uri()


class Ros1Transport(Transport):
    """:class:`~pycram.backends.ros.transport.Transport` over rospy/actionlib. Use :func:`ros1_transport`.

    ``server_timeout`` [s, wall]: a goal's server is lost after this long without status.
    ``connect_timeout`` [s, wall]: how long :meth:`ActionChannel.send` waits for a server.
    """

    def __init__(self, node_name: str = "pycram", server_timeout: float = 2.0, connect_timeout: float = 10.0) -> None:
        self.server_timeout, self.connect_timeout = float(server_timeout), float(connect_timeout)
        if not rospy.core.is_initialized():
            rospy.init_node(node_name, anonymous=True, disable_signals=True)
        self._channels: dict[str, Ros1ActionChannel] = {}
        self._topics: dict[str, _Topic] = {}
        self._subscriptions: list[_Ros1Subscription] = []
        self._watch_cond = threading.Condition()
        self._watched: dict[_Ros1GoalHandle, Ros1ActionChannel] = {}
        self._closed = False
        self._watchdog = threading.Thread(target=self._watch_servers, name="pycram-ros-watchdog", daemon=True)
        self._watchdog.start()

    # -- Transport ------------------------------------------------------------------------------
    def action(self, name: str, action_type: str) -> Ros1ActionChannel:
        with _lock:
            channel = self._channels.get(name)
            if channel is None:
                channel = self._channels[name] = Ros1ActionChannel(self, name, action_type)
        if channel.action_type != action_type:
            raise ValueError(f"action {name!r} is used as {channel.action_type!r}, not {action_type!r}")
        return channel

    def subscribe(self, topic: str, msg_type: str, callback: Callable[[Any], None]) -> Subscription:
        with _lock:
            shared = self._topics.get(topic)
            if shared is None:
                shared = self._topics[topic] = _Topic(topic, msg_type)
        if shared.msg_type != msg_type:
            raise ValueError(f"topic {topic!r} is subscribed as {shared.msg_type!r}, not {msg_type!r}")
        subscription = _Ros1Subscription(shared, callback)
        self._subscriptions.append(subscription)
        return subscription

    def message(self, msg_type: str, **fields: Any) -> Any:
        return message_class(msg_type)(**fields)

    def advertise(self, topic: str, msg_type: str) -> Publication:
        """A rospy publisher on ``topic`` with ``queue_size=1``: ``publish`` never waits for a
        subscriber, one that cannot keep up gets the newest message. ``close`` unregisters it
        (rospy shares one publisher per topic and process; the last ``close`` ends it)."""
        return _Ros1Publication(rospy.Publisher(topic, message_class(msg_type), queue_size=1))

    def service(self, name: str, srv_type: str, timeout: float = 10.0) -> Any:
        """A callable proxy of service ``name``; ``ActionServerUnavailable`` if it does not
        appear within ``timeout`` [s, wall]."""
        try:
            rospy.wait_for_service(name, timeout)
        except rospy.ROSException:
            raise ActionServerUnavailable(
                f"call service {name}", "unavailable", f"not offered within {timeout:.1f} s"
            ) from None
        return rospy.ServiceProxy(name, message_class(srv_type, "srv"))

    def duration(self, seconds: float) -> Any:
        return rospy.Duration.from_sec(seconds)

    def time_to_seconds(self, stamp: Any) -> float:
        return stamp.to_sec()

    def sim_clock(self, topic: str = "/clock") -> ManualClock:
        """A PyCRAM clock that follows the simulated time published on ``topic`` [s] (as ROS'
        ``use_sim_time`` does for rospy): activate it with ``pycram.runtime.set_clock`` and
        ``pycram.sleep``, fluent time-outs and the process modules' goal time-outs run in
        simulated time. It never goes backwards (an older ``/clock``, e.g. of a restarted
        simulator, is ignored until the new one passes it) and stands still while no ``/clock``
        arrives."""
        clock = ManualClock(0.0)

        def tick(message: Any) -> None:
            t = message.clock.to_sec()
            if t > clock.now():
                clock.advance_to(t)

        self.subscribe(topic, "rosgraph_msgs/Clock", tick)
        return clock

    def shutdown(self) -> None:
        """Close the subscriptions and stop the watchdog (the node stays: rospy cannot re-init)."""
        for subscription in self._subscriptions:
            subscription.close()
        self._subscriptions.clear()

    # -- liveness -------------------------------------------------------------------------------
    def _watch(self, handle: _Ros1GoalHandle, channel: Ros1ActionChannel) -> None:
        with self._watch_cond:
            self._watched[handle] = channel
            self._watch_cond.notify_all()

    def _unwatch(self, handle: _Ros1GoalHandle) -> None:
        with self._watch_cond:
            self._watched.pop(handle, None)

    def _watch_servers(self) -> None:
        """End goals whose server went silent; sleeps until the next deadline (condition)."""
        with self._watch_cond:
            while not self._closed:
                now = time.monotonic()
                next_deadline = None
                for handle, channel in list(self._watched.items()):
                    deadline = max(channel.last_status, handle.sent) + self.server_timeout
                    if now >= deadline:
                        del self._watched[handle]
                        silent = now - max(channel.last_status, handle.sent)
                        if handle._finish(
                            GoalOutcome(
                                "lost", None, f"the action server {channel.name} vanished: no status for {silent:.1f} s"
                            )
                        ):
                            logger.warning("goal on %s lost: its server stopped answering", channel.name)
                    elif next_deadline is None or deadline < next_deadline:
                        next_deadline = deadline
                self._watch_cond.wait(None if next_deadline is None else next_deadline - now)
