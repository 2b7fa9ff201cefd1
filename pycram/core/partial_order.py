"""`partial_order`: concurrent steps with "a before b" constraints (CRAM's `partial-order`).

    partial_order({"grasp": grasp, "open": open_gripper, "lift": lift},
                  [("open", "grasp"), ("grasp", "lift")])

The steps run as the branches of one `par`; a step ordered after others starts its body only
when all of them have *ended* (CRAM: `task-dead`). A constraint may also be a `Fluent`
(`(door_open, "enter")`): the step then waits until the fluent is not None. Everything else is
`par`: the first failure evaporates the other steps (waiting ones included), failures go to
`errors`, the state fluent is returned, `state.result` lists every step's value in step order.

Steps are a mapping name → callable, or a sequence of callables named by their number (1, 2,
...) or, if unique, by their tag / `__pycram_name__` / function name. Unknown names and cyclic
orderings raise `ValueError` before anything runs (CRAM would deadlock on a cycle).

Block syntax: `with partial_order([(1, 3), (2, 3)]) as s:` — each statement is a step, named
by its number (1 = first statement).
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Mapping, Sequence
from typing import Any

from pycram.core.expressions import Branch, StateFluent, _BlockUse, par
from pycram.core.fluent import Fluent
from pycram.core.runtime.task import Task, TaskStatus

__all__ = ["partial_order"]


def _step_names(steps: Mapping[Hashable, Branch] | Sequence[Branch]) -> dict[Hashable, int]:
    """key → step index; every step answers to its number, named steps to their name too."""
    if isinstance(steps, Mapping):
        return {key: index for index, key in enumerate(steps)}
    names: dict[Hashable, int] = {index + 1: index for index in range(len(steps))}
    seen: dict[str, int] = {}
    for index, fn in enumerate(steps):
        name = getattr(fn, "__pycram_name__", None) or getattr(fn, "__name__", None)
        if name and name != "<lambda>":
            seen[name] = -1 if name in seen else index
    names.update({name: index for name, index in seen.items() if index >= 0})
    return names


def _cycle(after: list[set[int]], labels: list[str]) -> list[str] | None:
    """A cycle of the ordering graph as step labels, or None."""
    state = [0] * len(after)  # 0 new, 1 on stack, 2 done
    stack: list[int] = []

    def visit(node: int) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for prev in sorted(after[node]):
            if state[prev] == 1:
                cycle = stack[stack.index(prev) :] + [prev]
                return [labels[i] for i in cycle]
            if state[prev] == 0:
                found = visit(prev)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    for node in range(len(after)):
        if state[node] == 0:
            found = visit(node)
            if found:
                return found
    return None


def partial_order(
    steps: Any,
    orderings: Iterable[tuple[Any, Any]] | None = None,
    *,
    errors: list | None = None,
    state: Fluent | None = None,
    name: str | None = None,
) -> Any:
    """Run `steps` concurrently under the `(before, after)` `orderings` (see the module doc).

    Returns the state fluent (as `par`). Raises `TypeError` / `ValueError` naming the step or
    ordering at fault for malformed input (nothing runs then). `partial_order(orderings)` alone
    is the head of the block form and needs the block syntax.
    """
    if orderings is None:
        return _BlockUse("partial_order(orderings) as s")
    label = name or "partial_order"
    fns: list[Branch] = list(steps.values()) if isinstance(steps, Mapping) else list(steps)
    keys = list(steps) if isinstance(steps, Mapping) else None
    for index, fn in enumerate(fns):
        if not callable(fn):
            which = repr(keys[index]) if keys else str(index + 1)
            raise TypeError(
                f"{label}: step {which} must be a callable taking no arguments, got {type(fn).__name__}: {fn!r}"
            )
    names = _step_names(steps)
    after: list[set[int]] = [set() for _ in fns]
    fluents: list[list[Fluent]] = [[] for _ in fns]
    for ordering in orderings:
        if not (isinstance(ordering, (tuple, list)) and len(ordering) == 2):
            raise ValueError(f"{label}: an ordering must be a pair (before, after), got {ordering!r}")
        before, later = ordering
        for key in (later,) if isinstance(before, Fluent) else (before, later):
            if key not in names:
                raise ValueError(f"{label}: ordering {ordering!r} names unknown step {key!r}; steps: {list(names)}")
        if isinstance(before, Fluent):
            fluents[names[later]].append(before)
        else:
            after[names[later]].add(names[before])
    labels = [str(k) for k in keys] if keys else [str(i + 1) for i in range(len(fns))]
    cycle = _cycle(after, labels)
    if cycle:
        raise ValueError(
            f"{label}: the orderings form a cycle {' -> '.join(reversed(cycle))}; no step of it could ever start"
        )
    ended = [Fluent(name=f"{label}: step {labels[i]} ended") for i in range(len(fns))]

    def branch_ended(index: int, task: Task) -> None:
        # runtime bookkeeping (the branch's thread, after its code): no evaporation lands here.
        # Succeeded, or evaporated from outside: the later steps may go. Failed: par evaporates
        # the waiting steps, which must not start meanwhile.
        if task.status.get_value() is not TaskStatus.FAILED:
            ended[index].set_value(True)

    def constrained(index: int) -> Branch:
        fn = fns[index]

        def step() -> Any:
            for prev in sorted(after[index]):
                ended[prev].wait_for()
            for fluent in fluents[index]:
                fluent.wait_for()
            return fn()

        given = getattr(fn, "__pycram_name__", None) or getattr(fn, "__name__", None)
        step.__pycram_name__ = labels[index] if keys or not given or given == "<lambda>" else given  # type: ignore[attr-defined]
        return step

    if state is None:
        state = StateFluent(name=label)
    par._run(
        [constrained(i) for i in range(len(fns))], errors if errors is not None else [], state, label, branch_ended
    )
    return state
