"""The thesis' block syntax (`with par(errors) as s:` ...) as a source transform.

The thesis wrote plans as MacroPy block macros. MacroPy no longer runs on current Python, so
PyCRAM rewrites the syntax itself: an AST transform turns every recognised block into a call of
the functional form of `pycram.language` (one runtime; the syntax is only a front end).

Forms (thesis ch. 3.2.2-3.2.3, 4.2.3)::

    with seq as s: / with seq(errors) as s:          -> language.seq(b1, b2, ...)
    with par / pursue / try_all / try_in_order ...   -> language.par(b1, b2, ...) etc.
    with failure_handling(5): / (): / bare           -> language.failure_handling(body, 5)
    with whenever(fluent):                           -> for _ in fluent.whenever(fluent): ...

Guarantees of the transform:

* Each top-level statement of an expression block becomes one branch (a nested function);
  `if True:` blocks and nested blocks group statements into one branch.
* The `as` name is bound to a fresh state Fluent *before* the branches start and is passed as
  `state=`; a branch can read `s.get_value()`.
* `errors`: any expression that evaluates to a list; errors are appended to it. As in the
  thesis (where the macro assigned the variable) a bare name that is still *unbound* when the
  block starts is bound to a new list, in the block's scope: at module level always; in a
  function when the name is local to it (assigned somewhere in it) or refers to nothing at
  all when the code is transformed (then it becomes a local of the function). A name that
  refers to a global or closure variable is only read: that list is used.
* Branch code reads and assigns the variables of the enclosing function (via `nonlocal`) or
  module (via `global`); assignments made in a branch are visible after the block. A name that
  is only assigned inside a branch becomes a local of the enclosing function, exactly as if the
  block ran inline (reading it before any branch assigned it raises UnboundLocalError).
* `return`, `yield`, `await`, `global`/`nonlocal` and a `break`/`continue` that would leave a
  branch are rejected at transform time with a SyntaxError naming file and line, with one
  exception: a bare `return` inside a `whenever` body leaves the `whenever` loop. When the
  `whenever` is inline (not inside a branch) this also returns from the enclosing function,
  so `return value` is allowed there; inside a branch it ends that branch.
* Line numbers and the file name are the user's: tracebacks, pdb breakpoints and coverage
  work inside branches. Branch functions are named after the user's line, e.g.
  `par@demo.py:12#1` (first statement of the `par` on line 12); the expression itself gets
  `name='par@demo.py:12'`.
* `retry` inside a `failure_handling` body needs no import (as in the thesis), unless the
  module/function binds the name `retry` itself, then that binding is used.

Names are recognised by what they refer to, not by spelling: any name or attribute chain that
resolves to the `seq`/`par`/`pursue`/`try_all`/`try_in_order`/`failure_handling`/`whenever`
objects of `pycram.language`, `pycram.fluent` or `pycram` (aliases included). In scripts and
import-hooked modules this is decided from the module's import statements; for `@plan` from
the function's globals and closure.

Three ways to switch the syntax on:

1. `@plan` on a function (re-compiles the function's source; globals, closure cells, defaults
   and stacked decorators above it are kept). `@plan` must be the innermost decorator.
2. `run_script(path, argv)` — used by `pycram run demo.py` and `python -m pycram demo.py`.
   While the script runs, the import hook (3) is active too.
3. `import pycram.activate` installs an import hook. A module opts in when it imports from
   `pycram.language`, `pycram.fluent` or `pycram` at its top level (as every thesis plan
   module does); other modules are left alone. Modules imported before the hook was installed
   are not transformed. Transformed modules are compiled from source each time (no .pyc).

A `macros` name in those imports (`from pycram.language import macros, par`) is dropped by
the transform for compatibility with the thesis; it is not required.
"""

from __future__ import annotations

import ast
import builtins
import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import inspect
import linecache
import logging
import os
import sys
import tokenize
import traceback
import types
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

__all__ = [
    "NOT_ENABLED_MESSAGE",
    "plan",
    "run_script",
    "format_script_error",
    "transform_source",
    "compile_source",
    "install_import_hook",
    "uninstall_import_hook",
    "PlanFinder",
    "opts_in",
]

from pycram.core import expressions, partial_order, policy
from pycram.core.block_forms import BRANCHES

log = logging.getLogger(__name__)

try:  # the lead's placeholder objects format this message; keep one text
    from pycram.core.block_forms import NOT_ENABLED_MESSAGE
except ImportError:  # pragma: no cover - only before block_forms exists
    NOT_ENABLED_MESSAGE = (
        "`with {form}:` is PyCRAM block syntax, which is not switched on for this code. "
        "Switch it on in one of three ways: decorate the enclosing function with "
        "`@plan` (from pycram.language import plan); run the script with "
        "`pycram run FILE.py` or `python -m pycram FILE.py`; or `import pycram.activate` "
        "before importing the module that holds the plan. Without it the block would run "
        "sequentially as plain Python, so PyCRAM refuses to run it."
    )

EXPRESSION_FORMS: tuple[str, ...] = ("seq", "par", "pursue", "try_all", "try_in_order")
"""Block forms whose statements become branches of a language expression."""
FORMS: tuple[str, ...] = EXPRESSION_FORMS + ("failure_handling", "whenever", "partial_order", "with_policy")
"""Every block form the transform knows."""
PYCRAM_MODULES: tuple[str, ...] = (
    "pycram.language",
    "pycram.fluent",
    "pycram",
    "pycram.core.expressions",
    "pycram.core.fluent",
    "pycram.core.partial_order",
    "pycram.core.policy",
)
"""Modules whose form objects are recognised (a module opts in by importing from one): the
public faces and the core modules behind them."""

_P = "_pycram_"  # prefix of every generated name (single underscore: no class-name mangling)
_TRANSFORMED_MARK = "__pycram_transformed__"

F = TypeVar("F", bound=Callable[..., Any])


# --------------------------------------------------------------------------------------------
# Runtime helpers called by generated code (kept tiny; they run on every block execution).
# --------------------------------------------------------------------------------------------


def expression(form: str) -> Callable[..., Any]:
    """The functional form `pycram.language.<form>` (generated code calls it)."""
    for module in (expressions, partial_order, policy):
        if hasattr(module, form):
            return getattr(module, form)  # type: ignore[no-any-return]
    raise AttributeError(f"pycram.language has no expression {form!r}")


