"""Start and stop a ROS master and the simulator bridge as subprocesses, on loopback.

Used by ``pycram demo --backend ros`` (when no ``ROS_MASTER_URI`` is given), the tests and the
benchmark. Nothing here imports rospy: the processes are plain ``roscore`` and
``python -m pycram sim-ros-bridge``.

The master is started with ``/use_sim_time`` set (:class:`RosMaster`): the nodes on it read
their time from the bridge's ``/clock``, i.e. simulated time.

Guarantees: every process is started in a session of its own, bound to 127.0.0.1
(``ROS_IP``/``ROS_HOSTNAME``), logs into a temporary folder, and :meth:`stop` ends it (SIGINT,
then SIGKILL after a bound) -- also the children roscore starts. Readiness is awaited with a
bound [s, wall]; a process that does not come up raises ``RuntimeError`` with its log's tail.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client
from pathlib import Path
from typing import cast
from urllib.parse import urlparse

__all__ = ["free_port", "loopback_env", "check_master_uri", "RosMaster", "BridgeProcess"]

LOOPBACK = "127.0.0.1"


def free_port() -> int:
    """A TCP port free on 127.0.0.1 right now."""
    with socket.socket() as s:
        s.bind((LOOPBACK, 0))
        return s.getsockname()[1]


def loopback_env(master_uri: str, log_dir: str | None = None) -> dict[str, str]:
    """The environment of a ROS process on loopback talking to ``master_uri``."""
    env = dict(os.environ)
    env.update(ROS_MASTER_URI=master_uri, ROS_IP=LOOPBACK, ROS_HOSTNAME=LOOPBACK)
    if log_dir is not None:
        env["ROS_LOG_DIR"] = log_dir
        env["ROS_HOME"] = log_dir
    return env


def check_master_uri(uri: str | None, allow_remote: bool = False) -> str:
    """``uri`` if it is an http URI of a master on loopback (or ``allow_remote``); else
    ``ValueError`` saying what is wrong."""
    if not uri:
        raise ValueError(
            "ROS_MASTER_URI is not set: start roscore (e.g. `roscore -p 11311`) and set "
            "ROS_MASTER_URI=http://127.0.0.1:11311"
        )
    parsed = urlparse(uri)
    if parsed.scheme != "http" or not parsed.hostname or not parsed.port:
        raise ValueError(f"ROS_MASTER_URI {uri!r} is not of the form http://HOST:PORT")
    if not allow_remote and parsed.hostname not in ("127.0.0.1", "localhost", "::1"):
        raise ValueError(
            f"ROS_MASTER_URI {uri!r} is not on loopback; pass --allow-remote-master to talk "
            f"to a master on another machine (anyone on that network can then command the robot)"
        )
    return uri


def _stop_process(process: subprocess.Popen, timeout: float = 10.0) -> None:
    if process.poll() is not None:
        return
    try:
        os.killpg(process.pid, signal.SIGINT)
        process.wait(timeout)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait(timeout)


class RosMaster:
    """``roscore`` on ``127.0.0.1:port`` (a free port by default). ``uri`` is its address.

    With ``use_sim_time`` (the default: this master serves a simulated robot) the parameter
    ``/use_sim_time`` is set to true as soon as the master answers -- before the constructor
    returns, so before any node of the launcher's user starts: every ROS node on this master
    then takes its time from ``/clock``, which ``pycram sim-ros-bridge`` publishes (simulated
    time). rospy reads the parameter once, when its node is initialised.
    """

    def __init__(self, port: int | None = None, startup_timeout: float = 20.0, use_sim_time: bool = True) -> None:
        if shutil.which("roscore") is None:
            raise RuntimeError("roscore not found: run scripts/install_ros.sh (Debian package ros-core)")
        self.port = port or free_port()
        self.uri = f"http://{LOOPBACK}:{self.port}"
        self.log_dir = tempfile.mkdtemp(prefix="pycram-ros-")
        self._log = open(Path(self.log_dir) / "roscore.log", "wb")
        self.process = subprocess.Popen(
            ["roscore", "-p", str(self.port)],
            env=loopback_env(self.uri, self.log_dir),
            stdout=self._log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )
        try:
            self._wait_ready(startup_timeout)
            if use_sim_time:
                self.set_param("/use_sim_time", True)
        except BaseException:
            self.stop()
            raise

    def set_param(self, name: str, value: bool | int | float | str) -> None:
        """Set the parameter ``name`` on this master (XML-RPC; ``RuntimeError`` if refused)."""
        code, message, _ = cast(
            tuple[int, str, int], xmlrpc.client.ServerProxy(self.uri).setParam("/pycram_launcher", name, value)
        )
        if code != 1:
            raise RuntimeError(f"the ROS master on {self.uri} refused to set {name}: {message}")

    def _wait_ready(self, timeout: float) -> None:
        """The master has no "ready" event: ask it (getPid) every 50 ms, within ``timeout``."""
        deadline = time.monotonic() + timeout
        proxy = xmlrpc.client.ServerProxy(self.uri)
        while True:
            if self.process.poll() is not None:
                raise RuntimeError(f"roscore exited with {self.process.returncode}: {self.log_tail()}")
            try:
                code, _, _ = cast(tuple[int, str, int], proxy.getPid("/pycram_launcher"))  # ROS master API reply
                if code == 1:
                    return
            except (OSError, xmlrpc.client.Error):
                pass
            if time.monotonic() > deadline:
                raise RuntimeError(f"roscore on {self.uri} did not answer within {timeout:.0f} s: {self.log_tail()}")
            time.sleep(0.05)

    def log_tail(self, chars: int = 1500) -> str:
        self._log.flush()
        return (Path(self.log_dir) / "roscore.log").read_text(errors="replace")[-chars:]

    def stop(self) -> None:
        """Stop roscore and everything it started (idempotent)."""
        _stop_process(self.process)
        self._log.close()
        shutil.rmtree(self.log_dir, ignore_errors=True)

    def __enter__(self) -> RosMaster:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


class BridgeProcess:
    """``python -m pycram sim-ros-bridge --robot ROBOT`` on the master at ``master_uri``.

    ``item_at``: where the demo's mug starts in the thesis kitchen (``--item-at``; None: not
    given); ``environment``: another environment (``--environment``) with ``objects``
    (``--object`` values, ``TYPE@X,Y`` or ``TYPE@X,Y,Z`` [m]). Returns from the constructor once
    the bridge printed that it serves (within ``startup_timeout`` [s, wall]). :meth:`kill` ends
    it abruptly (SIGKILL, as a crash would); :meth:`stop` ends it cleanly.
    """

    def __init__(
        self,
        robot: str,
        master_uri: str,
        item_at: int | None = 1,
        realtime: bool = False,
        startup_timeout: float = 60.0,
        extra_args: tuple[str, ...] = (),
        environment: str | None = None,
        objects: tuple[str, ...] = (),
    ) -> None:
        self.robot, self.master_uri = robot, master_uri
        self.log_dir = tempfile.mkdtemp(prefix="pycram-bridge-")
        env = loopback_env(master_uri, self.log_dir)
        env.setdefault("MUJOCO_GL", "egl")
        command = [
            sys.executable,
            "-m",
            "pycram",
            "sim-ros-bridge",
            "--robot",
            robot,
            *(["--item-at", str(item_at)] if item_at is not None else []),
            *(["--environment", environment] if environment is not None else []),
            *[arg for value in objects for arg in ("--object", value)],
            *(["--realtime"] if realtime else []),
            *extra_args,
        ]
        self.process = subprocess.Popen(
            command,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )
        self._lines: list[str] = []
        self._ready = threading.Event()
        self._reader = threading.Thread(target=self._read, name="pycram-bridge-output", daemon=True)
        self._reader.start()
        if not self._ready.wait(startup_timeout) or self.process.poll() is not None:
            output = self.output()
            self.stop()
            raise RuntimeError(f"sim-ros-bridge for {robot} did not come up within {startup_timeout:.0f} s: {output}")

    def _read(self) -> None:
        assert self.process.stdout is not None
        for raw in self.process.stdout:
            line = raw.decode(errors="replace").rstrip()
            self._lines.append(line)
            del self._lines[:-200]
            if "sim-ros-bridge ready" in line:
                self._ready.set()
        self._ready.set()  # the process ended: wake the constructor

    def output(self) -> str:
        """The bridge's last lines of output."""
        return "\n".join(self._lines[-40:])

    def kill(self) -> None:
        """SIGKILL the bridge (a crash: no goal is ended cleanly)."""
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait(10)

    def stop(self) -> None:
        """Stop the bridge (SIGINT, then SIGKILL) and wait for it (idempotent)."""
        _stop_process(self.process)
        self._reader.join(5)
        shutil.rmtree(self.log_dir, ignore_errors=True)

    def __enter__(self) -> BridgeProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
