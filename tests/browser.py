"""Opens a page in headless Chromium over the DevTools protocol (on a pipe: no extra packages),
and returns its console errors, what a JavaScript expression evaluates to, and a screenshot."""

import base64
import fcntl
import json
import os
import shlex
import shutil
import subprocess
import tempfile
import time

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


def _high(fd):
    new = fcntl.fcntl(fd, fcntl.F_DUPFD, 10)
    os.close(fd)
    return new


class Browser:
    def __init__(self):
        self.profile = tempfile.mkdtemp(prefix="tf-chromium-")
        to_chrome_r, self._w = os.pipe()
        self._r, from_chrome_w = os.pipe()
        # the child's ends go above fd 10, so that moving them to 3 and 4 cannot close either
        to_chrome_r, from_chrome_w = (_high(fd) for fd in (to_chrome_r, from_chrome_w))
        args = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--remote-debugging-pipe", f"--user-data-dir={self.profile}", "--window-size=1300,900"]
        # Chromium reads commands on fd 3 and answers on fd 4: a shell moves the pipe ends there
        # (subprocess would close fds that a preexec_fn made; bash, unlike dash, takes fds above 9)
        script = (f"exec {' '.join(shlex.quote(a) for a in args)} 3<&{to_chrome_r} 4>&{from_chrome_w} "
                  f"{to_chrome_r}<&- {from_chrome_w}>&-")
        self.proc = subprocess.Popen([shutil.which("bash") or "/bin/bash", "-c", script], pass_fds=(to_chrome_r, from_chrome_w),
                                     stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._buf = b""
        self._id = 0
        self.events = []

    def _send(self, method, params=None, session=None):
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        return self._id

    def _read(self, deadline):
        while b"\0" not in self._buf:
            if time.time() > deadline:
                raise TimeoutError("no answer from Chromium")
            chunk = os.read(self._r, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed the pipe")
            self._buf += chunk
        raw, self._buf = self._buf.split(b"\0", 1)
        return json.loads(raw)

    def call(self, method, params=None, session=None, timeout=30):
        i = self._send(method, params, session)
        deadline = time.time() + timeout
        while True:
            msg = self._read(deadline)
            if msg.get("id") == i:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            self.events.append(msg)

    def wait_event(self, name, timeout=30):
        deadline = time.time() + timeout
        for m in self.events:
            if m.get("method") == name:
                return m
        while True:
            msg = self._read(deadline)
            self.events.append(msg)
            if msg.get("method") == name:
                return msg

    def open(self, url, expression, screenshot=None, height=None):
        self.events = []  # a second page must wait for its own load event, and report its own errors
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable", session=session)
        self.call("Page.navigate", {"url": url}, session=session)
        self.wait_event("Page.loadEventFired")
        value = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True},
                          session=session)["result"].get("value")
        if screenshot:
            full = self.call("Runtime.evaluate", {"expression": "document.documentElement.scrollHeight",
                                                  "returnByValue": True}, session=session)["result"]["value"]
            self.call("Emulation.setDeviceMetricsOverride", {"width": 1300, "height": min(int(height or full), 16000),
                                                              "deviceScaleFactor": 1, "mobile": False},
                      session=session)
            png = self.call("Page.captureScreenshot", {"format": "png"}, session=session, timeout=60)["data"]
            with open(screenshot, "wb") as fh:
                fh.write(base64.b64decode(png))
        errors = []
        for m in self.events:
            p = m.get("params", {})
            if m.get("method") == "Runtime.exceptionThrown":
                errors.append(p["exceptionDetails"].get("text", "exception"))
            elif m.get("method") == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                errors.append(" ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
            elif m.get("method") == "Log.entryAdded" and p["entry"].get("level") == "error":
                errors.append(p["entry"].get("text", ""))
        return value, errors

    def close(self):
        try:
            self.call("Browser.close", timeout=5)
        except Exception:
            pass
        self.proc.kill()
        self.proc.wait()
        os.close(self._w)
        os.close(self._r)
        shutil.rmtree(self.profile, ignore_errors=True)
