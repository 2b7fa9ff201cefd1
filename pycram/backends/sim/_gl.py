"""Choose an OpenGL backend for MuJoCo before `mujoco` is imported anywhere in `pycram.sim`."""

from __future__ import annotations

import logging
import os

_log = logging.getLogger(__name__)


def configure_gl() -> None:
    """Set `MUJOCO_GL=egl` when no display is set and nothing else is configured (headless)."""
    if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        os.environ["MUJOCO_GL"] = "egl"
        if "PYOPENGL_PLATFORM" not in os.environ:
            os.environ["PYOPENGL_PLATFORM"] = "egl"
        _log.debug("no display: MUJOCO_GL=egl")
