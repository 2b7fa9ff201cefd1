"""Every Python example in the documentation runs, so examples cannot rot.

Each fenced ```python block of every page under docs/ is written to a file of its own and run
in a fresh interpreter (a file, not `python -c`, so that `@plan` can read its source), with the
repository first on the path, in a temporary directory, with a time-out. A block passes when the
interpreter exits with 0: the examples check their own claims with `assert`.

Shell commands are fenced as ```sh and are not run here (`make docs`, `pycram demo`, ...).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
FENCE = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
TIMEOUT = 120  # [s] per example; the simulator examples take a few seconds


def examples() -> list[tuple[str, str]]:
    """(id, code) of every ```python block under docs/, in page order."""
    found = []
    for page in sorted(DOCS.rglob("*.md")):
        for index, match in enumerate(FENCE.finditer(page.read_text(encoding="utf-8")), start=1):
            found.append((f"{page.relative_to(DOCS)}#{index}", match.group(1)))
    return found


EXAMPLES = examples()


def test_the_examples_are_found():
    pages = {example_id.split("#")[0] for example_id, _ in EXAMPLES}
    assert {"getting-started.md", "language.md", "designators.md", "robots.md", "simulator.md", "traces.md"} <= pages
    assert len(EXAMPLES) >= 15


@pytest.mark.timeout(TIMEOUT + 30)
@pytest.mark.parametrize("example_id, code", EXAMPLES, ids=[example_id for example_id, _ in EXAMPLES])
def test_example_runs(example_id, code, tmp_path):
    script = tmp_path / ("example_" + re.sub(r"\W", "_", example_id) + ".py")
    script.write_text(code, encoding="utf-8")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.setdefault("MUJOCO_GL", "egl")
    env["PYCRAM_RECORD"] = "0"
    env["PYCRAM_DB_URL"] = f"sqlite:///{tmp_path / 'runs.sqlite3'}"  # never the user's database
    result = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=TIMEOUT
    )
    assert result.returncode == 0, f"docs/{example_id} failed (exit {result.returncode}):\n{result.stderr[-3000:]}"


def test_a_failing_example_is_reported(tmp_path):
    # The fence pattern finds blocks the way the test above reads them, and a failing block fails.
    page = "text\n\n```python\nassert 1 + 1 == 3, 'arithmetic'\n```\n\n```sh\nmake docs\n```\n"
    blocks = FENCE.findall(page)
    assert blocks == ["assert 1 + 1 == 3, 'arithmetic'\n"]
    script = tmp_path / "failing.py"
    script.write_text(blocks[0])
    result = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert result.returncode != 0 and "arithmetic" in result.stderr
