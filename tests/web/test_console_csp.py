"""The console and the reports under their Content-Security-Policy (issue 27): the headers are there and strict
(no inline script on the console, none at all on a report, never framed, no MIME sniffing); the console still
works in headless Chromium with no CSP violation of its own; and an inline script put into the page (what an
escaping bug would let a campaign's name do) is refused by the browser. Wall time ~15 s (daemon, Chromium)."""
import json
import time
import unittest
import urllib.request

from console_fixture import (ConsoleLog, Daemon, browser, console_dir_is_built, create_key, free_port, wait_for)


def directives(policy: str) -> dict:
    out = {}
    for part in policy.split(";"):
        words = part.split()
        if words:
            out[words[0]] = words[1:]
    return out


class ConsoleCspTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not console_dir_is_built():
            raise AssertionError("the build has no share/colorlab/console/index.html (target colorlab_console)")
        cls.daemon = Daemon(time_scale=500, port=free_port())
        cls.addClassCleanup(cls.daemon.cleanup)
        cls.driver = browser()
        cls.addClassCleanup(cls.driver.quit)
        cls.log = ConsoleLog(cls.driver)
        # The console learns its access by a control request the keyless loopback is refused (test_console.py).
        cls.allowed = [r"/v1/executions - Failed to load resource: the server responded with a status of (400|401|403)"]

    def get(self, path, headers=None):
        req = urllib.request.Request(self.daemon.url + path, headers=headers or {})
        try:
            with urllib.request.urlopen(req, timeout=10) as r:
                return r.status, r.headers, r.read()
        except urllib.error.HTTPError as e:
            return e.code, e.headers, e.read()

    def test_console_headers_forbid_inline_script_and_framing(self):
        for path in ("/", "/js/main.js", "/css/console.css"):
            status, headers, _ = self.get(path)
            self.assertEqual(status, 200, path)
            self.assertEqual(headers.get("X-Content-Type-Options"), "nosniff", path)
            policy = headers.get("Content-Security-Policy")
            self.assertIsNotNone(policy, f"{path}: no Content-Security-Policy")
            d = directives(policy)
            self.assertEqual(d.get("script-src"), ["'self'"], f"{path}: {policy}")
            self.assertEqual(d.get("frame-ancestors"), ["'none'"], policy)
            self.assertEqual(d.get("object-src"), ["'none'"], policy)
            self.assertEqual(d.get("base-uri"), ["'none'"], policy)
            self.assertEqual(d.get("connect-src"), ["'self'"], policy)

    def test_console_works_and_an_injected_inline_script_is_refused(self):
        d = self.driver
        d.get(f"{self.daemon.url}/#lab")
        wait_for(self, "the event stream", lambda: d.find_element("css selector", "#conn").text == "LIVE")
        wait_for(self, "the Lab page's instruments", lambda: "ls110" in d.find_element("css selector", "#page-lab").text)
        d.get(f"{self.daemon.url}/#runs")
        wait_for(self, "the Runs page", lambda: d.find_element("css selector", "#page-runs").text.strip() != "")
        self.assertEqual(self.log.errors(self.allowed), [], "the console broke its own policy")
        # What an escaping bug would do: markup with an inline script (and a handler) put into the page.
        d.execute_script("""
            window.__violations = [];
            document.addEventListener('securitypolicyviolation', e => window.__violations.push(e.violatedDirective));
            const s = document.createElement('script');
            s.textContent = 'window.__inline_ran = true;';
            document.body.appendChild(s);
            const div = document.createElement('div');
            div.innerHTML = '<img src="data:,x" onerror="window.__handler_ran = true">';
            document.body.appendChild(div);""")
        wait_for(self, "the browser's report of the refused inline script",
                 lambda: len(d.execute_script("return window.__violations")) >= 2)
        self.assertIsNone(d.execute_script("return window.__inline_ran"), "an inline script ran")
        self.assertIsNone(d.execute_script("return window.__handler_ran"), "an inline event handler ran")
        self.assertTrue(all(v.startswith("script-src") for v in d.execute_script("return window.__violations")))
        self.log.errors(self.allowed + [r"Refused to execute inline"])

    def test_a_report_runs_no_script(self):
        key = create_key(self.daemon, "csp-test", "control")
        client = self.daemon.tcp_client(key)
        self.addCleanup(client.close)
        self.daemon.wait_ready("ls110")
        started = client.conn.post("/v1/executions", {"campaign": "luminance-spot", "params": {"readings": 1}})
        deadline = time.monotonic() + 120
        while client.conn.get(f"/v1/executions/{started['id']}")["status"] not in ("finished_ok", "finished_error"):
            self.assertLess(time.monotonic(), deadline, "the run did not end within 120 s")
            time.sleep(0.2)
        # The first answer is the "making the report" page (202) or, if it was quick, the report: both carry it.
        status, headers, _ = self.get(f"/v1/runs/{started['run_id']}/report", {"Accept": "text/html"})
        self.assertIn(status, (200, 202))
        d = directives(headers.get("Content-Security-Policy") or "")
        self.assertEqual(d.get("default-src"), ["'none'"], headers.get("Content-Security-Policy"))
        self.assertNotIn("script-src", d)
        self.assertEqual(d.get("frame-ancestors"), ["'none'"])


if __name__ == "__main__":
    unittest.main()
