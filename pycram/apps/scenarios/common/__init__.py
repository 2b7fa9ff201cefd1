"""What the scenarios of the household task suite share (issue 33), one module per concept:

- `scene`: start spots anywhere a robot reaches, where object types are put away, the seats;
- `plan`: errands -- bring each object to one of its targets, robot-agnostic (`put_away`, `serve`);
- `faults`: set-table's simulated person and flaky camera for any scene;
- `judge`: success and failure causes from the simulator's truth;
- `driver`: the plan in its thread under time limits, a whole task run (`TaskScenario`);
- `display`: `pycram demo --scenario NAME` in the terminal.

Nothing is imported here: import the module you need (the set-table scenario imports `driver`
and `scene` too).
"""
