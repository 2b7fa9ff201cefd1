"""The scenario registry: names `pycram experiment --scenario` knows, and the thesis scenario.

A *scenario* is a function that runs one headless episode for a robot and a seed and returns
its result as a JSON-serialisable dict:

    scenario(robot: str, seed: int, faults: frozenset[str] = frozenset(),
             db_url: str | None = None, pictures: bool = False, stepping: str = "lockstep") -> dict

with at least `success` (bool), `failure_causes` (list of failure type names, empty on
success), `sim_time` and `wall_time` [s], `robot`, `seed` and `faults`; optionally `objects`
(per object: `placed`, `failure`, `reason`) and `trace_run_id` (the run's id in the trace
database when the scenario recorded it into `db_url`). A scenario raises `ValueError` for a
robot or fault it does not know, and `RunInterrupted` when a signal stopped it (such a run is
not finished: a resumed experiment runs it again). A scenario that can run in more than one
environment takes an ``environment`` keyword too (an environment name, see
`pycram.environments.load`: ``apartment``, ``procedural:SEED``, ``file:PATH``) and puts it into
its result as `environment`; `pycram experiment --env` and `pycram demo --env` pass it.

Scenarios are registered by name, either as a callable or lazily as an import path
`"package.module:function"` that is imported only when the scenario is used (so a scenario
whose module does not exist yet costs nothing until then). `--scenario` also takes such an
import path directly. Worker processes and Ray tasks look the scenario up by its import path
(`Scenario.spec`), never by pickling a closure: a module-level function is found there even
when it was registered only in the driver.
"""

from __future__ import annotations

import importlib
import inspect
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from pycram.core.runtime.lockstep import DEFAULT_STEPPING
from pycram.world.robot_registry import RegisteredRobots

log = logging.getLogger(__name__)

__all__ = [
    "Scenario",
    "ScenarioFunction",
    "UnknownScenario",
    "RunInterrupted",
    "SCENARIOS",
    "ROBOTS",
    "THESIS_FAULTS",
    "register_scenario",
    "scenario_names",
    "get_scenario",
    "demo_scenario_names",
    "thesis_scenario",
    "accepts_keyword",
]

#: The signature of a scenario: `(robot, seed, faults, db_url, pictures) -> result dict`.
ScenarioFunction = Callable[..., dict[str, Any]]

#: The robots every built-in scenario runs on: the registered robots
#: (:func:`pycram.world.robot_registry.robot_names`), read from the registry whenever it is used.
ROBOTS: Sequence[str] = RegisteredRobots()

#: The faults of the thesis scenario: `steal` takes the item from the gripper during transport
#: (once or twice, by the seed); `misplaced` puts the item at position 2 or 3 (by the seed), so
#: that one or two grasps fail before the robot finds it.
THESIS_FAULTS = ("misplaced", "steal")


class UnknownScenario(LookupError):
    """A scenario name that is not registered, or an import path that cannot be imported.

    The message names the registered scenarios.
    """


class RunInterrupted(KeyboardInterrupt):
    """A scenario run was stopped by a signal before it finished: it has no result."""


@dataclass(frozen=True)
class Scenario:
    """A registered scenario: its `name`, the function (`target`: a callable or an import path
    `"module:function"`), the fault names it knows (`faults`, None when it does not say), the
    robots it runs on, and its terminal front end for `pycram demo --scenario NAME` (`demo`: an
    import path of ``main(robot, seed, faults, output, db, record, quiet, animation, stepping) ->
    exit code``; None when `pycram demo` does not run it)."""

    name: str
    target: ScenarioFunction | str
    faults: tuple[str, ...] | None = None
    robots: Sequence[str] = ROBOTS
    description: str = ""
    demo: str | None = None
    #: The environment the scenario is written for (None: it does not say). A scenario whose
    #: function takes an ``environment`` keyword runs in others too (`takes_environment`).
    environment: str | None = None

    def takes_environment(self) -> bool:
        """Whether the scenario's function takes an ``environment`` keyword (an environment
        name: ``apartment``, ``procedural:SEED``, ``file:PATH``), so that `pycram experiment
        --env` can choose where it runs."""
        return accepts_keyword(self.load(), "environment")

    def load(self) -> ScenarioFunction:
        """The scenario's function (importing its module for an import path).

        Raises `UnknownScenario` when the module or the function does not exist.
        """
        if callable(self.target):
            return self.target
        return _import_target(self.target, self.name)

    def load_demo(self) -> Callable[..., Any]:
        """The scenario's terminal front end (see `demo`); `UnknownScenario` when it has none or
        its module or function does not exist."""
        if self.demo is None:
            raise UnknownScenario(f"scenario {self.name!r} has no terminal front end for `pycram demo`")
        return _import_target(self.demo, self.name)

    @property
    def spec(self) -> str:
        """How worker processes and Ray tasks find the scenario: its import path
        (`"module:function"`) when it has one — so that a scenario registered at run time in
        the driver needs no registration in the workers — else its name."""
        if isinstance(self.target, str):
            return self.target
        module = getattr(self.target, "__module__", None)
        qualname = getattr(self.target, "__qualname__", "")
        if module and module != "__main__" and qualname and "<" not in qualname:
            return f"{module}:{qualname}"
        return self.name

    def known_faults(self) -> tuple[str, ...] | None:
        """The fault names the scenario accepts: `faults`, else the `FAULTS` attribute of its
        function or module (read after importing it), else None (unknown: not checked)."""
        if self.faults is not None:
            return self.faults
        function = self.load()
        found = getattr(function, "FAULTS", None)
        if found is None:
            module = importlib.import_module(function.__module__)
            found = getattr(module, "FAULTS", None)
        return tuple(sorted(found)) if found is not None else None