def new_state(name: str) -> Any:
    """A fresh, unset state fluent (holding the winning branch's `result`) for a block's `as` target."""
    from pycram.core.expressions import StateFluent

    return StateFluent(None, name)


def retry_function() -> Callable[[], Any]:
    """`pycram.language.retry`, injected into `failure_handling` bodies as `retry`."""
    return expression("retry")


def whenever_loop(fluent: Any, where: str) -> Any:
    """The iterable of `for _ in whenever(fluent)`; a non-Fluent raises TypeError naming `where`."""
    from pycram.core.fluent import Fluent, whenever

    if not isinstance(fluent, Fluent):
        raise TypeError(f"`with whenever(...)` at {where} needs a Fluent, got {type(fluent).__name__}: {fluent!r}")
    return whenever(fluent)


# --------------------------------------------------------------------------------------------
# Recognising the forms
# --------------------------------------------------------------------------------------------


def _form_table() -> dict[int, str]:
    """id(object) -> form name for the form objects of the core modules."""
    from pycram.core import fluent  # (the faces re-export these objects)

    table: dict[int, str] = {}
    for module in (expressions, partial_order, policy, fluent):
        for name in FORMS:
            obj = getattr(module, name, None)
            if obj is not None:
                table[id(obj)] = name
    return table


def _attr_chain(node: ast.expr) -> list[str] | None:
    """`a.b.c` -> ['a', 'b', 'c']; None for anything that is not a dotted name."""
    parts: list[str] = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    parts.append(node.id)
    return parts[::-1]


class _Resolver:
    """Decides which form (if any) an expression such as `par` or `L.par` refers to."""

    def __init__(self, table: dict[int, str]) -> None:
        self.table = table

    def form_of_object(self, obj: Any) -> str | None:
        return self.table.get(id(obj))

    def form_of_static(self, modname: str, attrs: Sequence[str]) -> str | None:
        """Form named by `modname.attrs[0].attrs[1]...` (modules imported only if pycram's)."""
        if not (modname == "pycram" or modname.startswith("pycram.")) or not attrs:
            return None
        *path, last = attrs
        full = ".".join([modname, *path])
        try:
            module = importlib.import_module(full)
        except Exception:  # noqa: BLE001
            module = None
        if module is not None and hasattr(module, last):
            return self.form_of_object(getattr(module, last))
        # The module is missing or still being written: fall back to the documented names.
        if full in PYCRAM_MODULES and last in FORMS:
            return last
        return None

    def resolve(self, node: ast.expr) -> str | None:  # pragma: no cover - overridden
        raise NotImplementedError

    def is_bound(self, name: str) -> bool:  # pragma: no cover - overridden
        raise NotImplementedError


class _StaticResolver(_Resolver):
    """Resolution from the import statements of a module (or a function) source."""

    def __init__(self, tree: ast.AST, table: dict[int, str]) -> None:
        super().__init__(table)
        # name -> (module, attrs): `from m import a as n` -> (m, [a]); `import m.x as n` -> (m.x, [])
        self.bindings: dict[str, tuple[str, list[str]]] = {}
        self.bound: set[str] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                for alias in node.names:
                    if alias.name == "*":
                        if node.module in PYCRAM_MODULES:
                            for form in FORMS:
                                self.bindings.setdefault(form, (node.module, [form]))
                        continue
                    self.bindings[alias.asname or alias.name] = (node.module, [alias.name])
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.asname:
                        self.bindings[alias.asname] = (alias.name, [])
                    else:
                        top = alias.name.split(".")[0]
                        self.bindings[top] = (top, [])
        if isinstance(tree, ast.Module):
            self.bound = _bound_names(tree.body) | set(self.bindings)
        else:
            self.bound = set(self.bindings)

    def resolve(self, node: ast.expr) -> str | None:
        chain = _attr_chain(node)
        if chain is None or chain[0] not in self.bindings:
            return None
        modname, attrs = self.bindings[chain[0]]
        return self.form_of_static(modname, [*attrs, *chain[1:]])

    def is_bound(self, name: str) -> bool:
        return name in self.bound


class _RuntimeResolver(_Resolver):
    """Resolution through a live function's closure, globals and builtins (for `@plan`)."""

    def __init__(self, fn: types.FunctionType, static: _StaticResolver, table: dict[int, str]) -> None:
        super().__init__(table)
        self.static = static
        self.namespace: dict[str, Any] = dict(vars(builtins))
        self.namespace.update(fn.__globals__)
        for name, cell in zip(fn.__code__.co_freevars, fn.__closure__ or ()):
            try:
                self.namespace[name] = cell.cell_contents
            except ValueError:  # empty cell
                pass

    def resolve(self, node: ast.expr) -> str | None:
        chain = _attr_chain(node)
        if chain is None:
            return None
        if chain[0] in self.static.bindings:  # imported inside the function itself
            return self.static.resolve(node)
        if chain[0] not in self.namespace:
            return None
        obj = self.namespace[chain[0]]
        for attr in chain[1:]:
            if not isinstance(obj, types.ModuleType):  # never run user getattr code
                return None
            obj = getattr(obj, attr, None)
        return self.form_of_object(obj)

    def is_bound(self, name: str) -> bool:
        return name in self.namespace or self.static.is_bound(name)


# --------------------------------------------------------------------------------------------
# Scope analysis
# --------------------------------------------------------------------------------------------

_SCOPE_NODES = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)
_COMPREHENSIONS = (ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp)


def _is_generated_def(node: ast.AST) -> bool:
    return isinstance(node, ast.FunctionDef) and node.name.startswith(_P)


