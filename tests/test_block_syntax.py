"""The block-syntax transform (pycram.macros): generated code, scoping, names and lines, the
three switches, and the errors users get for misuse."""

from __future__ import annotations

import ast
import functools
import importlib
import json
import os
import subprocess
import sys
import textwrap
import threading
import traceback
import types
from pathlib import Path
from typing import Any

import pytest

from pycram.core.block_forms import BlockSyntaxNotEnabled
from pycram.fluent import Fluent, whenever
from pycram.language import State, par, plan, seq
from pycram.macros import (
    NOT_ENABLED_MESSAGE,
    compile_source,
    install_import_hook,
    opts_in,
    run_script,
    transform_source,
    uninstall_import_hook,
)
from pycram.runtime import add_task_listener, current_task, remove_task_listener

ROOT = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.timeout(60)

HEADER = "from pycram.language import par, seq, pursue, try_all, try_in_order, failure_handling, State\nfrom pycram.fluent import Fluent, whenever\n"


def run(source: str, tmp_path: Path, name: str = "plan_src.py") -> dict[str, Any]:
    """Write `source` to a file and run it with the block syntax (script mode)."""
    path = tmp_path / name
    path.write_text(textwrap.dedent(source))
    return run_script(path, activate=False)


# -- generated code ----------------------------------------------------------------------------------


def test_each_statement_is_one_branch_and_state_is_bound_first() -> None:
    tree, names = transform_source(
        HEADER + "with par(errors) as s:\n    a = 1\n    if True:\n        b = 2\n        c = 3\n", "/x/demo.py"
    )
    module = ast.unparse(tree)
    assert sorted(names.values()) == ["par@demo.py:3#1", "par@demo.py:3#2"]
    assert module.index("s = _pycram_state") < module.index("def _pycram_par")  # bound before branches
    assert "expression('par')(_pycram_par" in module and "errors=_pycram_errors" in module
    assert "global a" in module and "global b, c" in module
    assert "macros" not in module.split("import pycram.core.macros")[0]


def test_thesis_macros_import_is_dropped(tmp_path: Path) -> None:
    ns = run(
        "from pycram.language import macros, par\nfrom pycram.fluent import macros, Fluent\nwith par as s:\n    x "
        "= 1\n",
        tmp_path,
    )
    assert ns["s"].get_value() is State.SUCCEEDED and ns["x"] == 1


def test_names_are_recognised_by_what_they_refer_to(tmp_path: Path) -> None:
    ns = run(
        """
        import pycram.language as L
        import pycram.language
        from pycram.language import par as together
        from pycram import language
        out = []
        with L.par as a:
            out.append(1)
        with pycram.language.seq as b:
            out.append(2)
        with together as c:
            out.append(3)
        with language.try_all as d:
            out.append(4)
        """,
        tmp_path,
    )
    assert sorted(ns["out"]) == [1, 2, 3, 4]
    assert all(ns[k].get_value() is State.SUCCEEDED for k in "abcd")


def test_unrelated_with_named_par_is_left_alone() -> None:
    source = "import contextlib\npar = contextlib.nullcontext\nwith par() as s:\n    x = 1\n"
    tree, names = transform_source(source, "mine.py")
    assert names == {} and "_pycram" not in ast.unparse(tree)


# -- scoping ------------------------------------------------------------------------------------------


def test_function_branches_read_and_assign_locals(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def f(n):
    total = 0
    with par(errors) as s:
        only_in_branch = n * 2
        total = n + 1
    with seq as t:
        later = only_in_branch + total
    return total, only_in_branch, later, s.get_value(), errors
""",
        tmp_path,
    )
    assert ns["f"](3) == (4, 6, 10, State.SUCCEEDED, [])


def test_branches_may_annotate_what_they_assign(tmp_path: Path) -> None:
    # a branch declares the names it binds nonlocal (global at module level), and Python refuses
    # annotations of such names: `x: int = 1` must still work in a branch, as in any function
    ns = run(
        HEADER
        + """
from typing import Optional

def f(n):
    with par:
        doubled: int = n * 2
        label: Optional[str]
        tripled = n * 3
    with seq:
        def nested() -> int:
            inner: int = 5  # a scope of its own: its annotation stays
            return inner
        total: int = doubled + tripled + nested()
    return doubled, tripled, total

with seq:
    at_module: float = 1.5
""",
        tmp_path,
    )
    assert ns["f"](2) == (4, 6, 15)
    assert ns["at_module"] == 1.5


def test_as_name_is_bound_before_the_branches_start(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def f():
    seen = []
    with par as s:
        seen.append(s.get_value())  # NameError if `s` were bound only after the branches
        seen.append(s.get_value())
    with try_all as t:
        seen.append(t.get_value())
    return seen, s.get_value(), t.get_value()
""",
        tmp_path,
    )
    assert ns["f"]() == ([None, None, None], State.SUCCEEDED, State.SUCCEEDED)


