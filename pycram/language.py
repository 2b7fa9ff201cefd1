"""The PyCRAM plan language expressions (thesis ch. 3.2.3, with CRAM's semantics).

Functional forms — each runs its callables as tasks and returns its *state fluent*, whose value
is `State.SUCCEEDED` or `State.FAILED` once it returns::

    errors = []
    s = par(move_base, move_head, errors=errors)   # concurrently; first failure evaporates the rest
    if s.get_value() is State.FAILED: print(errors)

| expression     | runs          | SUCCEEDED when       | stops early                                   |
|----------------|---------------|----------------------|-----------------------------------------------|
| `seq`          | in order      | all succeed          | at the first failure                          |
| `try_in_order` | in order      | one succeeds         | at the first success                          |
| `par`          | concurrently  | all succeed          | first failure evaporates the others           |
| `try_all`      | concurrently  | one succeeds         | first success evaporates the others           |
| `pursue`       | concurrently  | first to end succeeded | first to end evaporates the others          |

Guarantees:

* An expression never raises its branches' exceptions to the caller: they are appended to
  `errors` (when given) in the order the branches failed. Exactly the branches whose task ended
  FAILED contribute; evaporated branches contribute nothing.
* The state fluent (a `StateFluent`) holds the winning branch's return value in `result` —
  `seq`: the last step's, `par`: every branch's in order, the others: the winner's — set before
  the value becomes SUCCEEDED; None on failure.
* The state fluent is set as soon as the outcome is decided (branches may watch it) and never
  changes afterwards. Pass `state=` a fresh `Fluent` to get it before the branches start.
* An expression returns only after every task it started — and all of theirs — has ended, on
  success, failure and evaporation alike. No thread outlives it.
* If the calling task is evaporated, the expression evaporates its branches, waits for them and
  raises `Evaporated`.

The thesis' block syntax (`with par(errors) as s:`) is a front end to these functions; see
`pycram.macros` and `plan`.
"""

from __future__ import annotations

from enum import Enum
from typing import Any, Callable, Sequence

from pycram.block_forms import BlockForm
from pycram.fluent import Behavior, Fluent, whenever
from pycram.runtime.evaporation import check_evaporation, shielded, wait_until
from pycram.runtime.task import Task, TaskGroup, TaskStatus, current_task, run_subtask, task_scope
from pycram.runtime.detached import detached_children
from pycram.runtime.suspension import (is_suspended, on_suspension, retry_after_suspension, suspend,
                                       wake_up, with_task_suspended)
from pycram.runtime.tags import Tags, find_task, find_tasks, tag, with_tags
from pycram.runtime.task_variables import TaskVariable

__all__ = [
    "State",
    "StateFluent",
    "seq",
    "par",
    "pursue",
    "try_all",
    "try_in_order",
    "failure_handling",
    "retry",
    "current_attempt",
    "with_timeout",
    "try_each_in_order",
    "par_loop",
    "partial_order",
    "Policy",
    "PolicyRun",
    "PolicyConditionMet",
    "PolicyInitFailed",
    "define_policy",
    "with_policy",
    "timeout_policy",
    "whenever",
    "TaskVariable",
    "suspend",
    "wake_up",
    "with_task_suspended",
    "on_suspension",
    "retry_after_suspension",
    "is_suspended",
    "detached_children",
    "Tags",
    "with_tags",
    "tag",
    "find_task",
    "find_tasks",
    "Fluent",
    "Behavior",
]


class State(Enum):
    """Outcome of an expression (the value of its state fluent)."""

    SUCCEEDED = 1
    FAILED = 2


Branch = Callable[[], Any]


def _label(fn: Branch, index: int) -> str:
    """Task name of the index-th branch: its given name, its function name, or its number."""
    given = getattr(fn, "__pycram_name__", None)
    if given:
        return given
    name = getattr(fn, "__name__", None)
    if name and "@" in name:  # named after its source line by the block syntax: unique already
        return name
    if not name or name == "<lambda>":
        return str(index + 1)
    return f"{index + 1}:{name}"


