"""Draw docs/layers.png: PyCRAM's layers (from the import-linter contracts in pyproject.toml)
and how many imports go from each layer to each other one (measured with grimp).

Usage: ``.venv/bin/python scripts/layers_picture.py [OUTPUT]`` (default ``docs/layers.png``).
The stack on the left is the layers contract, top (apps) to bottom (core); the matrix on the
right counts the import statements from a module of the row's layer to a module of the column's
layer. The layering holds when every count sits right of the diagonal: a layer only imports the
layers below it.
"""

from __future__ import annotations

import sys
import tomllib
from collections import Counter
from pathlib import Path

import grimp
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

#: What each layer holds, one line each (the picture's labels).
WHAT = {
    "pycram.apps": "CLI, thesis demo, scenarios, experiments",
    "pycram.trace": "run database, pictures",
    "pycram.robots": "descriptions, common resolvers and modules",
    "pycram.backends": "simulator (MuJoCo) | ROS 1",
    "pycram.actions": "robot-agnostic plans",
    "pycram.reasoning": "location reasoning",
    "pycram.environments": "environments as data",
    "pycram.world": "belief, objects, scenes, prospection",
    "pycram.execution": "process modules, robot, failures",
    "pycram.designators": "designators, resolver sets",
    "pycram.core": "fluents, tasks, plan language",
}


def layers() -> list[str]:
    """The layers contract of pyproject.toml, top to bottom."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    for contract in config["tool"]["importlinter"]["contracts"]:
        if contract["type"] == "layers":
            return list(contract["layers"])
    raise SystemExit("pyproject.toml has no import-linter layers contract")


def layer_of(module: str, names: list[str]) -> str | None:
    for name in names:
        if module == name or module.startswith(name + "."):
            return name
    return None


def import_counts(names: list[str]) -> Counter[tuple[str, str]]:
    """(importer layer, imported layer) -> number of module-to-module imports between them."""
    graph = grimp.build_graph("pycram", exclude_type_checking_imports=True)
    counts: Counter[tuple[str, str]] = Counter()
    for module in graph.modules:
        source = layer_of(module, names)
        if source is None:
            continue
        for imported in graph.find_modules_directly_imported_by(module):
            target = layer_of(imported, names)
            if target is not None and target != source:
                counts[(source, target)] += 1
    return counts


def draw(output: Path) -> None:
    names = layers()
    counts = import_counts(names)
    n = len(names)
    fig, (stack, matrix) = plt.subplots(1, 2, figsize=(15, 6.8), gridspec_kw={"width_ratios": [1, 1.35]})
    for i, name in enumerate(names):
        y = n - 1 - i
        stack.add_patch(plt.Rectangle((0, y + 0.08), 1, 0.84, color=plt.cm.viridis(0.15 + 0.75 * i / n), alpha=0.85))
        stack.text(0.03, y + 0.58, name.removeprefix("pycram.") + "/", fontsize=12, weight="bold", color="white")
        stack.text(0.03, y + 0.24, WHAT.get(name, ""), fontsize=9.5, color="white")
    stack.annotate(
        "", xy=(1.06, 0.1), xytext=(1.06, n - 0.1), arrowprops={"arrowstyle": "->", "lw": 1.5, "color": "0.3"}
    )
    stack.text(1.09, n / 2, "imports only\nlayers below", rotation=90, va="center", fontsize=10, color="0.3")
    stack.set_xlim(0, 1.2)
    stack.set_ylim(0, n)
    stack.axis("off")
    stack.set_title("Layers (import-linter contract, pyproject.toml)", fontsize=12)

    short = [name.removeprefix("pycram.") for name in names]
    grid = [[counts.get((a, b), 0) for b in names] for a in names]
    matrix.imshow([[min(v, 40) for v in row] for row in grid], cmap="Blues", vmin=0, vmax=40)
    for i in range(n):
        for j in range(n):
            if grid[i][j]:
                colour = "red" if j <= i else "black"  # an import of a layer above (or of itself)
                matrix.text(j, i, str(grid[i][j]), ha="center", va="center", fontsize=9, color=colour)
    matrix.plot([-0.5, n - 0.5], [-0.5, n - 0.5], color="0.6", lw=0.8)
    matrix.set_xticks(range(n), short, rotation=45, ha="right")
    matrix.set_yticks(range(n), short)
    matrix.set_xlabel("imported layer")
    matrix.set_ylabel("importing layer")
    broken = sum(grid[i][j] for i in range(n) for j in range(n) if j < i)
    matrix.set_title(f"Imports between layers (grimp): {sum(map(sum, grid))} in all, {broken} upwards", fontsize=12)
    fig.tight_layout()
    fig.savefig(output, dpi=90)
    print(f"wrote {output}")


if __name__ == "__main__":
    draw(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "layers.png")
