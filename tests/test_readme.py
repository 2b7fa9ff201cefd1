"""Every Python code block of README.md runs, as a user would run it (docs/: test_docs_examples.py).

The blocks are read from the files at test time, so the documentation cannot rot. Each block
runs on its own in a fresh interpreter (`python block.py`, plain Python: the block syntax must
be switched on by the block itself, e.g. with `@plan`), in a temporary folder, headless
(`MUJOCO_GL=egl` unless set), with a time-out. A block that reads recorded runs gets a temporary
SQLite database (`PYCRAM_DB_URL`) holding one recorded run. A block that defines functions must
also use them: defining a plan that is never run proves nothing.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCUMENTS = [REPO / "README.md"]
#: Wall-time limit of one block [s]; blocks that start the simulator need a few seconds.
BLOCK_TIMEOUT = 300

_FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.DOTALL | re.MULTILINE)


def python_blocks(path: Path, root: Path = REPO) -> list[tuple[str, str]]:
    """(id, code) of every ```python block of `path`; the id is `file:line` of the fence."""
    text = path.read_text(encoding="utf-8")
    blocks = []
    for match in _FENCE.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        blocks.append((f"{path.relative_to(root)}:{line}", match.group(1)))
    return blocks


BLOCKS = [block for document in DOCUMENTS for block in python_blocks(document)]

#: A plan that leaves one failed grasp and one non-waited drive in the trace: the data the
#: README's query example asks for. It runs on a robot of test doubles (pycram.testing).
RECORDED_PLAN = textwrap.dedent("""
    from pycram.designator import MotionDesignator, perform
    from pycram.language import seq
    from pycram.robot import Robot
    from pycram.testing import ScriptedProcessModule

    class GraspFailed(Exception):
        pass

    def grasp():
        raise GraspFailed("nothing between the fingers")

    robot = Robot("test-double robot")
    navigation = robot.add_process_module("navigation", ScriptedProcessModule("navigation", script=["arrived"]))
    robot.process_module_resolvers.append(
        lambda d: navigation if d.check_constraints([("type", "moving")]) else None)
    with robot:
        assert perform(MotionDesignator(type="moving", pose=(1.0, 2.0, 0.0), wait=False)).wait() == "arrived"
        seq(grasp, name="grasp")
""")


def test_the_documents_have_python_blocks():
    assert any(block_id.startswith("README.md:") for block_id, _ in BLOCKS)
    assert len(BLOCKS) >= 4, [block_id for block_id, _ in BLOCKS]


def test_block_extraction_sees_every_fence(tmp_path):
    doc = tmp_path / "doc.md"
    doc.write_text("text\n```python\nx = 1\n```\n\n```sh\nls\n```\n```python\ny = 2\n\nz = 3\n```\n")
    assert python_blocks(doc, tmp_path) == [("doc.md:2", "x = 1\n"), ("doc.md:9", "y = 2\n\nz = 3\n")]


def unused_functions(code: str) -> list[str]:
    """Top-level functions of `code` that no top-level statement outside their own definition
    names (calls them or passes them on)."""
    tree = ast.parse(code)
    defined = [node.name for node in tree.body if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]
    used: set[str] = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            scope = [*node.decorator_list, *node.args.defaults]
        else:
            scope = [node]
        for part in scope:
            used.update(n.id for n in ast.walk(part) if isinstance(n, ast.Name))
    # a function used only by another used function counts as used
    bodies = {node.name: node for node in tree.body if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))}
    changed = True
    while changed:
        changed = False
        for name in list(used & bodies.keys()):
            inner = {n.id for n in ast.walk(bodies[name]) if isinstance(n, ast.Name)}
            if not inner <= used:
                used |= inner
                changed = True
    return [name for name in defined if name not in used]


def test_unused_functions_are_found():
    assert unused_functions("def f():\n    pass\n") == ["f"]
    assert unused_functions("def f():\n    g()\ndef g():\n    pass\nf()\n") == []
    assert unused_functions("def f(h):\n    h()\ndef g():\n    pass\nf(g)\n") == []


def _run_block(code: str, tmp_path: Path, **extra_env: str) -> subprocess.CompletedProcess:
    script = tmp_path / "block.py"
    script.write_text(code, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(REPO), PYCRAM_RECORD="0", **extra_env)
    env.setdefault("MUJOCO_GL", "egl")
    env.setdefault("PYCRAM_DB_URL", f"sqlite:///{tmp_path / 'runs.sqlite3'}")
    return subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=BLOCK_TIMEOUT
    )


def _record_a_run(db_url: str, tmp_path: Path) -> None:
    plan = tmp_path / "recorded_plan.py"
    plan.write_text(RECORDED_PLAN)
    env = dict(os.environ, PYTHONPATH=str(REPO), PYCRAM_DB_URL=db_url)
    env.pop("PYCRAM_RECORD", None)
    out = subprocess.run(
        [sys.executable, "-m", "pycram.apps.cli", "run", str(plan)],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    assert out.returncode == 0 and "recorded as run 1" in out.stderr, out.stderr


@pytest.mark.parametrize("code", [code for _, code in BLOCKS], ids=[block_id for block_id, _ in BLOCKS])
def test_block_runs(code, tmp_path):
    assert not unused_functions(code), f"the block defines but never uses {unused_functions(code)}"
    reads_runs = "pycram.trace" in code
    db_url = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    if reads_runs:
        _record_a_run(db_url, tmp_path)
    out = _run_block(code, tmp_path, PYCRAM_DB_URL=db_url)
    assert out.returncode == 0, f"stdout:\n{out.stdout}\nstderr:\n{out.stderr}"
    if reads_runs:  # it found the recorded failure and the drive's duration
        assert "nothing between the fingers" in out.stdout, out.stdout
        assert re.search(r"\[\d+\.\d+", out.stdout), out.stdout