#: The registered scenarios by name (see `register_scenario`).
SCENARIOS: dict[str, Scenario] = {}


def register_scenario(
    name: str,
    target: ScenarioFunction | str,
    *,
    faults: tuple[str, ...] | None = None,
    robots: Sequence[str] = ROBOTS,
    description: str = "",
    demo: str | None = None,
    environment: str | None = None,
) -> Scenario:
    """Register (or replace) the scenario `name`: a callable, or an import path
    `"module:function"` imported when the scenario is first used; `demo`: the import path of its
    terminal front end for `pycram demo --scenario NAME` (see `Scenario`); `environment`: the
    environment it is written for. Returns the entry."""
    if not name or ":" in name:
        raise ValueError(f"a scenario name must be non-empty and contain no ':', not {name!r}")
    if isinstance(target, str) and ":" not in target:
        raise ValueError(f"a scenario's import path reads 'package.module:function', not {target!r}")
    if demo is not None and ":" not in demo:
        raise ValueError(f"a scenario's demo import path reads 'package.module:function', not {demo!r}")
    entry = Scenario(
        name, target, tuple(faults) if faults is not None else None, tuple(robots), description, demo, environment
    )
    SCENARIOS[name] = entry
    return entry


def scenario_names() -> list[str]:
    """The registered scenario names, sorted."""
    return sorted(SCENARIOS)


def demo_scenario_names() -> list[str]:
    """The registered scenarios `pycram demo --scenario` runs (those with a terminal front end),
    in the order they were registered."""
    return [name for name, entry in SCENARIOS.items() if entry.demo is not None]


def get_scenario(spec: str) -> Scenario:
    """The scenario `spec` names: a registered name, or an import path `"module:function"`.

    Raises `UnknownScenario` naming the registered scenarios, also when the registered
    scenario's module cannot be imported (yet).
    """
    spec = spec.strip()
    entry = SCENARIOS.get(spec)
    if entry is None:
        if ":" not in spec:
            raise UnknownScenario(
                f"unknown scenario {spec!r}; available scenarios: {', '.join(scenario_names())} "
                "(or an import path package.module:function)"
            )
        entry = Scenario(spec, spec)
    entry.load()  # fail here, in the driver, rather than in every worker
    return entry


def accepts_keyword(function: Any, name: str) -> bool:
    """Whether `function` takes the keyword argument `name` (or any keyword: ``**kwargs``)."""
    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):
        return False
    return any(p.name == name or p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters)


def _import_target(path: str, name: str) -> ScenarioFunction:
    module_name, _, attribute = path.partition(":")
    available = ", ".join(scenario_names())
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as e:
        if e.name is not None and module_name.startswith(e.name):
            raise UnknownScenario(
                f"scenario {name!r} is not available in this installation: its module {module_name} does not "
                f"exist (yet); available scenarios: {available}"
            ) from None
        raise UnknownScenario(f"scenario {name!r} cannot be imported ({module_name}): {e}") from None
    function: ScenarioFunction | None = getattr(module, attribute, None)
    if not callable(function):
        raise UnknownScenario(
            f"scenario {name!r}: {module_name} has no function {attribute!r}; available scenarios: {available}"
        )
    return function


