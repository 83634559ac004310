"""Everything a campaign script or a client can put in a run, hostile, rendered in headless Chromium (issue 27).

A lab script whose name, description, parameters (descriptions, units, allowed values, the value given), progress
labels, step keys, quantities, units, data, log lines, operator prompt and options and summary all carry markup
that would run if it were ever parsed as HTML — an <img onerror>, a </script> break-out, an attribute break-out
into <svg onload>, a javascript: URL — is run on the simulated lab. Every console page (Lab, Queue, Now with the
pending request, Runs, the run) and the run's HTML report are then opened, and each must show the strings as
literal text with no handler run (window.__pwned stays unset) and no element the strings describe in the DOM."""
from __future__ import annotations

import json
import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from security_fixture import ConsoleLog, Daemon, browser, free_port, screenshot, wait_for  # noqa: E402

HOSTILE = [
    "<img src=x onerror=window.__pwned=1>",
    "</script><script>window.__pwned=1</script>",
    "\"'><svg onload=window.__pwned=1>",
    "javascript:window.__pwned=1",
]
# The file's name is the campaign's: it holds an <img> too (a file name can hold anything but '/').
NAME = "evil<img src=x onerror=window.__pwned=1>"


def lua(s: str) -> str:
    return json.dumps(s)  # a JSON string of these characters is a valid Lua string literal


ALL = " ".join(HOSTILE)
SCRIPT = f'''
local H = {{ {", ".join(lua(s) for s in HOSTILE)} }}
local ALL = {lua(ALL)}
return {{
  description = ALL,
  needs = {{ "luminance_meter" }},
  parameters = {{
    label = {{ type = "string", default = H[1], description = ALL, values = H }},
    level = {{ type = "number", default = 1, min = 0, max = 10, unit = H[2], description = H[3] }},
  }},
  run = function(p)
    lab.progress(0.1, ALL)
    lab.log(ALL)
    local r = lab.meter.measure()
    for i, s in ipairs(H) do
      lab.record(s .. " #" .. i, {{ quantity = s, value = r.luminance + i, unit = H[(i % #H) + 1], instrument = r.instrument,
                                   data = {{ note = s, link = H[4] }} }})
    end
    local a = lab.operator.request {{ action = "confirm_" .. "hostile", prompt = ALL, options = {{ H[1], H[3] }},
                                      default = H[1], timeout_s = 360000, details = {{ note = H[2] }} }}
    lab.progress(0.9, H[3])
    return {{ note = ALL, link = H[4], answer = a.answer, [H[1]] = H[2] }}
  end,
}}
'''

# No element these strings describe may exist, and no element may carry an inline handler (the console attaches
# its own with addEventListener; the report has no script at all).
PROBE = """
const bad = [];
for (const el of document.querySelectorAll('*')) {
  for (const a of el.attributes) {
    if (a.name.startsWith('on')) bad.push(el.tagName + ' ' + a.name + '=' + a.value);
    if (/^\\s*javascript:/i.test(a.value) && (a.name === 'href' || a.name === 'src' || a.name === 'action'))
      bad.push(el.tagName + ' ' + a.name + '=' + a.value);
  }
}
for (const el of document.querySelectorAll('img[src="x"], script:not([src])')) bad.push(el.outerHTML.slice(0, 120));
return {pwned: window.__pwned === undefined ? null : String(window.__pwned), bad,
        text: document.body ? document.body.innerText : ''};
"""


