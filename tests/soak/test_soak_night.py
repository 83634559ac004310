"""The soak's CI version (issue 27; bench/soak/ is the week): one short night twice on colorlabd's embedded simulated
lab — a reference night, then the same night with kill -9 of the daemon in the middle of its cabinet grid — with
the console open in headless Chromium, two event-stream followers and the API poller running throughout, and the
soak's sampler taking a row every SAMPLE_EVERY seconds.

Checked, with no timing threshold (every wait bounded, with a message):
- every sample was taken (one row per sampler round, none failed, every series read);
- the killed run resumed — the same execution, not a new one — and the night completed;
- no measurement lost or doubled: the killed night's runs have the reference night's rows and shape digest per
  run (bench/soak/ledger.py), seqs 1..N, and the grid's keys are exactly the ones its parameters define;
- nothing committed before the kill changed: every row in the file the killed daemon left (both nights' so far,
  the grid's first measurements among them) is there at the night's end with the same values and data;
- the followers saw every event of the log exactly once, across the kill;
- the restarted daemon, idle after its night, holds no more threads than the first daemon did idle after a
  whole night of the same work, and no more descriptors than that plus the browser's connections (below).

Fails — never skips — where chromium, chromedriver or python3-selenium are missing: scripts/setup.sh installs them.
"""
from __future__ import annotations

import os
import sys
import time
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("COLORLAB_SOURCE_DIR") or Path(__file__).resolve().parents[2])
sys.path.insert(0, str(SOURCE_DIR / "bench" / "soak"))

from checks import compare_nights  # noqa: E402
from ledger import check_kills  # noqa: E402
from night import enqueue, run_night, status  # noqa: E402
from sampler import COLUMNS, proc_stats  # noqa: E402
from soak import Soak, newest_seq, wait_followers_caught_up  # noqa: E402

import colorlab  # noqa: E402  (on the path bench/soak/lab.py set)

ARTIFACTS = Path(os.environ.get("COLORLAB_ARTIFACT_DIR") or SOURCE_DIR / "build" / "test-artifacts" / "soak")
TIME_SCALE = 200
SAMPLE_EVERY = 2.0
GRID = {"rows": 2, "cols": 3, "lamps": ["D65"], "dimmer_levels": [100, 50], "settle_s": 0}
NIGHT = [{"campaign": "frame-average", "params": {"frames": 4}}, {"campaign": "cabinet-grid", "params": GRID}]
# Chromium keeps at most six connections per host (its per-host socket pool): an idle page may hold up to that many
# keep-alive sockets to the daemon, which the two idle moments compared need not hold in the same number.
BROWSER_CONNECTIONS = 6
WAIT_S = 240


def grid_keys(p: dict) -> set[str]:
    """The keys campaigns/scripts/cabinet-grid.lua records: one per spot, lamp and dimmer level."""
    return {f"L/{lamp}/D{level:g}/r{r}c{c}" for lamp in p["lamps"] for level in p["dimmer_levels"]
            for r in range(p["rows"]) for c in range(p["cols"])}