def _bound_names(stmts: Iterable[ast.AST]) -> set[str]:
    """Names bound in the scope that runs `stmts` (not in nested user scopes).

    Generated branch functions are transparent: what they bind is bound in the enclosing
    scope (they declare it nonlocal/global). Generated `_pycram_*` names are left out.
    """
    names: set[str] = set()

    def visit(node: ast.AST, in_comprehension: bool = False) -> None:
        if isinstance(node, ast.Name):
            if isinstance(node.ctx, (ast.Store, ast.Del)) and not in_comprehension:
                names.add(node.id)
            return
        if isinstance(node, ast.NamedExpr):  # binds in the enclosing function even in comprehensions
            if isinstance(node.target, ast.Name):
                names.add(node.target.id)
            visit(node.value, in_comprehension)
            return
        if _is_generated_def(node):
            for child in node.body:  # type: ignore[attr-defined]
                visit(child)
            return
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
            for child in node.decorator_list:
                visit(child)
            if isinstance(node, ast.ClassDef):
                for child in [*node.bases, *node.keywords]:
                    visit(child)
            else:
                for child in [*node.args.defaults, *(d for d in node.args.kw_defaults if d is not None)]:
                    visit(child)
            return
        if isinstance(node, ast.Lambda):
            for child in [*node.args.defaults, *(d for d in node.args.kw_defaults if d is not None)]:
                visit(child)
            return
        if isinstance(node, _COMPREHENSIONS):
            for child in ast.iter_child_nodes(node):
                visit(child, True)
            return
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            for alias in node.names:
                if alias.name != "*":
                    names.add(alias.asname or alias.name.split(".")[0])
            return
        if isinstance(node, ast.ExceptHandler) and node.name:
            names.add(node.name)
        elif isinstance(node, (ast.MatchAs, ast.MatchStar)) and node.name:
            names.add(node.name)
        elif isinstance(node, ast.MatchMapping) and node.rest:
            names.add(node.rest)
        for child in ast.iter_child_nodes(node):
            visit(child, in_comprehension)

    for stmt in stmts:
        visit(stmt)
    return {n for n in names if not n.startswith(_P)}


def _without_annotations_of(stmts: list[ast.stmt], names: set[str]) -> list[ast.stmt]:
    """`stmts` with annotated assignments to `names` made plain (``x: T = v`` -> ``x = v``; a
    bare ``x: T`` -> nothing): a branch declares the names it binds nonlocal or global, and Python
    refuses annotations of such names. The annotation stays in the source for type checkers."""

    class Strip(ast.NodeTransformer):
        def visit_AnnAssign(self, node: ast.AnnAssign) -> ast.stmt | None:
            if not (isinstance(node.target, ast.Name) and node.target.id in names):
                return node
            if node.value is None:
                return ast.copy_location(ast.Pass(), node)
            return ast.copy_location(ast.Assign(targets=[node.target], value=node.value), node)

        def _keep(self, node: ast.AST) -> ast.AST:  # a nested scope of the user's: its own names
            return node

        visit_FunctionDef = visit_AsyncFunctionDef = visit_ClassDef = visit_Lambda = _keep

    strip = Strip()
    out: list[ast.stmt] = []
    for stmt in stmts:
        if _is_generated_def(stmt):  # transparent: it binds in this scope too
            new = strip.generic_visit(stmt)
        else:
            new = strip.visit(stmt)
        if new is not None:
            out.append(new)  # type: ignore[arg-type]
    return out


def _declared(stmts: Iterable[ast.AST], kind: type) -> set[str]:
    """Names in `global` (kind=ast.Global) or `nonlocal` statements of this scope."""
    names: set[str] = set()
    stack = list(stmts)
    while stack:
        node = stack.pop()
        if isinstance(node, kind):
            names.update(node.names)  # type: ignore[attr-defined]
        if isinstance(node, _SCOPE_NODES):
            continue
        stack.extend(ast.iter_child_nodes(node))
    return names


def _parameters(args: ast.arguments) -> set[str]:
    params = {a.arg for a in [*args.posonlyargs, *args.args, *args.kwonlyargs]}
    if args.vararg:
        params.add(args.vararg.arg)
    if args.kwarg:
        params.add(args.kwarg.arg)
    return params


@dataclass
class _Scope:
    """The real (user) scope a block sits in; generated branch functions are transparent."""

    kind: str  # "module" | "function" | "class"
    global_names: set[str] = field(default_factory=set)
    nonlocal_names: set[str] = field(default_factory=set)
    params: set[str] = field(default_factory=set)
    local_names: set[str] = field(default_factory=set)
    hoist: set[str] = field(default_factory=set)
    first_param: str | None = None  # for rewriting zero-argument super() inside branches
    enclosing: set[str] = field(default_factory=set)  # locals of enclosing functions (closures)


# --------------------------------------------------------------------------------------------
# The transform
# --------------------------------------------------------------------------------------------


@dataclass
class _Form:
    name: str
    node: ast.With
    args: list[ast.expr]
    keywords: list[ast.keyword]
    target: ast.expr | None


def _what_it_does(stmt: ast.stmt) -> str | None:
    """A task name for a branch whose body is the single call `stmt` (also `x = call(...)`,
    `return call(...)`): the callee's name, followed by the designator type if the call names
    one (`motion(type="moving", ...)` → `motion moving`, `ProcessModule.perform(
    MotionDesignator([('type', 'moving'), ...]))` → `perform moving`). None for anything else."""
    value = getattr(stmt, "value", None) if isinstance(stmt, (ast.Expr, ast.Assign, ast.Return)) else None
    if not isinstance(value, ast.Call):
        return None
    func = value.func
    callee = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else None
    if callee is None:
        return None
    for node in ast.walk(value):
        if isinstance(node, ast.keyword) and node.arg == "type":
            kind = node.value
        elif (
            isinstance(node, (ast.Tuple, ast.List))
            and len(node.elts) == 2
            and isinstance(node.elts[0], ast.Constant)
            and node.elts[0].value == "type"
        ):
            kind = node.elts[1]
        else:
            continue
        if isinstance(kind, ast.Constant) and isinstance(kind.value, str):
            return f"{callee} {kind.value}"
    return callee


