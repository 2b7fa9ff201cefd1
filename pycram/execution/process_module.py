"""Process modules (thesis ch. 3.4): the only place that talks to hardware or the simulator.

A process module executes motion designators for one component of a robot (base, head, an arm,
a gripper...). Subclasses override ``_execute(designator)`` (and optionally the cancel hook
``_cancel(designator)``); plans call ``ProcessModule.perform(designator)`` or
``pycram.designator.perform(designator)``, which picks a module through the resolvers::

    class Pr2Navigation(ProcessModule):
        def _execute(self, designator):
            solution = designator.reference()
            ...

    ProcessModule.resolvers.append(lambda d: pr2_navigation
                                   if d.check_constraints([('type', 'moving')]) else None)

Guarantees
----------
- **One at a time, first come first served.** A module executes one designator at a time;
  callers are served in arrival order. The claim of the module is atomic (no check-then-set):
  it happens under the module's condition, in the predicate of the wait.
- ``_execute`` runs in the calling task's thread (blocking ``execute``) or in a child task of
  the caller (``execute_nowait``), so evaporating the caller evaporates the motion.
- **Cancellation.** When the task waiting in ``execute`` is evaporated while queued, its entry
  leaves the queue; while running, the cancel hook ``_cancel(designator)`` runs (protected from
  evaporation), the module is freed and the next queued designator starts. ``Evaporated`` then
  propagates to the caller.
- **Failures.** An exception raised by ``_execute`` reaches the caller as
  :class:`ProcessModuleFailure` (``cause`` / ``__cause__`` is the original exception); the module
  is freed and its status becomes ``FAILED``. ``SystemExit`` and ``KeyboardInterrupt`` raised
  inside ``_execute`` also end it ``FAILED`` (not ``CANCELLED``: only evaporation cancels) and
  propagate unchanged.
- **Status.** ``module.status`` is a :class:`~pycram.fluent.Fluent` of
  :class:`ProcessModuleStatus`: ``WAITING`` (idle, ready) → ``RUNNING`` → ``SUCCEEDED`` /
  ``FAILED`` / ``CANCELLED`` (outcome of the last designator; the module is idle again) →
  ``RUNNING`` ...; ``OFFLINE`` after :meth:`ProcessModule.shutdown`. Every transition is set
  while the module's state is consistent (under its condition).
- **Checked first.** :meth:`ProcessModule.perform` checks a motion designator against the active
  robot's motion types before choosing a module (a missing, misspelled or invalid key raises
  :class:`~pycram.designators.motion_types.MotionPropertyError`; nothing is queued).
- **No module.** :class:`NoProcessModuleError` names the designator's properties, the resolvers
  asked and the active robot; :class:`UnknownMotionTypeError` (a subclass) also lists the motion
  types the active robot knows when the designator's type is none of them.
- **Events.** Every started execution is announced once on :mod:`pycram.core.events`
  (``PROCESS_MODULE_EXECUTED``, in the executing task's thread, when its outcome is settled);
  every :meth:`ProcessModule.perform` announces ``DESIGNATOR_PERFORMED``. Observers never change
  what happens (see :mod:`pycram.core.events`).
"""

from __future__ import annotations

import itertools
import logging
import threading
from collections import deque
from collections.abc import Callable
from enum import Enum
from typing import Any, ClassVar

from pycram.core import events
from pycram.core.fluent import Fluent
from pycram.core.runtime import Evaporated, current_clock, no_evaporation, wait_until
from pycram.core.runtime.evaporation import call_plan_code, runtime_code
from pycram.core.runtime.lockstep import Condition
from pycram.core.runtime.suspension import on_suspension, retry_after_suspension
from pycram.designators.core import DesignatorError, callable_name, known_solution
from pycram.designators.motion import MotionDesignator
from pycram.designators.motion_types import active_motion_types, check_motion, describe_known_types
from pycram.designators.resolvers import describe_active_robot, gather
from pycram.execution.robot import current_robot

