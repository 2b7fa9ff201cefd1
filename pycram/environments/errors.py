"""Errors of loading environments (re-exported by `pycram.environments`)."""

from __future__ import annotations

__all__ = ["KitchenFileError"]


class KitchenFileError(ValueError):
    """A kitchen's sidecar or model file (``file:PATH``, `pycram.environments.from_file`) that
    cannot be read: the message names the file, the entry and what is wrong with it."""
