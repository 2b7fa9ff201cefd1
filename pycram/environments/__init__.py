"""Environments, one module each (`pycram.environments.<module>.ENVIRONMENT`), looked up by name.

    from pycram.environments import load
    kitchen = load("thesis-kitchen")
    kitchen.surface("cooker #1").height   # 0.9

Importing this package is cheap: an environment's module is imported by `load`. Other modules
read an environment through its `Environment` description, never through its module's constants.
A new environment is its module plus one line in `_MODULES`.

May import: :mod:`pycram.world` (the `Environment` description) and the standard library.
"""

from __future__ import annotations

import importlib

from pycram.world.environment import Environment
from pycram.world.errors import UnknownNameError

__all__ = ["ENVIRONMENT_NAMES", "DEFAULT_ENVIRONMENT", "load"]

#: Environment name -> module under `pycram.environments`.
_MODULES = {"thesis-kitchen": "thesis_kitchen", "apartment": "apartment"}
#: The names `load` accepts.
ENVIRONMENT_NAMES = tuple(_MODULES)
#: The environment a `World` gets when none is named (the thesis demo's kitchen).
DEFAULT_ENVIRONMENT = "thesis-kitchen"


def load(name: str | Environment) -> Environment:
    """The environment called `name` (an `Environment` is returned as it is).

    Raises `UnknownNameError` (a `KeyError`) listing the valid names for an unknown one.
    """
    if isinstance(name, Environment):
        return name
    if name not in _MODULES:
        raise UnknownNameError("environment", name, ENVIRONMENT_NAMES)
    return importlib.import_module(f"pycram.environments.{_MODULES[name]}").ENVIRONMENT
