"""Headless Chromium (Debian's `chromium`) driven over the Chrome DevTools Protocol with the
`websockets` package: no WebDriver, no Selenium. It opens pages, evaluates JavaScript, takes
screenshots, and keeps every console error, uncaught exception, log error and failed request
of the page, so a test can say the page ran clean. Everything has a time limit and
`close()` ends the browser (and its children: it runs in its own process group)."""

from __future__ import annotations

import base64
import ctypes
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from websockets.sync.client import connect


def chromium_path() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


def die_with_parent() -> None:
    """preexec_fn: the child gets SIGKILL when the process that started it dies, even if that
    one is killed before its `finally` runs (Linux prctl PR_SET_PDEATHSIG)."""
    ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)


class Browser:
    def __init__(self, width: int = 1280, height: int = 800, timeout: float = 20.0):
        exe = chromium_path()
        if exe is None:
            raise RuntimeError("chromium not installed (scripts/setup installs Debian's chromium)")
        self.profile = tempfile.mkdtemp(prefix="agrisim-chromium-")
        self.timeout = timeout
        args = [
            exe,
            "--headless=new",
            "--no-sandbox",  # root in a container: Chromium's sandbox needs user namespaces it may not get
            "--no-first-run",
            "--no-default-browser-check",
            "--disable-extensions",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-breakpad",
            "--disable-crash-reporter",
            # No GPU here: WebGL runs on SwiftShader, Chromium's software renderer.
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            f"--window-size={width},{height}",
            f"--user-data-dir={self.profile}",
            "--remote-debugging-address=127.0.0.1",
            "--remote-debugging-port=0",
            "about:blank",
        ]
        self.proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=die_with_parent)
        self.stderr: list[str] = []
        url = None
        deadline = time.monotonic() + timeout
        while url is None and time.monotonic() < deadline:
            line = self.proc.stderr.readline()
            if not line:
                break
            self.stderr.append(line)
            m = re.search(r"DevTools listening on (ws://\S+)", line)
            if m:
                url = m.group(1)
        if url is None:
            self.close()
            raise RuntimeError("chromium did not start its DevTools endpoint:\n" + "".join(self.stderr[-20:]))
        threading.Thread(target=self._drain, daemon=True).start()
        self.ws = connect(url, max_size=None, open_timeout=timeout, legacy=True)
        self._next = 0
        self._lock = threading.Condition()
        self._results: dict[int, dict] = {}
        self.events: list[dict] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _drain(self) -> None:
        for line in self.proc.stderr:
            self.stderr.append(line)

    def _read(self) -> None:
        try:
            for frame in self.ws:
                msg = json.loads(frame)
                with self._lock:
                    if "id" in msg:
                        self._results[msg["id"]] = msg
                    else:
                        self.events.append(msg)
                    self._lock.notify_all()
        except Exception:  # the socket closed: the waiters time out with the browser's stderr
            pass

    def send(self, method: str, params: dict | None = None, session: str | None = None, timeout: float | None = None) -> dict:
        with self._lock:
            self._next += 1
            mid = self._next
        msg = {"id": mid, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        deadline = time.monotonic() + (timeout or self.timeout)
        with self._lock:
            while mid not in self._results:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"chromium: no answer to {method} in {timeout or self.timeout} s")
                self._lock.wait(left)
            r = self._results.pop(mid)
        if "error" in r:
            raise RuntimeError(f"chromium: {method}: {r['error']}")
        return r.get("result", {})

    def new_page(self) -> "Page":
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        return Page(self, session)

    def close(self) -> None:
        try:
            if getattr(self, "ws", None) is not None:
                self.ws.close()
        finally:
            if self.proc.poll() is None:
                try:
                    os.killpg(self.proc.pid, signal.SIGTERM)
                    self.proc.wait(timeout=5)
                except (ProcessLookupError, subprocess.TimeoutExpired):
                    try:
                        os.killpg(self.proc.pid, signal.SIGKILL)
                    except ProcessLookupError:
                        pass
                    self.proc.wait(timeout=5)
            shutil.rmtree(self.profile, ignore_errors=True)


class Page:
    def __init__(self, browser: Browser, session: str):
        self.browser, self.session = browser, session
        self.first_event = len(browser.events)
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.send(f"{domain}.enable")

    def send(self, method: str, params: dict | None = None, timeout: float | None = None) -> dict:
        return self.browser.send(method, params, self.session, timeout)

    def my_events(self) -> list[dict]:
        with self.browser._lock:
            return [e for e in self.browser.events[self.first_event :] if e.get("sessionId") == self.session]

    def navigate(self, url: str, timeout: float = 20.0) -> None:
        start = len(self.my_events())
        r = self.send("Page.navigate", {"url": url})
        if r.get("errorText"):
            raise RuntimeError(f"chromium: cannot open {url}: {r['errorText']}")
        self.wait_for(lambda: any(e["method"] == "Page.loadEventFired" for e in self.my_events()[start:]), timeout, f"{url} did not finish loading")

    def eval(self, expression: str, timeout: float | None = None):
        r = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True}, timeout)
        if "exceptionDetails" in r:
            raise RuntimeError(f"page: {expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait_for(self, cond, timeout: float, what: str, poll: float = 0.2):
        deadline = time.monotonic() + timeout
        while True:
            v = cond()
            if v:
                return v
            if time.monotonic() > deadline:
                raise TimeoutError(f"{what} (after {timeout} s)")
            time.sleep(poll)

    def screenshot(self, path: Path | None = None) -> bytes:
        png = base64.b64decode(self.send("Page.captureScreenshot", {"format": "png", "optimizeForSpeed": True}, timeout=60)["data"])
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(png)
        return png

    def errors(self) -> list[str]:
        """Console errors, uncaught exceptions, log errors and failed requests, as text."""
        out = []
        events = self.my_events()
        urls = {e["params"]["requestId"]: e["params"]["request"]["url"] for e in events if e["method"] == "Network.requestWillBeSent"}
        for e in events:
            m, p = e["method"], e.get("params", {})
            if m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                out.append("console." + p["type"] + ": " + " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
            elif m == "Runtime.exceptionThrown":
                d = p.get("exceptionDetails", {})
                out.append("exception: " + str(d.get("exception", {}).get("description", d.get("text"))))
            elif m == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
                out.append("log: " + p["entry"].get("text", "") + " " + p["entry"].get("url", ""))
            elif m == "Network.loadingFailed" and not p.get("canceled"):
                out.append("request failed: " + p.get("errorText", "") + " " + urls.get(p.get("requestId"), "?"))
        return out
