"""Property test (issue 18): the random-plan generator of `test_language_properties`, extended
with CRAM's new expressions — `partial_order`, `par_loop`, `try_each_in_order`, `with_policy`
(timeout policy) — while a controller thread suspends and wakes random tasks of the running
plan at random moments.

Rules checked on top of those of `test_language_properties` (which are re-used: a
`partial_order` / `par_loop` invocation obeys every rule of `par`, `try_each_in_order` those
of `try_in_order`):

* no hang: the plan ends within the time-out although tasks were suspended meanwhile;
* no orphan: no task is left unfinished (or SUSPENDED), no worker thread stays busy;
* statuses consistent: every task's status history is CREATED? RUNNING (SUSPENDED RUNNING)*
  followed by exactly one final status — SUSPENDED is always left through RUNNING, nothing
  follows a final status;
* ordering: a `partial_order` step starts its body only after the steps ordered before it
  ended;
* task variables: a leaf reads the value bound by its innermost enclosing `bound` block (in
  whatever thread it runs);
* tags: the task that ran a tagged body is tagged with that name;
* a `with_policy` raised `PolicyConditionMet` only when its body task was EVAPORATED (a body
  that ended by itself in a tie with the check wins).

Kept in its own file so that it can evolve with `test_language_properties` (which it imports).
"""

from __future__ import annotations

import random
import threading
import time
from typing import Any

import pytest
import test_language_properties as base
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pycram.core.runtime.workers import shutdown_idle_workers
from pycram.fluent import Fluent
from pycram.language import (
    PolicyConditionMet,
    TaskVariable,
    par_loop,
    partial_order,
    suspend,
    tag,
    timeout_policy,
    try_each_in_order,
    wake_up,
    with_policy,
    with_tags,
)
from pycram.runtime import Task, TaskStatus, add_task_listener, current_task, remove_task_listener

S, F, E, R, P = (
    TaskStatus.SUCCEEDED,
    TaskStatus.FAILED,
    TaskStatus.EVAPORATED,
    TaskStatus.RUNNING,
    TaskStatus.SUSPENDED,
)
EXAMPLES = 120
VARIABLE = TaskVariable("property-test variable", default=None)


# -- plan descriptions ------------------------------------------------------------------------------
# ("partial_order", children, orderings, raise_on_fail)   orderings: (i, j) with i < j (acyclic)
# ("par_loop", children, raise_on_fail)   ("try_each", children, raise_on_fail)
# ("policy", ms, child)   ("bind", value, child): TaskVariable bound around child
# ("tagged", name, child): tag(name, child)    ("var",): a leaf recording the variable's value


@st.composite
def plans(draw: Any, depth: int = 0, must_end: bool = True, in_fh: bool = False) -> tuple:
    if depth >= base.MAX_DEPTH or (depth > 0 and draw(st.integers(0, 9)) < 2 * depth):
        return ("var",) if draw(st.integers(0, 5)) == 0 else draw(base.leaves(must_end, in_fh))
    kind = draw(
        st.sampled_from(
            [
                "seq",
                "par",
                "pursue",
                "fh",
                "timeout",
                "partial_order",
                "par_loop",
                "try_each",
                "policy",
                "bind",
                "tagged",
            ]
        )
    )
    if kind == "bind":
        return (kind, draw(st.integers(0, 99)), draw(plans(depth + 1, must_end, in_fh)))
    if kind == "tagged":
        return (kind, draw(st.sampled_from(["a", "b", "c"])), draw(plans(depth + 1, must_end, in_fh)))
    if kind == "fh":
        return ("fh", draw(st.integers(0, 3)), draw(plans(depth + 1, must_end, True)))
    if kind in ("timeout", "policy"):
        return (kind, draw(st.integers(1, 30)), draw(plans(depth + 1, False, in_fh)))
    n = draw(st.integers(1, 4))
    if kind == "pursue":
        ender = draw(st.integers(0, n - 1)) if must_end else -1
        children = [draw(plans(depth + 1, must_end and i == ender, in_fh)) for i in range(n)]
    else:
        children = [draw(plans(depth + 1, must_end, in_fh)) for _ in range(n)]
    if kind == "partial_order":
        pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
        orderings = draw(st.lists(st.sampled_from(pairs), unique=True)) if pairs else []
        return (kind, tuple(children), tuple(orderings), draw(st.booleans()))
    return (kind, tuple(children), draw(st.booleans()))


