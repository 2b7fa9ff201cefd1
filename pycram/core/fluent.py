"""Fluents: observable values that threads can wait on (thesis ch. 3.2.2, CRAM's fluents).

A `Fluent` holds a value. `set_value` stores it and *pulses* the fluent, which wakes every
thread waiting on it and on every fluent network built from it. `wait_for` blocks while the
value is `None`. Operators build fluent networks::

    f = Fluent(1)
    (f / 3 < 1).wait_for()       # network valued True / None, re-evaluated on every change
    with_pulses = f.pulsed()     # True once f was pulsed, for `whenever`

Guarantees (unlike the thesis implementation):

* every waiter wakes on a change (`notify_all`), not just one -- except when no wait on the
  fluent can end: a pulse that leaves `get_value()` None wakes nobody if the runtime knows
  reading it runs no code of yours (a plain value, a network built by the operators from such
  fluents, a pulse fluent), since every waiter would only find None and wait again. A fluent
  whose value is your own callable wakes its waiters on every pulse. (In lock-step a woken
  thread takes a turn while the simulation stands still: a watcher such as
  `(opening < 0.01).wait_for()` no longer costs one hand-over per sensor publication.)
  Waits on a fluent are `wait_for` and `whenever` only: they end exactly when the value is
  not None;
* parents hold their children (networks, pulse fluents) weakly: a loop that builds `(f < 3)`
  a million times keeps memory flat;
* `<=` and `>=` work; comparisons and arithmetic with a `None` input yield `None` (not
  `TypeError`), so a network over a not-yet-known value simply is not true yet;
* a `Fluent` is hashable by identity (usable in sets and as dict keys) although `==` builds a
  network; `bool(fluent)` is an error, because `if f > 3:` would otherwise always be true;
* waits follow the active clock and are evaporable (see `pycram.runtime`).

Bridging to other systems: `f.on_change(callback)` calls `callback(value)` after every pulse
of `f` (networks: after every pulse of an input), in the pulsing thread, outside every lock;
an exception of a callback is logged, never propagated. `Fluent(v, changes_only=True)` is
CRAM's value fluent that pulses only when `set_value` changes the value (`!=`). `peek()` reads
a value without consuming anything (a pulse fluent's pulses stay for `whenever`).
"""

from __future__ import annotations

import logging
import operator
import threading
import weakref
from collections.abc import Callable, Iterator
from enum import Enum
from typing import Any

from pycram.core.block_forms import BlockForm
from pycram.core.runtime.evaporation import Evaporated, current_runner, notify_waiters, wait_until
from pycram.core.runtime.lockstep import Condition

__all__ = ["Fluent", "Behavior", "whenever", "Whenever", "STOP", "ChangeCallback"]

log = logging.getLogger(__name__)

_pulse_lock = threading.Lock()
_create_lock = threading.Lock()


class Behavior(Enum):
    """How `whenever` treats pulses that arrive while its body runs (thesis 3.2.2)."""

    NEVER = 1  #: missed pulses are ignored
    ONCE = 2  #: the body runs once more, however many pulses were missed
    ALWAYS = 3  #: the body runs once more for every missed pulse


def _value_of(x: Any) -> Any:
    return x.get_value() if isinstance(x, Fluent) else x


