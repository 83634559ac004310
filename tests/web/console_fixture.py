"""Headless Chromium on the console of a real colorlabd (the Python client's daemon fixture, reused), with the
helpers the console tests share: keys made through the CLI over the Unix socket, waits, screenshots kept as
artifacts, and the browser's console log checked for errors."""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import time
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("COLORLAB_SOURCE_DIR") or Path(__file__).resolve().parents[2])
sys.path.insert(0, str(SOURCE_DIR / "client" / "python"))
sys.path.insert(0, str(SOURCE_DIR / "client" / "python" / "tests" / "integration"))

import daemon_fixture  # noqa: E402  (the path above first)
from daemon_fixture import Daemon, free_port  # noqa: E402,F401

BIN_DIR = daemon_fixture.BIN_DIR
ARTIFACTS = Path(os.environ.get("COLORLAB_ARTIFACT_DIR") or BIN_DIR.parent / "test-artifacts" / "web")
CHROMIUM = os.environ.get("COLORLAB_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("COLORLAB_CHROMEDRIVER", "/usr/bin/chromedriver")


def browser(width: int = 1280, height: int = 1000):
    """A headless Chromium, or SkipTest naming what is missing (CI has all of it)."""
    for path in (CHROMIUM, CHROMEDRIVER):
        if not Path(path).exists():
            print(f"SKIP: {path} is not installed (apt install chromium chromium-driver)", flush=True)
            raise unittest.SkipTest(f"{path} is not installed")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError as e:
        print(f"SKIP: selenium is not importable ({e}; apt install python3-selenium)", flush=True)
        raise unittest.SkipTest("python3-selenium is not installed") from e
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                "--disable-extensions", f"--window-size={width},{height}"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


def create_key(daemon: Daemon, name: str, scope: str) -> str:
    """A key made the way an admin makes one: the CLI over the daemon's Unix socket."""
    out = subprocess.run([str(BIN_DIR / "colorlab"), "--socket", str(daemon.state / "colorlabd.sock"), "--json",
                          "keys", "create", name, "--scope", scope],
                         check=True, capture_output=True, text=True, timeout=30).stdout
    return json.loads(out)["secret"]


def simulator(daemon: Daemon, command: dict) -> dict:
    """A command to the embedded simulated lab's control socket (docs/simulator.md): one JSON line each way."""
    import socket
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        s.settimeout(10)
        s.connect(daemon.endpoint["simulator_control"])
        s.sendall((json.dumps(command) + "\n").encode())
        answer = b""
        while not answer.endswith(b"\n"):
            chunk = s.recv(65536)
            if not chunk:
                break
            answer += chunk
    return json.loads(answer)


def wait_for(test: unittest.TestCase, what: str, predicate, timeout: float = 30, interval: float = 0.1):
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        try:
            last = predicate()
            if last:
                return last
        except Exception as e:  # an element mid-replacement: try again
            last = e
        time.sleep(interval)
    test.fail(f"timed out after {timeout} s waiting for {what} (last: {last!r})")


def screenshot(driver, name: str) -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    path = ARTIFACTS / f"{name}.png"
    driver.save_screenshot(str(path))
    return path


class ConsoleLog:
    """The browser's console since the last look. Errors fail the test, except the ones a test says it
    caused on purpose (a daemon restarted under the page, a refused request it provoked)."""

    def __init__(self, driver):
        self.driver = driver
        self.kept: list[dict] = []

    def take(self) -> list[dict]:
        entries = self.driver.get_log("browser")
        self.kept.extend(entries)
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        with open(ARTIFACTS / "browser-console.log", "a") as f:
            for e in entries:
                f.write(json.dumps(e) + "\n")
        return entries

    def errors(self, allowed: list[str] = ()) -> list[str]:
        out = []
        for e in self.take():
            if e.get("level") not in ("SEVERE", "ERROR"):
                continue
            if any(re.search(p, e.get("message", "")) for p in allowed):
                continue
            out.append(e.get("message", ""))
        return out


def console_dir_is_built() -> bool:
    """The build tree's copy of client/web (what the test exercises unless COLORLAB_CONSOLE_DIR says otherwise)."""
    if os.environ.get("COLORLAB_CONSOLE_DIR"):
        return True
    return (BIN_DIR.parent / "share" / "colorlab" / "console" / "index.html").exists()


def cleanup_artifacts() -> None:
    """Screenshots of the previous run would be mistaken for this one's."""
    shutil.rmtree(ARTIFACTS, ignore_errors=True)
