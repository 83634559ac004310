"""The daemon under soak: the Python client's test fixture (client/python/tests/integration/daemon_fixture.py) —
colorlabd with its embedded simulated lab in a temporary state directory, on a fixed loopback port so the console
page and the event followers find it again after a kill -9 — plus what the soak needs beyond it: the night's queue
group, and the kill and restart done under a lock the sampler also takes, so no sample reads a dead process."""
from __future__ import annotations

import os
import sys
import threading
import time
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("COLORLAB_SOURCE_DIR") or Path(__file__).resolve().parents[2])
sys.path.insert(0, str(SOURCE_DIR / "client" / "python"))
sys.path.insert(0, str(SOURCE_DIR / "client" / "python" / "tests" / "integration"))

import colorlab  # noqa: E402
import daemon_fixture  # noqa: E402
from daemon_fixture import Daemon, free_port  # noqa: E402
from ledger import committed_values  # noqa: E402

BIN_DIR = daemon_fixture.BIN_DIR


class SoakError(Exception):
    """Something the soak could not do (a daemon that does not come back, a group that does not end)."""


# The DSLR at the size the study's own test gives it (client/python/tests/integration/test_study.py): the chart
# must be located in its photographs for characterize-camera; half the 20D's full size keeps a night's CPU down.
LAB_TOML = "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n"


class Lab:
    def __init__(self, *, time_scale: float, seed: int, extra: str = ""):
        saved = daemon_fixture.LAB_TOML
        daemon_fixture.LAB_TOML = LAB_TOML
        try:
            self.daemon = Daemon(time_scale=time_scale, seed=seed, port=free_port(), extra=extra)
        finally:
            daemon_fixture.LAB_TOML = saved
        self.lock = threading.Lock()  # held across kill + restart; the sampler holds it while it reads /proc
        self.starts = 1
        self.kills: list[dict] = []

    @property
    def url(self) -> str:
        return self.daemon.url

    @property
    def state(self) -> Path:
        return self.daemon.state

    @property
    def pid(self) -> int:
        return self.daemon.proc.pid

    def call(self, method: str, path: str, body=None, headers=None, timeout: float = 120):
        """A request over the Unix socket, retried while the daemon is being restarted (the socket is absent
        or refuses): bounded, with the last problem in the failure."""
        deadline = time.monotonic() + timeout
        last = None
        while time.monotonic() < deadline:
            with self.lock:
                client = self.daemon.client
            try:
                if method == "GET":
                    return client.conn.get(path)
                return client.conn.post(path, body, headers=headers)
            except (colorlab.ConnectionFailed, colorlab.ServiceUnavailable) as e:
                last = e
                time.sleep(0.5)
        raise SoakError(f"{method} {path}: the daemon did not answer for {timeout} s (last: {last})\n"
                        f"{self.daemon.log_text()}")

    def kill_and_restart(self, why: dict) -> dict:
        """kill -9 of colorlabd, then the same daemon started again on the same state and port. Between the two, what
        the dead daemon had committed is read from its file (``kept``: every run's rows and values digest; or
        ``kept_error`` when that read failed — the daemon is started again all the same), for ledger.check_kills once
        the night has ended. ``restart_s``: from the kill to the new daemon's endpoint file, without that read;
        ``read_s``: the read, which the clients also wait out."""
        with self.lock:
            old = self.pid
            t0 = time.monotonic()
            self.daemon.kill9()
            killed = time.monotonic()
            kept: dict = {}
            try:
                kept["kept"] = committed_values(self.state / "colorlab.db")
            except Exception as e:  # noqa: BLE001 — whatever it was, the night must go on and the check says so
                kept["kept_error"] = f"{type(e).__name__}: {e}"
            finally:
                read_s = time.monotonic() - killed
                self.daemon.start()
            self.starts += 1
            kill = {**why, "killed_pid": old, "new_pid": self.pid,
                    "restart_s": round(time.monotonic() - t0 - read_s, 3), "read_s": round(read_s, 3), **kept}
        self.kills.append(kill)
        return kill

    def cleanup(self) -> None:
        self.daemon.cleanup()
