"""Debian's headless Chromium driven over the DevTools protocol (a pipe, no websocket, no
download): open a page, evaluate JavaScript in it, take screenshots. Its network is confined to
127.0.0.1: every host name resolves to nothing and every other address goes to a proxy that
does not exist. For the browser tests of the Rerun view (tests/view)."""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import tempfile
import threading
import time
from typing import Any

#: Flags that keep the browser to the loopback interface (and quiet, headless, without GPU).
OFFLINE_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-breakpad",
    "--disable-features=MediaRouter,OptimizationHints,Translate",
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
    "--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE 127.0.0.1",
    "--proxy-server=http://127.0.0.1:9",
    "--proxy-bypass-list=127.0.0.1",
)


def chromium_path() -> str | None:
    """The `chromium` executable on the PATH (Debian's package), or None."""
    return shutil.which("chromium")


def _pipe_fds(read: int, write: int) -> None:
    """(In the child, before exec) put the pipe's ends at fds 3 and 4."""
    read, write = os.dup(read), os.dup(write)  # above 4: dup2 below cannot clobber one with the other
    os.dup2(read, 3)
    os.dup2(write, 4)


class Chromium:
    """A headless Chromium process and one page, driven over `--remote-debugging-pipe`."""

    def __init__(self, width: int = 1280, height: int = 800) -> None:
        exe = chromium_path()
        if exe is None:
            raise RuntimeError("chromium is not installed (scripts/install_chromium.sh installs it)")
        self._profile = tempfile.mkdtemp(prefix="pycram-chromium-")
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()
        self._proc = subprocess.Popen(
            [
                exe,
                *OFFLINE_FLAGS,
                f"--window-size={width},{height}",
                f"--user-data-dir={self._profile}",
                "--remote-debugging-pipe",
                "about:blank",
            ],
            pass_fds=(3, 4),  # the DevTools pipe: the browser reads fd 3, writes fd 4
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=lambda: _pipe_fds(to_browser_r, from_browser_w),
        )
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._next_id = 0
        self._replies: dict[int, dict[str, Any]] = {}
        self._cond = threading.Condition()
        self._reader = threading.Thread(target=self._read, name="chromium-devtools", daemon=True)
        self._reader.start()
        self.session: str | None = None
        #: The URL of every response the page received (`Network.responseReceived`), in order.
        self.responses: list[str] = []

    def _read(self) -> None:
        buffer = b""
        while True:
            chunk = os.read(self._from_browser, 1 << 16)
            if not chunk:
                with self._cond:
                    self._replies[-1] = {"closed": True}
                    self._cond.notify_all()
                return
            buffer += chunk
            while b"\0" in buffer:
                raw, buffer = buffer.split(b"\0", 1)
                message = json.loads(raw)
                if "id" in message:
                    with self._cond:
                        self._replies[message["id"]] = message
                        self._cond.notify_all()
                elif message.get("method") == "Network.responseReceived":
                    self.responses.append(message["params"]["response"]["url"])

    def call(self, method: str, timeout: float = 60.0, session: bool = True, **params: Any) -> dict[str, Any]:
        """Send one DevTools command (to the page's session unless `session` is False) and wait
        at most `timeout` [s] for its result; raises RuntimeError for an error reply."""
        with self._cond:
            self._next_id += 1
            ident = self._next_id
        message: dict[str, Any] = {"id": ident, "method": method, "params": params}
        if session and self.session is not None:
            message["sessionId"] = self.session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        with self._cond:
            while ident not in self._replies:
                if -1 in self._replies:
                    raise RuntimeError(f"chromium exited while waiting for {method}")
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"chromium did not answer {method} within {timeout:.0f} s")
                self._cond.wait(left)
            reply = self._replies.pop(ident)
        if "error" in reply:
            raise RuntimeError(f"{method}: {reply['error']}")
        return reply.get("result", {})

    def open(self, url: str) -> None:
        """Open `url` in a new page and attach to it."""
        target = self.call("Target.createTarget", session=False, url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", session=False, targetId=target, flatten=True)["sessionId"]
        self.call("Page.enable")
        self.call("Runtime.enable")
        self.call("Network.enable")  # from the first request on: `responses`
        self.call("Page.navigate", url=url)

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (JSON-serialisable values)."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        return result.get("result", {}).get("value")

    def screenshot(self) -> bytes:
        """A PNG of the page as it is now."""
        return base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])

    def close(self) -> None:
        """End the browser (and forget its profile)."""
        try:
            self.call("Browser.close", session=False, timeout=10.0)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self._proc.wait(10.0)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        for fd in (self._to_browser, self._from_browser):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self._profile, ignore_errors=True)

    def __enter__(self) -> Chromium:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
