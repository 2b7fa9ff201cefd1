"""Policies: named monitors around a plan (CRAM's `define-policy` / `with-policy`).

A policy has up to four phases, each called with a `PolicyRun` (`run.vars`, a dict for
values shared between the phases, CRAM's `policy-setf` / `policy-get`) and the parameters
given to `with_policy`::

    too_hot = define_policy(
        "too-hot",
        init=lambda run, limit: run.vars.setdefault("limit", limit) is not None,
        check=lambda run, limit: temperature > limit,   # a Fluent network: waited on
        recover=lambda run, limit: log.warning("cooling down"),
        clean_up=lambda run, limit: fan.stop(),
    )
    result = with_policy(too_hot, grasp_cup, 60.0)

`with_policy(policy, body, *params)`:

1. `init` runs first; if it returns a falsy value, `PolicyInitFailed` is raised and nothing
   else runs (clean-up neither).
2. `body` and the check run concurrently, as the two branches of a `pursue`. The check is
   called in a loop until it returns a truthy value. It must *wait* between answers — block
   on a fluent, `sleep`, ... — or return a `Fluent`, which is then waited for (condition met
   once it is not None). Nothing polls.
3. If the condition is met first, `body` is evaporated (its clean-up runs, its branches end),
   then `recover` runs, and `PolicyConditionMet` is raised. If `body` ends by itself — first,
   or in a tie with the check, before its evaporation reached it — the check is evaporated
   and `with_policy` returns body's result or raises body's exception.
4. `clean_up` runs in every case once init succeeded (in a `finally`).

`timeout_policy` (parameter: seconds [s] of the active clock) is built with it. Block form
(with the block syntax): `with with_policy(timeout_policy, 5.0): ...` runs the block as body.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pycram.core.expressions import State, pursue
from pycram.core.fluent import Fluent
from pycram.core.runtime import TaskStatus, current_task, sleep

__all__ = [
    "Policy",
    "PolicyRun",
    "PolicyConditionMet",
    "PolicyInitFailed",
    "define_policy",
    "with_policy",
    "timeout_policy",
]

Phase = Callable[..., Any]


class PolicyConditionMet(Exception):
    """A policy's check reported its condition (CRAM's `policy-check-condition-met`)."""

    def __init__(self, policy: Policy, params: tuple) -> None:
        super().__init__(f"policy {policy.name!r} condition met (parameters {params!r})")
        self.policy = policy
        self.params = params


class PolicyInitFailed(Exception):
    """A policy's init phase returned a falsy value (CRAM's `policy-init-failed`)."""

    def __init__(self, policy: Policy, params: tuple) -> None:
        super().__init__(f"policy {policy.name!r} could not be initialised (parameters {params!r})")
        self.policy = policy
        self.params = params


class PolicyRun:
    """One use of a policy: `policy`, `params`, and `vars` shared by its phases."""

    __slots__ = ("policy", "params", "vars")

    def __init__(self, policy: Policy, params: tuple) -> None:
        self.policy = policy
        self.params = params
        self.vars: dict[str, Any] = {}


class Policy:
    """A named monitor (see the module doc); made by `define_policy`."""

    __slots__ = ("name", "check", "init", "recover", "clean_up", "description")

    def __init__(
        self,
        name: str,
        check: Phase,
        init: Phase | None = None,
        recover: Phase | None = None,
        clean_up: Phase | None = None,
        description: str = "",
    ) -> None:
        for phase, fn in (("check", check), ("init", init), ("recover", recover), ("clean_up", clean_up)):
            if fn is not None and not callable(fn):
                raise TypeError(f"policy {name!r}: {phase} must be callable, got {type(fn).__name__}: {fn!r}")
        self.name = name
        self.check = check
        self.init = init
        self.recover = recover
        self.clean_up = clean_up
        self.description = description

    def __call__(self, body: Callable[[], Any], *params: Any) -> Any:
        """`policy(body, *params)` is `with_policy(policy, body, *params)`."""
        return with_policy(self, body, *params)

    def __repr__(self) -> str:
        return f"<Policy {self.name}>"


def define_policy(
    name: str,
    *,
    check: Phase,
    init: Phase | None = None,
    recover: Phase | None = None,
    clean_up: Phase | None = None,
    description: str = "",
) -> Policy:
    """A `Policy` with the given phases (see the module doc for when each runs)."""
    if not isinstance(name, str) or not name:
        raise TypeError(f"define_policy(): name must be a non-empty string, got {name!r}")
    return Policy(name, check, init, recover, clean_up, description)


_MET = object()


def with_policy(policy: Policy, body: Callable[[], Any], *params: Any) -> Any:
    """Run `body` under `policy` with `params` (see the module doc). Returns body's result;
    raises `PolicyConditionMet`, `PolicyInitFailed` or body's exception."""
    if not isinstance(policy, Policy):
        raise TypeError(f"with_policy() needs a Policy (from define_policy), got {type(policy).__name__}: {policy!r}")
    if not callable(body):
        raise TypeError(
            f"with_policy({policy.name!r}): body must be a callable taking no arguments, got {body!r}; "
            f"the block form `with with_policy(policy, *params):` needs the block syntax (`@plan`, "
            f"`pycram run FILE.py` or `import pycram.activate`)"
        )
    run = PolicyRun(policy, params)
    if policy.init is not None and not policy.init(run, *params):
        raise PolicyInitFailed(policy, params)
    try:

        def monitor() -> object:
            while True:
                answer = policy.check(run, *params)
                if isinstance(answer, Fluent):
                    answer.wait_for()
                    return _MET
                if answer:
                    return _MET

        monitor.__pycram_name__ = f"policy {policy.name}"  # type: ignore[attr-defined]
        body_branch = body
        if getattr(body, "__name__", "<lambda>") == "<lambda>" and not getattr(body, "__pycram_name__", None):

            def body_branch() -> Any:
                return body()

            body_branch.__pycram_name__ = "body"  # type: ignore[attr-defined]
        errors: list = []
        state = pursue(monitor, body_branch, errors=errors, name=f"with_policy {policy.name}")
        body_task = current_task().children[-1].children[1]  # the pursue's second branch
        body_status = body_task.status.get_value()
        if body_status is TaskStatus.SUCCEEDED:  # the body ended by itself (maybe in a tie): its result
            return body_task.result
        if body_status is TaskStatus.FAILED:
            raise body_task.exception  # type: ignore[misc]
        if state.get_value() is State.FAILED:  # the check raised
            raise errors[0]
        if policy.recover is not None:
            policy.recover(run, *params)
        raise PolicyConditionMet(policy, params)
    finally:
        if policy.clean_up is not None:
            policy.clean_up(run, *params)


def _timeout_check(run: PolicyRun, seconds: float) -> bool:
    sleep(seconds)
    return True


timeout_policy = define_policy(
    "timeout",
    check=_timeout_check,
    description="Evaporate the body when it has not ended after `seconds` [s] of the active clock.",
)
"""CRAM's timeout policy: `with_policy(timeout_policy, body, seconds)` raises
`PolicyConditionMet` (after evaporating body) when body has not ended after `seconds` [s]."""