class _Transformer:
    """Rewrites recognised `with` blocks of one module / function tree (in place)."""

    def __init__(self, filename: str, resolver: _Resolver, lines: Sequence[str] | None = None) -> None:
        self.filename = filename
        self.basename = os.path.basename(filename)
        self.resolver = resolver
        self.lines = list(lines) if lines is not None else linecache.getlines(filename)
        self.names: dict[str, str] = {}  # generated def name -> nice name
        self.changed = False
        self._counter = 0

    # -- errors ---------------------------------------------------------------------------------

    def error(self, node: ast.AST, message: str) -> SyntaxError:
        lineno = getattr(node, "lineno", 1)
        text = self.lines[lineno - 1] if 0 < lineno <= len(self.lines) else None
        col = getattr(node, "col_offset", 0) + 1
        end_lineno = getattr(node, "end_lineno", None) or lineno
        end_col = (getattr(node, "end_col_offset", None) or col - 1) + 1
        if end_lineno != lineno:
            end_lineno, end_col = lineno, len(text or "") + 1
        return SyntaxError(message, (self.filename, lineno, col, text, end_lineno, end_col))

    def where(self, node: ast.AST) -> str:
        return f"{self.basename}:{node.lineno}"  # type: ignore[attr-defined]

    # -- scopes ---------------------------------------------------------------------------------

    def module(self, tree: ast.Module) -> None:
        scope = _Scope("module")
        tree.body = self.stmts(tree.body, scope)
        self._drop_macros_imports(tree)

    def function(self, node: ast.FunctionDef | ast.AsyncFunctionDef, outer: _Scope | None = None) -> None:
        scope = _Scope(
            "function",
            enclosing=(outer.enclosing | outer.local_names)
            if outer is not None and outer.kind == "function"
            else set(),
            global_names=_declared(node.body, ast.Global),
            nonlocal_names=_declared(node.body, ast.Nonlocal),
            params=_parameters(node.args),
        )
        positional = [*node.args.posonlyargs, *node.args.args]
        scope.first_param = positional[0].arg if positional else None
        scope.local_names = (_bound_names(node.body) | scope.params) - scope.global_names - scope.nonlocal_names
        node.body = self.stmts(node.body, scope)
        hoist = sorted(scope.hoist - scope.params - scope.global_names - scope.nonlocal_names)
        if hoist:
            # `if False: a = b = None` makes the names locals of this function (so the branches'
            # `nonlocal` finds them) without binding them: unbound stays unbound.
            assign = ast.Assign(targets=[ast.Name(n, ast.Store()) for n in hoist], value=ast.Constant(None))
            guard = ast.copy_location(ast.If(test=ast.Constant(False), body=[assign], orelse=[]), node)
            index = 1 if _has_docstring(node.body) else 0
            node.body.insert(index, guard)

    def stmts(self, stmts: list[ast.stmt], scope: _Scope) -> list[ast.stmt]:
        out: list[ast.stmt] = []
        for stmt in stmts:
            out.extend(self.stmt(stmt, scope))
        return out

    def stmt(self, stmt: ast.stmt, scope: _Scope) -> list[ast.stmt]:
        if isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef)):
            self.function(stmt, scope)
            return [stmt]
        if isinstance(stmt, ast.ClassDef):
            stmt.body = self.stmts(stmt.body, _Scope("class"))
            return [stmt]
        if isinstance(stmt, (ast.With, ast.AsyncWith)):
            form = self.recognise(stmt)
            if form is not None:
                if scope.kind == "class":
                    raise self.error(
                        stmt,
                        f"`with {form.name}` block syntax cannot be used directly in a class body; put it in a method",
                    )
                self.changed = True
                if form.name == "whenever":
                    return self.whenever(form, scope)
                if form.name == "failure_handling":
                    return self.failure_handling(form, scope)
                if form.name == "partial_order":
                    return self.partial_order(form, scope)
                if form.name == "with_policy":
                    return self.with_policy(form, scope)
                return self.expression(form, scope)
        for name in ("body", "orelse", "finalbody"):
            value = getattr(stmt, name, None)
            if isinstance(value, list) and value and isinstance(value[0], ast.stmt):
                setattr(stmt, name, self.stmts(value, scope))
        for handler in getattr(stmt, "handlers", ()):
            handler.body = self.stmts(handler.body, scope)
        for case in getattr(stmt, "cases", ()):
            case.body = self.stmts(case.body, scope)
        return [stmt]

    # -- recognition ----------------------------------------------------------------------------

    def recognise(self, node: ast.With | ast.AsyncWith) -> _Form | None:
        found: list[tuple[ast.withitem, str]] = []
        for item in node.items:
            head = item.context_expr.func if isinstance(item.context_expr, ast.Call) else item.context_expr
            form = self.resolver.resolve(head)
            if form is not None:
                found.append((item, form))
        if not found:
            return None
        item, form = found[0]
        if isinstance(node, ast.AsyncWith):
            raise self.error(node, f"`async with {form}` is not supported; use `with {form}`")
        if len(node.items) > 1:
            raise self.error(node, f"`with {form}` must be the only item of its `with` statement")
        call = item.context_expr
        args = list(call.args) if isinstance(call, ast.Call) else []
        keywords = list(call.keywords) if isinstance(call, ast.Call) else []
        if any(isinstance(a, ast.Starred) for a in args) or any(k.arg is None for k in keywords):
            raise self.error(call, f"`with {form}(...)` does not accept *args or **kwargs")
        return _Form(form, node, args, keywords, item.optional_vars)

    # -- validation of branch bodies --------------------------------------------------------------

    def check_branch(self, stmts: list[ast.stmt], form: str) -> None:
        """Reject statements whose meaning would change when moved into a nested function."""
        what = f"a `{form}` block"

        def visit(node: ast.AST, loops: int, in_whenever: bool) -> None:
            if isinstance(node, _SCOPE_NODES):
                return
            if isinstance(node, ast.Return):
                if in_whenever and node.value is None:
                    return
                if in_whenever:
                    raise self.error(
                        node,
                        f"`return <value>` inside a `whenever` that is a branch of {what} cannot return from the "
                        f"enclosing function; use a bare `return` to leave the loop and end the branch, and pass "
                        f"results through a variable",
                    )
                raise self.error(
                    node,
                    f"`return` is not allowed inside {what}: each statement runs as its own branch (a task), so it "
                    f"cannot return from the enclosing function. Assign a variable in the branch and return after "
                    f"the block",
                )
            if isinstance(node, (ast.Yield, ast.YieldFrom, ast.Await)):
                kind = "await" if isinstance(node, ast.Await) else "yield"
                raise self.error(
                    node, f"`{kind}` is not allowed inside {what}: its statements run as separate branches (tasks)"
                )
            if isinstance(node, (ast.Global, ast.Nonlocal)):
                kind = "global" if isinstance(node, ast.Global) else "nonlocal"
                raise self.error(
                    node, f"`{kind}` is not allowed inside {what}; declare it at the top of the enclosing function"
                )
            if isinstance(node, (ast.Break, ast.Continue)) and loops == 0:
                kind = "break" if isinstance(node, ast.Break) else "continue"
                raise self.error(
                    node,
                    f"`{kind}` inside {what} cannot leave the block: its statements run as separate branches (tasks)",
                )
            if isinstance(node, ast.With):
                inner = self.recognise(node)
                if inner is not None:
                    if inner.name == "whenever":
                        for child in node.body:
                            visit(child, loops + 1, True)
                    # other blocks become branches of their own and are checked when transformed
                    return
            if isinstance(node, (ast.For, ast.AsyncFor, ast.While)):
                for child in node.body:
                    visit(child, loops + 1, in_whenever)
                for child in node.orelse:
                    visit(child, loops, in_whenever)
                return
            for sub in ast.iter_child_nodes(node):
                visit(sub, loops, in_whenever)

        for stmt in stmts:
            visit(stmt, 0, False)

    def check_not_empty(self, form: _Form) -> None:
        def trivial(stmt: ast.stmt) -> bool:
            return isinstance(stmt, ast.Pass) or (
                isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant) and stmt.value.value is Ellipsis
            )

        if all(trivial(s) for s in form.node.body):
            raise self.error(
                form.node,
                f"`with {form.name}` block has no statements; each statement of the block is one "
                f"{'step' if form.name in ('seq', 'try_in_order') else 'branch'}",
            )

    # -- code generation --------------------------------------------------------------------------

    def _located(self, nodes: list[ast.stmt], where: ast.AST) -> list[ast.stmt]:
        """Put every node of generated `nodes` on the first line of `where` (the user's `with`).

        The end position is the same line too: CPython attributes some instructions (attribute
        loads) to a node's end line, and a debugger must not see the block's last line here.
        """
        lineno = where.lineno  # type: ignore[attr-defined]
        col = where.col_offset  # type: ignore[attr-defined]
        text = self.lines[lineno - 1] if 0 < lineno <= len(self.lines) else ""
        end_col = max(len(text.rstrip().encode("utf-8")), col + 1)
        for node in nodes:
            for child in ast.walk(node):
                if "lineno" in child._attributes:
                    child.lineno, child.col_offset = lineno, col  # type: ignore[attr-defined]
                    child.end_lineno, child.end_col_offset = lineno, end_col  # type: ignore[attr-defined]
        return nodes

    def _parse(self, code: str) -> list[ast.stmt]:
        return ast.parse(code).body

    def _fresh(self, kind: str, line: int) -> str:
        self._counter += 1
        return f"{_P}{kind}_L{line}_{self._counter}"

    def _branch_def(
        self,
        gen_name: str,
        nice: str,
        body: list[ast.stmt],
        scope: _Scope,
        where: ast.AST,
        prelude: Sequence[ast.stmt] = (),
    ) -> ast.FunctionDef:
        """A nested function running `body`; assigned names are shared with the real scope."""
        names = _bound_names(body)
        body = _without_annotations_of(body, names)
        if scope.first_param is not None:
            _explicit_super(body, scope.first_param)
        decls: list[ast.stmt] = []
        if scope.kind == "module":
            if names:
                decls.append(ast.Global(sorted(names)))
        else:
            globals_ = sorted(names & scope.global_names)
            nonlocals = sorted(names - scope.global_names)
            if globals_:
                decls.append(ast.Global(globals_))
            if nonlocals:
                decls.append(ast.Nonlocal(nonlocals))
                scope.hoist.update(nonlocals)
        self._located([*decls], where)
        fn = ast.FunctionDef(
            name=gen_name,
            args=ast.arguments(
                posonlyargs=[], args=[], vararg=None, kwonlyargs=[], kw_defaults=[], kwarg=None, defaults=[]
            ),
            body=[*decls, *prelude, *body],
            decorator_list=[],
            returns=None,
            type_comment=None,
        )
        header = self._located([ast.Pass()], where)[0]  # the def's own position; its body stays the user's
        ast.copy_location(fn, header)
        self.names[gen_name] = nice
        return fn

    def _single_arg(self, form: _Form, keyword: str) -> ast.expr | None:
        if len(form.args) > 1 or any(k.arg != keyword for k in form.keywords) or (form.args and form.keywords):
            raise self.error(form.node, f"`with {form.name}(...)` takes at most one argument ({keyword})")
        if form.args:
            return form.args[0]
        if form.keywords:
            return form.keywords[0].value
        return None

    def expression(self, form: _Form, scope: _Scope) -> list[ast.stmt]:
        node = form.node
        line = node.lineno
        self.check_not_empty(form)
        self.check_branch(node.body, form.name)
        errors = self._single_arg(form, "errors")
        label = f"{form.name}@{self.basename}:{line}"
        out: list[ast.stmt] = self._parse("import pycram.core.macros as _pycram_rt")
        state = self._fresh("state", line)
        out += self._parse(f"{state} = _pycram_rt.new_state({label!r})")
        if form.target is not None:
            if not isinstance(form.target, (ast.Name, ast.Attribute, ast.Subscript)):
                raise self.error(
                    form.target, f"`with {form.name} as ...` needs a name (or attribute) to bind the state fluent to"
                )
            out.append(ast.Assign(targets=[form.target], value=ast.Name(state, ast.Load())))
        errors_expr: ast.expr = ast.Constant(None)
        if errors is not None:
            tmp = self._fresh("errors", line)
            if isinstance(errors, ast.Name) and (
                scope.kind == "module"
                or errors.id in scope.local_names
                or errors.id in scope.global_names
                or (
                    errors.id not in scope.nonlocal_names
                    and errors.id not in scope.enclosing
                    and not self.resolver.is_bound(errors.id)
                )
            ):
                out += self._parse(f"try:\n    {tmp} = {errors.id}\nexcept NameError:\n    {tmp} = {errors.id} = []")
            else:
                out.append(ast.Assign(targets=[ast.Name(tmp, ast.Store())], value=errors))
            errors_expr = ast.Name(tmp, ast.Load())
        self._located(out, node)
        branch_names: list[str] = []
        for index, stmt in enumerate(node.body, 1):
            BRANCHES[(self.filename, f"{label}#{index}")] = (_what_it_does(stmt), f"{self.basename}:{stmt.lineno}")
            body = self.stmt(stmt, scope)
            gen = self._fresh(form.name, line)
            out.append(self._branch_def(gen, f"{label}#{index}", body, scope, node))
            branch_names.append(gen)
        call = ast.Expr(
            ast.Call(
                func=ast.Call(
                    ast.Attribute(ast.Name("_pycram_rt", ast.Load()), "expression", ast.Load()),
                    [ast.Constant(form.name)],
                    [],
                ),
                args=[ast.Name(n, ast.Load()) for n in branch_names],
                keywords=[
                    ast.keyword("errors", errors_expr),
                    ast.keyword("state", ast.Name(state, ast.Load())),
                    ast.keyword("name", ast.Constant(label)),
                ],
            )
        )
        out += self._located([call], node)
        return out

    def partial_order(self, form: _Form, scope: _Scope) -> list[ast.stmt]:
        """`with partial_order(orderings[, errors]) as s:` — each statement is step 1, 2, ...;
        generated as `expression("partial_order")([b1, b2, ...], orderings, errors=..., state=s)`."""
        orderings = form.args[0] if form.args else None
        rest = form.args[1:]
        keywords = [k for k in form.keywords if k.arg != "orderings"]
        orderings = orderings or next((k.value for k in form.keywords if k.arg == "orderings"), None)
        if orderings is None:
            raise self.error(form.node, "`with partial_order(orderings) as s:` needs the orderings, e.g. [(1, 2)]")
        stripped = _Form(form.name, form.node, rest, keywords, form.target)
        out = self.expression(stripped, scope)
        call = out[-1].value  # type: ignore[attr-defined]
        call.args = [ast.List(elts=call.args, ctx=ast.Load()), orderings]
        self._located([out[-1]], form.node)
        return out

    def with_policy(self, form: _Form, scope: _Scope) -> list[ast.stmt]:
        """`with with_policy(policy, *params):` — the block is the body; generated as
        `expression("with_policy")(policy, body, *params)`."""
        node = form.node
        line = node.lineno
        if form.target is not None:
            raise self.error(node, "`with with_policy(...)` does not bind a value; remove `as ...`")
        if not form.args or form.keywords:
            raise self.error(
                node, "`with with_policy(policy, *params):` needs the policy and positional parameters only"
            )
        self.check_not_empty(form)
        self.check_branch(node.body, form.name)
        label = f"with_policy@{self.basename}:{line}"
        out: list[ast.stmt] = self._located(self._parse("import pycram.core.macros as _pycram_rt"), node)
        body = self.stmts(node.body, scope)
        gen = self._fresh("with_policy", line)
        out.append(self._branch_def(gen, label, body, scope, node))
        call = ast.Expr(
            ast.Call(
                func=ast.Call(
                    ast.Attribute(ast.Name("_pycram_rt", ast.Load()), "expression", ast.Load()),
                    [ast.Constant("with_policy")],
                    [],
                ),
                args=[form.args[0], ast.Name(gen, ast.Load()), *form.args[1:]],
                keywords=[],
            )
        )
        out += self._located([call], node)
        return out

    def failure_handling(self, form: _Form, scope: _Scope) -> list[ast.stmt]:
        node = form.node
        line = node.lineno
        if form.target is not None:
            raise self.error(node, "`with failure_handling(...)` does not bind a value; remove `as ...`")
        self.check_not_empty(form)
        self.check_branch(node.body, form.name)
        limit = self._single_arg(form, "max_retries")
        label = f"failure_handling@{self.basename}:{line}"
        out: list[ast.stmt] = self._located(self._parse("import pycram.core.macros as _pycram_rt"), node)
        prelude: list[ast.stmt] = []
        if not self.resolver.is_bound("retry"):
            prelude = self._located(self._parse("retry = _pycram_rt.retry_function()"), node)
        body = self.stmts(node.body, scope)
        gen = self._fresh("failure_handling", line)
        out.append(self._branch_def(gen, label, body, scope, node, prelude))
        args: list[ast.expr] = [ast.Name(gen, ast.Load())]
        if limit is not None:
            args.append(limit)
        call = ast.Expr(
            ast.Call(
                func=ast.Call(
                    ast.Attribute(ast.Name("_pycram_rt", ast.Load()), "expression", ast.Load()),
                    [ast.Constant("failure_handling")],
                    [],
                ),
                args=args,
                keywords=[ast.keyword("name", ast.Constant(label))],
            )
        )
        out += self._located([call], node)
        return out

    def whenever(self, form: _Form, scope: _Scope) -> list[ast.stmt]:
        node = form.node
        if form.target is not None:
            raise self.error(node, "`with whenever(fluent)` does not bind a value; remove `as ...`")
        if len(form.args) != 1 or form.keywords:
            raise self.error(node, "`with whenever(fluent)` needs exactly one argument: the fluent to wait for")
        self.check_not_empty(form)
        out: list[ast.stmt] = self._parse(
            f"import pycram.core.macros as _pycram_rt\nfor _pycram_pulse in _pycram_rt.whenever_loop(_pycram_fluent, "
            f"{self.where(node)!r}):\n    pass"
        )
        loop = out[1]
        assert isinstance(loop, ast.For)
        self._located(out, node)
        loop.iter.args[0] = form.args[0]  # type: ignore[attr-defined]
        loop.body = self.stmts(node.body, scope)
        return out

    # -- compatibility --------------------------------------------------------------------------

    def _drop_macros_imports(self, tree: ast.Module) -> None:
        """Drop `macros` from `from pycram.language import macros, ...` (thesis compatibility)."""
        for node in ast.walk(tree):
            for field_name in ("body", "orelse", "finalbody"):
                stmts = getattr(node, field_name, None)
                if not isinstance(stmts, list):
                    continue
                for i, stmt in enumerate(stmts):
                    if isinstance(stmt, ast.ImportFrom) and stmt.level == 0 and stmt.module in PYCRAM_MODULES:
                        kept = [a for a in stmt.names if a.name != "macros"]
                        if len(kept) != len(stmt.names):
                            mod = importlib.import_module(stmt.module) if stmt.module else None
                            if mod is not None and hasattr(mod, "macros"):
                                continue  # the module provides it: leave the import alone
                            stmt.names = kept
                            if not kept:
                                stmts[i] = ast.copy_location(ast.Pass(), stmt)


