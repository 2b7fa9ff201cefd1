"""The public surface: every name a public module exports exists and is documented.

A public module is every module of the `pycram` package whose dotted path has no component
starting with `_` and that declares `__all__` (found from the source, without importing
anything first). For each name in its `__all__`:

* the module has that attribute (a typo in `__all__` would break `from m import *`);
* it is documented: a class, function or module by its own docstring (not one inherited from
  a base class or from `object`); a constant, type alias or other value by an attribute
  docstring (a string literal right after the assignment) or a `#:` comment right before it,
  in the module that assigns it (re-exports are followed to their origin).

Every public module also has a page in the API reference (`docs/reference/`), so the reference
cannot silently miss a module.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import os
import types
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "pycram"
REFERENCE = ROOT / "docs" / "reference"

os.environ.setdefault("MUJOCO_GL", "egl")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@cache
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _declares_all(tree: ast.Module) -> bool:
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return True
        if isinstance(node, ast.ImportFrom) and any(a.name == "__all__" for a in node.names):
            return True
    return False


def public_modules() -> list[str]:
    """Dotted names of the public modules that declare `__all__`, sorted."""
    names = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = _module_name(path)
        if any(part.startswith("_") for part in name.split(".")):
            continue
        if _declares_all(_tree(path)):
            names.append(name)
    return names


def _source_of(module_name: str) -> Path | None:
    spec = importlib.util.find_spec(module_name)
    return Path(spec.origin) if spec is not None and spec.origin else None


def _resolve_relative(module_name: str, node: ast.ImportFrom, is_package: bool) -> str:
    if node.level == 0:
        return node.module or ""
    base = module_name.split(".")
    base = base if is_package else base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _variable_documented(module_name: str, name: str, depth: int = 0) -> bool:
    """Whether `name`, a value assigned in (or re-exported by) the module, has a docstring."""
    path = _source_of(module_name)
    if path is None or depth > 5:
        return False
    tree = _tree(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    for body in _blocks(tree.body):
        found = _documented_in_block(module_name, name, body, lines, path, depth)
        if found is not None:
            return found
    return False


def _blocks(body: list[ast.stmt]):
    """The module's top-level statement lists, including those inside `try` and `if`."""
    yield body
    for node in body:
        if isinstance(node, ast.Try):
            for block in (node.body, node.orelse, node.finalbody, *(h.body for h in node.handlers)):
                yield from _blocks(block)
        elif isinstance(node, ast.If):
            yield from _blocks(node.body)
            yield from _blocks(node.orelse)


def _documented_in_block(module_name, name, body, lines, path, depth) -> bool | None:
    """True/False when the block assigns or imports `name`, None when it does not."""
    for i, node in enumerate(body):
        if isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if not any(isinstance(t, ast.Name) and t.id == name for t in targets):
                continue
            following = body[i + 1] if i + 1 < len(body) else None
            if (
                isinstance(following, ast.Expr)
                and isinstance(following.value, ast.Constant)
                and isinstance(following.value.value, str)
            ):
                return True
            before = lines[node.lineno - 2].strip() if node.lineno >= 2 else ""
            return before.startswith("#:")
        elif isinstance(node, ast.ImportFrom):
            for alias in node.names:
                if (alias.asname or alias.name) == name:
                    origin = _resolve_relative(module_name, node, path.name == "__init__.py")
                    return _variable_documented(origin, alias.name, depth + 1)
                if alias.name == "*":  # a public face re-exporting a module's `__all__`
                    origin = _resolve_relative(module_name, node, path.name == "__init__.py")
                    if name in getattr(importlib.import_module(origin), "__all__", ()):
                        return _variable_documented(origin, name, depth + 1)
    return None


def _own_docstring(obj: object) -> str | None:
    if isinstance(obj, type):
        doc = obj.__dict__.get("__doc__")
    else:
        doc = getattr(obj, "__doc__", None)
    return doc if isinstance(doc, str) and doc.strip() else None


