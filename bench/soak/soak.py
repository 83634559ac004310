"""The soak's set-up, shared by the week (bench/soak/week.py) and its CI version (tests/soak/): the daemon on the
simulated lab, the console in headless Chromium, two event-stream followers, the API poller and the sampler —
all started before the first night and stopped after the last, so they live through every kill."""
from __future__ import annotations

import json
import time
from pathlib import Path

from lab import Lab
from page import ConsolePage
from probes import ApiPoller, EventFollower
from sampler import Sampler


class Soak:
    def __init__(self, out: Path, *, time_scale: float, seed: int, sample_every: float, poll_every: float = 0.2,
                 extra: str = ""):
        self.out = out
        out.mkdir(parents=True, exist_ok=True)
        self.lab = Lab(time_scale=time_scale, seed=seed, extra=extra)
        self.page = self.poller = self.sampler = None
        self.followers: list[EventFollower] = []
        try:
            self.page = ConsolePage(self.lab.url)
            # From the log's start: the followers must see every event the daemon ever logged, once.
            self.followers = [EventFollower(self.lab.url, n, 0) for n in ("a", "b")]
            for f in self.followers:
                f.start()
            self.poller = ApiPoller(self.lab.url, poll_every)
            self.poller.start()
            self.sampler = Sampler(self.lab, self.page, self.poller, self.followers, out / "samples.csv",
                                   sample_every)
            self.sampler.start()
        except BaseException:
            self.close()
            raise

    def wait_instruments(self, ids=("ls110",), timeout: float = 120) -> None:
        for i in ids:
            self.lab.daemon.wait_ready(i, timeout)

    def finish(self) -> dict:
        """Stops the probes (the sampler takes its last row first) and says what they saw."""
        self.sampler.stop()
        self.poller.stop()
        log_last = newest_seq(self.lab)
        followers = [{"name": f.name, "events": f.count, "last_seq": f.last_seq, "duplicates": f.duplicates,
                      "gaps": f.gaps, "error": f.error, "started_after": f.after} for f in self.followers]
        console_errors = self.page.console_errors()
        for f in self.followers:
            f.stop()
        return {"samples": len(self.sampler.rows), "sample_errors": self.sampler.errors,
                "poller_rounds": self.poller.rounds, "followers": followers, "log_last_seq": log_last,
                "console_errors": console_errors[-50:], "daemon_starts": self.lab.starts, "kills": self.lab.kills}

    def close(self) -> None:
        for f in self.followers:
            f.stop_flag.set()
        if self.poller:
            self.poller.stop_flag.set()
        if self.sampler and self.sampler.is_alive():
            self.sampler.stop_flag.set()
        if self.page:
            try:
                self.page.quit()
            except Exception:  # noqa: BLE001
                pass
        self.lab.cleanup()


def write_json(path: Path, doc) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(doc, indent=1, default=str))
    tmp.replace(path)


def newest_seq(lab) -> int:
    """The event log's newest seq: its pages from the end of what the followers saw, until an empty one."""
    seq = 0
    while True:
        items = lab.call("GET", f"/v1/events?after={seq}&limit=300").get("items") or []
        if not items:
            return seq
        seq = items[-1]["seq"]


def wait_followers_caught_up(soak: Soak, timeout: float = 60) -> None:
    """The followers have every event the log has (bounded; a follower that stays behind is reported, not waited)."""
    target = newest_seq(soak.lab)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and any(f.last_seq < target for f in soak.followers):
        time.sleep(0.2)