def test_name_assigned_only_in_a_branch_that_did_not_run_stays_unbound(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def f():
    with seq(errors) as s:
        raise ValueError("first")
        x = 1
    return x
""",
        tmp_path,
    )
    with pytest.raises(UnboundLocalError):
        ns["f"]()


def test_global_and_nonlocal_declarations_are_honoured(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
g = 0
def outer():
    c = 0
    def inner():
        global g
        nonlocal c
        with par as s:
            g = 5
            c = 7
    inner()
    return c
""",
        tmp_path,
    )
    assert ns["outer"]() == 7 and ns["g"] == 5


def test_nested_blocks_share_variables(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def f():
    with par as s:
        with seq as inner:
            a = 1
            b = a + 1
        with try_in_order as t:
            c = 3
    return a, b, c, inner.get_value(), t.get_value(), s.get_value()
""",
        tmp_path,
    )
    assert ns["f"]() == (1, 2, 3, State.SUCCEEDED, State.SUCCEEDED, State.SUCCEEDED)


def test_errors_name_rules(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
collected = []
def uses_global():
    with seq(collected) as s:
        raise KeyError("g")
def makes_local():
    with seq(errors) as s:
        raise KeyError("l")
    return errors
""",
        tmp_path,
    )
    ns["uses_global"]()
    assert [str(e) for e in ns["collected"]] == ["'g'"]
    assert [str(e) for e in ns["makes_local"]()] == ["'l'"]


def test_failure_handling_retry_and_return_value(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def f():
    n = 0
    with failure_handling(10):
        try:
            n += 1
            if n < 4:
                raise IOError(n)
        except IOError:
            retry()
    return n
""",
        tmp_path,
    )
    assert ns["f"]() == 4


def test_return_inside_whenever_returns_from_function(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def count_up(f):
    with whenever(f):
        if f.get_value() >= 3:
            return "done at %d" % f.get_value()
        f.set_value(f.get_value() + 1)
""",
        tmp_path,
    )
    assert ns["count_up"](Fluent(0)) == "done at 3"


def test_bare_return_in_whenever_branch_ends_the_branch(tmp_path: Path) -> None:
    ns = run(
        HEADER
        + """
def f(trigger):
    seen = []
    with par as s:
        with whenever(trigger):
            seen.append(trigger.get_value())
            return
        trigger.set_value(1)
    return seen, s.get_value()
""",
        tmp_path,
    )
    seen, state = ns["f"](Fluent())
    assert (seen, state) == ([1], State.SUCCEEDED)


# -- names, lines, tracebacks, task tree --------------------------------------------------------------


def test_branch_functions_carry_user_file_line_and_name(tmp_path: Path) -> None:
    path = tmp_path / "lines.py"
    path.write_text(HEADER + "errs = []\nwith par(errs) as s:\n    x = 1\n    1 / 0\n")
    ns = run_script(path, activate=False)
    (error,) = ns["errs"]
    frame = traceback.extract_tb(error.__traceback__)[-1]
    assert (frame.filename, frame.lineno, frame.name) == (str(path), 6, "par@lines.py:4#2")
    code = compile_source(path.read_text(), str(path))
    branches = [c for c in code.co_consts if isinstance(c, types.CodeType)]
    assert {c.co_name for c in branches} == {"par@lines.py:4#1", "par@lines.py:4#2"}
    assert {line for c in branches for *_, line in c.co_lines() if line} >= {5, 6}  # coverage sees them


