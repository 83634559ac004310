"""The web console in headless Chromium against colorlab-central, opened at central's URL as a lab user would.
Run by central_console_test.cpp: central_console_check.py CENTRAL_URL KEY EXPECTED_JSON, where EXPECTED_JSON holds
{"benches": {BENCH_ID: [run ids, oldest first]}, "open": RUN_ID}. Checks: the console knows it is on central from
GET /v1 (no live stream asked for, only the Runs page offered, read-only), the Runs page lists every bench's runs
with a bench column and filters by bench, a run opens with its measurements (as the API pages them) and frames,
no control is offered anywhere, and the browser logs no error (no CSP violation, no request central refuses).
Exits non-zero on any failure; a missing Chromium is a failure here, not a skip."""
import json
import os
import re
import sys
import time
import unittest
import urllib.request
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "web"))

from console_fixture import ConsoleLog, browser, screenshot, wait_for  # noqa: E402
from selenium.webdriver.support.select import Select  # noqa: E402  (browser() has checked selenium is there)

# What would change something on a bench: no button or link of the page may offer it on central.
CONTROL_WORDS = re.compile(r"\b(start|abort|pause|resume|answer|enqueue|queue it|dry run|acquire|release|stop)\b", re.I)


class CentralConsole(unittest.TestCase):
    url = key = None
    expected = {}

    @classmethod
    def setUpClass(cls):
        try:
            cls.driver = browser()
        except unittest.SkipTest as e:
            raise AssertionError(f"the console test on central needs Chromium: {e}") from e
        cls.addClassCleanup(cls.driver.quit)
        cls.log = ConsoleLog(cls.driver)

    def api(self, path):
        req = urllib.request.Request(self.url + path, headers={"Authorization": f"Bearer {self.key}"})
        with urllib.request.urlopen(req, timeout=30) as r:
            return json.loads(r.read())

    def css(self, selector):
        return self.driver.find_element("css selector", selector)

    def csss(self, selector):
        return self.driver.find_elements("css selector", selector)

    def rows(self, table_selector):
        return [[td.text for td in tr.find_elements("css selector", "td")]
                for tr in self.csss(f"{table_selector} tbody tr")]

    def test_runs_page_on_central(self):
        d = self.driver
        started = time.monotonic()
        all_runs = {run: bench for bench, runs in self.expected["benches"].items() for run in runs}
        d.get(f"{self.url}/")
        # GET /v1 said central: no stream opened, the header says so, the home page is Runs.
        wait_for(self, "the connection badge to say CENTRAL", lambda: self.css("#conn").text == "CENTRAL")
        wait_for(self, "the Runs page", lambda: self.css("#page-runs").is_displayed())
        # A lab user's key, through the key form as on a bench.
        if not self.css("#key-box").get_attribute("open"):
            self.css("#key-box summary").click()
        self.css("#key").send_keys(self.key)
        self.css("#key-apply").click()
        wait_for(self, "the access line to say read-only", lambda: self.css("#access-word").text == "READ-ONLY")
        self.assertIn("changes nothing", self.css("#access-note").text)
        stream = d.execute_script("return window.colorlabConsole.stream.stats")
        self.assertEqual(stream["connects"], 0, "the console opened an event stream central does not have")
        shown = [a.get_attribute("href").split("#")[1] for a in self.csss("nav a") if a.is_displayed()]
        self.assertEqual(shown, ["runs"], "pages central cannot fill are offered")

        # The Runs page: every bench's runs (fewer than a page), newest first, each with its bench.
        wait_for(self, "the runs table", lambda: len(self.rows("#runs-list table.runs")) == len(all_runs))
        header = [th.text for th in self.csss("#runs-list table.runs thead th")]
        self.assertEqual(header[:2], ["run", "bench"])
        listed = {}
        for a, row in zip(self.csss("#runs-list table.runs tbody tr td:first-child a"), self.rows("#runs-list table.runs")):
            listed[a.get_attribute("href").split("#runs/")[1]] = row[1]
        self.assertEqual(set(listed), set(all_runs))
        for run, bench in all_runs.items():
            self.assertIn(f"({bench})", listed[run], f"run {run}'s bench")
        self.assertGreaterEqual(len(set(listed.values())), 2, "runs of at least two benches")
        # Each bench's lag, from GET /v1/benches.
        wait_for(self, "each bench's lag", lambda: len(self.csss("#bench-lag .bench-lag")) == len(self.expected["benches"]))

        # The bench filter pages only that bench's runs (GET /v1/runs?bench=).
        wait_for(self, "the bench filter's choices", lambda: len(self.csss("#filter-bench option")) == 1 + len(self.expected["benches"]))
        Select(self.css("#filter-bench")).select_by_value("bench-south")
        south = self.expected["benches"]["bench-south"]
        wait_for(self, "only bench-south's runs", lambda: sorted(
            a.get_attribute("href").split("#runs/")[1] for a in self.csss("#runs-list table.runs tbody tr td:first-child a"))
            == sorted(south))
        Select(self.css("#filter-bench")).select_by_value("")
        wait_for(self, "every bench's runs again", lambda: len(self.rows("#runs-list table.runs")) == len(all_runs))

        # Opening a run: its bench, its measurements as GET /v1/runs/{id}/measurements pages them, its frames.
        run = self.expected["open"]
        self.css(f"#runs-list a[href='#runs/{run}']").click()
        wait_for(self, "the run's bench line", lambda: all_runs[run] in self.css("#run-bench").text)
        page = self.api(f"/v1/runs/{run}/measurements?limit=50")
        wait_for(self, "the first page of measurements", lambda: len(self.rows("#measurements table")) == len(page["items"]))
        table = self.rows("#measurements table")
        self.assertEqual([r[0] for r in table], [str(m["seq"]) for m in page["items"]])
        self.assertEqual([r[1] for r in table], [m["step"] for m in page["items"]])
        self.assertTrue(page["next_cursor"], "the opened run should have a second page")
        self.css("#meas-next").click()
        second = self.api(f"/v1/runs/{run}/measurements?limit=50&cursor={page['next_cursor']}")
        wait_for(self, "the second page of measurements",
                 lambda: [r[0] for r in self.rows("#measurements table")] == [str(m["seq"]) for m in second["items"]])
        blobs = self.api(f"/v1/runs/{run}/blobs")["items"]
        self.assertTrue(blobs, "the opened run kept frames")
        wait_for(self, "the run's frames", lambda: len(self.csss("#blobs figure")) == len(blobs))
        self.assertEqual(self.csss("#blobs img"), [], "central renders no previews: none may be asked for")
        self.assertTrue(self.csss(".downloads a.download"), "exports are offered")
        self.assertFalse([a for a in self.csss(".downloads a") if a.text == "script"], "central has no run scripts")
        screenshot(d, "central-run")

        # No control anywhere: pages central has not are not reached, nothing on the page offers a change.
        for page_name in ("queue", "now", "lab"):
            d.get(f"{self.url}/#{page_name}")
            wait_for(self, f"#{page_name} to land on the Runs page", lambda: self.css("#page-runs").is_displayed())
            self.assertFalse(self.css(f"#page-{page_name}").is_displayed())
        offered = [e.text for e in self.csss("button, a, input[type=submit]")
                   if e.is_displayed() and CONTROL_WORDS.search(e.text or "")]
        self.assertEqual(offered, [], "control offered on central")
        screenshot(d, "central-runs")
        self.assertEqual(self.log.errors(), [], "errors in the browser's console")
        print(f"  browser part: {time.monotonic() - started:.1f} s", flush=True)


def main() -> int:
    CentralConsole.url, CentralConsole.key, expected = sys.argv[1:4]
    CentralConsole.expected = json.loads(Path(expected).read_text())
    os.environ.setdefault("COLORLAB_ARTIFACT_DIR", str(Path(expected).parent / "artifacts"))
    result = unittest.TextTestRunner(verbosity=2).run(unittest.defaultTestLoader.loadTestsFromTestCase(CentralConsole))
    if not result.wasSuccessful() or result.testsRun != 1:
        return 1
    print("the console works on central")
    return 0


if __name__ == "__main__":
    sys.exit(main())
