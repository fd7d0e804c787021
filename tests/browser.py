"""Headless Chromium driven over the DevTools protocol: screenshots and page state (test support).

``Chromium()`` starts one headless browser with the flags that work on machines
without a display or GPU (software WebGL through SwiftShader) and a fresh
profile directory, and talks to it over ``--remote-debugging-pipe`` (file
descriptors 3 and 4 of the child, NUL-terminated JSON): no port is opened, so
nothing else on the machine can reach it.  Leaving the ``with`` block closes the
browser, kills its process group if it does not exit, and removes the profile.

``Chromium.open(page)`` loads a file in a new tab of a given size and returns
a ``Tab``, which takes screenshots (``Tab.screenshot``) and evaluates
JavaScript (``Tab.evaluate``), e.g. the animation clock of a rendered page.

The browser tests (``tests/viz/test_viz.py``) drive it; it is not part of the installed
package.  From the repository's root it also makes ``docs/animation.png`` and
``docs/review.png``::

    python -m tests.browser PAGE.html OUT.png [--wait 3] [--size 1000x700]
"""

from __future__ import annotations

import argparse
import base64
import fcntl
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from pendverify.atomic import write_atomic


class BrowserError(RuntimeError):
    """Chromium is missing, failed, or did not answer in time (``main`` prints it in one line, exit 1)."""


CANDIDATES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--hide-scrollbars",
    "--mute-audio",
    "--remote-debugging-pipe",
)
URL_SCHEMES = ("file:", "http:", "https:", "about:", "data:")
TIMEOUT_S = 60.0  # for any one protocol reply or page load


def find_chromium() -> str | None:
    """The path of a Chromium (or Chrome) binary on PATH, or None."""
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


class Chromium:
    """One headless Chromium process, controlled over a pipe; use as a context manager."""

    def __init__(self, binary: str | None = None):
        self.binary = binary or find_chromium()
        if self.binary is None:
            raise BrowserError(f"no Chromium binary found on PATH (tried {', '.join(CANDIDATES)})")
        self._next_id = 0
        self._buffer = b""
        self._events: list[dict] = []
        self.proc: subprocess.Popen | None = None

    # -- process ---------------------------------------------------------------------------
    def __enter__(self) -> Chromium:
        self._profile = tempfile.TemporaryDirectory(prefix="pendverify-chromium-")
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()
        # copies above 10 (close-on-exec), so that placing them at 3 and 4 cannot clobber each other
        high = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (to_child_r, from_child_w)]
        for fd in (to_child_r, from_child_w):
            os.close(fd)

        def wire_pipes() -> None:  # in the child, before exec: the protocol's fds 3 and 4
            os.dup2(high[0], 3)  # commands to the browser (dup2 leaves them open across exec)
            os.dup2(high[1], 4)  # its replies

        cmd = [self.binary, *FLAGS, f"--user-data-dir={self._profile.name}", "about:blank"]
        try:
            self.proc = subprocess.Popen(
                cmd,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                close_fds=False,  # keep 3 and 4; every other fd of ours is close-on-exec (PEP 446)
                preexec_fn=wire_pipes,
                start_new_session=True,  # its own process group, ended with all its helpers
            )
        finally:
            for fd in high:
                os.close(fd)
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Ask the browser to quit; kill its process group if it has not within 10 s."""
        if self.proc is None:
            return
        try:
            self.send("Browser.close", timeout=10.0)
        except (BrowserError, OSError):
            pass
        try:
            self.proc.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            pass
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)  # helpers that outlived the browser, if any
        except ProcessLookupError:
            pass
        self.proc.wait()
        for fd in (self._to_child, self._from_child):
            os.close(fd)
        self._profile.cleanup()
        self.proc = None

    # -- protocol --------------------------------------------------------------------------
    def _read_message(self, deadline: float) -> dict:
        import select

        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise BrowserError("Chromium did not answer in time")
            ready, _, _ = select.select([self._from_child], [], [], left)
            if ready:
                chunk = os.read(self._from_child, 1 << 20)
                if not chunk:
                    raise BrowserError(f"Chromium exited (status {self.proc.poll()})")
                self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method: str, params: dict | None = None, session: str | None = None, timeout=TIMEOUT_S):
        """Send one command and return its result (events that arrive meanwhile are kept)."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._to_child, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._read_message(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise BrowserError(f"{method}: {reply['error'].get('message')}")
                return reply.get("result", {})
            self._events.append(reply)

    def wait_event(self, method: str, session: str, timeout=TIMEOUT_S) -> dict:
        deadline = time.monotonic() + timeout
        while True:
            for i, event in enumerate(self._events):
                if event.get("method") == method and event.get("sessionId") == session:
                    return self._events.pop(i)
            self._events.append(self._read_message(deadline))

    def open(self, page: str | Path, size: tuple[int, int] = (1000, 700)) -> Tab:
        """Load a local file (or URL) in a new tab of ``size`` CSS pixels, after its load event."""
        url = str(page) if str(page).startswith(URL_SCHEMES) else Path(page).resolve().as_uri()
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        self.send("Page.enable", session=session)
        self.send(
            "Emulation.setDeviceMetricsOverride",
            {"width": size[0], "height": size[1], "deviceScaleFactor": 1, "mobile": False},
            session=session,
        )
        self.send("Page.navigate", {"url": url}, session=session)
        self.wait_event("Page.loadEventFired", session)
        return Tab(self, target, session)


class Tab:
    """A loaded page in a ``Chromium``."""

    def __init__(self, browser: Chromium, target: str, session: str):
        self.browser, self.target, self.session = browser, target, session

    def evaluate(self, expression: str):
        """The value of a JavaScript expression in the page."""
        result = self.browser.send(
            "Runtime.evaluate", {"expression": expression, "returnByValue": True}, session=self.session
        )
        if "exceptionDetails" in result:
            raise BrowserError(f"{expression}: {result['exceptionDetails'].get('text')}")
        return result["result"].get("value")

    def screenshot(self, png: str | Path) -> Path:
        """Capture the viewport as PNG (written atomically)."""
        data = self.browser.send("Page.captureScreenshot", {"format": "png"}, session=self.session)["data"]
        return write_atomic(png, base64.b64decode(data))

    def close(self) -> None:
        self.browser.send("Target.closeTarget", {"targetId": self.target})


def screenshot(
    page: str | Path, png: str | Path, wait_s: float = 3.0, size: tuple[int, int] = (1000, 700)
) -> Path:
    """Open ``page`` in a fresh headless Chromium, wait ``wait_s`` seconds after loading, save a PNG."""
    with Chromium() as browser:
        tab = browser.open(page, size)
        time.sleep(wait_s)
        return tab.screenshot(png)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.browser", description=__doc__.split("\n")[0])
    parser.add_argument("page", help="an HTML file")
    parser.add_argument("png", help="the screenshot to write")
    parser.add_argument("--wait", type=float, default=3.0, help="seconds after loading before the shot")
    parser.add_argument("--size", default="1000x700", help="viewport size WxH in CSS pixels")
    args = parser.parse_args(argv)
    width, height = (int(x) for x in args.size.lower().split("x"))
    try:
        print(screenshot(args.page, args.png, args.wait, (width, height)))
    except BrowserError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
