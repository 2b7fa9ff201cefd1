"""The Rerun web viewer, served from this machine: `ViewerServer`.

Rerun's wheel (`rerun-sdk`, the ``view`` extra) ships the web viewer inside its command-line
program (``rerun_cli/rerun``), so nothing is fetched from the internet. `ViewerServer` starts that
program as a child process with ``--serve-web``: it hosts the viewer's page (HTML, JavaScript,
WebAssembly) over HTTP and a gRPC server that buffers what a run logs, so a browser that connects
late still gets the whole run. Both listen on 127.0.0.1 only, unless another `host` is asked for
(Rerun's own defaults listen on every interface; ours never do).

    server = ViewerServer(port=9090).start()   # raises ViewError when it cannot start
    print(server.url)                          # open it in a browser
    ...log into server.grpc_url (`ViewSession`)...
    server.stop()

With `files` (``.rrd`` recordings) the server shows them instead of waiting for a run.
"""

from __future__ import annotations

import collections
import importlib.util
import logging
import os
import re
import subprocess
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from urllib.parse import quote

from pycram.core.process_lifetime import end_with_parent

__all__ = ["ViewerServer", "ViewError", "rerun_program", "DEFAULT_PORT", "LOOPBACK"]

log = logging.getLogger(__name__)

#: The web viewer's port by default (Rerun's own default).
DEFAULT_PORT = 9090
#: Where the servers listen unless told otherwise: this machine only.
LOOPBACK = "127.0.0.1"
#: Wall time [s] the viewer program may take to start listening.
START_TIMEOUT = 60.0

_WEB = re.compile(r"Hosting a web-viewer at http://[^:\s]+:(\d+)")
_GRPC = re.compile(r"Listening for gRPC connections on [^\s]*:(\d+)")
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


class ViewError(RuntimeError):
    """The view cannot be served or written (the message says why and what to try)."""


def rerun_program() -> Path:
    """The `rerun` program shipped in the `rerun-sdk` wheel; raises `ViewError` when the ``view``
    extra is not installed."""
    spec = importlib.util.find_spec("rerun_cli")
    if spec is None or spec.origin is None:
        raise ViewError("the view needs the 'view' extra (pip install 'pycram[view]'): rerun-sdk is not installed")
    program = Path(spec.origin).parent / "rerun"
    if not program.exists():
        raise ViewError(f"rerun-sdk is installed without its viewer program ({program} is missing); reinstall it")
    return program


