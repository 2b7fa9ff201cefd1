"""``perform(designator)``: the one entry point from plans to the robot."""

from __future__ import annotations

import logging
from typing import Any

from pycram.core import events
from pycram.designators.action import ActionDesignator
from pycram.designators.core import UnknownKindError
from pycram.designators.motion import MotionDesignator

__all__ = ["perform"]

logger = logging.getLogger("pycram.designator")


def perform(designator: Any) -> Any:
    """Perform ``designator`` and return its result.

    - :class:`MotionDesignator`: executed by a process module chosen by the process-module
      resolvers of the active robot (then the global ``ProcessModule.resolvers``); see
      :meth:`pycram.process_module.ProcessModule.perform` (blocks until done, unless the
      designator says ``('wait', False)``: then an execution handle is returned).
    - :class:`ActionDesignator`: resolved to a plan, which runs as a child task named
      ``perform <type>`` of the current task; its result is returned and its exception re-raised
      unchanged (so failure handling in the caller sees the plan's own errors).
    - anything else: :class:`UnknownKindError`.

    Every performed designator is announced on :mod:`pycram.core.events` (``DESIGNATOR_PERFORMED``,
    with its solution -- the plan for an action -- and the exception, if any).

    Evaporable: evaporating the calling task stops the motion or plan (see process modules).
    """
    if isinstance(designator, MotionDesignator):
        from pycram.execution.process_module import ProcessModule

        return ProcessModule.perform(designator)
    if isinstance(designator, ActionDesignator):
        plan = None
        try:
            plan = designator.reference()
            action_type = designator.prop_value("type")
            name = f"perform {action_type}" if action_type is not None else "perform action"
            logger.debug("performing %r with plan %r", designator, plan)
            from pycram.core.runtime import run_subtask

            result = run_subtask(name, plan, designator, kind="action")
        except BaseException as e:
            events.designator_performed(designator, plan, e)
            raise
        events.designator_performed(designator, plan, None)
        return result
    raise UnknownKindError(
        f"perform() accepts motion and action designators, got {designator!r} ({type(designator).__name__})"
    )
