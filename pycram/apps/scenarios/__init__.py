"""The scenarios of `pycram demo` and `pycram experiment`, one package per scenario.

Each scenario is split by concept: its data (objects, regions, thresholds), its scene (where the
objects start), its faults (the simulated world misbehaving), its judge (success from the
simulator's truth), its driver (running the plan under time limits) and, for `pycram demo`, its
terminal display; the plan itself is a module of its own that knows nothing of the simulator.

- `pycram.apps.scenarios.set_table`: setting the breakfast table in the apartment (issue 17).
- The household task suite (issue 33), in the apartment and in generated apartments:
  `pycram.apps.scenarios.clear_table` (everything on the table into the drawers and the
  cupboard), `pycram.apps.scenarios.put_away` (groceries into the fridge and the cupboard) and
  `pycram.apps.scenarios.serve` (requested objects to a seat); what they share is in
  `pycram.apps.scenarios.common` (set-table's driver uses its plan thread and time limits too).

`pycram.apps.scenarios.reachability` is a scene-generation filter scenarios and benchmarks share:
where some standing pose of a robot grasps an object, or places one on a target.
"""
