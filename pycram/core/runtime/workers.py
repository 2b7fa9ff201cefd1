"""A pool of parked worker threads that run the branches of concurrent expressions.

Starting an operating-system thread costs ~100 µs here, which would make `par` of 100 branches
take over 10 ms. Branches therefore run on pooled threads: a finished branch's thread parks
(blocked on a lock, no CPU) and is handed the next branch. Parked workers exit after
`IDLE_SECONDS` without work, and `shutdown_idle_workers()` ends them at once.

The guarantee that matters is unchanged: a branch — its code, its `finally` blocks and its
children — has ended before its expression returns. What may remain afterwards is a parked
worker running no plan code, never a branch.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

__all__ = ["submit", "shutdown_idle_workers", "worker_count", "IDLE_SECONDS"]

IDLE_SECONDS = 10.0
"""A parked worker exits after this many seconds [s] of wall time without work."""

_lock = threading.Lock()
_idle: list[_Worker] = []
_all: set[_Worker] = set()
_names = iter(range(1, 1 << 62))


class _Worker:
    __slots__ = ("thread", "_go", "_job")

    def __init__(self, job: Callable[[], None]) -> None:
        self._go = threading.Lock()
        self._go.acquire()
        self._job: Callable[[], None] | None = job
        self.thread = threading.Thread(target=self._main, name=f"pycram-worker-{next(_names)}", daemon=True)

    def _main(self) -> None:
        try:
            while True:
                job, self._job = self._job, None
                if job is None:
                    return  # told to exit
                job()
                with _lock:
                    _idle.append(self)
                if not self._go.acquire(timeout=IDLE_SECONDS):
                    with _lock:
                        if self in _idle:  # nobody handed us work meanwhile: exit
                            _idle.remove(self)
                            return
                    self._go.acquire()  # work was handed over just now: take it
        finally:
            with _lock:
                _all.discard(self)

    def hand(self, job: Callable[[], None] | None) -> None:
        self._job = job
        self._go.release()


def submit(job: Callable[[], None]) -> None:
    """Run `job()` on a parked worker, or on a new one if none is parked. Never blocks.

    `job` must not raise (the task runtime catches everything in its branch wrapper).
    """
    with _lock:
        worker = _idle.pop() if _idle else None
        if worker is None:
            worker = _Worker(job)
            _all.add(worker)
    if worker.thread.ident is None:
        worker.thread.start()
    else:
        worker.hand(job)


def shutdown_idle_workers(timeout: float = 5.0) -> int:
    """End every parked worker and wait for their threads; returns how many ended.

    Workers that are running a branch are left alone.
    """
    with _lock:
        parked = list(_idle)
        _idle.clear()
    for worker in parked:
        worker.hand(None)
    for worker in parked:
        worker.thread.join(timeout)
    return len(parked)


def worker_count() -> tuple[int, int]:
    """(busy, parked) numbers of worker threads."""
    with _lock:
        return len(_all) - len(_idle), len(_idle)