class StateFluent(Fluent):
    """The state fluent an expression returns: its value is a `State` once decided, and
    `result` holds the return value of the winning branch (see `_set_result`).

    `result` is set *before* the value becomes `State.SUCCEEDED`, so a branch or caller that
    waited for the state reads the final result. It stays None on failure.
    """

    __slots__ = ("result",)

    def __init__(self, value: Any = None, name: str | None = None) -> None:
        super().__init__(value, name)
        self.result: Any = None


def _set_result(state: Fluent, result: Any) -> None:
    """Record the winning branch's return value on `state` (if undecided and it can hold one)."""
    if state.get_value() is None and isinstance(state, StateFluent):
        state.result = result


def _decide(state: Fluent, outcome: State) -> None:
    if state.get_value() is None:
        state.set_value(outcome)


class _Expression(BlockForm):
    """Callable expression object; refuses `with expr:` unless the block syntax rewrote it."""

    def __init__(self, kind: str, run: Callable[..., Fluent], doc: str) -> None:
        self.kind = kind
        self._run = run
        self._block_form_name = kind
        self.__name__ = kind
        self.__qualname__ = kind
        self.__doc__ = doc

    def __call__(
        self,
        *fns: Branch,
        errors: list | None = None,
        state: Fluent | None = None,
        name: str | None = None,
    ) -> Any:
        if len(fns) == 1 and isinstance(fns[0], list) and errors is None:
            # `par(errors)` as in `with par(errors) as s:` — the block form.
            return _BlockUse(f"{self.kind}(errors) as s")
        for index, fn in enumerate(fns):
            if not callable(fn):
                raise TypeError(
                    f"{self.kind}(): branch {index + 1} must be a callable taking no arguments, "
                    f"got {type(fn).__name__}: {fn!r}"
                )
        if errors is not None and not isinstance(errors, list):
            raise TypeError(f"{self.kind}(): errors must be a list, got {type(errors).__name__}")
        if state is not None and not isinstance(state, Fluent):
            raise TypeError(f"{self.kind}(): state must be a Fluent, got {type(state).__name__}")
        state = state if state is not None else StateFluent(name=name or self.kind)
        self._run(fns, errors if errors is not None else [], state, name or self.kind)
        return state

    def __repr__(self) -> str:
        return f"<pycram expression {self.kind}>"


class _BlockUse(BlockForm):
    def __init__(self, form: str) -> None:
        self._block_form_name = form


# -- sequential expressions ----------------------------------------------------------------------


def _run_seq(fns: Sequence[Branch], errors: list, state: Fluent, name: str) -> None:
    with task_scope(name, "seq") as scope:
        result = None
        for index, fn in enumerate(fns):
            try:
                result = run_subtask(_label(fn, index), fn, kind="step")
            except Exception as exc:
                errors.append(exc)
                scope.fail(exc)
                _decide(state, State.FAILED)
                return
        scope.task.result = result
        _set_result(state, result)
        _decide(state, State.SUCCEEDED)


def _run_try_in_order(fns: Sequence[Branch], errors: list, state: Fluent, name: str) -> None:
    with task_scope(name, "try_in_order") as scope:
        for index, fn in enumerate(fns):
            try:
                result = run_subtask(_label(fn, index), fn, kind="step")
            except Exception as exc:
                errors.append(exc)
                continue
            scope.task.result = result
            _set_result(state, result)
            _decide(state, State.SUCCEEDED)
            return
        scope.fail(errors[-1] if errors else RuntimeError(f"{name}: no alternatives"))
        _decide(state, State.FAILED)


# -- concurrent expressions ------------------------------------------------------------------------


class RetryRequested(BaseException):
    """Raised by `retry()`; caught by the failure_handling it belongs to (ends the attempt)."""

    def __init__(self, handler: _FailureHandler) -> None:
        super().__init__("retry() restarts the failure_handling body")
        self.handler = handler