def _thesis_options(seed: int, faults: frozenset[str]) -> tuple[int, int]:
    """(item_at, steal) of the thesis demo for `seed` and `faults` (see `THESIS_FAULTS`)."""
    item_at = 2 + seed % 2 if "misplaced" in faults else 1
    steal = 1 + (seed // 2) % 2 if "steal" in faults else 0
    return item_at, steal


def thesis_scenario(
    robot: str,
    seed: int,
    faults: frozenset[str] = frozenset(),
    db_url: str | None = None,
    pictures: bool = False,
    stepping: str = DEFAULT_STEPPING,
) -> dict[str, Any]:
    """The thesis demo (fetch and place in the kitchen) as a scenario: headless, no animation,
    pictures only with `pictures` (into `output/demo-ROBOT-RUNID`), simulated with `stepping`.

    `faults` is a subset of `THESIS_FAULTS`; the seed chooses where the misplaced item is and
    how often it is stolen, and drives the thief's timing. The run is recorded into `db_url`
    (None: the default database) unless `$PYCRAM_RECORD` is off. Raises `ValueError` for an
    unknown robot or fault, `RunInterrupted` when a signal stopped the run.
    """
    import os

    from pycram.apps.demos.kitchen import DemoOptions, run_demo
    from pycram.apps.demos.kitchen_world import ITEM_NAME

    if robot not in ROBOTS:
        raise ValueError(f"unknown robot {robot!r}; available robots: {', '.join(ROBOTS)}")
    unknown = sorted(set(faults) - set(THESIS_FAULTS))
    if unknown:
        raise ValueError(
            f"unknown fault(s) {', '.join(unknown)}; the thesis scenario knows: {', '.join(THESIS_FAULTS)}"
        )
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        from pycram.trace.recorder import recording_enabled

        record = recording_enabled(True)
    except ImportError:
        record = False
    item_at, steal = _thesis_options(seed, frozenset(faults))
    started = time.monotonic()
    result = run_demo(
        DemoOptions(
            robot=robot,
            item_at=item_at,
            steal=steal,
            seed=seed,
            db=db_url,
            record=record,
            quiet=True,
            animation=False,
            pictures=pictures,
            stepping=stepping,
        )
    )
    if result.interrupted:
        raise RunInterrupted(result.message)
    success = result.exit_code == 0
    causes = [] if success else [_thesis_cause(result)]
    return {
        "scenario": "thesis",
        "robot": robot,
        "seed": seed,
        "faults": sorted(faults),
        "stepping": stepping,
        "success": success,
        "objects": {
            ITEM_NAME: {
                "placed": result.item_on_cooker_1,
                "failure": causes[0] if causes else None,
                "reason": None if success else result.message,
            }
        },
        "failure_causes": causes,
        "sim_time": result.sim_time,
        "wall_time": time.monotonic() - started,
        "plan_wall_time": result.plan_wall_time,
        "failed_grasps": result.failed_grasps,
        "recoveries": result.recoveries,
        "trace_run_id": result.run_id,
    }


def _thesis_cause(result: Any) -> str:
    """The failure type that ended an unsuccessful thesis run: the plan's error, a time limit
    (`TimeLimitExceeded`), or `ItemNotPlaced` when the plan ended without the item in place."""
    if result.message.startswith("the plan did not end within"):
        return "TimeLimitExceeded"
    task = result.plan_task
    error = getattr(task, "exception", None) if task is not None else None
    if error is not None:
        return type(error).__name__
    return "ItemNotPlaced"


register_scenario(
    "thesis",
    thesis_scenario,
    faults=THESIS_FAULTS,
    description="the thesis demo: fetch the item in the kitchen and place it on cooker #1",
    environment="thesis-kitchen",
)
register_scenario(
    "set-table",
    "pycram.apps.scenarios.set_table:run_set_table",
    demo="pycram.apps.scenarios.set_table.display:main",
    description="set the table for breakfast in the apartment, objects on counters and in a drawer (issue 17)",
    environment="apartment",
)
register_scenario(
    "set-table-open",
    "pycram.apps.scenarios.set_table:run_set_table_on_open_surfaces",
    demo="pycram.apps.scenarios.set_table.display:main_on_open_surfaces",
    description="set the table, every object starting on an open surface (none in a closed drawer)",
    environment="apartment",
)
register_scenario(
    "set-table-anywhere",
    "pycram.apps.scenarios.set_table:run_set_table_anywhere",
    demo="pycram.apps.scenarios.set_table.display:main_anywhere",
    description="set the table, all six breakfast types starting anywhere the robot reaches: whole worktops, "
    "drawers, fridge shelves, cupboard (issue 33)",
    environment="apartment",
)
register_scenario(
    "clear-table",
    "pycram.apps.scenarios.clear_table:run_clear_table",
    demo="pycram.apps.scenarios.clear_table.display:main",
    description="clear the table: a cup and a bowl into a drawer, a plate into the cupboard, all closed (issue 33)",
    environment="apartment",
)
register_scenario(
    "put-away",
    "pycram.apps.scenarios.put_away:run_put_away",
    demo="pycram.apps.scenarios.put_away.display:main",
    description="put the groceries away: milk into the fridge, cereal into the cupboard, doors closed (issue 33)",
    environment="apartment",
)
register_scenario(
    "serve",
    "pycram.apps.scenarios.serve:run_serve",
    demo="pycram.apps.scenarios.serve.display:main",
    description="serve: bring two requested objects to a seat at the table, next to each other (issue 33)",
    environment="apartment",
)
