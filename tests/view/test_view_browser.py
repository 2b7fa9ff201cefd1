"""`pycram demo --view` in a real browser: Debian's headless Chromium (installed by
scripts/install_chromium.sh, which `make test` runs) opens the URL the command prints, with no
network beyond 127.0.0.1, and finds Rerun's web viewer loaded and showing the run.

With `PYCRAM_DOCS_SCREENSHOTS=1` the screenshot is also written to docs/view.png (the picture
of docs/view.md)."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path
from urllib.parse import urlparse

import pytest

pytest.importorskip("rerun")
pytest.importorskip("mujoco")

from chromium import Chromium, chromium_path  # noqa: E402
from view_helpers import ROOT, interrupt, pycram_env  # noqa: E402

from pycram.core.process_lifetime import end_with_parent  # noqa: E402

#: Wall time [s] the viewer may take to load and show the run (software rendering, 2 cores).
LOAD_TIMEOUT = 200.0


class _Lines:
    """The lines a child process writes to a pipe, collected by a thread as they come."""

    def __init__(self, pipe) -> None:
        self.lines: list[str] = []
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._read, args=(pipe,), daemon=True)
        self._thread.start()

    def _read(self, pipe) -> None:
        for line in pipe:
            with self._cond:
                self.lines.append(line)
                self._cond.notify_all()
        with self._cond:
            self.lines.append("")  # the end
            self._cond.notify_all()

    def wait_for(self, pattern: str, timeout: float) -> re.Match[str]:
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in self.lines:
                    found = re.search(pattern, line)
                    if found:
                        return found
                left = deadline - time.monotonic()
                if left <= 0 or (self.lines and self.lines[-1] == ""):
                    raise AssertionError(f"no line matching {pattern!r}: {''.join(self.lines)[-3000:]}")
                self._cond.wait(left)


def _distinct_colors(png: bytes, box: tuple[int, int, int, int]) -> int:
    import numpy as np
    from PIL import Image

    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB").crop(box))
    return len(np.unique(image.reshape(-1, 3), axis=0))


def _listening_addresses(pid: int) -> set[str]:
    """The addresses the process `pid` and its children listen on (TCP)."""
    import psutil

    process = psutil.Process(pid)
    addresses = set()
    for p in [process, *process.children(recursive=True)]:
        for connection in p.net_connections(kind="tcp"):
            if connection.status == psutil.CONN_LISTEN:
                addresses.add(connection.laddr.ip)
    return addresses


needs_chromium = pytest.mark.skipif(
    chromium_path() is None,
    reason="Debian's chromium is not installed and scripts/install_chromium.sh could not install it "
    "(`make test` runs it; it needs apt-get)",
)


def _start(args: list[str], folder: Path) -> tuple[subprocess.Popen[str], _Lines]:
    """`pycram ARGS` in a child process, its standard error collected line by line."""
    child = subprocess.Popen(
        [sys.executable, "-m", "pycram.apps.cli", *args],
        cwd=folder,
        env=pycram_env(),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=end_with_parent,  # ended with the test run even when a time-out kills it
    )
    return child, _Lines(child.stderr)


def _look(browser: Chromium, url: str, ended: _Lines, ended_pattern: str) -> bytes:
    """Open `url`, wait until the command says the run ended (`ended_pattern` on its standard
    error) and the viewer shows the run: its state names a PyCRAM recording and the view's
    layout, and the 3D view (top left) is not the empty background. Returns a screenshot."""
    browser.open(url)
    ended.wait_for(ended_pattern, 240.0)  # the run ended: all of it went to the viewer
    deadline = time.monotonic() + LOAD_TIMEOUT
    state = ""
    while time.monotonic() < deadline:
        state = browser.evaluate("window._handle ? String.fromCharCode(...window._handle.viewer_state()) : ''") or ""
        loaded = "recording_id=pycram-" in state and "world: truth, belief, reasoning" in state
        if loaded and _distinct_colors(browser.screenshot(), (10, 70, 900, 560)) > 150:
            break
        time.sleep(2.0)
    else:
        raise AssertionError(f"the viewer did not show the run within {LOAD_TIMEOUT:.0f} s (state: {state[:300]!r})")
    time.sleep(3.0)  # let the viewer finish drawing the last frame for the picture
    outside = [u for u in browser.responses if urlparse(u).scheme in ("http", "https")]
    outside = [u for u in outside if urlparse(u).hostname != "127.0.0.1"]
    assert not outside, f"the page got answers from beyond 127.0.0.1: {outside[:5]}"
    assert any(urlparse(u).hostname == "127.0.0.1" for u in browser.responses)
    return browser.screenshot()


@needs_chromium
def test_the_live_view_loads_in_a_browser_and_shows_the_run(tmp_path):
    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    args = ["demo", "--scenario", "set-table", "--seed", "7", "--view", "--view-port", "0", "--view-wait", "--no-rrd"]
    args += ["--no-animation", "-q", "--db", db]
    demo, stderr = _start([*args, "-o", str(tmp_path / "out")], tmp_path)
    try:
        url = stderr.wait_for(r"view: open (http://\S+) in a browser", 120.0).group(1)
        assert urlparse(url).hostname == "127.0.0.1"
        assert _listening_addresses(demo.pid) == {"127.0.0.1"}, "the viewer listens beyond this machine"
        with Chromium(1600, 1000) as browser:
            png = _look(browser, url, stderr, r"view: still at")
        (tmp_path / "view.png").write_bytes(png)
        if os.environ.get("PYCRAM_DOCS_SCREENSHOTS") == "1":
            (ROOT / "docs" / "view.png").write_bytes(png)
    finally:
        code = interrupt(demo)
    assert code == 0, "".join(stderr.lines)[-2000:]
    assert (tmp_path / "out" / "end.png").is_file()


@needs_chromium
def test_an_experiment_streams_the_run_it_is_asked_to_show(tmp_path):
    """`pycram experiment --view 2`: of the seeds 1-2, seed 2's run streams into the viewer."""
    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    args = ["experiment", "--scenario", "thesis", "--seeds", "1-2", "--workers", "1", "--db", db]
    experiment, stderr = _start([*args, "--view", "2", "--view-port", "0", "--view-wait"], tmp_path)
    try:
        url = stderr.wait_for(r"view: seed 2 streams into (http://\S+)", 120.0).group(1)
        with Chromium(1600, 1000) as browser:
            png = _look(browser, url, stderr, r"view: still at")
            state = browser.evaluate("String.fromCharCode(...window._handle.viewer_state())")
        (tmp_path / "experiment-view.png").write_bytes(png)
        shown = set(re.findall(r"recording_id=(pycram-[0-9a-f-]+)", state))
        assert len(shown) == 1, f"only seed 2's run is shown, not {shown}"
    finally:
        code = interrupt(experiment)
    assert code == 0, "".join(stderr.lines)[-2000:]


def test_bad_view_options_of_an_experiment_are_refused(tmp_path):
    from view_helpers import run_pycram

    db = f"sqlite:///{tmp_path / 'runs.sqlite3'}"
    done = run_pycram(["experiment", "--seeds", "1-2", "--db", db, "--view", "pr2:x"], tmp_path)
    assert done.returncode == 2 and "SEED or ROBOT:SEED" in done.stderr
    done = run_pycram(["experiment", "--seeds", "1-2", "--db", db, "--view", "7"], tmp_path)
    assert done.returncode == 2 and "seed 7 is not among the experiment's seeds" in done.stderr
    done = run_pycram(["experiment", "--seeds", "1-2", "--db", db, "--view", "1", "--ray", "local"], tmp_path)
    assert done.returncode == 2 and "not with --ray" in done.stderr