class Fluent:
    """A thread-safe observable value.

    `value` may be a callable; it is then called on every read (a hand-made fluent network —
    register it with the fluents it reads via `add_child` so its waiters wake on their
    changes). `name` defaults to a random string.
    """

    __slots__ = (
        "_value",
        "_name",
        "_cv",
        "_children",
        "_live",
        "_pulses",
        "_handle_missed",
        "_callbacks",
        "_changes_only",
        "_inputs",
        "__weakref__",
    )

    def __init__(self, value: Any = None, name: str | None = None, changes_only: bool = False) -> None:
        self._value = value
        self._callbacks: tuple[Callable[[Any], Any], ...] = ()
        self._changes_only = changes_only
        self._name = name
        self._cv: threading.Condition | None = None
        self._children: list[weakref.ref[Fluent]] = []  # replaced, never shrunk in place (see add_child)
        self._live = 0  # number of children after the last pruning of dead references
        self._pulses = 0
        self._handle_missed = Behavior.NEVER
        # a network's own value function and the fluents it reads (see `_network`, `_pure`)
        self._inputs: tuple[Callable[[], Any], tuple[Fluent, ...]] | None = None

    # -- identity ---------------------------------------------------------------------------------

    @property
    def name(self) -> str:
        """The fluent's name (a random UUID string unless one was given)."""
        if self._name is None:
            from uuid import uuid4  # lazily: uuid costs a few ms at import time

            self._name = str(uuid4())
        return self._name

    @name.setter
    def name(self, name: str) -> None:
        self._name = name

    __hash__ = object.__hash__

    def __bool__(self) -> bool:
        raise TypeError(
            "a Fluent has no truth value (`if f > 3:` would always be true): read it with "
            "f.get_value() or wait for it with f.wait_for()"
        )

    def __repr__(self) -> str:
        return f"<Fluent {self._name or hex(id(self))} value={self.get_value()!r}>"

    # -- value ------------------------------------------------------------------------------------

    def get_value(self) -> Any:
        """The current value; a callable value is called and its result returned."""
        value = self._value
        if callable(value):
            return value()
        return value

    def set_value(self, value: Any) -> None:
        """Store `value` and pulse — always, even when the value did not change, unless the
        fluent was made with `changes_only=True` (then only when `value != old value`)."""
        if self._changes_only:
            old, self._value = self._value, value
            if old is value or _equal(old, value):
                return
        else:
            self._value = value
        self.pulse()

    def peek(self) -> Any:
        """The current value, without consuming a pulse or blocking (same as `get_value`, which
        never consumes either: only a `whenever` pass does)."""
        return self.get_value()

    def on_change(self, callback: Callable[[Any], Any]) -> ChangeCallback:
        """Call `callback(value)` after every pulse of this fluent; returns a handle whose
        `remove()` stops it (idempotent).

        The callback runs in the thread that set or pulsed the fluent, after the waiters were
        woken, outside every lock; keep it short. An exception it raises is logged (logger
        `pycram.fluent`) and otherwise ignored. The fluent holds the callback strongly.
        """
        if not callable(callback):
            raise TypeError(f"on_change() needs a callable, got {type(callback).__name__}: {callback!r}")
        with _create_lock:
            self._callbacks = self._callbacks + (callback,)
        return ChangeCallback(self, callback)

    def pulse(self) -> None:
        """Wake every waiter on this fluent and on the networks and pulse fluents built from it
        (not those of a fluent whose value is None for sure: their waits cannot end, see
        `_none_for_sure`), then call the `on_change` callbacks (also if waking raised
        `Evaporated`)."""
        try:
            for ref in self._children:
                child = ref()
                if child is not None:
                    with _pulse_lock:
                        child._pulses += 1
                    child.pulse()
            cv = self._cv
            if cv is not None and not self._none_for_sure():
                notify_waiters(cv)  # may raise Evaporated (where an asynchronous one was due)
        finally:
            if self._callbacks:
                self._run_callbacks()

    def _none_for_sure(self) -> bool:
        """Whether no wait on this fluent can end now: its value is None and reading it runs no
        code but the runtime's (`_pure`), so it is None in every thread. Then a pulse need not
        wake the waiters (each would find None and wait again).

        No wake-up is lost: every waiter tests `get_value() is not None` under the condition's
        lock before it blocks, and every change of a pure value is followed by a pulse of the
        fluent (a network is pulsed by each of its inputs' pulses) that reads the value after
        the change. If that reads None, the value was None after the change; the change that
        last makes it not None is followed by a pulse that reads not None and wakes them."""
        try:
            return self._pure() and self.get_value() is None
        except Exception:  # noqa: BLE001 - a value that cannot be computed: the waiters find out
            return False

    def _pure(self) -> bool:
        """Whether reading the value runs no code but the runtime's: a value that is no
        callable, a pulse fluent, or a network built by the operators over such fluents (the
        same in every thread, without side effects)."""
        get_value = type(self).get_value
        if get_value is not Fluent.get_value:
            return get_value is _PulseFluent.get_value
        value = self._value
        if not callable(value):
            return True
        inputs = self._inputs
        if inputs is None or inputs[0] is not value:  # a callable of the user's
            return False
        for fluent in inputs[1]:
            if not fluent._pure():
                return False
        return True

    def _run_callbacks(self) -> None:
        runner = current_runner()
        token = runner.enter_runtime()  # an asynchronous Evaporated waits until the callbacks ran
        try:
            value = self.get_value()
            for callback in self._callbacks:
                try:
                    callback(value)
                except Exception:
                    log.exception("on_change callback %r of fluent %s failed", callback, self.name)
        finally:
            due = runner.leave_runtime(token)
        if due:
            raise Evaporated()

    def add_child(self, fluent: Fluent) -> None:
        """Make `fluent` be pulsed whenever this fluent is. Held weakly: it dies with its users.

        Amortised O(1): the list is appended to; dead references are pruned (into a new list,
        so that a concurrent `pulse` iterating the old one is unaffected) whenever it has grown
        to twice its live size since the last pruning.
        """
        ref = weakref.ref(fluent)
        with _create_lock:
            children = self._children
            if len(children) >= 2 * self._live + 8:
                children = self._children = [r for r in children if r() is not None]
                self._live = len(children)
            children.append(ref)

    def _condition(self) -> threading.Condition:
        """The condition `wait_for` waits on. Wait on it only for `get_value() is not None`: a
        pulse that leaves the value None may wake nobody (see `_none_for_sure`)."""
        cv = self._cv
        if cv is None:
            with _create_lock:
                cv = self._cv
                if cv is None:
                    cv = self._cv = Condition(threading.Lock())
        return cv

    def wait_for(self, timeout: float | None = None) -> bool:
        """Block while the value is None.

        Returns True once the value is not None (at once if it already is), False when
        `timeout` [s] of the active clock passed first. Raises `Evaporated` when the calling
        task is evaporated while waiting.
        """
        return wait_until(self._condition(), self._is_set, timeout)

    def _is_set(self) -> bool:
        return self.get_value() is not None

    # -- pulses ---------------------------------------------------------------------------------

    def pulsed(self, handle_missed: Behavior = Behavior.ONCE) -> Fluent:
        """A fluent that becomes True when this one is pulsed (for `whenever`).

        `handle_missed` tells `whenever` what to do with pulses that arrive while its body runs.
        """
        if not isinstance(handle_missed, Behavior):
            handle_missed = Behavior(handle_missed)
        fluent = _PulseFluent(name=f"pulsed({self._name})" if self._name else None)
        fluent._handle_missed = handle_missed
        self.add_child(fluent)
        return fluent

    def _consume_pulse(self) -> None:
        """Account for one run of a `whenever` body (thesis semantics of missed pulses)."""
        with _pulse_lock:
            if self._handle_missed is Behavior.NEVER:
                self._pulses = 0
            else:
                self._pulses = max(self._pulses - 1, 0)
                if self._pulses > 1 and self._handle_missed is Behavior.ONCE:
                    self._pulses = 1

    # -- networks -------------------------------------------------------------------------------

    def _network(self, value: Callable[[], Any], other: Any = None) -> Fluent:
        fluent = Fluent(value)
        self.add_child(fluent)
        if isinstance(other, Fluent):
            other.add_child(fluent)
            fluent._inputs = (value, (self, other))
        else:
            fluent._inputs = (value, (self,))
        return fluent

    def _compare(self, op: Callable[[Any, Any], Any], other: Any, none_safe: bool = False) -> Fluent:
        def value() -> bool | None:
            a, b = self.get_value(), _value_of(other)
            if not none_safe and (a is None or b is None):
                return None
            return True if op(a, b) else None

        return self._network(value, other)

    def __lt__(self, other: Any) -> Fluent:
        return self._compare(operator.lt, other)

    def __le__(self, other: Any) -> Fluent:
        return self._compare(operator.le, other)

    def __gt__(self, other: Any) -> Fluent:
        return self._compare(operator.gt, other)

    def __ge__(self, other: Any) -> Fluent:
        return self._compare(operator.ge, other)

    def __eq__(self, other: Any) -> Fluent:  # type: ignore[override]
        return self._compare(operator.eq, other, none_safe=True)

    def __ne__(self, other: Any) -> Fluent:  # type: ignore[override]
        return self._compare(operator.ne, other, none_safe=True)

    def IS(self, other: Any) -> Fluent:
        """Network valued True while `self.get_value() is other` (or other's value)."""
        return self._compare(operator.is_, other, none_safe=True)

    def IS_NOT(self, other: Any) -> Fluent:
        """Network valued True while `self.get_value() is not other` (or other's value)."""
        return self._compare(operator.is_not, other, none_safe=True)

    def AND(self, other: Any) -> Fluent:
        """Network valued True while both values are truthy."""
        return self._compare(lambda a, b: a and b, other, none_safe=True)

    def OR(self, other: Any) -> Fluent:
        """Network valued True while either value is truthy."""
        return self._compare(lambda a, b: a or b, other, none_safe=True)

    def NOT(self) -> Fluent:
        """Network valued True while the value is falsy (None included)."""
        return self._network(lambda: True if not self.get_value() else None)

    def _math(self, op: Callable[[Any, Any], Any], left: Any, right: Any) -> Fluent:
        def value() -> Any:
            a, b = _value_of(left), _value_of(right)
            if a is None or b is None:
                return None
            return op(a, b)

        other = right if left is self else left
        return self._network(value, other)

    def __add__(self, other: Any) -> Fluent:
        return self._math(operator.add, self, other)

    def __radd__(self, other: Any) -> Fluent:
        return self._math(operator.add, other, self)

    def __sub__(self, other: Any) -> Fluent:
        return self._math(operator.sub, self, other)

    def __rsub__(self, other: Any) -> Fluent:
        return self._math(operator.sub, other, self)

    def __mul__(self, other: Any) -> Fluent:
        return self._math(operator.mul, self, other)

    def __rmul__(self, other: Any) -> Fluent:
        return self._math(operator.mul, other, self)

    def __truediv__(self, other: Any) -> Fluent:
        return self._math(operator.truediv, self, other)

    def __rtruediv__(self, other: Any) -> Fluent:
        return self._math(operator.truediv, other, self)


