"""Child processes that end with the process that started them (Linux).

A child started by PyCRAM -- an experiment's worker, the view's Rerun server -- must not outlive
a parent that was killed (``kill -9``, a crashed driver, a CI job cancelled): left running, it
holds a CPU core and ports until its work ends on its own, if ever. `end_with_parent` asks the
kernel (``PR_SET_PDEATHSIG``) to send the calling process a signal when its parent dies, however
it dies. It is called in the child: as the initializer of a process pool's worker, or as the
``preexec_fn`` of `subprocess.Popen` (it does not log: it may run between ``fork`` and ``exec``).
"""

from __future__ import annotations

import os
import signal

__all__ = ["end_with_parent"]

_PR_SET_PDEATHSIG = 1


def end_with_parent(signum: int = signal.SIGTERM, parent: int | None = None) -> bool:
    """(In a child process.) Have the kernel send `signum` to this process when its parent dies.

    `parent`: the pid the parent had when it started this child; when given and the parent has
    already gone (this process was re-parented before the call), the signal is sent at once --
    the kernel only signals deaths that come after the request. Returns False where the request
    is not available (not Linux): there the parent's own clean-up is all that ends the child."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(_PR_SET_PDEATHSIG, int(signum)) != 0:
            return False
    except (OSError, AttributeError):  # no libc with prctl: not Linux
        return False
    if parent is not None and os.getppid() != parent:
        os.kill(os.getpid(), signum)
    return True
