"""Helpers for the report's integration tests: a daemon on the simulated lab with the campaigns a test needs
(``ReportCase``), a report made through the CLI exactly as colorlab's own CLI will (``python3 -m colorlab.report``),
its tables read back from the markup, and the file opened in headless Chromium."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import unittest
from html.parser import HTMLParser
from pathlib import Path

import daemon_fixture
from daemon_fixture import BIN_DIR, SOURCE_DIR

ARTIFACTS = Path(os.environ.get("COLORLAB_BIN_DIR") or BIN_DIR).resolve().parent / "test-artifacts" / "report"
CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")


def start_daemon(*, seed: int, lab_toml: str | None = None, time_scale: float = 500) -> daemon_fixture.Daemon:
    """A daemon on the simulated lab; `lab_toml` replaces the fixture's simulated-lab configuration for it."""
    saved = daemon_fixture.LAB_TOML
    if lab_toml is not None:
        daemon_fixture.LAB_TOML = lab_toml
    try:
        return daemon_fixture.Daemon(time_scale=time_scale, seed=seed)
    finally:
        daemon_fixture.LAB_TOML = saved


class ReportCase(unittest.TestCase):
    """One daemon per test class: started in setUpClass with SEED and LAB_TOML, then ``campaigns(daemon)`` runs what
    the class needs (and may make its report); the daemon is cleaned up when that fails, and after the class."""

    SEED = 3
    LAB_TOML: str | None = None

    @classmethod
    def campaigns(cls, daemon) -> None:
        raise NotImplementedError

    @classmethod
    def setUpClass(cls):
        cls.daemon = start_daemon(seed=cls.SEED, lab_toml=cls.LAB_TOML)
        try:
            cls.campaigns(cls.daemon)
        except BaseException:
            cls.daemon.cleanup()
            raise

    @classmethod
    def tearDownClass(cls):
        cls.daemon.cleanup()


def make_report(daemon, run_ids, name: str) -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    out = ARTIFACTS / f"{name}.html"
    env = dict(os.environ, PYTHONPATH=str(SOURCE_DIR / "client" / "python"))
    p = subprocess.run([sys.executable, "-m", "colorlab.report", *run_ids, "-o", str(out), "--url", daemon.url],
                       capture_output=True, text=True, env=env, timeout=120)
    if p.returncode != 0:
        raise AssertionError(f"colorlab.report exited {p.returncode}: {p.stderr}")
    if p.stdout.strip().splitlines()[-1] != str(out.resolve()):
        raise AssertionError(f"the last line of stdout is not the report's path: {p.stdout!r}")
    if 'data-error="true"' in out.read_text(encoding="utf-8"):
        raise AssertionError(f"a section of the report failed: {p.stderr}")
    return out


class _Tables(HTMLParser):
    """{table id: {(data-row, data-col, data-kind): float}} from every <td data-value=…>."""

    def __init__(self):
        super().__init__()
        self.tables, self.current, self.ids = {}, None, set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "table":
            self.current = a.get("id")
            self.tables.setdefault(self.current, {})
        elif tag == "td" and self.current and "data-value" in a:
            self.tables[self.current][(a.get("data-row"), a.get("data-col"), a.get("data-kind"))] = float(a["data-value"])


def parse(path: Path):
    p = _Tables()
    p.feed(path.read_text(encoding="utf-8"))
    return p.tables, p.ids


def check_in_browser(test: unittest.TestCase, path: Path, figure_ids, name: str) -> None:
    """Headless Chromium loads the file: no console errors, each figure's <svg> shown with a size, a screenshot kept."""
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.common.by import By
    except ImportError:
        print("report browser check skipped: python3-selenium is not installed", file=sys.stderr)
        test.skipTest("python3-selenium is not installed")
    if not CHROMIUM.exists() or not CHROMEDRIVER.exists() or not shutil.which(str(CHROMEDRIVER)):
        print("report browser check skipped: /usr/bin/chromium or /usr/bin/chromedriver is absent", file=sys.stderr)
        test.skipTest("chromium or chromedriver absent")
    opts = webdriver.ChromeOptions()
    opts.binary_location = str(CHROMIUM)
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1200,900"):
        opts.add_argument(arg)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(str(CHROMEDRIVER)), options=opts)
    try:
        driver.get(path.resolve().as_uri())
        test.assertEqual(driver.execute_script("return document.readyState"), "complete")
        for fid in figure_ids:
            figs = driver.find_elements(By.ID, fid)
            test.assertEqual(len(figs), 1, f"figure {fid} missing")
            svgs = figs[0].find_elements(By.TAG_NAME, "svg")
            test.assertTrue(svgs, f"figure {fid} has no <svg>")
            driver.execute_script("arguments[0].scrollIntoView()", svgs[0])
            size = svgs[0].size
            test.assertTrue(svgs[0].is_displayed(), f"figure {fid} not visible")
            test.assertGreater(size["width"], 50, f"figure {fid}: {size}")
            test.assertGreater(size["height"], 50, f"figure {fid}: {size}")
            # Drawn, not an empty frame: matplotlib's paths are there.
            test.assertGreater(len(svgs[0].find_elements(By.TAG_NAME, "path")), 5, f"figure {fid} has nothing drawn")
        height = driver.execute_script("return document.documentElement.scrollHeight")
        driver.set_window_size(1200, min(int(height) + 100, 16000))
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        test.assertTrue(driver.save_screenshot(str(ARTIFACTS / f"{name}.png")))
        errors = [e for e in driver.get_log("browser") if e.get("level") in ("SEVERE", "ERROR")]
        test.assertEqual(errors, [], "console errors")
    finally:
        driver.quit()