class Plan(base.Plan):
    def __init__(self, spec: tuple) -> None:
        self.order_checks: list[tuple[dict, tuple]] = []
        self.policies: list[dict] = []
        self.bindings: list[Any] = [None]  # innermost binding while building (None: the default)
        self.var_reads: list[tuple[Any, Any]] = []  # (expected, read) of every "var" leaf
        self.tagged: list[tuple[str, list]] = []
        super().__init__(spec)

    def build(self, spec: tuple) -> Any:
        kind = spec[0]
        if kind == "var":
            expected = self.bindings[-1]

            def read_var() -> None:
                self.var_reads.append((expected, VARIABLE.get()))

            return read_var
        if kind == "bind":
            self.bindings.append(spec[1])
            child = self.build(spec[2])
            self.bindings.pop()

            def bind() -> None:
                with VARIABLE.bound(spec[1]):
                    child()

            return bind
        if kind == "tagged":
            child = self.build(spec[2])
            ran: list = []
            self.tagged.append((spec[1], ran))

            def tagged_child() -> None:
                ran.append(current_task())
                child()

            return tag(spec[1], tagged_child)
        if kind == "partial_order":
            return self.partial_order([self.build(c) for c in spec[1]], spec[2], spec[3])
        if kind in ("par_loop", "try_each"):
            return self.loop(kind, [self.build(c) for c in spec[1]], spec[2])
        if kind == "policy":
            return self.policy(spec[1], self.build(spec[2]))
        return super().build(spec)

    def _invoke(self, kind: str, n: int, run: Any, raise_on_fail: bool) -> None:
        parent = current_task()
        inv = base.Invocation(kind, n, parent, len(parent.children), state=Fluent())
        self.invocations.append(inv)
        try:
            run(inv)
        except BaseException as exc:
            inv.raised = exc
            raise
        inv.returned = True
        if raise_on_fail and inv.state.get_value() is base.State.FAILED:
            raise base.NodeFailed(kind)

    def partial_order(self, fns: list, orderings: tuple, raise_on_fail: bool) -> Any:
        def run_partial_order() -> None:
            times: dict = {}

            def timed(i: int, fn: Any) -> Any:
                def step() -> None:
                    times[("start", i)] = time.perf_counter()
                    try:
                        fn()
                    finally:
                        times[("end", i)] = time.perf_counter()

                return step

            self.order_checks.append((times, orderings))
            steps = [timed(i, fn) for i, fn in enumerate(fns)]
            self._invoke(
                "par",
                len(fns),
                lambda inv: partial_order(
                    steps, [(a + 1, b + 1) for a, b in orderings], errors=inv.errors, state=inv.state
                ),
                raise_on_fail,
            )

        return run_partial_order

    def loop(self, kind: str, fns: list, raise_on_fail: bool) -> Any:
        form, as_kind = (par_loop, "par") if kind == "par_loop" else (try_each_in_order, "try_in_order")

        def run_loop() -> None:
            self._invoke(
                as_kind,
                len(fns),
                lambda inv: form(fns, lambda fn: fn(), errors=inv.errors, state=inv.state),
                raise_on_fail,
            )

        return run_loop

    def policy(self, ms: int, fn: Any) -> Any:
        def run_policy() -> None:
            record: dict = {"parent": current_task()}
            record["before"] = len(record["parent"].children)
            self.policies.append(record)
            try:
                record["result"] = with_policy(timeout_policy, fn, ms / 1000)
            except BaseException as exc:
                record["raised"] = exc
                if isinstance(exc, PolicyConditionMet):
                    return
                raise

        return run_policy


class StatusHistory:
    """Task listener recording every status each task goes through (via `on_change`)."""

    def __init__(self) -> None:
        self.histories: dict[int, tuple[Task, list]] = {}
        self.lock = threading.Lock()

    def task_started(self, task: Task) -> None:
        history = [task.status.get_value()]
        with self.lock:
            self.histories[id(task)] = (task, history)
        task.status.on_change(history.append)

    def task_ended(self, task: Task) -> None:
        pass

    def problems(self) -> list[str]:
        out = []
        for task, history in list(self.histories.values()):
            states = [s for s in history if s is not TaskStatus.CREATED]
            finals = [i for i, s in enumerate(states) if s.done]
            if len(finals) != 1 or finals[0] != len(states) - 1:
                out.append(f"{task.path}: status history {[s.name for s in history]}")
                continue
            for before, after in zip(states, states[1:], strict=False):
                if before is P and after is not R:
                    names = [s.name for s in history]
                    out.append(f"{task.path}: SUSPENDED left to {after.name}, not RUNNING ({names})")
        return out


