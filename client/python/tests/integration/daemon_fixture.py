"""A real colorlabd on the embedded simulated lab, in a temporary state directory — the Python twin of
tests/support's DaemonProcess and resume_support's write_daemon_config: the daemon listens on 127.0.0.1:0
(or a given port, to come back on it after a restart) and says where in <state>/colorlabd.endpoint.
``client`` is Client.local(): through the daemon's Unix socket, which may do everything."""
from __future__ import annotations

import ctypes
import json
import os
import shutil
import signal
import socket
import sqlite3
import subprocess
import tempfile
import time
import unittest
from pathlib import Path

import colorlab

SOURCE_DIR = Path(os.environ.get("COLORLAB_SOURCE_DIR") or Path(__file__).resolve().parents[4])
BIN_DIR = Path(os.environ.get("COLORLAB_BIN_DIR") or SOURCE_DIR / "build" / "bin")
# No GigE Vision camera (its fake serves 127.0.0.1 once, for the tests holding the loopback lock); the
# simulated DSLR, small, is the lab's camera.
LAB_TOML = "[genicam]\nenabled = false\n[dslr]\nsize = [640, 428]\n"
TERMINAL = colorlab.TERMINAL


def _die_with_parent() -> None:
    """In the child: SIGKILL when the test process dies (a ctest timeout), so no daemon outlives its test."""
    PR_SET_PDEATHSIG = 1
    ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Daemon:
    def __init__(self, *, time_scale: float = 200, seed: int = 3, port: int = 0, extra: str = ""):
        self.dir = Path(tempfile.mkdtemp(prefix="colorlab-python-"))
        self.state = self.dir / "state"
        self.port = port
        (self.dir / "lab.toml").write_text(LAB_TOML)
        (self.dir / "colorlabd.toml").write_text(
            f"[simulator]\nenabled = true\ntime_scale = {time_scale}\nseed = {seed}\nconfig = \"lab.toml\"\n{extra}")
        self.log = self.dir / "colorlabd.log"
        self.proc = None
        self.endpoint = {}
        try:
            self.start()
        except BaseException:
            self.cleanup()  # a daemon that did not come up must not outlive the test
            raise

    def start(self) -> None:
        binary = BIN_DIR / "colorlabd"
        if not binary.exists():
            raise unittest.SkipTest(f"{binary} is not built")
        with open(self.log, "ab") as log:  # appended: a restarted daemon's log follows the killed one's
            self.proc = subprocess.Popen([str(binary), "--config", str(self.dir / "colorlabd.toml"), "--state",
                                          str(self.state), "--listen", f"127.0.0.1:{self.port}"],
                                         stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                         preexec_fn=_die_with_parent)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            try:
                endpoint = json.loads((self.state / "colorlabd.endpoint").read_text())
                if endpoint.get("pid") == self.proc.pid:
                    self.endpoint = endpoint
                    if getattr(self, "client", None):
                        self.client.close()
                    self.client = colorlab.Client.local(self.state)
                    return
            except (FileNotFoundError, ValueError):
                pass
            if self.proc.poll() is not None:
                break
            time.sleep(0.01)
        raise RuntimeError(f"colorlabd did not write its endpoint file:\n{self.log_text()}")

    @property
    def url(self) -> str:
        return self.endpoint["url"]

    def tcp_client(self, key: str | None = None) -> colorlab.Client:
        """A client over loopback TCP, as a remote user's would be: reads need no key, control does."""
        return colorlab.Client(self.url, key=key or "")

    def log_text(self) -> str:
        try:
            return self.log.read_text(errors="replace")[-6000:]
        except FileNotFoundError:
            return ""

    def wait_ready(self, instrument: str, timeout: float = 60) -> dict:
        """Until the instrument is ready (instruments connect in the background after start-up)."""
        deadline = time.monotonic() + timeout
        item = {}
        while time.monotonic() < deadline:
            for item in self.client.conn.get("/v1/instruments")["items"]:
                if item["id"] == instrument and item["state"] in ("ready", "needs_calibration"):
                    return item
            time.sleep(0.05)
        raise AssertionError(f"{instrument} not ready: {item}\n{self.log_text()}")

    def wait_terminal(self, execution_id: str, timeout: float = 300) -> dict:
        """The test's own view of the end, by polling the execution: independent of the client's stream."""
        deadline = time.monotonic() + timeout
        e = {}
        while time.monotonic() < deadline:
            e = self.client.conn.get(f"/v1/executions/{execution_id}")
            if e["status"] in TERMINAL:
                return e
            time.sleep(0.05)
        raise AssertionError(f"execution {execution_id} did not end: {e}\n{self.log_text()}")

    def run_to_end(self, campaign: str, **params) -> dict:
        e = self.client.conn.post("/v1/executions", {"campaign": campaign, "params": params})
        done = self.wait_terminal(e["id"])
        if done["status"] != "finished_ok":
            raise AssertionError(f"{campaign} ended {done['status']}: {done}\n{self.log_text()}")
        return done

    def stored_measurements(self, run_id: str) -> list[dict]:
        """The run's measurements as stored: read from the daemon's SQLite file (read-only, beside the running
        daemon: WAL readers never block its writer), not through its API."""
        con = sqlite3.connect(f"file:{self.state / 'colorlab.db'}?mode=ro", uri=True)
        try:
            rows = con.execute("SELECT seq, step, instrument_id, simulated, quantity, value, unit, data, measured_at "
                               "FROM measurements WHERE run_id = ? ORDER BY seq", (run_id,)).fetchall()
        finally:
            con.close()
        keys = ("seq", "step", "instrument_id", "simulated", "quantity", "value", "unit", "data", "measured_at")
        out = []
        for row in rows:
            m = dict(zip(keys, row))
            m["simulated"] = bool(m["simulated"])
            m["data"] = json.loads(m["data"]) if m["data"] else None
            out.append(m)
        return out

    def _wait_simulator_gone(self) -> None:
        pid = self.endpoint.get("simulator_pid", -1)
        for _ in range(1000):
            if pid <= 0:
                return
            try:
                os.kill(pid, 0)
                state = Path(f"/proc/{pid}/stat").read_text().split(") ")[-1][:1]
                if state == "Z":
                    return
            except (ProcessLookupError, FileNotFoundError):
                return
            time.sleep(0.01)

    def kill9(self) -> None:
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(10)
        self._wait_simulator_gone()

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(10)
        self._wait_simulator_gone()
        if getattr(self, "client", None):
            self.client.close()

    def cleanup(self) -> None:
        self.stop()
        shutil.rmtree(self.dir, ignore_errors=True)


def skip_unless_served(test: unittest.TestCase, call, route: str):
    """Runs ``call``; a 404 from the daemon's router ("no route for …") means the route has not landed yet,
    and only the test that needs it is skipped, naming it."""
    try:
        return call()
    except colorlab.NotFound as e:
        if "no route" in (e.detail or ""):
            test.skipTest(f"colorlabd does not serve {route} yet (issue 10)")
        raise