class _Concurrent:
    """Shared engine of par, try_all and pursue: outcome rules differ, guarantees do not."""

    def __init__(self, kind: str, errors: list, state: Fluent) -> None:
        self.kind = kind
        self.errors = errors
        self.state = state
        self.outcome: State | None = None
        self.first_error: BaseException | None = None
        self.retry: RetryRequested | None = None
        self.succeeded = 0
        self.failed = 0
        self.count = 0
        self.group: TaskGroup | None = None
        self.result: Any = None  #: the winning branch's return value (par: all branches' in order)

    def on_end(self, task: Task) -> None:
        """Called in the branch's thread, under the group's lock, when a branch ends."""
        status = task.status.get_value()
        if status is TaskStatus.FAILED:
            if isinstance(task.exception, RetryRequested):
                self.retry = self.retry or task.exception
                self._decide(State.FAILED)
                return
            self.failed += 1
            self.errors.append(task.exception)
            if self.first_error is None:
                self.first_error = task.exception
        elif status is TaskStatus.SUCCEEDED:
            self.succeeded += 1
        if self.outcome is not None:
            return
        kind, ended = self.kind, self.succeeded + self.failed
        if kind == "par":
            if status is TaskStatus.FAILED:
                self._decide(State.FAILED)
            elif self.succeeded == self.count:
                self.result = [t.result for t in self.group.tasks]  # every branch's, in branch order
                self._decide(State.SUCCEEDED)
        elif kind == "try_all":
            if status is TaskStatus.SUCCEEDED:
                self.result = task.result
                self._decide(State.SUCCEEDED)
            elif ended == self.count:
                self._decide(State.FAILED)
        elif kind == "pursue":
            if status is TaskStatus.SUCCEEDED:
                self.result = task.result
                self._decide(State.SUCCEEDED)
            elif status is TaskStatus.FAILED:
                self._decide(State.FAILED)

    def _decide(self, outcome: State) -> None:
        if self.outcome is None:
            self.outcome = outcome
            if outcome is State.SUCCEEDED:
                _set_result(self.state, self.result)
            _decide(self.state, outcome)

    def run(self, fns: Sequence[Branch], name: str, deadline: float | None = None) -> bool:
        """Run the branches; returns False if `deadline` [s] passed before an outcome."""
        self.count = len(fns)
        group = self.group = TaskGroup(self.on_end)
        try:
            with shielded():  # never leave a started thread behind half-registered
                for index, fn in enumerate(fns):
                    group.spawn(_label(fn, index), fn)
            in_time = wait_until(group._cv, lambda: self.outcome is not None or group._running == 0, deadline)
        except BaseException:  # evaporated, or interrupted (KeyboardInterrupt): no branch outlives us
            group.stop_all()
            raise
        try:
            group.evaporate()  # may raise a re-delivered Evaporated: the wait below still runs
        finally:
            group.wait_all()
        if self.outcome is None and in_time:
            # every branch ended without deciding (e.g. all evaporated from outside)
            self._decide(State.SUCCEEDED if self.kind == "par" and self.failed == 0 else State.FAILED)
        return in_time


def _concurrent_runner(kind: str) -> Callable[[Sequence[Branch], list, Fluent, str], None]:
    def run(fns: Sequence[Branch], errors: list, state: Fluent, name: str) -> None:
        engine = _Concurrent(kind, errors, state)
        with task_scope(name, kind) as scope:
            if not fns:
                engine._decide(State.SUCCEEDED if kind in ("par", "pursue") else State.FAILED)
            else:
                engine.run(fns, name)
            if engine.outcome is State.FAILED:
                scope.fail(engine.first_error or engine.retry or RuntimeError(f"{name} failed"))
            else:
                scope.task.result = engine.result
        if engine.retry is not None:
            raise engine.retry  # a branch called retry(): restart the enclosing failure_handling

    return run


