"""Environments, one module each (`pycram.environments.<module>.ENVIRONMENT`), looked up by name.

    from pycram.environments import load
    kitchen = load("thesis-kitchen")
    kitchen.surface("cooker #1").height   # 0.9
    flat = load("procedural:17")          # a generated apartment (`procedural`), one per seed
    mine = load("file:examples/kitchens/small_kitchen.toml")  # a kitchen from files (`from_file`)

Importing this package is cheap: an environment's module is imported by `load`. Other modules
read an environment through its `Environment` description, never through its module's constants.
A new environment is its module plus one line in `_MODULES`.

Names `load` accepts (`ENVIRONMENT_HELP` says the same for command lines):

- the hand-made environments of `ENVIRONMENT_NAMES` (``apartment``, ``thesis-kitchen``);
- ``procedural:SEED``: the apartment generated from SEED, a non-negative integer
  (`pycram.environments.procedural`; the same seed gives the same apartment);
- ``file:PATH``: the kitchen described by the sidecar file PATH (TOML) and the MJCF or URDF
  model it names (`pycram.environments.from_file`).

May import: :mod:`pycram.world` (the `Environment` description) and the standard library.
"""

from __future__ import annotations

import importlib

from pycram.world.environment import Environment
from pycram.world.errors import UnknownNameError

from .errors import KitchenFileError

__all__ = [
    "ENVIRONMENT_NAMES",
    "DEFAULT_ENVIRONMENT",
    "ENVIRONMENT_HELP",
    "PROCEDURAL_PREFIX",
    "FILE_PREFIX",
    "EnvironmentNameError",
    "KitchenFileError",
    "load",
    "check_name",
    "procedural_seed",
]

#: Environment name -> module under `pycram.environments`.
_MODULES = {"thesis-kitchen": "thesis_kitchen", "apartment": "apartment"}
#: The names of the hand-made environments (`load` also takes ``procedural:SEED`` and ``file:PATH``).
ENVIRONMENT_NAMES = tuple(_MODULES)
#: The environment a `World` gets when none is named (the thesis demo's kitchen).
DEFAULT_ENVIRONMENT = "thesis-kitchen"
#: Names of generated apartments start with this, then the seed: ``procedural:17``.
PROCEDURAL_PREFIX = "procedural:"
#: Names of kitchens from files start with this, then the sidecar's path: ``file:kitchen.toml``.
FILE_PREFIX = "file:"
#: What `load` takes, in one line (for help texts and error messages).
ENVIRONMENT_HELP = (
    f"{', '.join(sorted(ENVIRONMENT_NAMES))}, procedural:SEED (a generated apartment, SEED = 0, 1, 2, ...) "
    "or file:PATH.toml (a kitchen from an MJCF/URDF file and its sidecar)"
)


class EnvironmentNameError(UnknownNameError):
    """An environment name `load` cannot read (a `KeyError`, like every unknown name): the
    message says what is wrong with it and which names are valid."""

    def __init__(self, name: object, problem: str) -> None:
        super().__init__("environment", name, ENVIRONMENT_NAMES)
        self.args = (f"environment {name!r}: {problem}; valid: {ENVIRONMENT_HELP}",)


def check_name(name: str) -> str:
    """`name` stripped, when it is a name `load` reads (a hand-made environment, a well-formed
    ``procedural:SEED``, or ``file:PATH`` of a file that exists); raises `EnvironmentNameError`
    otherwise. Cheap: nothing is generated or loaded."""
    text = str(name).strip()
    if text in _MODULES:
        return text
    if text.startswith(PROCEDURAL_PREFIX):
        from . import procedural

        try:
            procedural.parse_seed(text)
        except ValueError as e:
            raise EnvironmentNameError(text, str(e)) from None
        return text
    if text.startswith(FILE_PREFIX):
        from pathlib import Path

        path = Path(text[len(FILE_PREFIX) :]).expanduser()
        if not path.is_file():
            raise EnvironmentNameError(text, f"no sidecar file {str(path)!r}")
        return text
    error = UnknownNameError("environment", text, ENVIRONMENT_NAMES)
    error.args = (
        f"{error.args[0]}; or procedural:SEED (a generated apartment) or file:PATH.toml (a kitchen from files)",
    )
    raise error


def procedural_seed(name: str) -> int:
    """The seed of a generated apartment's name ``procedural:SEED``. Raises `ValueError` saying
    what is wrong (not a decimal, non-negative seed; too large)."""
    from .procedural import parse_seed

    return parse_seed(name)


def load(name: str | Environment) -> Environment:
    """The environment called `name` (an `Environment` is returned as it is): a hand-made one,
    ``procedural:SEED`` or ``file:PATH`` (see the module's docstring). Generated apartments and
    kitchens from files are cached: the same name gives the same object.

    Raises `UnknownNameError` (a `KeyError`) listing the valid names for an unknown or garbled
    name; `KitchenFileError` (a `ValueError`) for a sidecar or model file that cannot be read.
    """
    if isinstance(name, Environment):
        return name
    text = check_name(name)
    if text.startswith(PROCEDURAL_PREFIX):
        from . import procedural

        return procedural.generate(procedural.parse_seed(text))
    if text.startswith(FILE_PREFIX):
        from . import from_file

        return from_file.load_file(text[len(FILE_PREFIX) :])
    return importlib.import_module(f"pycram.environments.{_MODULES[text]}").ENVIRONMENT