__all__ = [
    "ProcessModule",
    "ProcessModuleStatus",
    "ProcessModuleError",
    "ProcessModuleFailure",
    "ProcessModuleOffline",
    "NoProcessModuleError",
    "UnknownMotionTypeError",
    "ExecutionCancelled",
    "Execution",
]

logger = logging.getLogger(__name__)

_ids = itertools.count(1)


class ProcessModuleStatus(Enum):
    """Status of a process module (and of one :class:`Execution`)."""

    OFFLINE = "offline"  #: shut down; performing on it raises ProcessModuleOffline
    WAITING = "waiting"  #: idle and ready (for an execution: queued)
    RUNNING = "running"  #: executing a designator
    SUCCEEDED = "succeeded"  #: the last designator succeeded; idle
    FAILED = "failed"  #: the last designator failed; idle
    CANCELLED = "cancelled"  #: the last designator was cancelled (evaporated); idle

    @property
    def done(self) -> bool:
        """True for the outcomes SUCCEEDED, FAILED and CANCELLED."""
        return self in (ProcessModuleStatus.SUCCEEDED, ProcessModuleStatus.FAILED, ProcessModuleStatus.CANCELLED)


class ProcessModuleError(Exception):
    """Base class of process-module errors. Attributes: ``designator``, ``module``, ``cause``."""

    def __init__(
        self, message: str, designator: Any = None, module: Any = None, cause: BaseException | None = None
    ) -> None:
        super().__init__(message)
        self.designator = designator
        self.module = module
        self.cause = cause


class ProcessModuleFailure(ProcessModuleError):
    """``_execute`` raised: the motion failed. ``cause`` is the original exception."""


class ProcessModuleOffline(ProcessModuleError):
    """The module was shut down (status ``OFFLINE``) before the designator could run."""


class ExecutionCancelled(ProcessModuleError):
    """The execution was cancelled through its handle (``Execution.cancel``)."""


class NoProcessModuleError(ProcessModuleError, DesignatorError, LookupError):
    """No resolver returned a process module for the designator."""


class UnknownMotionTypeError(NoProcessModuleError):
    """No process module serves the designator and its type is not among the motion types the
    active robot declares (``robot.motion_types``); the message lists them. ``motion_type`` is
    the unknown type, ``known_types`` the declared ones."""

    def __init__(self, message: str, designator: Any = None, motion_type: Any = None, known_types: Any = ()) -> None:
        super().__init__(message, designator=designator)
        self.motion_type = motion_type
        self.known_types = sorted(known_types, key=str)


class Execution:
    """One designator submitted to one module: its place in the queue and its outcome.

    Returned by :meth:`ProcessModule.execute_nowait` as a handle: ``status`` is a fluent of
    :class:`ProcessModuleStatus` (``WAITING`` while queued, then ``RUNNING``, then an outcome),
    ``wait()`` blocks for the outcome, ``cancel()`` stops it.
    """

    def __init__(self, module: ProcessModule, designator: Any) -> None:
        self.id = next(_ids)
        self.module = module
        self.designator = designator
        self.status = Fluent(ProcessModuleStatus.WAITING, name=f"{module.name}.execution-{self.id}.status")
        self.result: Any = None
        self.exception: BaseException | None = None
        #: Active-clock times [s] when ``_execute`` started and when the outcome was settled
        #: (``None`` if it never started).
        self.start: float | None = None
        self.end: float | None = None
        self._task: Any = None  # the child task of a nowait execution
        self._group: Any = None
        self._cancel_requested = False

    @property
    def done(self) -> bool:
        status: ProcessModuleStatus = self.status.get_value()
        return status.done

    def wait(self, timeout: float | None = None) -> Any:
        """Block until the execution ended and return ``_execute``'s result.

        Raises :class:`ProcessModuleFailure` if it failed, :class:`ExecutionCancelled` if it was
        cancelled, ``TimeoutError`` if ``timeout`` [s] (active clock) passed first. Evaporable.
        """
        if not wait_until(self.module._cond, lambda: self.done, timeout):
            raise TimeoutError(f"{self!r} did not end within {timeout} s")
        if self._group is not None:
            self._group.wait_all()  # the child thread ends right after the outcome is set
            self._group = None
        status = self.status.get_value()
        if status is ProcessModuleStatus.SUCCEEDED:
            return self.result
        if status is ProcessModuleStatus.CANCELLED:
            raise ExecutionCancelled(
                f"execution of {self.designator!r} on {self.module.name} was cancelled",
                designator=self.designator,
                module=self.module,
                cause=self.exception,
            )
        assert self.exception is not None
        raise self.exception

    @runtime_code
    def cancel(self) -> None:
        """Stop the execution: leave the queue, or evaporate the running ``_execute`` (the
        module's cancel hook runs). Returns at once; idempotent; no effect once done."""
        self._cancel_requested = True
        self.module._abandon(self)
        task = self._task
        if task is not None:
            task.evaporate()

    def __repr__(self) -> str:
        return f"<Execution {self.id} of {self.designator!r} on {self.module.name} {self.status.get_value().value}>"