def _explicit_super(stmts: list[ast.stmt], first_param: str) -> None:
    """Rewrite zero-argument `super()` (which needs the method's frame) to `super(__class__, self)`."""
    stack: list[ast.AST] = list(stmts)
    while stack:
        node = stack.pop()
        if isinstance(node, _SCOPE_NODES) and not _is_generated_def(node):
            continue
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id == "super"
            and not node.args
            and not node.keywords
        ):
            node.args = [
                ast.copy_location(ast.Name("__class__", ast.Load()), node),
                ast.copy_location(ast.Name(first_param, ast.Load()), node),
            ]
        stack.extend(ast.iter_child_nodes(node))


def _has_docstring(body: list[ast.stmt]) -> bool:
    return (
        bool(body)
        and isinstance(body[0], ast.Expr)
        and isinstance(body[0].value, ast.Constant)
        and isinstance(body[0].value.value, str)
    )


def _rename_code(
    code: types.CodeType, names: Mapping[str, str], qualname_fix: tuple[str, str] | None = None
) -> types.CodeType:
    """Give generated branch code objects their helpful names (recursively, at compile time)."""
    consts = tuple(_rename_code(c, names, qualname_fix) if isinstance(c, types.CodeType) else c for c in code.co_consts)
    changes: dict[str, Any] = {}
    if any(a is not b for a, b in zip(consts, code.co_consts)):
        changes["co_consts"] = consts
    qualname = code.co_qualname
    if qualname_fix is not None and qualname.startswith(qualname_fix[0]):
        qualname = qualname_fix[1] + qualname[len(qualname_fix[0]) :]
    if code.co_name in names:
        nice = names[code.co_name]
        changes["co_name"] = nice
        qualname = qualname[: len(qualname) - len(code.co_name)] + nice
    if qualname != code.co_qualname:
        changes["co_qualname"] = qualname
    return code.replace(**changes) if changes else code