def test_task_tree_names_point_at_user_lines(tmp_path: Path) -> None:
    names: list[str] = []
    lock = threading.Lock()

    class Listener:
        def task_started(self, task: Any) -> None:
            with lock:
                names.append(task.name)

        def task_ended(self, task: Any) -> None:
            pass

    listener = Listener()
    add_task_listener(listener)
    try:
        run(HEADER + "with par as s:\n    a = 1\n    b = 2\n", tmp_path, "tree.py")
    finally:
        remove_task_listener(listener)
    assert any("par@tree.py:3" in n for n in names)
    assert any("par@tree.py:3#2" in n for n in names)


# -- @plan ---------------------------------------------------------------------------------------------


def test_plan_keeps_closure_defaults_and_outer_decorators() -> None:
    calls = []

    def record(fn: Any) -> Any:
        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            calls.append(args)
            return fn(*args, **kwargs)

        return wrapper

    factor = 10

    @record
    @plan
    def compute(a: int, b: int = 2, *, c: int = 3) -> tuple:
        """Docstring kept."""
        nonlocal factor
        with par as s:
            x = a * factor
            y = b + c
        factor = 11
        return x, y, s.get_value()

    assert compute(1) == (10, 5, State.SUCCEEDED)
    assert factor == 11 and calls == [(1,)]
    assert compute.__doc__ == "Docstring kept." and compute.__wrapped__.__defaults__ == (2,)
    assert compute.__wrapped__.__kwdefaults__ == {"c": 3}


def test_plan_methods_and_super() -> None:
    class Base:
        def where(self) -> str:
            return "base"

    class Child(Base):
        @plan
        def where(self) -> str:
            with seq as s:
                r = super().where()
            return r + "+child"

        @staticmethod
        @plan
        def static() -> int:
            with par as s:
                v = 4
            return v

    assert Child().where() == "base+child"
    assert Child.static() == 4


def test_plan_without_block_syntax_returns_function_unchanged() -> None:
    def f() -> int:
        return 1

    assert plan(f) is f


def test_plan_must_be_innermost() -> None:
    def deco(fn: Any) -> Any:
        return functools.wraps(fn)(lambda *a: fn(*a))

    def f() -> None:
        with par as s:
            pass

    with pytest.raises(TypeError, match="innermost"):
        plan(deco(f))


def test_plan_without_source() -> None:
    ns: dict[str, Any] = {}
    exec("def f():\n    return 1\n", ns)
    with pytest.raises(TypeError, match="source"):
        plan(ns["f"])


# -- misuse ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make",
    [
        lambda: par([]),
        lambda: par,
        lambda: seq,
        lambda: whenever(Fluent()),
    ],
)
def test_block_without_any_mode_refuses_and_says_how(make: Any) -> None:
    ran = []
    with pytest.raises(BlockSyntaxNotEnabled) as info:
        with make():
            ran.append(1)
    assert ran == []
    message = str(info.value)
    for hint in ("@plan", "pycram run", "python -m pycram", "import pycram.activate"):
        assert hint in message
    assert "{form}" in NOT_ENABLED_MESSAGE


def check_syntax_error(tmp_path: Path, body: str, line: int, match: str) -> None:
    path = tmp_path / "bad.py"
    path.write_text(HEADER + textwrap.dedent(body))
    with pytest.raises(SyntaxError, match=match) as info:
        run_script(path, activate=False)
    assert info.value.filename == str(path)
    assert info.value.lineno == line + 2  # + the two HEADER lines


@pytest.mark.parametrize(
    "body, line, match",
    [
        ("def f():\n    with par as s:\n        return 1\n", 3, "`return` is not allowed inside a `par` block"),
        ("def f():\n    with seq as s:\n        x = 1\n        return\n", 4, "`return` is not allowed"),
        ("def f(g):\n    with par as s:\n        with whenever(g):\n            return 5\n", 4, "bare `return`"),
        ("for i in range(3):\n    with par as s:\n        break\n", 3, "`break` inside a `par` block"),
        ("def f():\n    with par as s:\n        yield 1\n", 3, "`yield` is not allowed"),
        ("def f():\n    with par as s:\n        global q\n", 3, "`global` is not allowed"),
        ("with par as s:\n    pass\n", 1, "has no statements"),
        ("with par(errors) as s:\n    ...\n", 1, "has no statements"),
        ("with par as s, seq as t:\n    x = 1\n", 1, "only item"),
        ("class C:\n    with par as s:\n        x = 1\n", 2, "class body"),
        ("with whenever(1, 2):\n    x = 1\n", 1, "exactly one argument"),
        ("with failure_handling(5) as f:\n    x = 1\n", 1, "does not bind"),
        ("with par(a, b) as s:\n    x = 1\n", 1, "at most one argument"),
        ("x = 1\nwith par as s:\n    y = (\n", 3, "never closed"),  # a plain syntax error, reported at the user's line
    ],
)
def test_misuse_is_a_syntax_error_at_the_user_line(tmp_path: Path, body: str, line: int, match: str) -> None:
    check_syntax_error(tmp_path, body, line, match)


