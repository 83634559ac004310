"""python3 -m colorlab.study: the dissertation study (reduced with --small) through the night queue on a colorlabd
with the embedded simulated lab, end to end to its report; re-attached with --resume after the study's process
and the daemon were killed -9 mid-study; the study's process killed right after it queued the study, and the night
completing in the daemon alone with each reference the right run; a campaign that fails ends the study with exit 4,
naming it; bad usage 2. The steps are the daemon's sequence `dissertation` (GET /v1/campaigns)."""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

import daemon_fixture
from daemon_fixture import SOURCE_DIR

# The chart must be located in the DSLR's photographs: the size characterize-camera's report test uses.
LAB_TOML = "[genicam]\nenabled = false\n[dslr]\nsize = [1752, 1168]\n"
ENV = dict(os.environ, PYTHONPATH=str(SOURCE_DIR / "client" / "python"), PYTHONUNBUFFERED="1")
CAMPAIGNS = ["chart-read", "frame-average", "cabinet-grid", "floor-luminance", "characterize-camera", "dimmer-exposure"]


def study_command(daemon, tmp: Path, *extra) -> list[str]:
    return [sys.executable, "-m", "colorlab.study", "dissertation", "--small", "--socket",
            daemon.endpoint["unix_socket"], "--state-file", str(tmp / "study.json"), "-o", str(tmp / "report.html"),
            *extra]


