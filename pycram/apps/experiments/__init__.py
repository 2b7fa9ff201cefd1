"""Experiments: many headless scenario runs across robots, seeds and faults, in parallel.

`pycram experiment --scenario thesis --robot pr2,tiago --seeds 1-200` runs a scenario for every
robot, seed and variant (fault set) in worker processes on this machine, or with `--ray` on a
Ray cluster, records every run in the trace database and reports success rates, failure
causes and times (see `docs/experiments.md`).

- `pycram.apps.experiments.scenarios`: the scenario registry (`thesis`, `set-table`, import paths).
- `pycram.apps.experiments.runner`: checking the input, running locally or on Ray, resuming.
- `pycram.apps.experiments.store`: the experiment's rows in the trace database.
- `pycram.apps.experiments.report`: the summary table and the plot.
- `pycram.apps.experiments.splits`: development and evaluation seeds and worlds (which a figure may rest on).

`import pycram.apps.experiments` is cheap: the submodules are imported when used.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "register_scenario",
    "scenario_names",
    "get_scenario",
    "prepare_experiment",
    "run_experiment",
]

_LAZY = {
    "register_scenario": "pycram.apps.experiments.scenarios",
    "scenario_names": "pycram.apps.experiments.scenarios",
    "get_scenario": "pycram.apps.experiments.scenarios",
    "prepare_experiment": "pycram.apps.experiments.runner",
    "run_experiment": "pycram.apps.experiments.runner",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'pycram.apps.experiments' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_LAZY))
