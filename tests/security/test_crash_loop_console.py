"""The crash-loop guard's suspension in the console (issue 27): colorlabd is killed (SIGKILL) while a run waits in
its first step, until the guard suspends the run with the category crash-loop; the Now page then shows the
category, the step it kept dying in and the back-off (retry n of m, its length), and the page's Resume sets it
running again. Every wait is bounded polling on a condition; the back-off is far longer than the test, so the
guard's own retry cannot be what resumes it."""
from __future__ import annotations

import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from security_fixture import ConsoleLog, Daemon, browser, create_key, free_port, screenshot, wait_for  # noqa: E402

STEP = "holding the cabinet dark"
# A first step that never commits: each restart resumes it from the start, so the kills are restarts without a
# committed step, which is what the guard counts (docs/campaigns.md, "Crash loops").
SCRIPT = f'''
return {{
  description = "waits a long while in its first step (the crash-loop console test)",
  needs = {{}},
  parameters = {{}},
  run = function(p)
    lab.progress(0.0, "{STEP}")
    lab.wait(86400)  -- 432 s of wall time at the time scale: longer than the test
  end,
}}
'''
BACKOFF_S = 900
# Trips after the second restart without a commit (the first is an ordinary resume).
CAMPAIGNS = (f"[campaigns]\nmax_resume_attempts = 1\ncrash_loop_backoff_s = {BACKOFF_S}\n"
             f"crash_loop_backoff_max_s = {BACKOFF_S}\ncrash_loop_retries = 2\n")


class CrashLoopInTheConsole(unittest.TestCase):
    def test_the_suspension_shows_its_cause_and_resume_works(self):
        started = time.monotonic()
        daemon = Daemon(time_scale=200, port=free_port(), extra=CAMPAIGNS)
        self.addCleanup(daemon.cleanup)
        (daemon.state / "campaigns").mkdir(exist_ok=True)
        (daemon.state / "campaigns" / "dark-wait.lua").write_text(SCRIPT)
        key = create_key(daemon, "crash-loop-console", "control")
        e = daemon.client.conn.post("/v1/executions", {"campaign": "dark-wait", "params": {}})

        def status():
            return daemon.client.conn.get(f"/v1/executions/{e['id']}")

        suspension = None
        for kill in range(6):
            # Running in its step (the journal has it) before each kill.
            wait_for(self, f"running before kill {kill + 1}",
                     lambda: status()["status"] == "running" and status().get("step") == STEP, timeout=60)
            daemon.kill9()
            daemon.start()
            now = wait_for(self, f"resumed or suspended after kill {kill + 1}",
                           lambda: (s := status())["status"] in ("running", "suspended") and s, timeout=60)
            if now["status"] == "suspended":
                suspension = now.get("suspension")
                break
        self.assertIsNotNone(suspension, "the guard never suspended the run")
        self.assertEqual(suspension["category"], "crash-loop", suspension)
        self.assertEqual((suspension["retry"], suspension["retries"], suspension["backoff_s"]), (1, 2, BACKOFF_S))

        driver = browser()
        self.addCleanup(driver.quit)
        log = ConsoleLog(driver)
        driver.get(f"{daemon.url}/#now")
        by_css = lambda css: driver.find_element("css selector", css)  # noqa: E731
        wait_for(self, "the event stream", lambda: by_css("#conn").text == "LIVE")
        # The key, as an operator gives it, so the page may resume.
        if not by_css("#key-box").get_attribute("open"):
            by_css("#key-box summary").click()
        by_css("#key").send_keys(key)
        by_css("#key-apply").click()
        wait_for(self, "control access", lambda: by_css("#access-word").text == "CONTROL")
        card = f'.execution[data-execution="{e["id"]}"]'
        wait_for(self, "the suspended card", lambda: by_css(f"{card} .badge").text == "suspended")
        line = by_css(f"{card} .suspension")
        self.assertEqual(line.get_attribute("data-category"), "crash-loop")
        self.assertEqual(line.find_element("css selector", ".suspension-category").text, "crash loop")
        self.assertIn(f"retry 1 of 2, back-off {BACKOFF_S} s", line.text)
        self.assertRegex(line.text, r"retries it by itself in \d+ s")
        self.assertIn(STEP, by_css(f"{card} .reason").text, "the step it kept dying in")
        screenshot(driver, "crash-loop-now")

        button = by_css(f"{card} button.resume")
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", button)
        self.assertTrue(button.is_enabled(), "Resume is disabled with a control key")
        button.click()
        seen = []
        try:
            wait_for(self, "running again after Resume",
                     lambda: seen.append((status()["status"], by_css("#toasts").text)) or seen[-1][0] == "running",
                     timeout=60)
        except AssertionError as failure:
            raise AssertionError(f"{failure}; status and the page's toasts last: {seen[-1:]}") from None
        wait_for(self, "the card running", lambda: by_css(f"{card} .badge").text == "running")
        resumed = [ev["payload"] for ev in daemon.client.conn.get("/v1/events?topic=execution&limit=300")["items"]
                   if ev["payload"].get("execution_id") == e["id"] and ev["payload"].get("resumed_by")]
        self.assertTrue(resumed and resumed[-1]["resumed_by"] != "back-off", f"resumed by the page: {resumed}")
        # The key rode in headers only: no URL the page fetched holds it (issue 27, "keys never in URLs").
        urls = driver.execute_script("return performance.getEntriesByType('resource').map(e => e.name)"
                                     ".concat([location.href])")
        self.assertTrue(any("/v1/" in u for u in urls), urls)
        self.assertEqual([u for u in urls if key[4:16] in u], [], "the key in a URL")
        daemon.client.conn.post(f"/v1/executions/{e['id']}/abort", {})
        daemon.wait_terminal(e["id"], timeout=60)
        # The daemon restarted under the page: its stream dropped and came back.
        self.assertEqual(log.errors([r"ERR_CONNECTION_REFUSED", r"net::ERR", r"favicon"]), [])
        print(f"  crash loop in the console: {time.monotonic() - started:.1f} s", flush=True)


if __name__ == "__main__":
    unittest.main()
