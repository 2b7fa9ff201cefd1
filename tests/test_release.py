"""Release habits: one version, `pycram --version`, the changelog, py.typed, pinned tools.

The wheel itself is checked outside pytest by `scripts/check_wheel.sh` (a stage of .ci/run): it
builds the wheel, installs it into a fresh virtual environment and runs its CLI there.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from typer.testing import CliRunner

import pycram
from pycram._version import __version__
from pycram.apps.cli import app

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_the_version_is_written_in_one_place():
    assert re.fullmatch(r"\d+\.\d+\.\d+", __version__)
    assert pycram.__version__ == __version__
    project = PYPROJECT["project"]
    assert "version" not in project and "version" in project["dynamic"]
    assert PYPROJECT["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "pycram._version.__version__"}


def test_pycram_version_prints_it():
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0, result.output
    assert result.output.strip() == f"pycram {__version__}"


def test_the_changelog_has_unreleased_and_the_current_version():
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    headings = re.findall(r"^## \[([^\]]+)\]", changelog, re.M)
    assert headings[0] == "Unreleased"
    assert __version__ in headings, f"CHANGELOG.md has no section for {__version__}: {headings}"


def test_py_typed_is_shipped():
    assert (ROOT / "pycram" / "py.typed").is_file()
    assert "py.typed" in PYPROJECT["tool"]["setuptools"]["package-data"]["pycram"]


def test_the_tools_are_pinned_and_installed_by_make_test():
    extras = PYPROJECT["project"]["optional-dependencies"]
    for requirement in extras["docs"] + [r for r in extras["dev"] if not r.startswith("pycram[")]:
        assert re.fullmatch(r"[A-Za-z0-9_.\-\[\]]+==[\w.]+", requirement), f"not pinned exactly: {requirement}"
    dev_names = {r.split("==")[0] for r in extras["dev"]}
    assert {"ruff", "mypy", "build"} <= dev_names
    assert "pycram[docs]" in extras["dev"]  # `make test` installs .[all,dev]
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert "-e '.[all,dev]'" in makefile


def test_the_docs_build_offline_and_strict():
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    assert re.search(r"^  font: false$", config, re.M), "the Material theme must not fetch Google fonts"
    assert re.search(r"^strict: true$", config, re.M)
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert "mkdocs build --strict" in makefile
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    for stage in ("stage docs make docs", "stage wheel make wheel", "stage test make test"):
        assert stage in ci


#: What `mypy --strict` turns on per module (mypy 2.4); `warn_redundant_casts` is global.
STRICT_FLAGS = {
    "disallow_any_generics": True,
    "disallow_subclassing_any": True,
    "disallow_untyped_calls": True,
    "disallow_untyped_defs": True,
    "disallow_incomplete_defs": True,
    "check_untyped_defs": True,
    "disallow_untyped_decorators": True,
    "warn_unused_ignores": True,
    "warn_return_any": True,
    "implicit_reexport": False,
    "strict_equality": True,
    "extra_checks": True,
}


def test_ci_type_checks_the_language_core_strictly_before_the_tests():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "stage types make types" in ci
    assert ci.index("stage types make types") < ci.index("stage test make test")
    mypy = PYPROJECT["tool"]["mypy"]
    assert mypy["files"] == ["pycram"] and mypy["warn_redundant_casts"] is True
    core = next(o for o in mypy["overrides"] if "pycram.runtime" in o["module"])
    for module in (
        "pycram.core.fluent",
        "pycram.core.runtime.*",
        "pycram.core.expressions",
        "pycram.designators.*",
        "pycram.execution.process_module",
        "pycram.language",
    ):
        assert module in core["module"]
    # `strict = true` in an override makes every module strict (python/mypy#11401): spelled out.
    assert "strict" not in core
    assert {flag: core.get(flag) for flag in STRICT_FLAGS} == STRICT_FLAGS
