"""Collapsing repeated siblings for display: a `whenever` loop that moved the head every 0.2 s
leaves thousands of identical sibling tasks; `show`, the SVG and the timeline draw them as one
node "✔ head: pointing_head ×83".

Only the displays collapse; the stored trace keeps every task.

Guarantees
----------
- `collapse(roots)` returns `DisplayNode`s in the original order. A display node stands for
  one task, or for a run of at least `min_run` *consecutive* siblings that are identical:
  same name, kind and status, status "succeeded", and identical subtrees (names, kinds,
  statuses, error types). Failed, evaporated and unfinished tasks are never merged.
- The children of a merged node merge the members' children position by position (they have
  the same shape), so nothing is dropped: every task record appears in exactly one display
  node's `records`.
- Iterative (no recursion limit), linear in the number of tasks.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

from pycram.trace.query import TaskNode, TaskRecord

__all__ = ["DisplayNode", "collapse", "MIN_RUN"]

#: Shortest run of identical successful siblings that is collapsed.
MIN_RUN = 3


@dataclass
class DisplayNode:
    """One node of a display: `records` are the tasks it stands for (one, or a run of
    identical siblings -- possibly from several collapsed parents), in time order."""

    records: list[TaskRecord]
    children: list[DisplayNode] = field(default_factory=list)

    @property
    def record(self) -> TaskRecord:
        """The first task (name, kind and status are those of every member)."""
        return self.records[0]

    @property
    def count(self) -> int:
        return len(self.records)

    @property
    def total_duration(self) -> float | None:
        """Sum of the members' durations [s] (None if none is known)."""
        known = [r.duration for r in self.records if r.duration is not None]
        return sum(known) if known else None

    @property
    def duration_range(self) -> tuple[float, float] | None:
        """(shortest, longest) member duration [s], None if none is known."""
        known = [r.duration for r in self.records if r.duration is not None]
        return (min(known), max(known)) if known else None

    def walk(self) -> Iterator[tuple[DisplayNode, int]]:
        """(node, depth) for this node and its descendants, depth first, in order."""
        stack: list[tuple[DisplayNode, int]] = [(self, 0)]
        while stack:
            node, depth = stack.pop()
            yield node, depth
            stack.extend((child, depth + 1) for child in reversed(node.children))


def _signatures(roots: Sequence[TaskNode]) -> dict[int, int]:
    """id(TaskNode) -> an integer that is equal for nodes with identical subtrees."""
    table: dict[tuple, int] = {}
    sig: dict[int, int] = {}
    stack: list[tuple[TaskNode, bool]] = [(root, False) for root in reversed(roots)]
    while stack:
        node, expanded = stack.pop()
        if not expanded:
            stack.append((node, True))
            stack.extend((child, False) for child in node.children)
            continue
        r = node.record
        key = (r.name, r.kind, r.status, r.error_type, tuple(sig[id(c)] for c in node.children))
        sig[id(node)] = table.setdefault(key, len(table))
    return sig


def _mergeable(node: TaskNode) -> bool:
    return node.record.status == "succeeded" and node.record.kind != "root"


def collapse(roots: Sequence[TaskNode], min_run: int = MIN_RUN) -> list[DisplayNode]:
    """Display nodes for the task trees `roots` (see the module guarantees). `min_run` <= 1
    disables collapsing (one display node per task)."""
    sig = _signatures(roots)
    out: list[DisplayNode] = []
    # work items: (bundle of identical TaskNodes, list to append the display node to)
    work: list[tuple[list[TaskNode], list[DisplayNode]]] = [([root], out) for root in reversed(roots)]
    # roots are never merged (one per thread); children are grouped below
    while work:
        bundle, target = work.pop()
        display = DisplayNode([node.record for node in bundle])
        target.append(display)
        width = len(bundle[0].children)
        groups: list[list[TaskNode]] = []
        j = 0
        while j < width:
            first = bundle[0].children[j]
            k = j + 1
            if min_run > 1 and _mergeable(first):
                while k < width and sig[id(bundle[0].children[k])] == sig[id(first)]:
                    k += 1
            if k - j < min_run:
                k = j + 1
            # members of the bundle have identical subtrees: position j..k-1 matches in each
            groups.append([member.children[i] for member in bundle for i in range(j, k)])
            j = k
        for group in reversed(groups):
            group.sort(key=lambda n: (n.record.start is None, n.record.start or 0.0, n.record.task_id))
            work.append((group, display.children))
    # work is LIFO: children were pushed reversed, so each list is filled in order
    return out
