"""Development and evaluation seeds and worlds: which runs a reported figure may rest on.

The rule (`docs/experiments.md`, "Development and evaluation"): develop -- look at runs, replay
failures, tune -- on the *development* seeds `DEV_SEEDS` (0-999) and the generated apartments
``procedural:0`` to ``procedural:999``; report figures on the *evaluation* seeds from
`EVAL_FIRST` (1 000 000) upward and the generated apartments ``procedural:1000000`` upward,
which nobody looks at while fixing. Seeds in between (1000-999 999) belong to neither: they are
free for one-off checks (older figures used some, e.g. set-table's 5001-5100). The hand-made
environments (``apartment``, ``thesis-kitchen``) and kitchens from files are single worlds
everybody develops in: a figure there is on evaluation *seeds* of a development *world*.

`experiment_split` says which split an experiment's seeds and environments are and, when it
mixes development (or unsplit) seeds or generated apartments into runs that are otherwise on
evaluation ones, what is wrong: `pycram experiment` prints that as a warning before it runs and
with its report.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

__all__ = [
    "DEV_SEEDS",
    "EVAL_FIRST",
    "SPLITS",
    "seed_split",
    "environment_split",
    "ExperimentSplit",
    "experiment_split",
]

#: Development seeds (of scenarios and of generated apartments): tune and look at these.
DEV_SEEDS = range(0, 1000)
#: The first evaluation seed: evaluation seeds and generated apartments are this and above.
EVAL_FIRST = 1_000_000
#: The splits a seed or environment can be in.
SPLITS = ("dev", "eval", "unsplit", "hand-made")


def seed_split(seed: int) -> str:
    """ "dev" for a development seed (`DEV_SEEDS`), "eval" from `EVAL_FIRST` upward, "unsplit"
    in between. Raises ValueError for a negative seed."""
    if seed < 0:
        raise ValueError(f"a seed is a non-negative integer, not {seed}")
    if seed in DEV_SEEDS:
        return "dev"
    return "eval" if seed >= EVAL_FIRST else "unsplit"


def environment_split(name: str) -> str:
    """The split of an environment name: ``procedural:SEED`` as its seed (`seed_split`); a
    hand-made environment or a kitchen from a file: "hand-made" (one world, developed in)."""
    from pycram.environments import PROCEDURAL_PREFIX, procedural_seed

    if name.startswith(PROCEDURAL_PREFIX):
        return seed_split(procedural_seed(name))
    return "hand-made"


def _ranges(numbers: Iterable[int]) -> str:
    """1,2,3,7 -> "1-3, 7" (at most five ranges, then "...")."""
    ordered = sorted(set(numbers))
    parts: list[str] = []
    start = previous = None
    for n in ordered:
        if start is None:
            start = previous = n
        elif previous is not None and n == previous + 1:
            previous = n
        else:
            parts.append(f"{start}" if start == previous else f"{start}-{previous}")
            start = previous = n
    if start is not None:
        parts.append(f"{start}" if start == previous else f"{start}-{previous}")
    return ", ".join(parts[:5]) + (", ..." if len(parts) > 5 else "")


@dataclass(frozen=True)
class ExperimentSplit:
    """Which split an experiment's runs are on: `label` ("evaluation", "development", "unsplit"
    or "mixed"), a `description` for the report, and `problems` (empty unless development or
    unsplit seeds or generated apartments are mixed into an evaluation)."""

    label: str
    description: str
    problems: list[str] = field(default_factory=list)


def experiment_split(seeds: Iterable[int], environments: Iterable[str] = ()) -> ExperimentSplit:
    """The split of an experiment over `seeds` in `environments` (empty: the scenario's own, a
    hand-made one). It is an *evaluation* when every seed is an evaluation seed and every
    generated apartment an evaluation one; it is labelled an evaluation as soon as one of them is
    -- and then every development or unsplit seed or apartment beside them is a problem (its
    figures would not be evaluation figures)."""
    seeds = list(seeds)
    environments = list(environments)
    by_seed = {s: seed_split(s) for s in seeds}
    by_env = {e: environment_split(e) for e in environments}
    generated = {e: split for e, split in by_env.items() if split != "hand-made"}
    hand_made = [e for e, split in by_env.items() if split == "hand-made"]
    kinds = set(by_seed.values()) | set(generated.values())
    nouns = "seeds and generated apartments" if generated else "seeds"
    if hand_made:
        where = f" in the hand-made {', '.join(hand_made)} (a world developed in)"
    else:
        where = "" if environments else " in the scenario's own environment"
    if kinds == {"eval"}:
        return ExperimentSplit("evaluation", f"evaluation {nouns}{where}")
    if kinds == {"dev"}:
        return ExperimentSplit("development", f"development {nouns}{where}: not evaluation figures")
    if "eval" not in kinds:
        return ExperimentSplit("unsplit", f"{nouns} outside the development/evaluation split{where}")
    problems = []
    others = [s for s, split in by_seed.items() if split != "eval"]
    if others:
        told = "seeds {} are not evaluation seeds" if len(others) > 1 else "seed {} is not an evaluation seed"
        problems.append(
            told.format(_ranges(others)) + f" (those are {EVAL_FIRST} and above; "
            f"{DEV_SEEDS.start}-{DEV_SEEDS.stop - 1} are for development)"
        )
    worlds = [e for e, split in generated.items() if split != "eval"]
    if worlds:
        shown = ", ".join(worlds[:5]) + (", ..." if len(worlds) > 5 else "")
        told = (
            "generated apartments {} are not evaluation worlds" if len(worlds) > 1 else "{} is not an evaluation world"
        )
        problems.append(told.format(shown) + f" (those are procedural:{EVAL_FIRST} and above)")
    return ExperimentSplit(
        "mixed",
        "evaluation seeds or worlds mixed with development or unsplit ones: not an evaluation",
        problems,
    )
