"""The serve scenario: bring N requested objects to a seat at the table, next to each other
(issue 33, the household task suite).

The objects asked for (`objects=`, or `COUNT` of `SERVABLE` drawn from the seed) start at spots
drawn uniformly over the kitchen's worktops, kept where some standing pose of the robot grasps
them (the scene generator's `ReachabilityFilter`). The plan (`plan.serve`, the suite's) uses the
action library only: `Transport` to ``('on', 'table'), ('near', point)`` for the first object --
the point `INWARD` (0.2 m) in from the table's edge in front of `SEAT` -- and ``('near', the
object served before)`` for each next one. Judged with the simulator's truth: each object
upright on the table within 0.5 m of that point and within 0.35 m of another served object.
An unknown type, a repeated one or too many raise `ValueError`. Runs in the apartment and in every
generated apartment (``procedural:SEED``).

Modules: `data`, `scene` (`requested`, `start_scene`), `plan`, `driver` (`TASK`, `run_serve`),
`display` (`main`); the judge and the faults are the suite's (`pycram.apps.scenarios.common`).
"""

from pycram.apps.scenarios.serve.data import COUNT, FAULTS, INWARD, SEAT, SERVABLE
from pycram.apps.scenarios.serve.driver import TASK, run_serve
from pycram.apps.scenarios.serve.scene import requested, start_scene

__all__ = ["SERVABLE", "COUNT", "SEAT", "INWARD", "FAULTS", "TASK", "run_serve", "requested", "start_scene"]