# --------------------------------------------------------------------------------------------
# Public entry points
# --------------------------------------------------------------------------------------------


def transform_source(source: str, filename: str = "<plan>") -> tuple[ast.Module, dict[str, str]]:
    """Parse `source` and rewrite its block forms.

    Returns the transformed tree (with the user's line numbers) and the map of generated
    function names to their display names. Raises SyntaxError (with `filename` and the
    user's line) for syntax errors and misuse of the block forms.
    """
    tree = ast.parse(source, filename)
    resolver = _StaticResolver(tree, _form_table())
    transformer = _Transformer(filename, resolver, source.splitlines(True))
    transformer.module(tree)
    ast.fix_missing_locations(tree)
    return tree, transformer.names


def compile_source(source: str, filename: str) -> types.CodeType:
    """Transform and compile a module's source; code objects carry `filename` and the user's lines."""
    tree, names = transform_source(source, filename)
    code = compile(tree, filename, "exec", dont_inherit=True)
    return _rename_code(code, names)


def plan(fn: F) -> F:
    """Decorator: switch on the block syntax in the body of `fn`.

    The function is re-compiled from its source (same file name and line numbers) and rebuilt
    with the original globals, closure cells, defaults, keyword defaults, annotations, doc and
    attributes. Decorators stacked *above* `@plan` apply as usual; `@plan` must be the
    innermost decorator (directly above `def`). A function without block forms is returned
    unchanged. Functions in modules already transformed by the import hook or `run_script`
    are returned unchanged.

    Raises TypeError if `fn` is not a plain function or its source is unavailable, and
    SyntaxError (with the user's file and line) for misuse of the block forms.
    """
    if isinstance(fn, (staticmethod, classmethod)):
        return type(fn)(plan(fn.__func__))
    if not isinstance(fn, types.FunctionType):
        raise TypeError(f"@plan needs a function defined with `def`, got {type(fn).__name__}")
    if fn.__globals__.get(_TRANSFORMED_MARK):
        return fn
    if getattr(fn, "__wrapped__", None) is not None:
        raise TypeError(
            f"@plan must be the innermost decorator (directly above `def {fn.__name__}`): it re-compiles the "
            f"function's source"
        )
    if fn.__name__ == "<lambda>":
        raise TypeError("@plan cannot be applied to a lambda; use `def`")
    code = fn.__code__
    filename = code.co_filename
    try:
        lines, start = inspect.getsourcelines(fn)
    except (OSError, TypeError) as exc:
        raise TypeError(
            f"@plan cannot find the source of {fn.__qualname__} ({filename}); the block syntax needs source code. "
            f"Use the functional forms (par(f1, f2, ...)) instead"
        ) from exc
    source = "".join(lines)
    indented = bool(lines) and lines[0][:1] in (" ", "\t")
    offset = start - 1
    if indented:  # parse inside `if 1:` so that columns stay the file's columns
        source = "if 1:\n" + source
        offset -= 1
    tree = ast.parse(source, filename)
    ast.increment_lineno(tree, offset)
    fdef = tree.body[0].body[0] if indented else tree.body[0]  # type: ignore[attr-defined]
    if not isinstance(fdef, (ast.FunctionDef, ast.AsyncFunctionDef)) or fdef.name != fn.__name__:
        raise TypeError(f"@plan could not locate `def {fn.__name__}` in its source at {filename}:{start}")
    table = _form_table()
    static = _StaticResolver(fdef, table)
    resolver = _RuntimeResolver(fn, static, table)
    transformer = _Transformer(filename, resolver)
    # Defaults, annotations and decorators were evaluated already: keep the originals instead.
    fdef.decorator_list = []
    fdef.returns = None
    fdef.args.defaults = []
    fdef.args.kw_defaults = [None] * len(fdef.args.kwonlyargs)
    for arg in [*fdef.args.posonlyargs, *fdef.args.args, *fdef.args.kwonlyargs, fdef.args.vararg, fdef.args.kwarg]:
        if arg is not None:
            arg.annotation = None
    transformer.function(fdef)
    if not transformer.changed:
        return fn
    freevars = code.co_freevars
    factory = ast.FunctionDef(
        name=f"{_P}factory",
        args=ast.arguments(
            posonlyargs=[],
            args=[ast.arg(n) for n in freevars],
            vararg=None,
            kwonlyargs=[],
            kw_defaults=[],
            kwarg=None,
            defaults=[],
        ),
        body=[fdef, ast.Return(ast.Name(fdef.name, ast.Load()))],
        decorator_list=[],
        returns=None,
        type_comment=None,
    )
    ast.copy_location(factory, fdef)
    module = ast.Module(body=[factory], type_ignores=[])
    ast.fix_missing_locations(module)
    module_code = compile(module, filename, "exec", dont_inherit=True)
    factory_code = next(c for c in module_code.co_consts if isinstance(c, types.CodeType))
    inner = next(c for c in factory_code.co_consts if isinstance(c, types.CodeType) and c.co_name == fn.__name__)
    inner = _rename_code(inner, transformer.names, (f"{_P}factory.<locals>.{fn.__name__}", fn.__qualname__))
    cells = dict(zip(freevars, fn.__closure__ or ()))
    closure = tuple(cells.get(name) or types.CellType() for name in inner.co_freevars)
    new = types.FunctionType(inner, fn.__globals__, fn.__name__, fn.__defaults__, closure or None)
    new.__kwdefaults__ = fn.__kwdefaults__
    new.__annotations__ = fn.__annotations__
    new.__dict__.update(fn.__dict__)
    new.__doc__ = fn.__doc__
    new.__module__ = fn.__module__
    new.__qualname__ = fn.__qualname__
    new.__pycram_plan__ = True  # type: ignore[attr-defined]
    log.debug("@plan re-compiled %s from %s:%d", fn.__qualname__, filename, start)
    return new  # type: ignore[return-value]


