"""Headless Chromium driven through the DevTools protocol over a pipe (no extra package).

``--dump-dom`` shows what a page drew but cannot click, measure or read plotly's state;
this drives one page: open it at a window width, run JavaScript in it (click a row, read
``scrollWidth``, read a trace's colour), take a screenshot.  Chromium reads commands from
its file descriptor 3 and writes answers and events to 4, one JSON message per NUL-ended
chunk (``--remote-debugging-pipe``).  Every console message and uncaught exception of the
page is kept in :attr:`Page.console` for the test to assert on.
"""

from __future__ import annotations

import base64
import json
import os
import select
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

OFFLINE_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--host-resolver-rules=MAP * ~NOTFOUND",
]
"""Headless, a fresh profile's first run quiet, and every host name resolving to nothing (a
fetch would fail loudly)."""

FLAGS = [*OFFLINE_FLAGS, "--hide-scrollbars", "--remote-debugging-pipe"]

TILE_HOST = "https://tile.openstreetmap.org/"
"""Where a page asks for OSM tiles: offline, its one try logs a failed load."""


def page_errors(console: list[str]) -> list[str]:
    """The console lines of a page, less the failed load of the OSM tile it tries once to
    learn whether the browser is online (every host resolves to nothing here)."""
    return [
        c
        for c in console
        if not (c.startswith("log error: Failed to load resource") and TILE_HOST in c)
    ]


class Page:
    """One tab of a headless Chromium, driven by protocol messages."""

    def __init__(self, proc: subprocess.Popen[bytes], write_fd: int, read_fd: int) -> None:
        self._proc, self._w, self._r = proc, write_fd, read_fd
        self._buf = b""
        self._id = 0
        self.session = ""
        self.console: list[str] = []

    def _message(self, timeout: float) -> dict[str, Any]:
        end = time.monotonic() + timeout
        while b"\0" not in self._buf:
            left = end - time.monotonic()
            if left <= 0 or not select.select([self._r], [], [], left)[0]:
                raise TimeoutError("Chromium did not answer in time")
            chunk = os.read(self._r, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed the pipe")
            self._buf += chunk
        raw, self._buf = self._buf.split(b"\0", 1)
        return json.loads(raw)

    def _event(self, msg: dict[str, Any]) -> None:
        method, params = msg.get("method"), msg.get("params", {})
        if method == "Runtime.consoleAPICalled":
            args = " ".join(str(a.get("value", a.get("description", ""))) for a in params["args"])
            self.console.append(f"console.{params['type']}: {args}")
        elif method == "Runtime.exceptionThrown":
            d = params["exceptionDetails"]
            self.console.append(f"exception: {d.get('exception', {}).get('description', d)}")
        elif method == "Log.entryAdded":
            e = params["entry"]
            self.console.append(f"log {e['level']}: {e['text']} {e.get('url', '')}".strip())

    def send(self, method: str, params: dict[str, Any] | None = None, timeout: float = 60) -> Any:
        """Send one command (to the page once attached); return its result."""
        self._id += 1
        msg: dict[str, Any] = {"id": self._id, "method": method, "params": params or {}}
        if self.session and not method.startswith(("Target.", "Browser.")):
            msg["sessionId"] = self.session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self._message(timeout)
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self._event(reply)

    def evaluate(self, expression: str, timeout: float = 60) -> Any:
        """The value of a JavaScript expression in the page (a promise is awaited)."""
        res = self.send(
            "Runtime.evaluate",
            {"expression": expression, "returnByValue": True, "awaitPromise": True},
            timeout,
        )
        if "exceptionDetails" in res:
            raise RuntimeError(f"{expression}: {res['exceptionDetails']}")
        return res["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 60) -> Any:
        """Poll ``expression`` until it is truthy; return its value."""
        end = time.monotonic() + timeout
        while True:
            value = self.evaluate(expression)
            if value:
                return value
            if time.monotonic() > end:
                raise TimeoutError(f"{expression} still false after {timeout} s")
            time.sleep(0.1)

    def open(self, url: str) -> None:
        """Load ``url`` and wait until the page's scripts are done (``data-map`` set)."""
        self.send("Page.navigate", {"url": url})
        self.wait_for("document.readyState === 'complete'")
        self.wait_for("document.body && document.body.hasAttribute('data-map')")

    def screenshot(self, path: Path) -> Path:
        """A PNG of the window."""
        data = self.send("Page.captureScreenshot", {"format": "png"})["data"]
        path.write_bytes(base64.b64decode(data))
        return path


@contextmanager
def browser(exe: str, width: int = 1280, height: int = 900) -> Iterator[Page]:
    """A headless Chromium with one tab ``width`` x ``height`` CSS pixels, closed after."""
    to_chrome_r, to_chrome_w = os.pipe()
    from_chrome_r, from_chrome_w = os.pipe()

    def wire() -> None:  # in the child: the pipe ends on the descriptors Chromium expects
        os.dup2(to_chrome_r, 3)
        os.dup2(from_chrome_w, 4)

    with tempfile.TemporaryDirectory(prefix="sailroute-cdp-") as profile:
        proc = subprocess.Popen(
            [exe, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
            pass_fds=(3, 4),
            preexec_fn=wire,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        page = Page(proc, to_chrome_w, from_chrome_r)
        try:
            target = page.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            page.session = page.send(
                "Target.attachToTarget", {"targetId": target, "flatten": True}
            )["sessionId"]
            for domain in ("Page", "Runtime", "Log"):
                page.send(f"{domain}.enable")
            page.send(
                "Emulation.setDeviceMetricsOverride",
                {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
            )
            yield page
        finally:
            with suppress(RuntimeError, TimeoutError, OSError):
                page.send("Browser.close", timeout=10)
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            os.close(to_chrome_w)
            os.close(from_chrome_r)