seq = _Expression("seq", _run_seq, "Run the callables in order; stop at the first failure.")
try_in_order = _Expression(
    "try_in_order", _run_try_in_order, "Run the callables in order until one succeeds; FAILED only if all fail."
)
par = _Expression(
    "par", _concurrent_runner("par"), "Run the callables concurrently; the first failure evaporates the others."
)
try_all = _Expression(
    "try_all",
    _concurrent_runner("try_all"),
    "Run the callables concurrently; the first success evaporates the others; FAILED when all fail.",
)
pursue = _Expression(
    "pursue",
    _concurrent_runner("pursue"),
    "Run the callables concurrently; the first to end decides the outcome and evaporates the others.",
)


def _item_branches(items: Any, body: Callable[[Any], Any], form: str) -> list[Branch]:
    if not callable(body):
        raise TypeError(f"{form}(): body must be a callable taking one item, got {type(body).__name__}: {body!r}")
    try:
        items = list(items)
    except TypeError:
        raise TypeError(f"{form}(): items must be iterable, got {type(items).__name__}: {items!r}") from None
    branches = []
    for index, item in enumerate(items):
        def branch(item: Any = item) -> Any:
            return body(item)

        branch.__pycram_name__ = f"{index + 1}:{item!r}"[:60]  # type: ignore[attr-defined]
        branches.append(branch)
    return branches


def try_each_in_order(items: Any, body: Callable[[Any], Any], errors: list | None = None,
                      name: str | None = None, state: Fluent | None = None) -> Fluent:
    """`try_in_order` over `body(item)` for each item (CRAM's `try-each-in-order`).

    Calls `body(item)` for the items in order until one returns without raising; returns the
    state fluent, whose `result` is that call's return value. FAILED (with every failure in
    `errors`, in order) when all calls fail or `items` is empty.
    """
    branches = _item_branches(items, body, "try_each_in_order")
    return try_in_order(*branches, errors=errors, state=state, name=name or "try_each_in_order")


def par_loop(items: Any, body: Callable[[Any], Any], errors: list | None = None,
             name: str | None = None, state: Fluent | None = None) -> Fluent:
    """`par` over `body(item)` for each item (CRAM's `par-loop`): one branch per item.

    SUCCEEDED when every call returned — `result` is then the list of return values in item
    order; the first failure evaporates the other branches (as `par`).
    """
    branches = _item_branches(items, body, "par_loop")
    return par(*branches, errors=errors, state=state, name=name or "par_loop")


def with_timeout(seconds: float, fn: Branch, errors: list | None = None, name: str | None = None) -> Fluent:
    """Run `fn` as a task; evaporate it if it has not ended after `seconds` [s] of the active clock.

    Returns the state fluent: SUCCEEDED if fn returned in time; FAILED if it raised (its
    exception goes to `errors`) or timed out (a `TimeoutError` goes to `errors`). Never raises
    fn's exceptions; returns only after fn's task has ended.
    """
    if not callable(fn):
        raise TypeError(f"with_timeout(): fn must be callable, got {type(fn).__name__}")
    errors = errors if errors is not None else []
    label = name or f"with_timeout({seconds:g} s)"
    state = StateFluent(name=label)
    engine = _Concurrent("pursue", errors, state)
    with task_scope(label, "with_timeout") as scope:
        if not engine.run([fn], label, deadline=seconds):
            error = TimeoutError(f"{label}: {getattr(fn, '__name__', 'body')} did not end within {seconds:g} s")
            errors.append(error)
            engine.first_error = engine.first_error or error
            engine._decide(State.FAILED)
        if engine.outcome is State.FAILED:
            scope.fail(engine.first_error)
    if engine.retry is not None:
        raise engine.retry
    return state


# -- failure handling --------------------------------------------------------------------------------


