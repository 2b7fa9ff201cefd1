"""The one place PyCRAM's version is written (pyproject.toml reads it; `pycram --version` shows it)."""

__version__ = "0.1.0"
