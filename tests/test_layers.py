"""The layering of ARCHITECTURE.md holds: every import-linter contract in pyproject.toml is kept,
no module imports in a cycle, and the checker itself catches a wrong arrow.

A new import against the layering (say, an action importing the simulator) fails here, so it
fails CI, with import-linter's message naming the chain of imports.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import grimp
import pytest

ROOT = Path(__file__).resolve().parent.parent
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def _lint_imports(cwd: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(cwd)},
    )


def test_every_layering_contract_is_kept():
    result = _lint_imports(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout
    kept = [line for line in result.stdout.splitlines() if line.startswith("Contracts:")]
    assert kept and int(kept[0].split()[1]) >= 5, result.stdout


def _cycles(graph: grimp.ImportGraph, modules: set[str]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[list[str]] = []
    counter = 0
    for root in sorted(modules):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.find_modules_directly_imported_by(root) & modules)))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.find_modules_directly_imported_by(child) & modules))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
    return found


def test_no_module_imports_in_a_cycle():
    # Function-level imports count (grimp reads every import statement); imports under
    # `if TYPE_CHECKING:` do not.
    graph = grimp.build_graph("pycram", exclude_type_checking_imports=True)
    modules = set(graph.modules)
    assert "pycram.core.expressions" in modules
    cycles = _cycles(graph, modules)
    assert not cycles, "modules importing each other (directly or through others): " + "; ".join(
        " <-> ".join(c) for c in cycles
    )


def test_the_cycle_finder_finds_a_cycle():
    graph = grimp.ImportGraph()
    for name in ("a", "a.x", "a.y", "a.z"):
        graph.add_module(name)
    graph.add_import(importer="a.x", imported="a.y")
    graph.add_import(importer="a.y", imported="a.z")
    graph.add_import(importer="a.z", imported="a.x")
    assert _cycles(graph, {"a.x", "a.y", "a.z"}) == [["a.x", "a.y", "a.z"]]


def test_a_wrong_arrow_breaks_the_layers_contract(tmp_path):
    # The checker can fail: a lower layer importing a higher one is reported, naming the chain.
    package = tmp_path / "layered"
    for layer in ("apps", "core"):
        (package / layer).mkdir(parents=True)
        (package / layer / "__init__.py").write_text("")
    (package / "__init__.py").write_text("")
    (package / "apps" / "cli.py").write_text("from layered.core import engine\n")
    (package / "core" / "engine.py").write_text("import layered.apps.cli\n")
    (tmp_path / ".importlinter").write_text(
        textwrap.dedent(
            """\
            [importlinter]
            root_package = layered

            [importlinter:contract:layers]
            name = Layers
            type = layers
            layers =
                layered.apps
                layered.core
            """
        )
    )
    result = _lint_imports(tmp_path)
    assert result.returncode == 1, result.stdout + result.stderr
    assert "BROKEN" in result.stdout
    assert "layered.core.engine -> layered.apps.cli" in result.stdout


@pytest.mark.parametrize(
    ("face", "name"),
    [
        ("pycram.language", "par"),
        ("pycram.language", "with_policy"),
        ("pycram.fluent", "Fluent"),
        ("pycram.designator", "perform"),
        ("pycram.process_module", "ProcessModule"),
        ("pycram.robot", "ResolverSet"),
        ("pycram.runtime", "sleep"),
        ("pycram.failures", "PlanFailure"),
    ],
)
def test_the_public_faces_reexport_the_layers_objects(face, name):
    # A face only re-exports: the object is the one its layer defines, not a copy.
    import importlib

    module = importlib.import_module(face)
    obj = getattr(module, name)
    assert obj.__module__.startswith(("pycram.core", "pycram.designators", "pycram.execution"))