class _FailureHandler:
    __slots__ = ("max_retries", "retries")

    def __init__(self, max_retries: int) -> None:
        self.max_retries = max_retries
        self.retries = 0


def _failure_handling_block(max_retries: int | None) -> _BlockUse:
    form = "failure_handling()" if max_retries is None else f"failure_handling({max_retries})"
    return _BlockUse(form)


def _run_failure_handling(body: Branch, max_retries: int, name: str | None) -> Any:
    handler = _FailureHandler(max_retries)

    def attempt() -> Any:
        current_task().info["retry_handler"] = handler
        return body()

    with task_scope(name or "failure_handling", "failure_handling") as scope:
        number = 0
        while True:
            number += 1
            scope.task.info["attempts"] = number
            try:
                return run_subtask(f"attempt {number}", attempt, kind="attempt")
            except RetryRequested as request:
                if request.handler is not handler:
                    raise


class _FailureHandling(BlockForm):
    """The `failure_handling` expression object (callable; refuses a bare `with` without the
    block syntax, as the thesis' `with failure_handling:` would otherwise fail obscurely)."""

    _block_form_name = "failure_handling"
    __name__ = __qualname__ = "failure_handling"

    def __call__(self, body: Branch | int | None = None, max_retries: int = -1, name: str | None = None) -> Any:
        """Run `body`; each `retry()` inside it restarts it (thesis 3.2.3).

        `max_retries` limits the restarts (the body then runs at most `max_retries + 1` times);
        once it is reached, `retry()` does nothing and returns. Negative means unlimited. Each
        run is a task "attempt N" under a "failure_handling" task (`task.info["attempts"]`;
        inside the body `current_attempt()`). Returns the body's result; other exceptions of
        the body propagate. Implemented as a loop: 10,000 retries do not grow the stack. An
        evaporating body is never restarted.

        `failure_handling(5)` / `failure_handling()` without a callable are the heads of the
        block form `with failure_handling(5):`, which needs the block syntax.
        """
        if body is None or not callable(body):
            return _failure_handling_block(body if isinstance(body, int) else None)
        return _run_failure_handling(body, max_retries, name)

    def __repr__(self) -> str:
        return "<pycram expression failure_handling>"


failure_handling = _FailureHandling()
failure_handling.__doc__ = _FailureHandling.__call__.__doc__


def _innermost_handler() -> tuple[Task, _FailureHandler] | None:
    task: Task | None = current_task()
    while task is not None:
        handler = task.info.get("retry_handler") if task.info else None
        if handler is not None:
            return task, handler
        task = task.parent
    return None


def retry() -> None:
    """Restart the body of the innermost enclosing `failure_handling`.

    Returns without doing anything once that failure_handling's `max_retries` is reached.
    Raises `Evaporated` if the task is evaporating (an evaporating body is never restarted) and
    `RuntimeError` outside any failure_handling.
    """
    check_evaporation()
    found = _innermost_handler()
    if found is None:
        raise RuntimeError("retry() was called outside any failure_handling body")
    _, handler = found
    if 0 <= handler.max_retries <= handler.retries:
        return
    handler.retries += 1
    raise RetryRequested(handler)


def current_attempt() -> int:
    """The attempt number (1, 2, ...) of the innermost enclosing failure_handling body."""
    found = _innermost_handler()
    if found is None:
        raise RuntimeError("current_attempt() was called outside any failure_handling body")
    return found[1].retries + 1


def __getattr__(name: str) -> Any:
    if name == "plan":  # the block-syntax decorator lives with the transformer
        from pycram.macros import plan

        return plan
    raise AttributeError(f"module 'pycram.language' has no attribute {name!r}")


# -- expressions built on the ones above (imported last: they import this module) ------------------

from pycram.partial_order import partial_order  # noqa: E402
from pycram.policy import (Policy, PolicyConditionMet, PolicyInitFailed, PolicyRun, define_policy,  # noqa: E402
                           timeout_policy, with_policy)
