"""The report of frame-average, chart-read and luminance-spot runs on the simulated lab: made through the CLI,
its numbers against the runs as stored in the daemon's SQLite file (and the dissertation's text), opened in
headless Chromium. Also the CLI's failure paths (exit codes 2 and 3)."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import unittest
from pathlib import Path

import numpy as np

from daemon_fixture import SOURCE_DIR
from report_support import ReportCase, check_in_browser, make_report, parse

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))


def thesis_table2():
    """Table 2 read straight from the dissertation's text: {('R', 'median'): [6 values for N = 1…25]}."""
    if not THESIS.exists():
        raise unittest.SkipTest(f"{THESIS} absent")
    out = {}
    for line in THESIS.read_text().splitlines():
        m = re.match(r"^([RGB]) (Median|Mean Value)\t(.*)$", line)
        if m:
            out[(m[1], "median" if m[2] == "Median" else "mean")] = [float(x) for x in m[3].split("\t")]
    assert len(out) == 6, out
    return out


class FrameAverageReport(ReportCase):
    SEED = 11

    @classmethod
    def campaigns(cls, d):
        cls.fa = d.run_to_end("frame-average", frames=25)["run_id"]
        cls.ls = d.run_to_end("luminance-spot", readings=6)["run_id"]
        cls.cr = d.run_to_end("chart-read")["run_id"]

    def report(self):
        if not hasattr(type(self), "_path"):
            type(self)._path = make_report(self.daemon, [self.fa, self.ls, self.cr], "frame-average")
        return type(self)._path

    def short(self, run_id):
        return "r" + run_id.replace("-", "")[-12:]

    def test_table2_is_the_stored_noise_beside_the_published(self):
        tables, _ = parse(self.report())
        t = tables[f"{self.short(self.fa)}-table2"]
        rel = tables[f"{self.short(self.fa)}-table2-relative"]
        stored = {}
        for m in self.daemon.stored_measurements(self.fa):
            _, n, ch = m["step"].split("/")
            stored.setdefault(ch, {})[int(n[1:])] = m["value"]
        self.assertEqual(set(stored), {"R", "G", "B"})
        self.assertEqual(sorted(stored["R"]), [1, 2, 4, 8, 16, 25])
        published = thesis_table2()
        for ch, per_n in stored.items():
            for k, n in enumerate([1, 2, 4, 8, 16, 25]):
                col = str(n)
                self.assertEqual(t[(f"{ch}-measured", col, "measured")], per_n[n])
                for stat in ("median", "mean"):
                    p = published[(ch, stat)][k]
                    self.assertEqual(t[(f"{ch}-published-{stat}", col, "published")], p)
                    self.assertAlmostEqual(t[(f"{ch}-diff-{stat}", col, "difference")], per_n[n] - p, places=9)
                r = per_n[n] / per_n[1]
                self.assertAlmostEqual(rel[(f"{ch}-measured", col, "measured")], r, places=12)
                pr = published[(ch, "median")][k] / published[(ch, "median")][0]
                self.assertAlmostEqual(rel[(f"{ch}-published-median", col, "published")], pr, places=12)
                self.assertAlmostEqual(rel[(f"{ch}-diff", col, "difference")], r - pr, places=12)
                self.assertAlmostEqual(rel[(f"{ch}-model", col, "model")], 1 / np.sqrt(n), places=12)

    def test_summaries_of_the_other_runs(self):
        tables, _ = parse(self.report())
        for run_id, quantity in ((self.ls, "luminance"), (self.cr, "reflectance_spectrum")):
            v = np.array([m["value"] for m in self.daemon.stored_measurements(run_id) if m["quantity"] == quantity])
            t = tables[f"{self.short(run_id)}-summary"]
            self.assertEqual(t[(quantity, "count", "measured")], len(v))
            for col, expect in (("min", v.min()), ("median", np.median(v)), ("mean", v.mean()),
                                ("stdev", v.std(ddof=1)), ("max", v.max())):
                self.assertAlmostEqual(t[(quantity, col, "measured")], expect, places=9, msg=col)

    def test_says_which_instruments_were_simulated(self):
        html = self.report().read_text()
        run = self.daemon.client.run(self.fa)
        camera = {m["instrument_id"] for m in self.daemon.stored_measurements(self.fa)}
        self.assertEqual(len(camera), 1)
        for inst in run["instruments"]:
            flag = "true" if inst["simulated"] else "false"
            self.assertIn(f'data-instrument="{inst["id"]}" data-simulated="{flag}"', html)
        self.assertIn('class="simulated" data-simulated="true"', html)
        self.assertIn(f"({camera.pop()})", html)

    def test_opens_in_chromium_with_every_figure(self):
        s = self.short
        check_in_browser(self, self.report(), [f"{s(self.fa)}-fig34", f"{s(self.ls)}-series", f"{s(self.cr)}-chart-lab"],
                         "frame-average")

    def test_cli_failure_paths(self):
        env = dict(os.environ, PYTHONPATH=str(SOURCE_DIR / "client" / "python"))

        def cli(*args):
            return subprocess.run([sys.executable, "-m", "colorlab.report", *args], capture_output=True, text=True,
                                  env=env, timeout=60)

        p = cli()
        self.assertEqual(p.returncode, 2, p.stderr)
        out = Path(self.daemon.dir) / "over-socket.html"
        p = cli("--socket", self.daemon.endpoint["unix_socket"], self.fa, "-o", str(out))
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.splitlines()[-1], str(out.resolve()))
        self.assertIn(f'data-run="{self.fa}"', out.read_text())
        p = cli("--url", self.daemon.url, "--socket", "/tmp/x.sock", self.fa)
        self.assertEqual(p.returncode, 2, p.stderr)
        p = cli("--url", self.daemon.url, "no-such-run", "-o", os.devnull)
        self.assertEqual(p.returncode, 3)
        self.assertIn("not found", p.stderr)
        p = cli("--url", "http://127.0.0.1:9", self.fa)  # discard port: nobody listens
        self.assertEqual(p.returncode, 3)
        self.assertIn("not reachable", p.stderr)

    def test_the_colorlab_cli_makes_the_same_report(self):
        """`colorlab report` (the C++ CLI) runs this package: same exit codes, the path as its last line."""
        from daemon_fixture import BIN_DIR
        out = Path(self.daemon.dir) / "via-colorlab.html"
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # the binary finds the package itself
        p = subprocess.run([str(BIN_DIR / "colorlab"), "--socket", self.daemon.endpoint["unix_socket"], "report",
                            self.fa, self.ls, "-o", str(out)], capture_output=True, text=True, env=env, timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.splitlines()[-1], str(out.resolve()))
        html = out.read_text()
        self.assertIn(f'data-run="{self.fa}"', html)
        self.assertIn(f'data-run="{self.ls}"', html)
        p = subprocess.run([str(BIN_DIR / "colorlab"), "--url", self.daemon.url, "report",
                            "01900000-0000-7000-8000-00000000dead", "-o", os.devnull],
                           capture_output=True, text=True, env=env, timeout=60)
        self.assertEqual(p.returncode, 3, p.stderr)
        p = subprocess.run([str(BIN_DIR / "colorlab"), "report", "not a run"], capture_output=True, text=True,
                           env=env, timeout=60)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("not a run id", p.stderr)

    def test_json_output(self):
        """`colorlab --json report` (and the module's --json): stdout is one JSON object — the report's path, its
        runs in order with their kinds, its size and where the time went — instead of the path."""
        import json
        from daemon_fixture import BIN_DIR
        out = Path(self.daemon.dir) / "as-json.html"
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        p = subprocess.run([str(BIN_DIR / "colorlab"), "--socket", self.daemon.endpoint["unix_socket"], "--json",
                            "report", self.fa, self.ls, "-o", str(out)], capture_output=True, text=True, env=env,
                           timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        j = json.loads(p.stdout)
        self.assertEqual(j["report"], str(out.resolve()))
        self.assertEqual([(r["id"], r["kind"]) for r in j["runs"]],
                         [(self.fa, "frame-average"), (self.ls, "luminance-spot")])
        self.assertEqual(j["bytes"], out.stat().st_size)
        parts = j["seconds"]
        self.assertTrue(all(parts[k] >= 0 for k in ("load", "render", "write")), parts)
        self.assertAlmostEqual(parts["total"], parts["load"] + parts["render"] + parts["write"], places=6)
        # The module itself, as `colorlab study` and the daemon run it; failures stay on stderr with their exit codes.
        menv = dict(os.environ, PYTHONPATH=str(SOURCE_DIR / "client" / "python"))
        p = subprocess.run([sys.executable, "-m", "colorlab.report", "--json", "--url", self.daemon.url, self.fa, "-o",
                            str(out)], capture_output=True, text=True, env=menv, timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(json.loads(p.stdout)["runs"][0]["id"], self.fa)
        p = subprocess.run([sys.executable, "-m", "colorlab.report", "--json", "--url", self.daemon.url,
                            "01900000-0000-7000-8000-00000000dead", "-o", os.devnull], capture_output=True, text=True,
                           env=menv, timeout=60)
        self.assertEqual((p.returncode, p.stdout), (3, ""))

    def test_the_daemon_serves_the_report_of_an_ended_run(self):
        """GET /v1/runs/{id}/report: 202 with Retry-After while the daemon's child process makes it, then the HTML,
        the same run's section as the CLI's; 404 for no such run; the run document links it."""
        import json
        import time
        import urllib.error
        import urllib.request

        url = f"{self.daemon.url}/v1/runs/{self.ls}/report"
        self.assertEqual(self.daemon.client.conn.get(f"/v1/runs/{self.ls}")["links"]["report"], f"/v1/runs/{self.ls}/report")
        seen_202 = False
        deadline = time.monotonic() + 180
        while True:
            with urllib.request.urlopen(url, timeout=30) as r:
                body = r.read()
                if r.status == 202:
                    seen_202 = True
                    self.assertEqual(r.headers["Retry-After"], "2")
                    self.assertEqual(json.loads(body)["state"], "generating")
                    self.assertLess(time.monotonic(), deadline, "the report was not made in 3 minutes")
                    time.sleep(0.5)
                    continue
                self.assertEqual(r.status, 200)
                self.assertTrue(r.headers["Content-Type"].startswith("text/html"), r.headers["Content-Type"])
                html = body.decode()
                etag = r.headers["ETag"]
                break
        self.assertTrue(seen_202, "the first request cannot find a report already made")
        self.assertIn(f'data-run="{self.ls}"', html)
        self.assertIn("SIMULATED", html)
        # Made once: the next request is the same file, and its ETag answers 304.
        req = urllib.request.Request(url, headers={"If-None-Match": etag})
        with self.assertRaises(urllib.error.HTTPError) as cached:
            urllib.request.urlopen(req, timeout=30)
        self.assertEqual(cached.exception.code, 304)
        with urllib.request.urlopen(urllib.request.Request(url, method="HEAD"), timeout=30) as r:
            self.assertEqual(r.status, 200)
            self.assertEqual(r.read(), b"")
        with self.assertRaises(urllib.error.HTTPError) as missing:
            urllib.request.urlopen(f"{self.daemon.url}/v1/runs/01900000-0000-7000-8000-00000000dead/report", timeout=30)
        self.assertEqual(missing.exception.code, 404)


if __name__ == "__main__":
    unittest.main()
