"""The live clients a lab has on its daemon while it works: an API poller (a dashboard's reads over loopback TCP)
and followers of the event stream (the Python client's reconnecting generator, as a script would follow a night).

Both keep running across a kill -9: the poller counts the requests the dead daemon refused apart from the answer
times; a follower reconnects with Last-Event-ID and must never see an event twice."""
from __future__ import annotations

import threading
import time

import requests

import lab  # noqa: F401,E402  (puts the repository's Python client on the path)
import colorlab  # noqa: E402

ROUTES = ("/v1", "/v1/runs", "/v1/control", "/v1/queue")


def p99(values: list[float]) -> float | None:
    if not values:
        return None
    s = sorted(values)
    return s[min(len(s) - 1, int(0.99 * len(s)))]


class ApiPoller(threading.Thread):
    """GET each route in turn, a round every ``interval`` s; ``take()`` hands over the answer times (ms) since the
    last take. A connection refused or reset (the daemon being restarted) is counted as failed, not timed."""

    def __init__(self, url: str, interval: float = 0.2):
        super().__init__(name="soak-api-poller", daemon=True)
        self.url, self.interval = url, interval
        self.stop_flag = threading.Event()
        self._lock = threading.Lock()
        self._times: list[float] = []
        self._by_route: dict[str, list[float]] = {r: [] for r in ROUTES}
        self._failed = 0
        self.rounds = 0

    def run(self) -> None:
        session = requests.Session()
        while not self.stop_flag.is_set():
            started = time.monotonic()
            for route in ROUTES:
                t0 = time.perf_counter()
                try:
                    r = session.get(self.url + route, timeout=30)
                    r.content  # noqa: B018  (the whole answer read)
                    ok = r.status_code == 200
                except requests.RequestException:
                    ok = False
                    session.close()
                    session = requests.Session()
                ms = (time.perf_counter() - t0) * 1000
                with self._lock:
                    if ok:
                        self._times.append(ms)
                        self._by_route[route].append(ms)
                    else:
                        self._failed += 1
            self.rounds += 1
            self.stop_flag.wait(max(0.0, self.interval - (time.monotonic() - started)))
        session.close()

    def take(self) -> tuple[list[float], int, dict[str, list[float]]]:
        """The answer times (ms) since the last take, all routes and per route, and the refused requests."""
        with self._lock:
            times, failed, by_route = self._times, self._failed, self._by_route
            self._times, self._failed, self._by_route = [], 0, {r: [] for r in ROUTES}
        return times, failed, by_route

    def stop(self) -> None:
        self.stop_flag.set()
        self.join(35)


class EventFollower(threading.Thread):
    """Follows GET /v1/events/stream from ``after`` (the log's last seq when it started) with the client's
    reconnecting generator. ``duplicates``: events yielded at or below a seq already seen (must stay 0);
    ``gaps``: seqs skipped between two consecutive events (the log's seqs are consecutive, so 0 too)."""

    def __init__(self, url: str, name: str, after: int):
        super().__init__(name=f"soak-follower-{name}", daemon=True)
        self.client = colorlab.Client(url)
        self.after = after
        self.count = 0
        self.duplicates = 0
        self.gaps = 0
        self.last_seq = after
        self.error: str | None = None
        self.stop_flag = threading.Event()

    def run(self) -> None:
        try:
            for ev in self.client.events(after=self.after, give_up_after=None):
                if self.stop_flag.is_set():
                    return
                if ev.topic == "snapshot":
                    continue
                if ev.seq <= self.last_seq:
                    self.duplicates += 1
                    continue
                if ev.seq != self.last_seq + 1:
                    self.gaps += ev.seq - self.last_seq - 1
                self.last_seq = ev.seq
                self.count += 1
        except Exception as e:  # noqa: BLE001  (kept for the report: a follower that died is a finding)
            if not self.stop_flag.is_set():
                self.error = f"{type(e).__name__}: {e}"

    def stop(self) -> None:
        self.stop_flag.set()
        self.client.close()  # unblocks the read; the thread is a daemon thread if it does not notice
        self.join(5)
