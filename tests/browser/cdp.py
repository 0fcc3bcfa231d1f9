"""cdp.py - one headless Chromium for a whole test run, driven over the
DevTools protocol on a pipe (--remote-debugging-pipe: the browser reads
commands on its file descriptor 3 and writes replies and events on 4,
each a JSON text ended by a NUL byte). Only the Python standard library.

    with Browser(exe, workdir) as b:
        page = b.open("file:///...#frame=3")   # a fresh tab, loaded
        page.status(), page.errors, page.screenshot(path)
        page.close()

Every wait has a deadline (timeout seconds): a browser that stops
answering raises BrowserError instead of hanging the test.
"""
import base64
import json
import os
import select
import subprocess
import time


class BrowserError(Exception):
    pass


class Browser:
    def __init__(self, exe, workdir, timeout=120, size=(860, 960)):
        self.timeout = timeout
        self.size = size
        self.next_id = 0
        self.buf = b""
        self.events = []  # (sessionId, method, params) not yet taken
        to_child, self.w = os.pipe()   # commands: the browser's fd 3
        self.r, from_child = os.pipe()  # replies: the browser's fd 4

        def fds():  # in the child, before exec
            os.dup2(to_child, 3)
            os.dup2(from_child, 4)
        cmd = [exe, "--headless", "--no-sandbox", "--no-first-run",
               "--disable-gpu-sandbox", "--use-angle=swiftshader",
               "--enable-unsafe-swiftshader", "--hide-scrollbars",
               "--window-size=%d,%d" % size, "--remote-debugging-pipe",
               "--user-data-dir=" + os.path.join(workdir, "profile"),
               "about:blank"]
        self.log = open(os.path.join(workdir, "chromium.log"), "wb")
        self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL,
                                     stdout=self.log, stderr=self.log,
                                     pass_fds=(3, 4), preexec_fn=fds,
                                     cwd=workdir)
        os.close(to_child)
        os.close(from_child)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.quit()

    def quit(self):
        if self.proc.poll() is None:
            try:
                self.send("Browser.close")
            except (BrowserError, OSError):
                pass
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for fd in (self.r, self.w):
            try:
                os.close(fd)
            except OSError:
                pass
        self.log.close()

    def _read(self, deadline):
        """The next message from the browser, before deadline."""
        while b"\0" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise BrowserError("Chromium did not answer within %d s"
                                   % self.timeout)
            ready, _, _ = select.select([self.r], [], [], left)
            if ready:
                chunk = os.read(self.r, 1 << 20)
                if not chunk:
                    raise BrowserError("Chromium closed its pipe (exit "
                                       "status %s)" % self.proc.poll())
                self.buf += chunk
        msg, self.buf = self.buf.split(b"\0", 1)
        return json.loads(msg)

    def send(self, method, params=None, session=None):
        """Send a command and wait for its reply (events meanwhile are
        kept): the reply's result, or BrowserError with its error."""
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.w, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            m = self._read(deadline)
            if m.get("id") == self.next_id:
                if "error" in m:
                    raise BrowserError("%s: %s" % (method, m["error"]))
                return m.get("result", {})
            if "method" in m:
                self.events.append((m.get("sessionId"), m["method"],
                                    m.get("params", {})))

    def wait_event(self, session, method):
        """The params of the first event method of session (kept or yet
        to come)."""
        deadline = time.monotonic() + self.timeout
        while True:
            for k, (s, meth, p) in enumerate(self.events):
                if s == session and meth == method:
                    del self.events[k]
                    return p
            m = self._read(deadline)
            if "method" in m:
                self.events.append((m.get("sessionId"), m["method"],
                                    m.get("params", {})))

    def open(self, url):
        """A new tab showing url, loaded: a Page."""
        target = self.send("Target.createTarget",
                           {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget",
                            {"targetId": target, "flatten": True})["sessionId"]
        page = Page(self, target, session)
        for domain in ("Page", "Runtime", "Log"):
            self.send(domain + ".enable", session=session)
        self.send("Emulation.setDeviceMetricsOverride",
                  {"width": self.size[0], "height": self.size[1],
                   "deviceScaleFactor": 1, "mobile": False},
                  session=session)
        self.send("Page.navigate", {"url": url}, session=session)
        self.wait_event(session, "Page.loadEventFired")
        return page


class Page:
    def __init__(self, browser, target, session):
        self.b, self.target, self.session = browser, target, session

    def eval(self, expr):
        r = self.b.send("Runtime.evaluate",
                        {"expression": expr, "returnByValue": True},
                        session=self.session)
        if "exceptionDetails" in r:
            raise BrowserError("%s: %s" % (expr, r["exceptionDetails"]))
        return r["result"].get("value")

    @property
    def errors(self):
        """The page's console errors and uncaught exceptions so far."""
        out, keep = [], []
        for ev in self.b.events:
            s, meth, p = ev
            if s != self.session:
                keep.append(ev)
            elif meth == "Runtime.exceptionThrown":
                d = p["exceptionDetails"]
                out.append(d.get("exception", {}).get("description") or
                           d.get("text"))
            elif meth == "Runtime.consoleAPICalled" and \
                    p["type"] in ("error", "assert"):
                out.append(" ".join(str(a.get("value", a.get("description")))
                                    for a in p["args"]))
            elif meth == "Log.entryAdded" and \
                    p["entry"]["level"] == "error":
                out.append(p["entry"]["text"])
        self.b.events = keep
        self._errors = getattr(self, "_errors", []) + out
        return list(self._errors)

    def status(self):
        """The page's #status object (after its first frame), or None."""
        deadline = time.monotonic() + self.b.timeout
        while time.monotonic() < deadline:
            text = self.eval("(document.getElementById('status') || "
                             "{}).textContent || ''")
            if text:
                return json.loads(text)
            time.sleep(0.05)
        return None

    def screenshot(self, path, clip=None):
        """A PNG of the window, or of clip (x, y, width, height, scale)
        in the page's CSS pixels, into path."""
        params = {"format": "png"}
        if clip:
            params["clip"] = dict(zip(("x", "y", "width", "height",
                                       "scale"), clip))
        r = self.b.send("Page.captureScreenshot", params,
                        session=self.session)
        with open(path, "wb") as f:
            f.write(base64.b64decode(r["data"]))

    def close(self):
        self.b.send("Target.closeTarget", {"targetId": self.target})