class ProcessModule:
    """A component of a robot that executes motion designators (thesis API).

    Override ``_execute(designator)`` (required) and ``_cancel(designator)`` (cancel hook:
    stop the base, stop the arm...). ``resolvers`` is the thesis' global list of functions
    ``f(designator) -> ProcessModule | None``; the active robot's ``process_module_resolvers``
    are asked first.
    """

    resolvers: ClassVar[list[Callable[[Any], ProcessModule | None]]] = []

    #: What suspending the executing task (`pycram.core.runtime.suspension`) does to a running
    #: execution. "pause": ``_pause(designator)`` runs when the task blocks for suspension and
    #: ``_resume(designator)`` when it is woken; ``_execute`` goes on where it waited.
    #: "cancel": the execution is evaporated (the cancel hook runs and the module is freed for
    #: other callers) and, after the wake-up, the designator is queued and executed again from
    #: the start (CRAM's retry-after-suspension). An ``execute_nowait`` execution always
    #: behaves as "pause".
    suspension: ClassVar[str] = "pause"

    def __init__(self, name: str | None = None) -> None:
        self.name = name or type(self).__name__
        self._cond = Condition(threading.Lock())
        self._queue: deque[Execution] = deque()
        self._current: Execution | None = None
        self._offline = False
        self.status = Fluent(ProcessModuleStatus.WAITING, name=f"{self.name}.status")
        #: Number of designators waiting in the queue (not counting the running one).
        self.queued = Fluent(0, name=f"{self.name}.queued")
        self._running = Fluent(False, name=f"{self.name}.running")  # thesis attribute

    # -- thesis API --------------------------------------------------------------------------

    @staticmethod
    def perform(designator: Any) -> Any:
        """Execute ``designator`` on the first module a resolver returns; return its result.

        Blocks until done, except for designators with the property ``('wait', False)``
        (thesis): then returns an :class:`Execution` handle at once. Raises
        :class:`NoProcessModuleError` when no resolver returns a module. Announces
        ``DESIGNATOR_PERFORMED`` (with the designator's solution if it was resolved, and the
        exception if one is raised) before returning or raising.
        """
        try:
            _check_motion(designator)
            module = ProcessModule.resolve(designator)
            if designator.prop_value("wait") is False:
                result = module.execute_nowait(designator)
            else:
                result = module.execute(designator)
        except BaseException as e:
            events.designator_performed(designator, known_solution(designator), e)
            raise
        events.designator_performed(designator, known_solution(designator), None)
        return result

    @staticmethod
    def perform_nowait(designator: Any) -> Execution:
        """Like :meth:`perform` but never blocks: returns the :class:`Execution` handle."""
        _check_motion(designator)
        return ProcessModule.resolve(designator).execute_nowait(designator)

    @staticmethod
    def resolve(designator: Any) -> ProcessModule:
        """The module chosen for ``designator`` by the active robot's resolvers, then the
        global ``ProcessModule.resolvers``. Raises :class:`NoProcessModuleError`."""
        resolvers = gather("process_module_resolvers", ProcessModule.resolvers)
        for resolver in resolvers:
            try:
                module = resolver(designator)
            except Exception as e:
                raise ProcessModuleError(
                    f"process-module resolver {callable_name(resolver)} failed for "
                    f"{designator!r} ({describe_active_robot()}): {e!r}",
                    designator=designator,
                    cause=e,
                ) from e
            if module is None:
                continue
            if not isinstance(module, ProcessModule):
                raise ProcessModuleError(
                    f"process-module resolver {callable_name(resolver)} returned {module!r} "
                    f"for {designator!r}, not a ProcessModule",
                    designator=designator,
                )
            return module
        types = active_motion_types()
        motion_type = _type_of(designator)
        if types and motion_type not in {str(t) for t in types}:
            raise UnknownMotionTypeError(
                f"no process module for {designator!r}: unknown motion type {motion_type!r}; "
                f"{describe_known_types(types, motion_type)}",
                designator=designator,
                motion_type=motion_type,
                known_types=types,
            )
        robot = current_robot()
        available = sorted(robot.process_modules) if robot is not None else []
        raise NoProcessModuleError(
            f"no process module for {designator!r} ({describe_active_robot()}"
            + (f" with modules {available}" if robot is not None else "")
            + f"); resolvers asked: {[callable_name(r) for r in resolvers]}",
            designator=designator,
        )

    def _execute(self, designator: Any) -> Any:
        """Execute ``designator`` (override). Runs in the caller's task; may be evaporated."""
        return None

    def _cancel(self, designator: Any) -> None:
        """Cancel hook (override): called when the execution of ``designator`` was evaporated or
        cancelled, in the caller's thread, protected from evaporation -- while running (after
        ``_execute(designator)`` was interrupted: stop the hardware here) and while still queued
        (``self.current`` is then another execution or None: nothing of this designator runs,
        so stop nothing that another caller started)."""

    def _pause(self, designator: Any) -> None:
        """Suspension hook (override; "pause" modules): the executing task was suspended."""

    def _resume(self, designator: Any) -> None:
        """Wake-up hook (override; "pause" modules): the executing task was woken up."""

    @runtime_code
    def execute(self, designator: Any) -> Any:
        """Queue ``designator``, wait for its turn, run ``_execute`` and return its result.

        Evaporable while queued and while running (see the module docstring); suspendable as
        the class attribute ``suspension`` says. Raises :class:`ProcessModuleFailure`,
        :class:`ProcessModuleOffline`.
        """
        if self.suspension == "cancel":
            return retry_after_suspension(
                lambda: self._execute_once(designator), name=f"{self.name}: retry after suspension"
            )
        if self.suspension != "pause":
            raise ValueError(f"{type(self).__name__}.suspension must be 'pause' or 'cancel', got {self.suspension!r}")
        return self._execute_once(designator)

    def _execute_once(self, designator: Any) -> Any:
        execution = self._submit(designator)
        self._run(execution)
        if execution.status.get_value() is ProcessModuleStatus.SUCCEEDED:
            return execution.result
        if execution.exception is not None:
            raise execution.exception
        raise ExecutionCancelled(
            f"execution of {designator!r} on {self.name} was cancelled", designator=designator, module=self
        )

    @runtime_code
    def execute_nowait(self, designator: Any) -> Execution:
        """Queue ``designator`` and return its :class:`Execution` handle at once.

        The designator runs in a child task of the calling task (in a thread of its own), so
        evaporating the caller cancels it. Wait on the handle (``wait()``) or cancel it; a
        handle left alone keeps executing.
        """
        from pycram.core.runtime import TaskGroup

        execution = self._submit(designator)
        # on_end runs when the child task ends -- also if it was evaporated before its body ran:
        # then the execution must not stay in the queue and block the module.
        group = TaskGroup(on_end=lambda task: self._abandon(execution), detached=True)
        execution._group = group

        def body() -> None:
            # The outcome is recorded in the execution; a failure or cancellation also ends the
            # task FAILED or EVAPORATED, so the task tree tells what became of the designator.
            # The group is detached: nothing propagates to the caller's task.
            self._run(execution)

        execution._task = group.spawn(f"{self.name}: {_type_of(designator)}", body, kind="process-module")
        if execution._cancel_requested:
            execution._task.evaporate()
        return execution

    # -- administration ----------------------------------------------------------------------

    @runtime_code
    def shutdown(self) -> None:
        """Take the module offline: queued designators fail with :class:`ProcessModuleOffline`,
        new ones are refused; a running one finishes. Status becomes ``OFFLINE``."""
        with self._cond:
            self._offline = True
            for execution in list(self._queue):
                self._finish_locked(
                    execution,
                    ProcessModuleStatus.CANCELLED,
                    ProcessModuleOffline(
                        f"{self.name} went offline before {execution.designator!r} ran",
                        designator=execution.designator,
                        module=self,
                    ),
                )
            self._queue.clear()
            self.queued.set_value(0)
            if self._current is None:
                self.status.set_value(ProcessModuleStatus.OFFLINE)
            self._cond.notify_all()

    @runtime_code
    def start(self) -> None:
        """Bring an offline module back online (status ``WAITING``)."""
        with self._cond:
            self._offline = False
            if self._current is None:
                self.status.set_value(ProcessModuleStatus.WAITING)
            self._cond.notify_all()

    @property
    @runtime_code
    def queue_length(self) -> int:
        """Number of designators waiting (not counting the running one)."""
        with self._cond:
            return len(self._queue)

    @property
    def current(self) -> Execution | None:
        """The running execution, if any."""
        return self._current

    @property
    @runtime_code
    def _designators(self) -> list[Any]:
        """Thesis attribute: the designators still to be processed (running one first)."""
        with self._cond:
            running = [self._current.designator] if self._current is not None else []
            return running + [e.designator for e in self._queue]

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name} {self.status.get_value().value}>"

    # -- internals ---------------------------------------------------------------------------

    def _submit(self, designator: Any) -> Execution:
        execution = Execution(self, designator)
        with self._cond:
            if self._offline:
                raise ProcessModuleOffline(
                    f"{self.name} is offline; cannot execute {designator!r}", designator=designator, module=self
                )
            self._queue.append(execution)
            self.queued.set_value(len(self._queue))
        return execution

    @runtime_code
    def _abandon(self, execution: Execution) -> None:
        """Remove a queued ``execution`` whose owner gave up (cancelled, or its task ended)."""
        with self._cond:
            if execution in self._queue:
                self._queue.remove(execution)
                self.queued.set_value(len(self._queue))
                self._finish_locked(execution, ProcessModuleStatus.CANCELLED, None)
            self._cond.notify_all()

    def _claim(self, execution: Execution) -> bool:
        """Predicate run under ``_cond``: take the module if it is our turn (atomic)."""
        if execution.done:
            return True  # removed from the queue (offline / cancelled)
        if execution._cancel_requested:
            self._queue.remove(execution)
            self.queued.set_value(len(self._queue))
            self._finish_locked(execution, ProcessModuleStatus.CANCELLED, None)
            self._cond.notify_all()
            return True
        if self._current is None and self._queue and self._queue[0] is execution:
            self._queue.popleft()
            self.queued.set_value(len(self._queue))
            self._current = execution
            execution.status.set_value(ProcessModuleStatus.RUNNING)
            self._running.set_value(True)
            self.status.set_value(ProcessModuleStatus.RUNNING)
            return True
        return False

    @runtime_code
    def _run(self, execution: Execution) -> None:
        """Wait for the turn of ``execution``, then execute it; records the outcome in it.

        Raises what the caller must see: ``Evaporated``, ProcessModuleFailure/Offline.
        Whatever happens -- evaporation while queued, while running, or an asynchronous
        ``Evaporated`` landing between two statements -- the ``finally`` clause leaves the
        queue, frees the module and settles the outcome (under ``no_evaporation``).
        """
        designator = execution.designator
        outcome, result = ProcessModuleStatus.CANCELLED, None
        error: BaseException | None = None
        started = False
        try:
            wait_until(self._cond, lambda: self._claim(execution))
            if self._current is execution:
                started = True
                execution.start = current_clock().now()
                logger.debug("%s: executing %r", self.name, designator)
                try:
                    with on_suspension(lambda: self._pause(designator), lambda: self._resume(designator)):
                        result = call_plan_code(self._execute, designator)
                    outcome = ProcessModuleStatus.SUCCEEDED
                except Exception as e:
                    failure = ProcessModuleFailure(
                        f"{self.name} failed to execute {designator!r}: {type(e).__name__}: {e}",
                        designator=designator,
                        module=self,
                        cause=e,
                    )
                    failure.__cause__ = e
                    error, outcome = failure, ProcessModuleStatus.FAILED
                except BaseException as e:  # SystemExit, KeyboardInterrupt: failed, not cancelled
                    if not isinstance(e, Evaporated):
                        error, outcome = e, ProcessModuleStatus.FAILED  # e propagates unchanged
                    raise
        finally:
            self._settle(execution, started, outcome, error, result)
        if error is not None:
            raise error
        if not started and execution.exception is not None:
            raise execution.exception  # e.g. ProcessModuleOffline while queued

    def _settle(
        self,
        execution: Execution,
        started: bool,
        outcome: ProcessModuleStatus,
        error: BaseException | None,
        result: Any,
    ) -> None:
        """Run the cancel hook if the execution was cancelled (see `_cancel`), then free the
        module / leave the queue and record the outcome. Idempotent for a settled execution.
        Raises ``Evaporated`` at the end if the calling task is evaporating."""
        with no_evaporation():
            # evaporated or cancelled -- while running, or while still queued (then nothing of
            # it runs: the hook may release what was reserved for it, and must not stop another
            # caller's motion); a module taken offline is not a cancellation of this designator
            if outcome is ProcessModuleStatus.CANCELLED and (started or execution.exception is None):
                try:
                    logger.debug("%s: cancelling %r", self.name, execution.designator)
                    self._cancel(execution.designator)
                except Exception:
                    logger.exception("%s: cancel hook failed for %r", self.name, execution.designator)
            with self._cond:
                if started and execution.end is None:
                    execution.end = current_clock().now()  # before waiters see the outcome
                if execution in self._queue:
                    self._queue.remove(execution)
                    self.queued.set_value(len(self._queue))
                if self._current is execution:
                    self._current = None
                    execution.result = result
                    self._running.set_value(False)
                    self.status.set_value(ProcessModuleStatus.OFFLINE if self._offline else outcome)
                if not execution.done:
                    self._finish_locked(execution, outcome, error)
                self._cond.notify_all()
            if started:
                cause = error.cause if isinstance(error, ProcessModuleFailure) else error
                events.process_module_executed(
                    self, execution.designator, outcome.value, execution.start, execution.end, cause
                )

    def _finish_locked(self, execution: Execution, outcome: ProcessModuleStatus, error: BaseException | None) -> None:
        execution.exception = error
        execution.status.set_value(outcome)


def _check_motion(designator: Any) -> None:
    """Check a motion designator against the active robot's motion types (before it is queued)."""
    if isinstance(designator, MotionDesignator):
        check_motion(designator)


def _type_of(designator: Any) -> str:
    try:
        return str(designator.prop_value("type"))
    except AttributeError:
        return type(designator).__name__