def run_script(path: str | os.PathLike[str], argv: Sequence[str] = (), *, activate: bool = True) -> dict[str, Any]:
    """Run a plan script as `__main__` with the block syntax switched on.

    `sys.argv` is `[path, *argv]` and the script's directory is put first on `sys.path` while it
    runs (like `python script.py`). With `activate` the import hook is installed for the run,
    so plan modules the script imports are transformed too. Returns the script's globals.
    Exceptions from the script propagate unchanged (tracebacks point at the script's lines);
    sys.argv, sys.path, sys.modules['__main__'] and the hook are restored afterwards.
    """
    filename = os.fspath(path)
    with tokenize.open(filename) as f:  # honours PEP 263 encoding declarations
        source = f.read()
    code = compile_source(source, filename)
    module = types.ModuleType("__main__")
    module.__file__ = filename
    module.__builtins__ = builtins  # type: ignore[attr-defined]
    setattr(module, _TRANSFORMED_MARK, True)
    saved_argv, saved_path = sys.argv, list(sys.path)
    saved_main = sys.modules.get("__main__")
    installed = activate and install_import_hook()
    sys.argv = [filename, *argv]
    sys.path.insert(0, os.path.dirname(os.path.abspath(filename)))
    sys.modules["__main__"] = module
    try:
        exec(code, module.__dict__)
    finally:
        sys.argv = saved_argv
        sys.path[:] = saved_path
        if saved_main is not None:
            sys.modules["__main__"] = saved_main
        if installed:
            uninstall_import_hook()
    return module.__dict__


