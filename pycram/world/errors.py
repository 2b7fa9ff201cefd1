"""Errors of the world model."""

from __future__ import annotations

from collections.abc import Iterable


class UnknownNameError(KeyError):
    """A name (environment, surface, container, place, object type ...) that does not exist.

    The message lists the valid choices; `kind`, `name` and `choices` say the same as data.
    """

    def __init__(self, kind: str, name: object, choices: Iterable[str]) -> None:
        self.kind, self.name, self.choices = kind, name, sorted(choices)
        super().__init__(f"{kind} {name!r} does not exist. Available: {', '.join(self.choices)}")

    def __str__(self) -> str:  # KeyError would repr() the message
        return self.args[0]
