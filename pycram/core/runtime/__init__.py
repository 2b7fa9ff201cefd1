"""The task runtime: tasks, the task tree, evaporation and clocks (standard library only).

Naming rules, as in trio: `wait_*` and `sleep` block (and are evaporable); `current_*` read the
state of the calling thread; `check_evaporation` raises, `is_evaporating` only tells.
"""

from pycram.core.runtime.clock import Clock, ManualClock, WallClock, current_clock, set_clock, use_clock
from pycram.core.runtime.evaporation import (
    Evaporated,
    check_evaporation,
    is_evaporating,
    no_evaporation,
    sleep,
    wait_until,
)
from pycram.core.runtime.task import (
    Task,
    TaskGroup,
    TaskListener,
    TaskStatus,
    add_task_listener,
    as_task,
    current_task,
    end_thread_root,
    format_task_tree,
    remove_task_listener,
    run_subtask,
    task_scope,
)

__all__ = [
    "Clock",
    "ManualClock",
    "WallClock",
    "current_clock",
    "set_clock",
    "use_clock",
    "Evaporated",
    "check_evaporation",
    "is_evaporating",
    "no_evaporation",
    "sleep",
    "wait_until",
    "Task",
    "TaskGroup",
    "TaskListener",
    "TaskStatus",
    "add_task_listener",
    "as_task",
    "current_task",
    "end_thread_root",
    "format_task_tree",
    "remove_task_listener",
    "run_subtask",
    "task_scope",
]