def controller(root_box: dict, actions: list, stop: threading.Event, log: list) -> None:
    """Suspend random unfinished tasks of the plan and wake them up again, at random moments."""
    for delay_ms, hold_ms, sync, pick in actions:
        if stop.wait(delay_ms / 1000):
            return
        root = root_box.get("root")
        candidates = [t for t in root.walk() if t is not root and not t.done] if root is not None else []
        if not candidates:
            continue
        target = candidates[pick % len(candidates)]
        try:
            if sync:
                try:
                    suspend(target, sync=True, timeout=1.0)  # a busy leaf may not block in time
                except TimeoutError:
                    pass
            else:
                suspend(target, sync=False)
            log.append(target)
            stop.wait(hold_ms / 1000)
        finally:
            wake_up(target)


def run_plan(spec: tuple, actions: list) -> list[str]:
    plan = Plan(spec)
    result: dict[str, Any] = {}
    history = StatusHistory()
    stop = threading.Event()
    suspended: list = []

    def main() -> None:
        result["root"] = current_task()
        try:
            with with_tags() as tags:
                result["tags"] = tags
                plan.fn()
        except BaseException as exc:
            result["raised"] = exc

    add_task_listener(history)
    try:
        thread = threading.Thread(target=main, name="plan-under-test", daemon=True)
        thread.start()
        chaos = threading.Thread(target=controller, args=(result, actions, stop, suspended), daemon=True)
        chaos.start()
        thread.join(base.PLAN_TIMEOUT + 5.0)
        stop.set()
        chaos.join(5.0)
    finally:
        remove_task_listener(history)
    problems: list[str] = []
    if thread.is_alive():
        return [f"plan did not end within {base.PLAN_TIMEOUT + 5.0} s (suspended: {[t.path for t in suspended]})"]
    root = result["root"]
    raised = result.get("raised")
    if raised is not None and not isinstance(raised, (base.Boom, base.NodeFailed, base.RetryRequested, RuntimeError)):
        problems.append(f"plan raised {raised!r}")
    base.check_tree(root, problems)
    for inv in plan.invocations:
        base.check_invocation(inv, problems)
    base.check_leaves(plan, problems)
    problems += history.problems()
    for expected, read in plan.var_reads:
        if expected != read:
            problems.append(f"task variable: a leaf read {read!r}, the innermost binding is {expected!r}")
    for name, ran in plan.tagged:
        for task in ran:  # the tagged task is the one that ran the child, or its parent
            if task.info.get("tag") != name:
                problems.append(f"tag {name!r}: {task.path} ran the tagged body but is not tagged")
    for times, orderings in plan.order_checks:
        for a, b in orderings:
            if ("start", b) in times and not (("end", a) in times and times[("end", a)] <= times[("start", b)]):
                problems.append(f"partial_order: step {b + 1} started before step {a + 1} ended")
    for record in plan.policies:
        children = record["parent"].children
        policy_task = children[record["before"]] if len(children) > record["before"] else None
        if isinstance(record.get("raised"), PolicyConditionMet) and policy_task is not None:
            bodies = [t for t in policy_task.children if not t.name.startswith("policy ")]
            if [t.status.get_value() for t in bodies] != [E]:
                problems.append(f"{policy_task.path}: condition met but body {[t.status.get_value() for t in bodies]}")
    busy = base._wait_no_busy_workers()
    if busy:
        problems.append(f"{busy} worker threads still busy after the plan returned")
    if problems:
        from pycram.runtime import format_task_tree

        problems.append("tree:\n" + format_task_tree(root))
    return problems


actions_strategy = st.lists(
    st.tuples(st.integers(0, 15), st.integers(0, 10), st.booleans(), st.integers(0, 1000)), max_size=4
)

_examples_run = [0]


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=plans(), actions=actions_strategy)
def check_random_plan_with_suspensions(spec: tuple, actions: list) -> None:
    _examples_run[0] += 1
    problems = run_plan(spec, actions)
    assert not problems, "\n".join(problems)
    shutdown_idle_workers()
    left = base._leftover_pycram_threads()
    assert not left, f"pycram worker threads left after shutdown_idle_workers(): {left}"


@pytest.mark.timeout(300)
def test_random_plans_with_new_expressions_and_suspensions_obey_the_rules() -> None:
    _examples_run[0] = 0
    check_random_plan_with_suspensions()
    assert _examples_run[0] >= EXAMPLES, f"only {_examples_run[0]} random plans ran"


def test_status_history_rule_catches_a_bad_history() -> None:
    """The history rule can fail: a task that went SUSPENDED -> SUCCEEDED is reported."""
    history = StatusHistory()
    task = Task("fake")
    history.histories[id(task)] = (task, [R, P, S])
    assert history.problems() and "SUSPENDED left to SUCCEEDED" in history.problems()[0]
    random.seed(0)
