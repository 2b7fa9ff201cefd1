"""PyCRAM: concurrent, reactive plans for mobile manipulation robots.

`import pycram` is fast and has no side effects: names are loaded on first use.
The layers: `pycram.fluent` (observable values), `pycram.runtime` (tasks, evaporation,
clocks), `pycram.language` (seq, par, pursue, try_all, try_in_order, failure_handling),
`pycram.designator` and `pycram.process_module` (symbolic descriptions and the hardware
abstraction), `pycram.sim` (the MuJoCo kitchen), `pycram.trace` (run recording).
"""

from typing import Any

from pycram._version import __version__ as __version__

_LAZY = {
    "perform": "pycram.execution.perform",
    "sleep": "pycram.core.runtime",
    "current_task": "pycram.core.runtime",
    "Evaporated": "pycram.core.runtime",
    "Fluent": "pycram.core.fluent",
    "State": "pycram.core.expressions",
}


def __getattr__(name: str) -> Any:  # lazy exports keep `import pycram` cheap
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'pycram' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_LAZY))
