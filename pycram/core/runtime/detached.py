"""What happens to detached children when the code that started them ends.

Detached task groups are started without being waited for (a process-module execution with
`('wait', False)`, `ProcessModule.execute_nowait`). Today's documented rule stays the default:
the branch thread that started them waits for them before it ends (they never outlive it).

`with detached_children("evaporate"):` offers CRAM's rule for a block: when the block ends —
normally, by failure or by evaporation — every detached group started inside it that still
runs is evaporated (its clean-up and cancel hooks run) and waited for. `"wait"` waits for them
at the block's end instead of the thread's::

    with detached_children("evaporate"):
        ProcessModule.perform(look_at_the_table_without_waiting)
        ask_for_help()
    # the head motion has been stopped (if it was still running) when we get here
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from pycram.core.runtime.evaporation import current_runner, shielded, wait_until

__all__ = ["detached_children", "DETACHED_RULES"]

DETACHED_RULES = ("wait", "evaporate")
"""The rules `detached_children` accepts."""


@contextmanager
def detached_children(rule: str = "evaporate") -> Iterator[None]:
    """Apply `rule` ("evaporate" or "wait") to the detached groups started in the block when
    it ends (see the module doc). Returns only after those groups have ended."""
    if rule not in DETACHED_RULES:
        raise ValueError(f"detached_children(): rule must be one of {DETACHED_RULES}, got {rule!r}")
    runner = current_runner()
    before = set(map(id, runner.detached))
    try:
        yield
    finally:
        started = [group for group in runner.detached if id(group) not in before]
        with shielded():
            for group in started:
                if rule == "evaporate":
                    group.evaporate()
                wait_until(group._cv, group._all_ended)
        runner.detached = [group for group in runner.detached if group not in started]
