"""`import pycram.activate` switches on PyCRAM's block syntax for plan modules imported afterwards.

Importing this module installs `pycram.macros.PlanFinder` at the front of `sys.meta_path`
(idempotent; this side effect is the module's only purpose). From then on every module that
imports from `pycram.language`, `pycram.fluent` or `pycram` at its top level is compiled
through the block-syntax transform when it is imported (see `pycram.macros.opts_in`). Modules
imported before this line, the `pycram` package itself and the importing file are not
transformed — put block syntax of a script in functions decorated with `@plan`, or run it with
`pycram run FILE.py` / `python -m pycram FILE.py`.

Undo with `pycram.macros.uninstall_import_hook()`.
"""

from __future__ import annotations

from pycram.core.macros import install_import_hook

install_import_hook()