class ViewerServer:
    """Rerun's web viewer and gRPC server in a child process (see the module docstring).

    `port`: the web viewer's HTTP port (0: any free port); `grpc_port`: the gRPC server's port
    (0: any free port); `host`: the address both listen on (default 127.0.0.1); `files`: ``.rrd``
    recordings to show; `memory_limit`: how much of what was logged the server keeps for viewers
    that connect late (Rerun's syntax: "1GiB", "25%")."""

    def __init__(
        self,
        port: int = DEFAULT_PORT,
        grpc_port: int = 0,
        host: str = LOOPBACK,
        files: Sequence[str | Path] = (),
        memory_limit: str = "2GiB",
    ) -> None:
        for name, value in (("port", port), ("grpc_port", grpc_port)):
            if not 0 <= int(value) <= 65535:
                raise ViewError(f"--view-port: a {name} is 0..65535 (0: any free port), not {value}")
        self.host = host
        self.port = int(port)
        self.grpc_port = int(grpc_port)
        self.files = [Path(f) for f in files]
        for f in self.files:
            if not f.is_file():
                raise ViewError(f"no recording at {f}")
        self.memory_limit = memory_limit
        self._process: subprocess.Popen[str] | None = None
        self._lines: collections.deque[str] = collections.deque(maxlen=200)
        self._ready = threading.Event()
        self._reader: threading.Thread | None = None

    # -- life cycle -------------------------------------------------------------------------------

    def start(self, timeout: float = START_TIMEOUT) -> ViewerServer:
        """Start the viewer program and wait (at most `timeout` [s of wall time]) until both servers
        listen; returns self. Raises `ViewError` naming the cause (a port in use, ...).

        On Linux the viewer program ends when the thread that started it ends (the kernel's
        parent-death signal: a killed run leaves no server behind): start it from a thread that
        lives as long as it should serve, e.g. the main thread."""
        if self._process is not None:
            return self
        command = [
            str(rerun_program()),
            "--serve-web",
            "--bind",
            self.host,
            "--port",
            str(self.grpc_port),
            "--web-viewer-port",
            str(self.port),
            "--server-memory-limit",
            self.memory_limit,
            "--hide-welcome-screen",
            *(str(f) for f in self.files),
        ]
        if not self.files:
            command.append("--expect-data-soon")
        env = dict(os.environ)
        env.setdefault("RUST_LOG", "info")
        self._process = subprocess.Popen(
            command,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            start_new_session=True,  # Ctrl-C in the terminal goes to pycram, which stops it
            preexec_fn=end_with_parent,  # a killed run leaves no server behind
        )
        self._reader = threading.Thread(target=self._read, name="pycram-view-server", daemon=True)
        self._reader.start()
        deadline = time.monotonic() + timeout
        while not self._ready.wait(0.1):
            if self._process.poll() is not None or time.monotonic() > deadline:
                lines = [line for line in self._lines if line]
                errors = [line for line in lines if "Error" in line or "ERROR" in line]
                tail = (errors or lines or ["(it said nothing)"])[-1]
                self.stop()
                hint = " (is the port in use? try another --view-port)" if "in use" in tail else ""
                raise ViewError(f"the Rerun viewer did not start on {self.host}:{self.port}{hint}: {tail}")
        log.info("serving the Rerun web viewer at %s", self.url)
        return self

    def _read(self) -> None:
        """Drain the program's messages (a full pipe would stop it), noting the ports it took."""
        assert self._process is not None and self._process.stderr is not None
        grpc_seen = web_seen = False
        for raw in self._process.stderr:
            line = _ANSI.sub("", raw).strip()
            self._lines.append(line)
            grpc = _GRPC.search(line)
            web = _WEB.search(line)
            if grpc:
                self.grpc_port = int(grpc.group(1))
                grpc_seen = True
            elif web:
                self.port = int(web.group(1))
                web_seen = True
            elif "WARN" in line or "ERROR" in line:
                log.debug("rerun: %s", line)
            if (grpc or web) and grpc_seen and web_seen:  # both listen (in either order): ready
                self._ready.set()

    def stop(self, timeout: float = 10.0) -> None:
        """End the viewer program (idempotent); browsers connected to it lose it."""
        process, self._process = self._process, None
        if process is None:
            return
        if process.poll() is None:
            process.terminate()
            try:
                process.wait(timeout)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        if self._reader is not None:
            self._reader.join(timeout)

    @property
    def running(self) -> bool:
        """True while the viewer program runs."""
        return self._process is not None and self._process.poll() is None

    @property
    def pid(self) -> int | None:
        """The process id of the viewer program while it runs (None before `start`)."""
        return None if self._process is None else self._process.pid

    def wait(self) -> int:
        """Block until the viewer program ends (e.g. on Ctrl-C); returns its exit code."""
        process = self._process
        return 0 if process is None else process.wait()

    # -- addresses -------------------------------------------------------------------------------

    @property
    def grpc_url(self) -> str:
        """Where a recording stream sends its data (``rerun+http://HOST:PORT/proxy``)."""
        return f"rerun+http://{self.host}:{self.grpc_port}/proxy"

    @property
    def url(self) -> str:
        """The page to open in a browser: the web viewer, connected to this server's data."""
        return f"http://{self.host}:{self.port}/?url={quote(self.grpc_url, safe='')}"

    def __enter__(self) -> ViewerServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()
