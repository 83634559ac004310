"""The console open in headless Chromium for the whole soak (Debian chromium + chromedriver + python3-selenium, as
tests/web/console_fixture.py starts it), and its JavaScript heap read through the DevTools protocol.

Unlike the console tests, a missing browser is an error here, never a skip: the soak measures the page, and CI
installs chromium through scripts/setup.sh."""
from __future__ import annotations

import os
from pathlib import Path

CHROMIUM = os.environ.get("COLORLAB_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("COLORLAB_CHROMEDRIVER", "/usr/bin/chromedriver")


class BrowserMissing(RuntimeError):
    pass


class ConsolePage:
    def __init__(self, url: str, page: str = "now"):
        for path in (CHROMIUM, CHROMEDRIVER):
            if not Path(path).exists():
                raise BrowserMissing(f"{path} is not installed: the soak needs the console in Chromium "
                                     "(apt install chromium chromium-driver; scripts/setup.sh lists them)")
        try:
            from selenium import webdriver
            from selenium.webdriver.chrome.service import Service
        except ImportError as e:
            raise BrowserMissing(f"python3-selenium is not importable ({e}); scripts/setup.sh lists it") from e
        options = webdriver.ChromeOptions()
        options.binary_location = CHROMIUM
        for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                    "--disable-extensions", "--window-size=1280,1000"):
            options.add_argument(arg)
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        self.driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
        self.driver.set_page_load_timeout(60)
        self.driver.get(f"{url}/#{page}")
        self.driver.execute_cdp_cmd("Performance.enable", {})

    def connection(self) -> str:
        """The console's own connection badge (LIVE when its event stream is up)."""
        try:
            return self.driver.find_element("css selector", "#conn").text
        except Exception:  # noqa: BLE001  (mid-replacement)
            return ""

    def metrics(self) -> dict:
        """The page's heap after a garbage collection (what it holds, not what it has not yet freed), its total
        heap, DOM nodes and event listeners: the numbers that grow when a page leaks."""
        self.driver.execute_cdp_cmd("HeapProfiler.collectGarbage", {})
        got = {m["name"]: m["value"] for m in self.driver.execute_cdp_cmd("Performance.getMetrics", {})["metrics"]}
        return {"js_heap_used": int(got.get("JSHeapUsedSize", 0)), "js_heap_total": int(got.get("JSHeapTotalSize", 0)),
                "dom_nodes": int(got.get("Nodes", 0)), "js_listeners": int(got.get("JSEventListeners", 0))}

    def console_errors(self) -> list[str]:
        return [e.get("message", "") for e in self.driver.get_log("browser") if e.get("level") in ("SEVERE", "ERROR")]

    def quit(self) -> None:
        self.driver.quit()
