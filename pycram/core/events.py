"""A tiny publish/subscribe bus for execution events (standard library only).

Library layers that know about an event publish it here; observers (the run recorder in
`pycram.trace`) subscribe. The designator and process-module layers call the two helpers
below; nothing in this module imports anything from pycram.

Guarantees
----------
- `publish` / the helpers cost one dictionary lookup and return at once when nobody listens
  (the common case: recording is off by default for library use).
- Subscribers are called synchronously in the publishing thread, in subscription order. They
  must be O(1) and never block (the recorder only enqueues). An exception raised by a
  subscriber is logged and swallowed: observing never changes what a plan does.
- Subscribing and unsubscribing are thread-safe; a publish that races with them sees either
  the old or the new subscriber tuple, never a torn one.

Topics
------
`DESIGNATOR_PERFORMED` ("designator.performed"), fields: ``designator``, ``solution`` (what it
resolved to: a plan function for action designators, the motion/solution data otherwise),
``error`` (exception or None).

`PROCESS_MODULE_EXECUTED` ("process_module.executed"), fields: ``module``, ``designator``,
``outcome`` (a string such as "succeeded", "failed", "cancelled"), ``start`` and ``end`` (active
clock [s]), ``error`` (exception or None; for a failure, the exception ``_execute`` raised).

Publishers: :meth:`pycram.process_module.ProcessModule.perform` and
:func:`pycram.designator.perform` publish ``DESIGNATOR_PERFORMED`` once per call (also when it
raises); a process module publishes ``PROCESS_MODULE_EXECUTED`` once per started execution, in
the executing task's thread.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

__all__ = [
    "DESIGNATOR_PERFORMED",
    "PROCESS_MODULE_EXECUTED",
    "subscribe",
    "unsubscribe",
    "publish",
    "has_subscribers",
    "designator_performed",
    "process_module_executed",
]

log = logging.getLogger(__name__)

#: Topic published once per ``perform`` call; fields ``designator``, ``solution``, ``error``.
DESIGNATOR_PERFORMED = "designator.performed"
#: Topic published once per started process-module execution; fields ``module``, ``designator``,
#: ``outcome``, ``start``, ``end`` (active clock [s]), ``error``.
PROCESS_MODULE_EXECUTED = "process_module.executed"

Callback = Callable[..., None]

_lock = threading.Lock()
_subscribers: dict[str, tuple[Callback, ...]] = {}


def subscribe(topic: str, callback: Callback) -> Callable[[], None]:
    """Call `callback(**fields)` for every event published on `topic` from now on.

    Returns a function that unsubscribes (idempotent).
    """
    with _lock:
        _subscribers[topic] = _subscribers.get(topic, ()) + (callback,)
    return lambda: unsubscribe(topic, callback)


def unsubscribe(topic: str, callback: Callback) -> None:
    """Stop calling `callback` for `topic` (no error if it was not subscribed)."""
    with _lock:
        remaining = tuple(c for c in _subscribers.get(topic, ()) if c is not callback)
        if remaining:
            _subscribers[topic] = remaining
        else:
            _subscribers.pop(topic, None)


def has_subscribers(topic: str) -> bool:
    """True when at least one callback listens on `topic` (to skip building costly fields)."""
    return topic in _subscribers


def publish(topic: str, **fields: Any) -> None:
    """Deliver an event to the subscribers of `topic`; returns at once when there are none."""
    callbacks = _subscribers.get(topic)
    if not callbacks:
        return
    for callback in callbacks:
        try:
            callback(**fields)
        except Exception:  # an observer must never break the plan
            log.exception("event subscriber %r failed on %s", callback, topic)


def designator_performed(designator: Any, solution: Any = None, error: BaseException | None = None) -> None:
    """Announce that `designator` was performed (resolved to `solution`, or failed with `error`).

    Call it from `perform()` after the designator was resolved. O(1) when nobody listens.
    """
    callbacks = _subscribers.get(DESIGNATOR_PERFORMED)
    if callbacks:
        publish(DESIGNATOR_PERFORMED, designator=designator, solution=solution, error=error)


def process_module_executed(
    module: Any,
    designator: Any,
    outcome: Any,
    start: float | None,
    end: float | None,
    error: BaseException | None = None,
) -> None:
    """Announce that `module` executed `designator` with `outcome` between `start` and `end`.

    `outcome` may be an enum (its `.value` is used) or a string; times are on the active
    clock [s]. Call it once per started execution, when its outcome is settled. O(1) when
    nobody listens.
    """
    callbacks = _subscribers.get(PROCESS_MODULE_EXECUTED)
    if callbacks:
        publish(
            PROCESS_MODULE_EXECUTED,
            module=module,
            designator=designator,
            outcome=outcome,
            start=start,
            end=end,
            error=error,
        )