def _is_documented(module_name: str, name: str, obj: object) -> bool:
    if isinstance(obj, (type, types.FunctionType, types.BuiltinFunctionType, types.ModuleType)):
        return _own_docstring(obj) is not None
    if inspect.isfunction(inspect.unwrap(obj)) if callable(obj) else False:
        return _own_docstring(obj) is not None
    if isinstance(obj, type(None) | bool | int | float | str | bytes | tuple | frozenset | dict | list):
        return _variable_documented(module_name, name)
    # Other objects (type aliases, enum members, singletons, callable instances): their own
    # class's docstring is not theirs to claim; look for an attribute docstring first.
    return _variable_documented(module_name, name) or (
        callable(obj) and _own_docstring(type(obj)) is not None and type(obj).__module__.startswith("pycram")
    )


MODULES = public_modules()


def test_the_public_modules_are_found():
    # The walk must find the core modules; if it found none, every test below would pass vacuously.
    for core in (
        "pycram.fluent",
        "pycram.language",
        "pycram.runtime",
        "pycram.designator",
        "pycram.process_module",
        "pycram.macros",
        "pycram.trace",
    ):
        assert core in MODULES
    # the simulator imports the core directly: no private stand-ins for fluents and clocks
    assert not (PACKAGE / "backends" / "sim" / "_runtime.py").exists()


@pytest.mark.parametrize("module_name", MODULES)
def test_every_exported_name_exists_and_is_documented(module_name):
    module = importlib.import_module(module_name)
    assert _own_docstring(module), f"{module_name} has no module docstring"
    exported = module.__all__
    assert len(set(exported)) == len(exported), f"{module_name}.__all__ lists a name twice"
    missing = [name for name in exported if not hasattr(module, name)]
    assert not missing, f"{module_name}.__all__ names what the module does not have: {missing}"
    undocumented = [name for name in exported if not _is_documented(module_name, name, getattr(module, name))]
    assert not undocumented, f"{module_name}: exported but undocumented: {undocumented}"


@pytest.mark.parametrize("module_name", MODULES)
def test_every_public_module_has_a_reference_page(module_name):
    pages = [p.read_text(encoding="utf-8") for p in REFERENCE.rglob("*.md")]
    assert any(f"::: {module_name}\n" in page for page in pages), (
        f"no page in docs/reference/ renders {module_name} (add a '::: {module_name}' block)"
    )


def test_the_checker_catches_an_undocumented_name(tmp_path, monkeypatch):
    # The checker itself can fail: an undocumented function and constant are reported.
    package = tmp_path / "surface_probe"
    package.mkdir()
    (package / "__init__.py").write_text(
        '"""Probe."""\n'
        '__all__ = ["documented", "bare", "LIMIT", "DOCUMENTED_LIMIT", "COMMENTED"]\n'
        'def documented():\n    """Has one."""\n'
        "def bare():\n    pass\n"
        "LIMIT = 3\n"
        'DOCUMENTED_LIMIT = 4\n"""In metres."""\n'
        "#: Seconds.\nCOMMENTED = 5\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("surface_probe")
    verdict = {name: _is_documented("surface_probe", name, getattr(module, name)) for name in module.__all__}
    assert verdict == {"documented": True, "bare": False, "LIMIT": False, "DOCUMENTED_LIMIT": True, "COMMENTED": True}


def test_the_reference_table_of_expressions_matches_their_docstrings():
    # docs/reference/language.md repeats the expressions' docstrings (griffe cannot read the
    # docstring of a callable object); this keeps the copy honest.
    language = importlib.import_module("pycram.language")
    page = (REFERENCE / "language.md").read_text(encoding="utf-8")
    for name in ("seq", "try_in_order", "par", "try_all", "pursue"):
        assert f"| `{name}` | {getattr(language, name).__doc__} |" in page, name