def format_script_error(error: BaseException, path: str | os.PathLike[str]) -> str:
    """The report of ``error`` raised by :func:`run_script` for the script at ``path``, as
    ``python path`` would print it: the traceback starts at the script's first frame, without
    the frames of ``run_script`` and its callers (a command line, ``runpy``). A syntax error in
    the script (also one the block-syntax transform reports) is shown without a traceback, as
    Python shows it. Chained exceptions keep their own tracebacks. An exception that did not
    pass through ``run_script`` is formatted whole.
    """
    tb = error.__traceback__
    while tb is not None and tb.tb_frame.f_code is not run_script.__code__:
        tb = tb.tb_next
    if tb is None:
        tb = error.__traceback__
    else:
        tb = tb.tb_next  # the script's module frame, or run_script's helpers (compiling it)
        in_script = tb is not None and os.path.abspath(tb.tb_frame.f_code.co_filename) == os.path.abspath(path)
        if not in_script and isinstance(error, SyntaxError):
            tb = None
    return "".join(traceback.format_exception(type(error), error, tb))


# --------------------------------------------------------------------------------------------
# Import hook
# --------------------------------------------------------------------------------------------


def opts_in(source: str) -> bool:
    """The import hook's rule: does this module import from a pycram language module at top level?

    True when a statement at the module's top level (also inside top-level `try`/`if`) is
    `from pycram.language import ...`, `from pycram.fluent import ...`, `from pycram import
    ...`, or `import pycram...`.
    """
    if "pycram" not in source:
        return False
    try:
        with warnings.catch_warnings():  # only sniffing: the module's own compile warns, if at all
            warnings.simplefilter("ignore")
            tree = ast.parse(source)
    except SyntaxError:
        return False  # let the regular loader report it
    stack: list[ast.stmt] = list(tree.body)
    while stack:
        stmt = stack.pop()
        if isinstance(stmt, ast.ImportFrom) and stmt.level == 0 and stmt.module in PYCRAM_MODULES:
            return True
        if isinstance(stmt, ast.Import) and any(a.name == "pycram" or a.name.startswith("pycram.") for a in stmt.names):
            return True
        if isinstance(stmt, (ast.If, ast.Try)):
            stack.extend(stmt.body)
            stack.extend(stmt.orelse)
            stack.extend(getattr(stmt, "finalbody", []))
            for handler in getattr(stmt, "handlers", []):
                stack.extend(handler.body)
    return False


class PlanLoader(importlib.machinery.SourceFileLoader):
    """Source loader that compiles through the block-syntax transform (never uses .pyc)."""

    def get_code(self, fullname: str) -> types.CodeType:
        path = self.get_filename(fullname)
        source = importlib.util.decode_source(self.get_data(path))
        return compile_source(source, path)

    def exec_module(self, module: types.ModuleType) -> None:
        setattr(module, _TRANSFORMED_MARK, True)
        super().exec_module(module)


class PlanFinder(importlib.abc.MetaPathFinder):
    """Meta path finder: modules that `opts_in` are loaded by `PlanLoader`; others are left alone."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: types.ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname == "pycram" or fullname.startswith("pycram."):
            return None
        spec = importlib.machinery.PathFinder.find_spec(fullname, path, target)
        if spec is None or type(spec.loader) is not importlib.machinery.SourceFileLoader or not spec.origin:
            return None
        try:
            source = importlib.util.decode_source(spec.loader.get_data(spec.origin))
        except (OSError, UnicodeDecodeError, SyntaxError):
            return None
        if not opts_in(source):
            return None
        spec.loader = PlanLoader(fullname, spec.origin)
        log.debug("block syntax: transforming module %s (%s)", fullname, spec.origin)
        return spec


def install_import_hook() -> bool:
    """Install the `PlanFinder` first on sys.meta_path; False if it was already installed."""
    if any(isinstance(f, PlanFinder) for f in sys.meta_path):
        return False
    sys.meta_path.insert(0, PlanFinder())
    return True


def uninstall_import_hook() -> None:
    """Remove every `PlanFinder` from sys.meta_path (already imported modules stay transformed)."""
    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, PlanFinder)]
