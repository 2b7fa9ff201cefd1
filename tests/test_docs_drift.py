"""Documentation that cannot drift from the code (issue 33, section 4): the tables a new user
reads are checked against what the code has.

- every named environment's row (docs/environments.md, README.md) names every kind of container
  and open surface it has (the apartment's row once left out its cupboard);
- every action constructor of `pycram.actions` is in docs/actions.md's table with exactly its
  parameters and defaults (`Transport` once took no `grasp`, `Open`/`Close` were missing);
- every typed failure is in docs/actions.md's table of reasons, with its default reason and
  every reason it has a hint for; `SimulationFault` with every kind of physics fault;
- the demo's picture folder is where getting-started says it is.

The runnable examples of the documents are run by test_readme.py and test_docs_examples.py.
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

from pycram import actions
from pycram.designators.action import ActionDesignator
from pycram.environments import ENVIRONMENT_NAMES
from pycram.environments import load as load_environment
from pycram.execution import failures

REPO = Path(__file__).resolve().parents[1]
ACTIONS = REPO / "docs" / "actions.md"


def _table_rows(path: Path, first_cell: str) -> list[str]:
    """The markdown table rows of `path` whose first cell starts with `first_cell`."""
    rows = []
    for line in path.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if line.lstrip().startswith("|") and cells and cells[0].startswith(first_cell):
            rows.append(line)
    return rows


def _base_word(name: str) -> str:
    """'drawer 1' -> 'drawer', 'cooker #2' -> 'cooker', 'counter_back' -> 'counter'."""
    return re.split(r"[ _#]", name)[0].lower()


@pytest.mark.parametrize("document", ["docs/environments.md", "README.md"])
@pytest.mark.parametrize("name", ENVIRONMENT_NAMES)
def test_every_environment_row_names_its_containers_and_surfaces(document, name):
    rows = _table_rows(REPO / document, f"`{name}`")
    assert len(rows) == 1, f"{document}: no row (or several) for the environment `{name}`"
    row = rows[0].lower()
    environment = load_environment(name)
    parts = [c.name for c in environment.containers] + [s.name for s in environment.surfaces]
    missing = sorted({_base_word(p) for p in parts if _base_word(p) not in row})
    assert not missing, f"{document}: the row of `{name}` does not mention {missing}"


def _constructors() -> list[str]:
    names = []
    for name in actions.__all__:
        thing = getattr(actions, name)
        if inspect.isfunction(thing) and name[0].isupper():
            hints = inspect.signature(thing).return_annotation
            if hints in (ActionDesignator, "ActionDesignator"):
                names.append(name)
    return names


def _documented_signature(function) -> str:
    parts = []
    for p in inspect.signature(function).parameters.values():
        parts.append(p.name if p.default is inspect.Parameter.empty else f"{p.name}={p.default!r}")
    return f"{function.__name__}({', '.join(parts)})"


def test_the_action_constructors_are_found():
    assert {"Navigate", "PickUp", "Place", "Transport", "Open", "Close", "Detect"} <= set(_constructors())


@pytest.mark.parametrize("name", _constructors())
def test_every_action_is_documented_with_its_parameters(name):
    rows = _table_rows(ACTIONS, f"`{name}(")
    assert len(rows) == 1, f"docs/actions.md: no row (or several) for {name}"
    documented = rows[0].strip().strip("|").split("|")[0].strip().strip("`")
    assert documented == _documented_signature(getattr(actions, name))


def _typed_failures() -> list[type]:
    return [
        getattr(failures, n)
        for n in failures.__all__
        if isinstance(getattr(failures, n), type)
        and issubclass(getattr(failures, n), (failures.PlanFailure, failures.SimulationFault))
    ]


@pytest.mark.parametrize("cls", _typed_failures(), ids=lambda c: c.__name__)
def test_every_typed_failure_and_its_reasons_are_documented(cls):
    rows = _table_rows(ACTIONS, f"`{cls.__name__}`")
    assert len(rows) == 1, f"docs/actions.md: no row (or several) for {cls.__name__} in the table of reasons"
    cells = rows[0].strip().strip("|").split("|")
    reasons = set(re.findall(r"`([a-z_]+)`", cells[1]))
    if cls is failures.SimulationFault:
        expected = set(failures.PHYSICS_FAULT_KINDS)
    else:
        expected = {cls.default_reason, *cls.hints}
        first = re.findall(r"`([a-z_]+)`", cells[1])[0]
        assert first == cls.default_reason, f"{cls.__name__}: the default reason comes first"
    assert expected <= reasons, f"{cls.__name__}: reasons not documented: {sorted(expected - reasons)}"
    assert cls.__name__ in ACTIONS.read_text(encoding="utf-8").split("## Picking out of drawers")[0]


def test_the_demo_pictures_are_where_getting_started_says():
    pytest.importorskip("mujoco")
    from pycram.apps.demos.kitchen import default_output

    assert default_output("pr2", 7) == Path("output") / "demo-pr2-7"
    text = (REPO / "docs" / "getting-started.md").read_text(encoding="utf-8")
    assert "output/demo-pr2-RUNID/" in text and "output/demo-pr2/" not in text