class HostileScript(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon(time_scale=200, port=free_port())
        cls.addClassCleanup(cls.daemon.cleanup)
        campaigns = cls.daemon.state / "campaigns"
        campaigns.mkdir(exist_ok=True)
        (campaigns / f"{NAME}.lua").write_text(SCRIPT)
        cls.driver = browser()
        cls.addClassCleanup(cls.driver.quit)
        cls.log = ConsoleLog(cls.driver)
        cls.daemon.wait_ready("ls110")

    def inert(self, where: str, must_show: list[str]):
        """The page as it stands: nothing ran, nothing parsed, and the strings it should show are there as text."""
        probe = self.driver.execute_script(PROBE)
        self.assertIsNone(probe["pwned"], f"{where}: an injected handler ran")
        self.assertEqual(probe["bad"], [], f"{where}: hostile markup became elements")
        for s in must_show:
            self.assertIn(s, probe["text"], f"{where}: the hostile string is not shown as literal text")

    def shows(self, strings: list[str]):
        return lambda: all(s in self.driver.execute_script("return document.body.innerText") for s in strings)

    def open(self, page: str, strings: list[str]):
        self.driver.get("about:blank")
        self.driver.get(f"{self.daemon.url}/#{page}")
        wait_for(self, f"{page} showing the hostile strings", self.shows(strings), timeout=60)
        self.inert(page, strings)
        screenshot(self.driver, f"hostile-{page.replace('/', '-')}")

    def test_every_page_and_the_report_show_hostile_text_as_text(self):
        started = time.monotonic()
        conn = self.daemon.client.conn
        names = [c["name"] for c in conn.get("/v1/campaigns")["items"]]
        self.assertIn(NAME, names, f"the hostile script is not listed: {conn.get('/v1/campaigns')}")
        # Queue: the campaign offered, its description and parameter form.
        self.driver.get(f"{self.daemon.url}/#queue")
        from selenium.webdriver.support.ui import Select
        wait_for(self, "the hostile campaign offered", lambda: NAME in self.driver.find_element(
            "css selector", "#campaign").get_attribute("textContent"))
        Select(self.driver.find_element("css selector", "#campaign")).select_by_value(NAME)
        wait_for(self, "its description and parameters", self.shows([ALL, HOSTILE[3]]))
        self.inert("queue with the hostile campaign chosen", [ALL])
        screenshot(self.driver, "hostile-queue-form")

        e = conn.post("/v1/executions", {"campaign": NAME, "params": {"label": HOSTILE[2], "level": 2}})
        deadline = time.monotonic() + 60
        while not conn.get("/v1/requests")["items"]:
            self.assertLess(time.monotonic(), deadline, "the hostile operator request never came")
            time.sleep(0.05)
        # Now: the running execution with its progress label and the operator's question and options.
        self.open("now", [ALL, HOSTILE[0], HOSTILE[2]])
        [request] = conn.get("/v1/requests")["items"]
        conn.post(f"/v1/requests/{request['id']}", {"answer": HOSTILE[2], "by": HOSTILE[0]})
        done = self.daemon.wait_terminal(e["id"], timeout=120)
        self.assertEqual(done["status"], "finished_ok", done)
        run_id = done["run_id"]

        # A client's own text too: a queue item (not started) whose parameter is hostile, listed on Queue.
        conn.post("/v1/queue", {"campaign": NAME, "params": {"label": HOSTILE[1], "level": 3}})
        self.open("queue", [NAME, HOSTILE[1]])
        self.open("lab", [])
        self.open("runs", [NAME])
        self.open(f"runs/{run_id}", [NAME, HOSTILE[0], HOSTILE[1], HOSTILE[2]])

        # The report, as the Runs page links it: the daemon's "making the report" page reloads itself until done.
        self.driver.get(f"{self.daemon.url}/v1/runs/{run_id}/report")
        wait_for(self, "the report", lambda: self.driver.find_elements("css selector", f'section[data-run="{run_id}"]'),
                 timeout=120)
        self.inert("the report", [NAME] + HOSTILE)
        screenshot(self.driver, "hostile-report")
        self.assertEqual(self.log.errors([r"favicon", r"/x - Failed to load"]), [], "errors in the browser's console")
        print(f"  hostile script: {time.monotonic() - started:.1f} s", flush=True)


if __name__ == "__main__":
    unittest.main()