def test_whenever_needs_a_fluent(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match=r"bad_whenever.py:3 needs a Fluent, got int"):
        run(HEADER + "with whenever(42):\n    x = 1\n", tmp_path, "bad_whenever.py")


def test_plan_reports_misuse_with_file_and_line() -> None:
    with pytest.raises(SyntaxError) as info:

        @plan
        def f() -> None:
            with par as s:
                return None

    assert info.value.filename == __file__
    assert "return None" in (info.value.text or "")


# -- scripts and the import hook --------------------------------------------------------------------


def test_run_script_sets_and_restores_argv_path_and_main(tmp_path: Path) -> None:
    before = (list(sys.argv), list(sys.path), sys.modules["__main__"])
    ns = run_script(_write(tmp_path / "args.py", "import sys\nargs = list(sys.argv)\nname = __name__\n"), ["-v", "x"])
    assert ns["args"] == [str(tmp_path / "args.py"), "-v", "x"] and ns["name"] == "__main__"
    assert (list(sys.argv), list(sys.path), sys.modules["__main__"]) == before


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_python_dash_m_pycram_failure_points_at_user_line(tmp_path: Path) -> None:
    path = _write(tmp_path / "boom.py", HEADER + "with failure_handling():\n    raise KeyError('boom')\n")
    proc = subprocess.run(
        [sys.executable, "-m", "pycram", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert proc.returncode == 1
    assert f'File "{path}", line 4, in failure_handling@boom.py:3' in proc.stderr
    assert "KeyError: 'boom'" in proc.stderr


def test_opt_in_rule() -> None:
    assert opts_in("from pycram.language import par\n")
    assert opts_in("import pycram.fluent\n")
    assert opts_in("try:\n    from pycram import language\nexcept ImportError:\n    pass\n")
    assert not opts_in("def f():\n    from pycram.language import par\n")  # not at top level
    assert not opts_in("import os  # mentions pycram\n")


def test_import_hook_transforms_only_opted_in_modules(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = tmp_path / "hooked_pkg"
    pkg.mkdir()
    _write(pkg / "__init__.py", "")
    _write(
        pkg / "plan_mod.py",
        HEADER
        + "from pycram.language import plan\nwith par as s:\n    x = 1\n\n@plan\ndef f():\n    with seq as t:\n        v = 2\n    return v\n",
    )
    _write(pkg / "plain_mod.py", "import contextlib\npar = contextlib.nullcontext\nwith par():\n    y = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    installed = install_import_hook()
    try:
        from hooked_pkg import plain_mod, plan_mod  # type: ignore[import-not-found]
    finally:
        if installed:
            uninstall_import_hook()
        for name in ("hooked_pkg", "hooked_pkg.plan_mod", "hooked_pkg.plain_mod"):
            sys.modules.pop(name, None)
    assert plan_mod.s.get_value() is State.SUCCEEDED and plan_mod.__pycram_transformed__
    assert plain_mod.y == 1 and not hasattr(plain_mod, "__pycram_transformed__")
    assert plan(plan_mod.f) is plan_mod.f and plan_mod.f() == 2  # already transformed by the hook


def test_debugger_breakpoint_inside_a_branch_stops_at_the_user_line(tmp_path: Path) -> None:
    import bdb

    path = _write(tmp_path / "dbg.py", HEADER + "hits = []\nwith seq as s:\n    hits.append(1)\n    hits.append(2)\n")
    stops: list[tuple[str, int, str]] = []

    class Recorder(bdb.Bdb):
        def user_line(self, frame: types.FrameType) -> None:
            if self.break_here(frame):
                stops.append((frame.f_code.co_filename, frame.f_lineno, frame.f_code.co_name))
            self.set_continue()

    debugger = Recorder()
    debugger.set_break(str(path), 6)
    code = compile_source(path.read_text(), str(path))
    ns: dict[str, Any] = {"__name__": "dbg"}
    debugger.runctx(code, ns, ns)  # seq runs its steps in the calling thread
    threading.settrace(None)
    assert ns["hits"] == [1, 2]
    assert stops == [(str(path), 6, "seq@dbg.py:4#2")]


# -- every mode reports misuse at the user's line; debuggers and coverage see branch lines -------------


def test_import_hook_reports_misuse_with_file_and_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pkg = tmp_path / "bad_hooked_pkg"
    pkg.mkdir()
    _write(pkg / "__init__.py", "")
    _write(pkg / "returns.py", HEADER + "def f():\n    with par as s:\n        return 1\n")
    _write(pkg / "empty.py", HEADER + "with par(errors) as s:\n    pass\n")
    _write(pkg / "broken.py", HEADER + "with par as s:\n    x = (\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    installed = install_import_hook()
    try:
        for name, line, match in (
            ("returns", 5, "`return` is not allowed"),
            ("empty", 3, "has no statements"),
            ("broken", 4, "never closed"),
        ):
            with pytest.raises(SyntaxError, match=match) as info:
                importlib.import_module(f"bad_hooked_pkg.{name}")
            assert (info.value.filename, info.value.lineno) == (str(pkg / f"{name}.py"), line)
    finally:
        if installed:
            uninstall_import_hook()
        for name in [m for m in sys.modules if m.startswith("bad_hooked_pkg")]:
            sys.modules.pop(name, None)


def test_plan_reports_an_empty_block_and_a_non_fluent_whenever_at_the_user_line() -> None:
    with pytest.raises(SyntaxError, match="has no statements") as info:

        @plan
        def empty() -> None:
            with par as s:
                pass

    assert info.value.filename == __file__ and "with par as s:" in (info.value.text or "")

    @plan
    def not_a_fluent() -> None:
        with whenever(42):  # marker: non-fluent whenever
            x = 1

    line = _line_of("# marker: non-fluent whenever")
    with pytest.raises(TypeError, match=rf"test_block_syntax.py:{line} needs a Fluent, got int"):
        not_a_fluent()


def test_plan_tracebacks_and_task_names_point_at_the_user_lines() -> None:
    @plan
    def failing() -> list:
        errors = []
        with par(errors) as s:  # marker: traceback par
            x = 1
            {}["missing"]  # marker: traceback failure
        return errors

    (error,) = failing()
    frame = traceback.extract_tb(error.__traceback__)[-1]
    par_line = _line_of("# marker: traceback par")
    assert (frame.filename, frame.lineno, frame.name) == (
        __file__,
        _line_of("# marker: traceback failure"),
        f"par@test_block_syntax.py:{par_line}#2",
    )
    assert frame.line.startswith('{}["missing"]')
    task = current_task().children[-1]
    assert task.name == f"par@test_block_syntax.py:{par_line}" and task.children[1].name.endswith("#2")


def test_a_branch_that_is_a_single_call_is_named_after_the_callee() -> None:
    def grab_item():
        return "grabbed"

    class ProcessModule:  # stands in for pycram's: only the call's shape matters for the name
        @staticmethod
        def perform(designator):
            return designator

    def motion(**properties):
        return properties

    @plan
    def fetch() -> None:
        with par:  # marker: names par
            grab_item()  # marker: names grab
            ProcessModule.perform([("type", "moving"), ("pose", (1, 2, 0))])
            pose = motion(type="looking", target="cup")
            if True:  # marker: names block
                x = 1
                grab_item()
        with seq:
            grab_item()  # marker: names step

    fetch()
    seq_task = current_task().children[-1]
    par_task = current_task().children[-2]
    here = "test_block_syntax.py"
    branches = [(b.name, b.location) for b in par_task.children]
    assert branches == [
        ("grab_item", f"{here}:{_line_of('# marker: names grab')}"),
        ("perform moving", f"{here}:{_line_of('# marker: names grab') + 1}"),
        ("motion looking", f"{here}:{_line_of('# marker: names grab') + 2}"),
        (f"par@{here}:{_line_of('# marker: names par')}#4", f"{here}:{_line_of('# marker: names block')}"),
    ]
    assert [(t.name, t.kind, t.location) for t in seq_task.children] == [
        ("grab_item", "step", f"{here}:{_line_of('# marker: names step')}")
    ]
    assert par_task.name == f"par@{here}:{_line_of('# marker: names par')}"  # the expression keeps its place


def _line_of(marker: str) -> int:
    """The line of this file that holds `marker` (once, besides this lookup's own argument)."""
    lines = [
        i
        for i, text in enumerate(Path(__file__).read_text().splitlines(), 1)
        if marker in text and "_line_of(" not in text
    ]
    assert len(lines) == 1, lines
    return lines[0]


def test_pdb_breakpoint_inside_a_par_branch_in_a_worker_thread(tmp_path: Path) -> None:
    path = _write(
        tmp_path / "pdb_plan.py",
        HEADER
        + "with par as s:\n    if True:\n        answer = 41 + 1\n        breakpoint()\n        after = answer\n    other = 1\n",
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONBREAKPOINT": "pdb.set_trace"}
    proc = subprocess.run(
        [sys.executable, "-m", "pycram", str(path)],
        input="p answer\nwhere\nnext\np after\ncontinue\n",
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    out = proc.stdout
    assert f"> {path}(7)par@pdb_plan.py:3#1()" in out  # stopped at the user's next line, in the branch
    assert "42" in out.split("(Pdb)")[1]  # `p answer` reads the branch's variable
    assert f"{path}(7)par@pdb_plan.py:3#1()" in out.split("(Pdb)")[2]  # `where` shows the user's frame
    assert "*** NameError" not in out.split("(Pdb)")[4] and "42" in out.split("(Pdb)")[4]  # `next` ran line 7


def test_coverage_style_line_tracing_sees_branch_lines_in_every_thread(tmp_path: Path) -> None:
    """coverage.py (like the standard `trace` module used here) records lines through
    sys.settrace/threading.settrace: branch bodies must be attributed to the user's lines."""
    path = _write(
        tmp_path / "covered.py",
        HEADER
        + "out = []\nwith par as s:\n    out.append(1)\n    if True:\n        out.append(2)\n        out.append(3)\nwith seq as t:\n    out.append(4)\n",
    )
    code = (
        "import json, sys, trace\n"
        "from pycram.macros import run_script\n"
        "tracer = trace.Trace(count=1, trace=0)\n"
        f"tracer.runctx({f'run_script({str(path)!r})'!r}, globals(), locals())\n"
        f"lines = sorted(line for (name, line) in tracer.results().counts if name == {str(path)!r})\n"
        "print(json.dumps(lines))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert proc.returncode == 0, proc.stderr
    lines = set(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert set(range(3, 11)) <= lines  # every statement, in the main thread and in the branch threads


def test_debugger_breakpoint_on_a_line_of_a_concurrent_branch(tmp_path: Path) -> None:
    """A breakpoint set in the debugger (not `breakpoint()`) on a line of a `par` branch stops
    there although the branch runs in a worker thread: branches inherit the debugger's tracer."""
    import bdb

    path = _write(
        tmp_path / "dbg_par.py",
        HEADER + "hits = []\nwith par as s:\n    hits.append(1)\n    hits.append(2)\nafter = 3\n",
    )
    stops: list[tuple[int, str, bool]] = []

    class Recorder(bdb.Bdb):
        def user_line(self, frame: types.FrameType) -> None:
            if self.break_here(frame):
                stops.append(
                    (frame.f_lineno, frame.f_code.co_name, threading.current_thread() is threading.main_thread())
                )
            self.set_continue()

    debugger = Recorder()
    assert debugger.set_break(str(path), 6) is None and debugger.set_break(str(path), 7) is None
    code = compile_source(path.read_text(), str(path))
    ns: dict[str, Any] = {"__name__": "dbg_par"}
    try:
        debugger.runctx(code, ns, ns)
    finally:
        sys.settrace(None)
    assert sorted(ns["hits"]) == [1, 2] and ns["after"] == 3
    assert (6, "par@dbg_par.py:4#2", False) in stops  # in the branch's worker thread
    assert (7, "<module>", True) in stops  # and the main thread still stops after the block
    par(lambda: None, lambda: None)  # workers are reused: they must not carry the tracer on
    assert sys.gettrace() is None
