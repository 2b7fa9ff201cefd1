"""How many tuned numbers the action library, location reasoning and the set-table plan carry.

Issue 32 asks for fewer patches: the planner should make tuned constants unnecessary. This script
counts the *module-level tunables* -- upper-case module-level names bound to a number, or to a
tuple, list or dict of numbers (``BACK_AWAY = 0.25``, ``START_REGIONS = {...}``) -- in
``pycram/actions``, ``pycram/reasoning/locations`` and ``pycram/apps/scenarios/set_table``, and
how many of them cite a seed (the comment block above them or on their line says "seed").

    .venv/bin/python benchmarks/tunables.py [--list] [--rev GIT_REVISION]

``--rev`` counts a committed revision instead of the working tree (``git show REV:path``). The last
line reads ``tunables: N (S citing a seed)``.
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = ("pycram/actions", "pycram/reasoning/locations", "pycram/apps/scenarios/set_table")
SEED = re.compile(r"\bseeds?\b", re.IGNORECASE)


def _numeric(node: ast.AST) -> bool:
    """A number, a signed number, or a (nested) tuple, list or dict of numbers and names of them."""
    if isinstance(node, ast.Constant):
        return isinstance(node.value, (int, float)) and not isinstance(node.value, bool)
    if isinstance(node, ast.UnaryOp):
        return _numeric(node.operand)
    if isinstance(node, ast.BinOp):  # math.pi / 2, 0.5 * WIDTH
        return _numeric(node.left) or _numeric(node.right)
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return bool(node.elts) and any(_numeric(e) for e in node.elts)
    if isinstance(node, ast.Dict):
        return bool(node.values) and any(_numeric(v) for v in node.values)
    if isinstance(node, ast.Call):  # math.radians(20)
        return any(_numeric(a) for a in node.args)
    return False


def tunables(source: str) -> list[tuple[str, int, bool]]:
    """(name, line, cites a seed) of each module-level tunable in ``source``."""
    lines = source.splitlines()
    found = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        elif isinstance(node, ast.AnnAssign) and node.value is not None:
            targets, value = [node.target], node.value
        else:
            continue
        names = [t.id for t in targets if isinstance(t, ast.Name) and t.id.isupper() and not t.id.startswith("__")]
        if not names or not _numeric(value):
            continue
        first = node.lineno - 1
        while first > 0 and lines[first - 1].lstrip().startswith("#"):
            first -= 1
        text = "\n".join(lines[first : node.end_lineno or node.lineno])
        found += [(name, node.lineno, bool(SEED.search(text))) for name in names]
    return found


def sources(rev: str | None) -> dict[str, str]:
    """Path -> source of every Python file under `FOLDERS`, in the working tree or at ``rev``."""
    if rev is None:
        return {str(p.relative_to(ROOT)): p.read_text() for f in FOLDERS for p in sorted((ROOT / f).rglob("*.py"))}
    listing = subprocess.run(
        ["git", "ls-tree", "-r", "--name-only", rev, "--", *FOLDERS],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return {
        path: subprocess.run(
            ["git", "show", f"{rev}:{path}"], cwd=ROOT, capture_output=True, text=True, check=True
        ).stdout
        for path in listing
        if path.endswith(".py")
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="list every tunable")
    parser.add_argument("--rev", help="count a git revision instead of the working tree")
    args = parser.parse_args(argv)
    total = seeded = 0
    for path, source in sources(args.rev).items():
        found = tunables(source)
        total += len(found)
        seeded += sum(s for _, _, s in found)
        if args.list:
            for name, line, seed in found:
                print(f"{path}:{line}: {name}{'  (cites a seed)' if seed else ''}")
        elif found:
            print(f"{path}: {len(found)} ({sum(s for _, _, s in found)} citing a seed)")
    print(f"tunables: {total} ({seeded} citing a seed)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