class Study(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        saved = daemon_fixture.LAB_TOML
        daemon_fixture.LAB_TOML = LAB_TOML
        try:
            cls.daemon = daemon_fixture.Daemon(time_scale=500, seed=9)
        finally:
            daemon_fixture.LAB_TOML = saved
        for instrument in ("spectrolino", "ls110", "dmx", "dslr"):
            cls.daemon.wait_ready(instrument)

    @classmethod
    def tearDownClass(cls):
        cls.daemon.cleanup()

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="colorlab-study-", dir=self.daemon.dir))

    def run_study(self, *extra, timeout=200) -> subprocess.CompletedProcess:
        return subprocess.run(study_command(self.daemon, self.tmp, *extra), capture_output=True, text=True, env=ENV,
                              timeout=timeout, cwd=self.tmp)

    def check_study(self, p: subprocess.CompletedProcess, as_json=False, progress=True) -> list[str]:
        self.assertEqual(p.returncode, 0, f"{p.stdout}\n{p.stderr}\n{self.daemon.log_text()}")
        report = self.tmp / "report.html"
        state = json.loads((self.tmp / "study.json").read_text())
        runs = [state["runs"][c] for c in CAMPAIGNS]
        if as_json:
            # stdout is one JSON object; the progress lines went to stderr.
            j = json.loads(p.stdout)
            self.assertEqual((j["study"], j["id"], j["report"]), ("dissertation", state["id"], str(report.resolve())))
            self.assertEqual(j["runs"], state["runs"])
            self.assertEqual(j["run_ids"], runs)
            self.assertEqual(j["state_file"], str((self.tmp / "study.json").resolve()))
            seconds = j["seconds"]
            self.assertGreaterEqual(seconds["total"], seconds["campaigns"] + seconds["report"] - 1e-6)
            self.assertGreaterEqual(seconds["report"], seconds["report_detail"]["total"])
            lines = p.stderr.strip().splitlines()
        else:
            lines = p.stdout.strip().splitlines()
            self.assertEqual(lines[-1], str(report.resolve()), "the report's path is the last line")
        self.assertTrue(any(re.search(rf"\[\d/{len(CAMPAIGNS)}\] \S+ +\d+\.\d % +ETA", line) for line in lines) or as_json
                        or not progress,
                        p.stdout)
        html = report.read_text(encoding="utf-8")
        self.assertNotIn('data-error="true"', html)
        for campaign, run_id in zip(CAMPAIGNS, runs):
            run = self.daemon.client.conn.get(f"/v1/runs/{run_id}")
            self.assertEqual((run["campaign"], run["status"]), (campaign, "finished_ok"))
            self.assertIn(f'data-run="{run_id}" data-kind="{campaign}"', html)
        cc = self.daemon.client.conn.get(f"/v1/runs/{runs[CAMPAIGNS.index('characterize-camera')]}")
        self.assertEqual(cc["params"]["reference_run"], runs[0], "characterized against the study's chart-read")
        de = runs[CAMPAIGNS.index("dimmer-exposure")]
        self.assertIn(f'id="r{de.replace("-", "")[-12:]}-table8"', html, "Tables 7 and 8 from the study's dimmer-exposure")
        grid = self.daemon.client.conn.get(f"/v1/runs/{runs[CAMPAIGNS.index('cabinet-grid')]}")["params"]
        self.assertEqual((grid["rows"], grid["cols"], grid["lamps"]), (2, 5, ["D65", "TL84"]))
        return runs

    def queue_items(self, state) -> list[dict]:
        return [self.daemon.client.conn.get(f"/v1/queue/{i}") for i in state["items"].values()]

    def test_1_the_study_runs_end_to_end_to_its_report(self):
        started = time.monotonic()
        p = self.run_study()
        self.check_study(p)
        print(f"study --small: {time.monotonic() - started:.1f} s", file=sys.stderr)

    def test_2_a_study_killed_with_its_daemon_resumes(self):
        proc = subprocess.Popen(study_command(self.daemon, self.tmp), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, env=ENV, cwd=self.tmp)
        state_file = self.tmp / "study.json"
        try:
            deadline = time.monotonic() + 120
            killed_in = None
            while time.monotonic() < deadline and killed_in is None:
                try:
                    state = json.loads(state_file.read_text())
                except (FileNotFoundError, ValueError):
                    state = {}
                item = state.get("items", {}).get("cabinet-grid")
                if item and self.daemon.client.conn.get(f"/v1/queue/{item}")["state"] == "running":
                    killed_in = "cabinet-grid"
                    break
                time.sleep(0.05)
            self.assertEqual(killed_in, "cabinet-grid", "the study never reached its cabinet grid")
            proc.send_signal(signal.SIGKILL)
            self.daemon.kill9()
        finally:
            proc.kill()
            first_out = proc.communicate()[0]
        self.daemon.start()
        p = self.run_study("--resume", "--json")
        self.assertIn("re-attaching", p.stderr)
        runs = self.check_study(p, as_json=True)
        self.assertEqual(len(set(runs)), len(CAMPAIGNS))
        state = json.loads(state_file.read_text())
        items = self.queue_items(state)
        self.assertEqual([i["state"] for i in items], ["done"] * len(CAMPAIGNS), f"{first_out}\n{p.stdout}")
        self.assertEqual(len({i["execution_id"] for i in items}), len(CAMPAIGNS), "each step ran once")

    def test_3_a_failing_campaign_ends_the_study_with_exit_4(self):
        # Validated (first_x_mm ≤ 310) but the SG's columns then run off the SpectroScan's 310 mm.
        p = self.run_study("--set", "chart-read.first_x_mm=300")
        self.assertEqual(p.returncode, 4, f"{p.stdout}\n{p.stderr}")
        self.assertIn("campaign chart-read (chart-read) of study dissertation failed", p.stderr)
        state = json.loads((self.tmp / "study.json").read_text())
        states = {i["campaign"]: i["state"] for i in self.queue_items(state)}
        self.assertEqual(states["chart-read"], "failed")
        # The whole study was queued at once: the failure takes every later step out of the queue.
        self.assertEqual({states[c] for c in CAMPAIGNS[1:]}, {"removed"}, states)
        self.assertFalse((self.tmp / "report.html").exists())

    def test_4_a_parameter_the_campaign_refuses_is_exit_4(self):
        p = self.run_study("--set", "cabinet-grid.rows=0")
        self.assertEqual(p.returncode, 4, f"{p.stdout}\n{p.stderr}")
        self.assertIn("cabinet-grid", p.stderr)
        self.assertIn("could not be queued", p.stderr)

    def test_5_usage(self):
        # The steps are the daemon's: an unknown step or study is known once it is asked.
        socket = ["--socket", self.daemon.endpoint["unix_socket"]]
        for extra in (["--set", "nosuchstep.x=1"], ["--set", "nodot"], ["--resume", "--state-file", "/nonexistent"]):
            p = subprocess.run([sys.executable, "-m", "colorlab.study", "dissertation", *socket, *extra],
                               capture_output=True, text=True, env=ENV, timeout=30, cwd=self.tmp)
            self.assertEqual(p.returncode, 2, f"{extra}: {p.stdout}{p.stderr}")
        p = subprocess.run([sys.executable, "-m", "colorlab.study", "nosuchstudy", *socket], capture_output=True,
                           text=True, env=ENV, timeout=30, cwd=self.tmp)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("dissertation", p.stderr, "the sequences the daemon has are named")

    def test_6_dry_run_estimates_the_study(self):
        p = self.run_study("--dry-run", timeout=120)
        self.assertEqual(p.returncode, 0, f"{p.stdout}\n{p.stderr}")
        self.assertRegex(p.stdout.splitlines()[-1], r"^study dissertation: estimated total .* \(\d+ s wall\)$")
        for campaign in CAMPAIGNS[:3]:
            self.assertRegex(p.stdout, rf"(?m)^{campaign} +\S+ wall")
        # --json: the same estimates as one object; the text went to stderr.
        j = json.loads(self.run_study("--dry-run", "--json", timeout=120).stdout)
        self.assertTrue(j["dry_run"])
        self.assertEqual([s["step"] for s in j["steps"]], CAMPAIGNS)
        estimated = [s for s in j["steps"] if s["estimated"]]
        # characterize-camera is estimated only when a chart-read run exists to reference (else it says why).
        self.assertEqual([s["step"] for s in estimated][:3], CAMPAIGNS[:3])
        self.assertTrue(all(s["reason"] for s in j["steps"] if not s["estimated"]), j["steps"])
        self.assertAlmostEqual(j["total_wall_seconds"], sum(s["wall_seconds"] for s in estimated), places=6)
        self.assertEqual(j["ok"], all(s["ok"] for s in estimated))

    def test_7_the_colorlab_cli_runs_the_study(self):
        """`colorlab study` (the C++ CLI, as scripts/quickstart.sh runs it) is this package: same options, same exits."""
        from daemon_fixture import BIN_DIR
        env = {k: v for k, v in ENV.items() if k != "PYTHONPATH"}  # the binary finds the package itself
        cli = [str(BIN_DIR / "colorlab"), "--socket", self.daemon.endpoint["unix_socket"], "study", "dissertation"]
        p = subprocess.run(cli + ["--dry-run"], capture_output=True, text=True, env=env, timeout=120, cwd=self.tmp)
        self.assertEqual(p.returncode, 0, f"{p.stdout}\n{p.stderr}")
        self.assertRegex(p.stdout.splitlines()[-1], r"^study dissertation: estimated total .* \(\d+ s wall\)$")
        p = subprocess.run(cli + ["--set", "no-dot"], capture_output=True, text=True, env=env, timeout=60, cwd=self.tmp)
        self.assertEqual(p.returncode, 2, f"{p.stdout}\n{p.stderr}")
        # Which studies exist is the daemon's catalogue's to say: an unknown one is a usage error naming its sequences.
        p = subprocess.run(cli[:-1] + ["no-such-study", "--dry-run"], capture_output=True, text=True, env=env,
                           timeout=60, cwd=self.tmp)
        self.assertEqual(p.returncode, 2, f"{p.stdout}\n{p.stderr}")
        self.assertIn("dissertation", p.stderr)
        # `colorlab --json study` hands --json to the module: one JSON object on stdout.
        cli_json = cli[:1] + ["--json"] + cli[1:]
        p = subprocess.run(cli_json + ["--dry-run"], capture_output=True, text=True, env=env, timeout=120, cwd=self.tmp)
        self.assertEqual(p.returncode, 0, f"{p.stdout}\n{p.stderr}")
        self.assertEqual(json.loads(p.stdout)["study"], "dissertation")

    def test_8_the_night_completes_without_the_study_process(self):
        """Killed right after it queued the study, the client is not needed: every step runs in the daemon and each
        reference is the run of the study's own referenced step; --resume then only writes the report."""
        proc = subprocess.Popen(study_command(self.daemon, self.tmp), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, env=ENV, cwd=self.tmp)
        state_file = self.tmp / "study.json"
        try:
            deadline = time.monotonic() + 60
            group_id = None
            while time.monotonic() < deadline and not group_id:
                try:
                    group_id = json.loads(state_file.read_text()).get("group")
                except (FileNotFoundError, ValueError):
                    pass
                time.sleep(0.01)
            self.assertTrue(group_id, "the study never queued its group")
            proc.send_signal(signal.SIGKILL)
        finally:
            proc.kill()
            out = proc.communicate()[0]
        self.assertNotIn("finished ok", out, "killed before any step ended")
        deadline = time.monotonic() + 200
        group = {}
        while time.monotonic() < deadline:
            group = self.daemon.client.conn.get(f"/v1/queue/groups/{group_id}")
            if group["state"] in ("done", "failed"):
                break
            time.sleep(0.2)
        self.assertEqual(group.get("state"), "done", json.dumps(group, indent=1))
        self.assertEqual([i["step"] for i in group["items"]], CAMPAIGNS)
        runs = group["runs"]
        self.assertEqual(group["run_ids"], [runs[c] for c in CAMPAIGNS])
        params = {c: self.daemon.client.conn.get(f"/v1/runs/{runs[c]}")["params"] for c in CAMPAIGNS}
        self.assertEqual(params["characterize-camera"]["reference_run"], runs["chart-read"])
        self.assertEqual(params["dimmer-exposure"]["reference_run"], runs["chart-read"])
        self.assertEqual(params["floor-luminance"]["grid_run"], runs["cabinet-grid"])
        for item in group["items"]:
            for param, ref in item["param_refs"].items():
                self.assertEqual(item["params"][param], next(i["run_id"] for i in group["items"] if i["id"] == ref))
        p = self.run_study("--resume")
        self.assertIn("re-attaching", p.stdout)
        self.assertEqual(self.check_study(p, progress=False), group["run_ids"], "the night had ended: nothing to follow")
        self.assertEqual(len(group["run_ids"]), len(set(group["run_ids"])))


if __name__ == "__main__":
    unittest.main()