def _equal(a: Any, b: Any) -> bool:
    try:
        return bool(a == b)
    except Exception:  # noqa: BLE001 - values that cannot be compared count as changed
        return False


class ChangeCallback:
    """Handle of an `on_change` registration."""

    __slots__ = ("fluent", "callback")

    def __init__(self, fluent: Fluent, callback: Callable[[Any], Any]) -> None:
        self.fluent = fluent
        self.callback = callback

    def remove(self) -> None:
        """Stop calling the callback (no error if it was removed already)."""
        fluent = self.fluent
        with _create_lock:
            callbacks = list(fluent._callbacks)
            if self.callback in callbacks:
                callbacks.remove(self.callback)
            fluent._callbacks = tuple(callbacks)


class _PulseFluent(Fluent):
    """Valued True while it has unconsumed pulses, None otherwise."""

    __slots__ = ()

    def get_value(self) -> bool | None:
        return True if self._pulses else None

    def set_value(self, value: Any) -> None:
        raise TypeError("a pulse fluent's value follows its parent; pulse the parent instead")


STOP = object()
"""Return this from a `whenever` body (function form) to leave the loop."""


class Whenever(BlockForm[None]):
    """Iterating over `whenever(fluent)` waits for the fluent before each pass.

    `for _ in whenever(f): body` runs `body` each time `f` is not None (a pulse fluent: each
    time its parent was pulsed, with missed pulses handled as the fluent's `Behavior` says).
    `break` or `return` leave the loop; evaporation stops it.
    """

    _block_form_name = "whenever(...)"

    def __init__(self, fluent: Fluent) -> None:
        if not isinstance(fluent, Fluent):
            raise TypeError(f"whenever() needs a Fluent, got {type(fluent).__name__}: {fluent!r}")
        self.fluent = fluent

    def __iter__(self) -> Iterator[None]:
        fluent = self.fluent
        while True:
            fluent.wait_for()
            yield None
            fluent._consume_pulse()


def whenever(fluent: Fluent, body: Callable[[], Any] | None = None) -> Any:
    """Run `body` each time `fluent` is not None, forever (thesis 3.2.2).

    Function form: `whenever(f, body)` loops until `body` returns `STOP` (then returns None),
    raises (the exception propagates), or the task is evaporated. Without `body` it returns an
    iterable for `for _ in whenever(f):` loops; in block syntax `with whenever(f):` is that
    loop, and `return` in its body leaves it.
    """
    loop = Whenever(fluent)
    if body is None:
        return loop
    for _ in loop:
        if body() is STOP:
            return None
    return None