class SoakNight(unittest.TestCase):
    def setUp(self):
        self.soak = Soak(ARTIFACTS, time_scale=TIME_SCALE, seed=5, sample_every=SAMPLE_EVERY)
        self.addCleanup(self.soak.close)
        self.lab = self.soak.lab

    def idle(self, what: str) -> dict:
        """The daemon once nothing runs or is queued (bounded wait)."""
        deadline = time.monotonic() + WAIT_S
        q = {}
        while time.monotonic() < deadline:
            q = self.lab.call("GET", "/v1/queue")
            if not q.get("items") and not q.get("current"):
                with self.lab.lock:
                    return proc_stats(self.lab.pid)
            time.sleep(0.2)
        self.fail(f"the daemon did not become idle {what} within {WAIT_S} s: {q}")

    def kill_mid_grid(self, queued: dict) -> dict:
        """kill -9 once the grid's run holds two measurements and its execution still runs (bounded waits). A step
        commits before each lab call, and the grid aims, lights and reads several times before its first record, so
        rows, not committed steps, say a kill leaves measurements of the grid behind. Once its execution is known
        only it is polled: two requests per look keep the window between looks short."""
        deadline = time.monotonic() + WAIT_S
        item = {}
        while time.monotonic() < deadline and not item.get("execution_id"):
            item = self.lab.call("GET", f"/v1/queue/{queued['items'][1]}")
            time.sleep(0.02)
        self.assertTrue(item.get("execution_id"), f"the grid did not start within {WAIT_S} s: {item}")
        ex, rows = {}, 0
        while time.monotonic() < deadline:
            ex = self.lab.call("GET", f"/v1/executions/{item['execution_id']}")
            if ex["status"] in colorlab.TERMINAL:
                self.fail(f"the grid ended before it could be killed mid-run: {ex}")
            if ex.get("run_id"):
                rows = self.lab.call("GET", f"/v1/runs/{ex['run_id']}")["measurement_count"]
                if rows >= 2:
                    return self.lab.kill_and_restart({"execution_id": ex["id"], "run_id": ex["run_id"],
                                                      "rows_seen": rows, "status": ex["status"]})
            time.sleep(0.01)
        self.fail(f"the grid did not record two measurements within {WAIT_S} s ({rows} seen): {ex}\n"
                  f"{self.lab.daemon.log_text()}")

    def settles_within(self, base: dict) -> dict:
        """The restarted daemon, idle, back within the first one's idle figures (bounded wait: a keep-alive socket
        the page has just opened may take a moment to close)."""
        deadline = time.monotonic() + 60
        while True:
            with self.lab.lock:
                now = proc_stats(self.lab.pid)
            if now["threads"] <= base["threads"] and now["fds"] <= base["fds"] + BROWSER_CONNECTIONS:
                return now
            if time.monotonic() > deadline:
                self.fail(f"idle after the killed night: {now['threads']} threads, {now['fds']} descriptors; idle "
                          f"after the reference night: {base['threads']} threads, {base['fds']} descriptors "
                          f"(+{BROWSER_CONNECTIONS} allowed for the page's sockets)")
            time.sleep(0.5)

    def test_a_short_night_killed_mid_run(self):
        started = time.monotonic()
        self.soak.wait_instruments(("ls110",))
        self.soak.sampler.night = 1
        reference = run_night(self.lab, 1, enqueue(self.lab, campaigns=NIGHT), [], timeout=WAIT_S)
        base = self.idle("after the reference night")

        self.soak.sampler.night = 2
        queued = enqueue(self.lab, campaigns=NIGHT)
        kill = self.kill_mid_grid(queued)
        killed = run_night(self.lab, 2, queued, [], timeout=WAIT_S)
        killed["kills"] = [kill]
        check_kills(self.lab.state / "colorlab.db", killed["kills"])

        # The night completed, the killed execution resumed (the same one, to its end).
        self.assertEqual([reference["state"], killed["state"]], ["done", "done"], [reference, killed])
        grid_item = status(self.lab, queued)["items"][1]
        self.assertEqual(grid_item["execution_id"], kill["execution_id"], "the grid was started anew, not resumed")
        ex = self.lab.call("GET", f"/v1/executions/{kill['execution_id']}")
        self.assertEqual(ex["status"], "finished_ok", ex)

        # No lost or doubled measurement: the reference night's rows and shapes, and the grid's own keys.
        checks = compare_nights([reference, killed])
        self.assertEqual(checks["problems"], [], checks)
        # The re-read covered the killed grid's own measurements: at least the two seen before the kill.
        kept = kill["kept_check"]
        self.assertGreaterEqual(kept["rows_by_run"].get(kill["run_id"], 0), kill["rows_seen"], kept)
        self.assertEqual(kept["runs"], 4, f"the file at the kill: the reference night's two runs, then the killed "
                                          f"night's frame-average and grid; {kept}")
        for night in (reference, killed):
            grid = night["ledger"]["cabinet-grid"]
            self.assertEqual(set(grid["steps"]), grid_keys(GRID), f"night {night['night']}: grid keys")
            self.assertEqual(grid["rows"], len(grid_keys(GRID)))

        # Back to the baseline: the restarted daemon, idle, holds no more than the first did after the same work.
        self.idle("after the killed night")
        after = self.settles_within(base)

        # Every event once to each follower, across the kill.
        wait_followers_caught_up(self.soak)
        probes = self.soak.finish()
        newest = newest_seq(self.lab)
        for f in probes["followers"]:
            self.assertEqual((f["duplicates"], f["gaps"], f["error"], f["last_seq"]), (0, 0, None, newest), f)
        self.assertEqual(probes["daemon_starts"], 2)

        # Every sample taken, every series read in each, across the kill.
        rows = self.soak.sampler.rows
        self.assertEqual(probes["sample_errors"], [])
        self.assertGreaterEqual(len(rows), 3, "the sampler took fewer than three rows")
        self.assertEqual([r["sample"] for r in rows], list(range(1, len(rows) + 1)))
        for r in rows:
            missing = [c for c in COLUMNS if r.get(c) is None and not c.startswith(("api_p99_ms", "api_max_ms"))]
            self.assertEqual(missing, [], f"sample {r['sample']}")
            self.assertGreater(r["js_heap_used"], 0, f"sample {r['sample']}: no JS heap read")
        self.assertEqual({r["daemon_pid"] for r in rows if r["daemon_starts"] == 2}, {kill["new_pid"]})
        print(f"soak night: {len(rows)} samples, {probes['poller_rounds']} poller rounds, kill at "
              f"{kill['rows_seen']} grid rows ({kept['rows']} rows of {kept['runs']} runs re-read unchanged), "
              f"idle threads {base['threads']} -> {after['threads']}, fds {base['fds']} -> {after['fds']}; "
              f"{time.monotonic() - started:.1f} s", flush=True)


if __name__ == "__main__":
    unittest.main()
