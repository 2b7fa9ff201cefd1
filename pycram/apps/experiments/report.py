"""What an experiment found: success rates, failure causes and times, as a table and a plot.

`summarize(runs)` groups the recorded runs (`pycram.apps.experiments.store.RunRecord`) by robot,
variant and environment (`by_environment=False`: over all environments); `summary_table`
renders that as a `rich` table (each success rate with its 95 % confidence interval, Wilson),
`comparisons` says which differences between groups -- variants of one robot, robots in one
variant (each in the same environment), or the same group in another experiment -- are larger
than the noise (:mod:`pycram.apps.experiments.statistics`), `write_plot` draws success rate
(with the intervals), times and failure causes into a PNG (matplotlib, the `db` extra).
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pycram.apps.experiments.statistics import compare_rates, wilson_interval

__all__ = [
    "GroupSummary",
    "summarize",
    "percentile",
    "variant_label",
    "group_label",
    "summary_table",
    "causes_table",
    "comparisons",
    "write_plot",
]


def percentile(values: Iterable[float], p: float) -> float | None:
    """The `p`-th percentile (0–100) of `values` by the nearest-rank method; None when empty."""
    ordered = sorted(v for v in values if v is not None)
    if not ordered:
        return None
    rank = max(1, math.ceil(p / 100.0 * len(ordered)))
    return ordered[min(rank, len(ordered)) - 1]


def variant_label(variant: str) -> str:
    """How a variant key reads in tables: "none", or its fault names "a,b"."""
    return variant if variant else "none"


def _natural(text: str | None) -> tuple[Any, ...]:
    """Sort key putting procedural:2 before procedural:10 (None first)."""
    if text is None:
        return ()
    return tuple(int(part) if part.isdigit() else part for part in re.split(r"(\d+)", text))


@dataclass
class GroupSummary:
    """The runs of one robot in one variant and environment: counts, success rate, times [s],
    failure causes. `environment` is None for the scenario's own, or for a group over all
    environments (`summarize(..., by_environment=False)`)."""

    robot: str
    variant: str
    environment: str | None = None
    runs: int = 0
    successes: int = 0
    errors: int = 0  # runs whose scenario raised
    sim_times: list[float] = field(default_factory=list)
    wall_times: list[float] = field(default_factory=list)
    causes: Counter[str] = field(default_factory=Counter)

    @property
    def success_rate(self) -> float:
        """Successful runs / runs (0 without runs)."""
        return self.successes / self.runs if self.runs else 0.0

    @property
    def confidence_interval(self) -> tuple[float, float]:
        """The 95 % confidence interval (Wilson) of the success rate, as fractions."""
        return wilson_interval(self.successes, self.runs)

    @property
    def real_time_factors(self) -> list[float]:
        """Simulated time / wall time of each run with both."""
        return [s / w for s, w in zip(self.sim_times, self.wall_times) if w and w > 0 and s is not None]


def group_label(group: GroupSummary) -> str:
    """How a group is named in plots and failure-cause tables: its robot, "faults: VARIANT"
    and its environment (when it has one), each on a line of its own."""
    label = f"{group.robot}\nfaults: {variant_label(group.variant)}"
    return label + (f"\n{group.environment}" if group.environment else "")


def summarize(runs: Iterable[Any], by_environment: bool = True) -> list[GroupSummary]:
    """Group recorded runs by robot, variant and (unless not `by_environment`) environment (a
    run's ``environment`` attribute; None or missing: the scenario's own), ordered by variant,
    robot and environment (procedural:2 before procedural:10)."""
    groups: dict[tuple[str, str, str | None], GroupSummary] = {}
    for run in runs:
        environment = getattr(run, "environment", None) if by_environment else None
        key = (run.robot, run.variant, environment)
        group = groups.setdefault(key, GroupSummary(run.robot, run.variant, environment))
        group.runs += 1
        group.successes += bool(run.success)
        group.errors += run.status == "error"
        if run.sim_time is not None and run.wall_time is not None:
            group.sim_times.append(run.sim_time)
            group.wall_times.append(run.wall_time)
        if not run.success:
            group.causes.update(run.failure_causes or ["unknown"])
    return sorted(groups.values(), key=lambda g: (g.variant, g.robot, _natural(g.environment)))


def _seconds(value: float | None) -> str:
    return "–" if value is None else f"{value:.1f}"


def summary_table(groups: list[GroupSummary], title: str = "") -> Any:
    """A `rich.table.Table`: per robot, variant and environment (a column when some group has
    one) the runs, success rate with its 95 % confidence interval (Wilson), simulated and wall
    time p50/p95 [s] and the median real-time factor."""
    from rich.table import Table

    environments = any(g.environment for g in groups)
    table = Table(title=title or None, header_style="bold")
    table.add_column("robot")
    table.add_column("faults", overflow="fold")
    if environments:  # names kept whole up to 24 characters (longer ones fold)
        widest = max(len(g.environment or "(its own)") for g in groups)
        table.add_column("environment", overflow="fold", min_width=min(widest, 24))
    for name in ("runs", "success\n95 % CI", "sim [s]\np50 / p95", "wall [s]\np50 / p95", "× real\ntime"):
        table.add_column(name, justify="right", no_wrap=True)
    for g in groups:
        rate = g.success_rate
        style = "green" if rate >= 0.95 else "yellow" if rate >= 0.85 else "red"
        rtf = percentile(g.real_time_factors, 50)
        low, high = g.confidence_interval
        table.add_row(
            g.robot,
            variant_label(g.variant),
            *([g.environment or "(its own)"] if environments else []),
            str(g.runs),
            f"[{style}]{100 * rate:.1f} %[/{style}] ({g.successes})\n{100 * low:.1f}-{100 * high:.1f} %",
            f"{_seconds(percentile(g.sim_times, 50))} / {_seconds(percentile(g.sim_times, 95))}",
            f"{_seconds(percentile(g.wall_times, 50))} / {_seconds(percentile(g.wall_times, 95))}",
            "–" if rtf is None else f"{rtf:.1f}",
        )
    return table


def causes_table(groups: list[GroupSummary]) -> Any:
    """A `rich.table.Table` of failure causes: how many failed runs each group (robot, variant,
    environment) had per cause (a run with several causes counts for each), most frequent first."""
    from rich.table import Table

    total: Counter[str] = Counter()
    for g in groups:
        total.update(g.causes)
    table = Table(title="failure causes", header_style="bold")
    table.add_column("cause")
    for g in groups:
        table.add_column(group_label(g), justify="right", overflow="fold")
    for cause, _ in total.most_common():
        table.add_row(cause, *(str(g.causes.get(cause, 0)) for g in groups))
    if not total:
        table.add_row("(no failures)", *("0" for _ in groups))
    return table


def comparisons(groups: list[GroupSummary], reference: list[GroupSummary] | None = None) -> list[str]:
    """Which differences of success rate are larger than the noise, one line each (difference in
    percentage points with its 95 % confidence interval, Newcombe's method):

    * with `reference` (the groups of another experiment, e.g. the same seeds on older code):
      each group against the reference's group of the same robot, variant and environment;
    * without: each robot's variants against its runs without faults ("none"), and in each
      variant the robots against each other -- each in the same environment.
    """
    lines: list[str] = []

    def line(what: str, a: GroupSummary, b: GroupSummary) -> None:
        difference = compare_rates(a.successes, a.runs, b.successes, b.runs)
        lines.append(f"{what}: {a.successes}/{a.runs} vs {b.successes}/{b.runs}, {difference.describe()}")

    def where(environment: str | None) -> str:
        return f" in {environment}" if environment else ""

    if reference is not None:
        theirs = {(g.robot, g.variant, g.environment): g for g in reference}
        for g in groups:
            other = theirs.get((g.robot, g.variant, g.environment))
            if other is not None and g.runs and other.runs:
                line(f"{g.robot}, faults {variant_label(g.variant)}{where(g.environment)}: this vs reference", g, other)
        return lines
    by_key = {(g.robot, g.variant, g.environment): g for g in groups if g.runs}
    for (robot, variant, environment), g in by_key.items():
        base = by_key.get((robot, "", environment))
        if variant and base is not None:
            line(f"{robot}: faults {variant_label(variant)} vs none{where(environment)}", g, base)
    variants = sorted({variant for _, variant, _ in by_key})
    robots = list(dict.fromkeys(robot for robot, _, _ in by_key))
    environments = sorted({environment for _, _, environment in by_key}, key=_natural)
    for variant in variants:
        for environment in environments:
            present = [r for r in robots if (r, variant, environment) in by_key]
            for i, a in enumerate(present):
                for b in present[i + 1 :]:
                    line(
                        f"faults {variant_label(variant)}{where(environment)}: {a} vs {b}",
                        by_key[(a, variant, environment)],
                        by_key[(b, variant, environment)],
                    )
    return lines


def write_plot(groups: list[GroupSummary], path: Path, title: str = "") -> Path:
    """Draw success rate, simulated and wall time (p50 with a bar up to p95) per group (robot,
    variant, environment), and the failure causes, into the PNG `path` (folders created).
    Returns `path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    labels = [group_label(g) for g in groups]
    xs = list(range(len(groups)))
    fig, (ax_rate, ax_time, ax_causes) = plt.subplots(1, 3, figsize=(15, 4.8))
    try:
        rates = [100 * g.success_rate for g in groups]
        bars = ax_rate.bar(xs, rates, color=["#3a7" if r >= 95 else "#db3" if r >= 85 else "#c44" for r in rates])
        intervals = [g.confidence_interval for g in groups]
        ax_rate.errorbar(
            xs,
            rates,
            yerr=[
                [r - 100 * low for r, (low, _) in zip(rates, intervals)],
                [100 * high - r for r, (_, high) in zip(rates, intervals)],
            ],
            fmt="none",
            ecolor="black",
            capsize=3,
        )
        for bar, g in zip(bars, groups):
            ax_rate.annotate(
                f"{g.successes}/{g.runs}",
                (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                ha="center",
                va="bottom",
                fontsize=8,
            )
        ax_rate.set_xticks(xs, labels, fontsize=8)
        ax_rate.set_ylim(0, 105)
        ax_rate.set_ylabel("success rate [%]")
        ax_rate.set_title("success rate (whiskers: 95 % CI, Wilson)")

        width = 0.38
        for offset, name, values, colour in (
            (-width / 2, "simulated", [g.sim_times for g in groups], "#47a"),
            (width / 2, "wall", [g.wall_times for g in groups], "#a74"),
        ):
            p50 = [percentile(v, 50) or 0.0 for v in values]
            p95 = [percentile(v, 95) or 0.0 for v in values]
            ax_time.bar([x + offset for x in xs], p50, width, label=f"{name} p50", color=colour)
            ax_time.errorbar(
                [x + offset for x in xs],
                p50,
                yerr=[[0] * len(xs), [b - a for a, b in zip(p50, p95)]],
                fmt="none",
                ecolor="black",
                capsize=3,
            )
        ax_time.set_xticks(xs, labels, fontsize=8)
        ax_time.set_ylabel("time per run [s] (bar: p50, whisker: p95)")
        ax_time.set_title("time per run")
        ax_time.legend(fontsize=8)

        causes: Counter[str] = Counter()
        for g in groups:
            causes.update(g.causes)
        names = [c for c, _ in causes.most_common(12)]
        if names:
            left = [0.0] * len(names)
            for g, label in zip(groups, labels):
                counts = [g.causes.get(c, 0) for c in names]
                ax_causes.barh(names, counts, left=left, label=label.replace("\n", ", "))
                left = [a + b for a, b in zip(left, counts)]
            ax_causes.invert_yaxis()
            ax_causes.legend(fontsize=7)
        else:
            ax_causes.text(0.5, 0.5, "no failures", ha="center", va="center", transform=ax_causes.transAxes)
            ax_causes.set_yticks([])
        ax_causes.set_xlabel("failed runs")
        ax_causes.set_title("failure causes")
        if title:
            fig.suptitle(title)
        fig.tight_layout()
        fig.savefig(path, dpi=100)
    finally:
        plt.close(fig)
    return path
