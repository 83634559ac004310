"""API keys on a real colorlabd (issue 27): a key never shows up where others read — the daemon's log, a problem
body, the event log and its stream, the CLI's output — whether it is right or wrong, sent as the API takes it
(Authorization: Bearer) or as a client might wrongly try it (in the query string, which the API does not accept);
and wrong keys are limited: the 10th failure within a minute from one address makes every later request from it
a 429 problem+json with Retry-After, logged once, without the key."""
from __future__ import annotations

import http.client
import json
import subprocess
import sys
import time
import unittest
import urllib.error
import urllib.request
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from security_fixture import BIN_DIR, Daemon, create_key  # noqa: E402

# A wrong key nobody could mistake for anything else in a log.
WRONG = "clk_LeakCanaryWrongKey0000000000000000000000000"


def request(url: str, method: str = "GET", key: str | None = None, body: dict | None = None,
            headers: dict | None = None) -> tuple[int, dict, str]:
    """status, headers, body text; HTTP errors are answers here, not exceptions."""
    data = json.dumps(body).encode() if body is not None else None
    req = urllib.request.Request(url, data=data, method=method, headers=dict(headers or {}))
    if data is not None:
        req.add_header("Content-Type", "application/json")
    if key is not None:
        req.add_header("Authorization", f"Bearer {key}")
    try:
        with urllib.request.urlopen(req, timeout=15) as r:
            return r.status, dict(r.headers), r.read().decode(errors="replace")
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read().decode(errors="replace")


def cli(daemon: Daemon, *args: str) -> str:
    r = subprocess.run([str(BIN_DIR / "colorlab"), "--url", daemon.url, *args], capture_output=True, text=True,
                       timeout=30)
    return r.stdout + r.stderr


def all_events(daemon: Daemon) -> str:
    """The whole event log as the API pages it, and a snapshot of the live stream: both as raw text."""
    text, after = [], 0
    while True:
        page = daemon.client.conn.get(f"/v1/events?after={after}&limit=300")
        if not page["items"]:
            break
        text.append(json.dumps(page))
        after = page["items"][-1]["seq"]
    # The live stream replays from seq 0 and then waits for more: read what the replay sent, until the stream
    # has been quiet for two seconds (every wait bounded by the socket's timeout).
    host, port = daemon.url.split("//")[1].rstrip("/").split(":")
    conn = http.client.HTTPConnection(host, int(port), timeout=2)
    chunks = []
    try:
        conn.request("GET", "/v1/events/stream?after=0")
        r = conn.getresponse()
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            chunk = r.read1(65536)
            if not chunk:
                break
            chunks.append(chunk)
    except (TimeoutError, OSError):
        pass
    finally:
        conn.close()
    text.append(b"".join(chunks).decode(errors="replace"))
    return "\n".join(text)


class KeysNeverLeak(unittest.TestCase):
    def test_right_and_wrong_keys_appear_in_no_log_body_or_event(self):
        started = time.monotonic()
        daemon = Daemon()
        self.addCleanup(daemon.cleanup)
        right = create_key(daemon, "leak-hunt", "control")
        url = daemon.url
        bodies = []
        # The right key, by header: reads, a refused control request (its problem body), a 404.
        for method, path, body in (("GET", "/v1", None), ("GET", "/v1/runs", None),
                                   ("POST", "/v1/executions", {"campaign": "no-such-campaign"}),
                                   ("GET", "/v1/runs/no-such-run", None)):
            status, _, text = request(url + path, method, right, body)
            bodies.append(text)
        # The wrong key, by header (4 failures: the limit, 10, is the other test's).
        for method, path in (("GET", "/v1"), ("POST", "/v1/queue/start"), ("GET", "/v1/keys"), ("GET", "/nope")):
            status, _, text = request(url + path, method, WRONG, {} if method == "POST" else None)
            self.assertIn(status, (401, 404), f"{method} {path} with a wrong key")
            bodies.append(text)
        # In the query string, as a careless client might: not accepted as a key, and not echoed.
        for key in (right, WRONG):
            for name in ("key", "api_key", "access_token"):
                status, _, text = request(f"{url}/v1/queue/start?{name}={key}", "POST", None, {})
                self.assertIn(status, (400, 401, 403), f"?{name}= was taken as a key")
                bodies.append(text)
                status, _, text = request(f"{url}/v1/nothing-here?{name}={key}")
                bodies.append(text)
        # The CLI, with each key.
        bodies.append(cli(daemon, "--key", right, "status"))
        bodies.append(cli(daemon, "--key", WRONG, "status"))
        bodies.append(cli(daemon, "--key", WRONG, "abort", "no-such-execution"))
        daemon.stop()  # the log complete; the Unix socket client is closed too
        daemon.start()
        events = all_events(daemon)
        log = daemon.log.read_text(errors="replace")
        for name, key in (("the right key", right), ("the wrong key", WRONG)):
            secret = key.split("_", 1)[1]  # the prefix alone is no leak; any 12 characters of the rest are
            pieces = {secret[i:i + 12] for i in range(0, len(secret) - 12)}
            for where, text in (("the daemon's log", log), ("the event log and stream", events)):
                self.assertFalse([p for p in pieces if p in text], f"{name} is in {where}")
            for text in bodies:
                self.assertFalse([p for p in pieces if p in text], f"{name} is in an answer: {text[:500]}")
        self.assertGreater(len(events), 100, "the event log was read")
        print(f"  keys never leak: {time.monotonic() - started:.1f} s", flush=True)


class WrongKeysLimited(unittest.TestCase):
    def test_ten_wrong_keys_then_429_for_the_address_even_with_the_right_key(self):
        started = time.monotonic()
        daemon = Daemon()
        self.addCleanup(daemon.cleanup)
        right = create_key(daemon, "limited", "control")
        status, _, _ = request(daemon.url + "/v1/control", key=right)
        self.assertEqual(status, 200)
        for i in range(10):
            status, _, text = request(daemon.url + "/v1/runs", key=WRONG)
            self.assertEqual(status, 401, f"wrong key {i + 1} of 10: {text}")
        began = time.monotonic()
        for key in (right, WRONG, None):  # the address is blocked, whatever it sends
            status, headers, text = request(daemon.url + "/v1/runs", key=key)
            elapsed = time.monotonic() - began
            self.assertEqual(status, 429, text)
            self.assertEqual(headers.get("Content-Type"), "application/problem+json")
            problem = json.loads(text)
            self.assertEqual(problem["status"], 429)
            self.assertEqual(problem["code"], "key-failures")
            retry = int(headers["Retry-After"])
            # A minute from the tenth failure, less what has passed since (whole seconds, rounded up).
            self.assertLessEqual(retry, 60)
            self.assertGreaterEqual(retry, 60 - elapsed - 1)
            self.assertNotIn(right, text)
            self.assertNotIn(WRONG[4:], text)
        # The Unix socket is never limited: an admin can still look at, and fix, the keys.
        self.assertTrue(daemon.client.conn.get("/v1/keys")["items"])
        daemon.stop()
        lines = [l for l in daemon.log.read_text(errors="replace").splitlines() if "wrong API keys" in l]
        self.assertEqual(len(lines), 1, f"the block is logged once: {lines}")
        self.assertIn("127.0.0.1", lines[0])
        self.assertNotIn(right[4:16], lines[0])
        self.assertNotIn(WRONG[4:16], lines[0])
        print(f"  wrong keys limited: {time.monotonic() - started:.1f} s", flush=True)


if __name__ == "__main__":
    unittest.main()
