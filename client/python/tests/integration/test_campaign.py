"""The Python client against a real colorlabd on the simulated lab: a campaign started and followed
through the event stream, its measurements as a DataFrame checked against the same run read from the
daemon's database file, its exports, keys and scopes, and the daemon's refusals as exceptions."""
import hashlib
import io
import json
import tempfile
import unittest
from pathlib import Path

import numpy as np
import pandas as pd

import colorlab
from daemon_fixture import SOURCE_DIR, Daemon, skip_unless_served

READINGS = 7


class CampaignTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon()
        cls.addClassCleanup(cls.daemon.cleanup)  # also when the rest of setUpClass fails
        cls.lab = cls.daemon.client
        cls.daemon.wait_ready("ls110")
        # One run for the data tests, made without the client's stream so they do not depend on it.
        cls.done = cls.daemon.run_to_end("luminance-spot", readings=READINGS)
        cls.run_id = cls.done["run_id"]
        cls.stored = cls.daemon.stored_measurements(cls.run_id)


    def test_local_finds_the_daemon_and_it_is_the_simulated_lab(self):
        self.assertEqual(self.lab.socket, self.daemon.endpoint["unix_socket"])
        with colorlab.Client.local(self.daemon.state, use_socket=False) as tcp:
            self.assertEqual(tcp.url, self.daemon.url)
            self.assertIs(tcp.status()["simulated_lab"], True)
        self.assertIs(self.lab.status()["simulated_lab"], True)
        self.assertIn("ls110", self.lab.instruments()["id"].tolist())
        self.assertIn("luminance-spot", self.lab.campaigns()["name"].tolist())

    def test_start_and_follow_through_the_event_stream_to_the_end(self):
        skip_unless_served(self, lambda: next(iter(self.lab.events(reconnect=False))), "GET /v1/events/stream")
        e = self.lab.start("luminance-spot", readings=4)
        seen = []
        gen = self.lab.follow(e)
        try:
            while True:
                seen.append(next(gen))
        except StopIteration as stop:
            final = stop.value
        self.assertEqual(final.status, "finished_ok", self.daemon.log_text())
        self.assertTrue(seen[-1].terminal)
        self.assertEqual(seen[-1].status, "finished_ok")
        # One progress event per committed step, in the script's order, ending at "done".
        progress = [p for p in seen if p.kind == "progress"]
        order = ["reading/0", "reading/1", "reading/2", "reading/3", "done"]
        steps = [p.step for p in progress]
        self.assertEqual(steps, sorted(set(steps), key=order.index), steps)
        self.assertEqual(steps[-1], "done")
        self.assertEqual([p.progress for p in progress], sorted(p.progress for p in progress))
        self.assertEqual(progress[-1].progress, 1.0)
        # From the first event seen on, exactly the stored log's progress events of this execution: none
        # lost, none twice (the ones before the stream opened are the state follow() read first).
        stored = [ev for ev in self.all_events("progress") if ev["payload"]["execution_id"] == e.id]
        first = progress[0].event.seq
        self.assertEqual([(p.event.seq, p.event.payload) for p in progress],
                         [(ev["seq"], ev["payload"]) for ev in stored if ev["seq"] >= first])
        # The steps' measurements add up to what the store holds.
        self.assertEqual(sum(ev["payload"]["measurements"] for ev in stored), 4)
        self.assertEqual(len(self.daemon.stored_measurements(final.run_id)), 4)
        # An execution that has ended is followed in one step.
        self.assertEqual([p.status for p in self.lab.follow(e)], ["finished_ok"])
        self.assertEqual(self.lab.wait(e).status, "finished_ok")

    def all_events(self, topic):
        events, after = [], 0
        while True:
            page = self.lab.event_log(after=after, topic=topic)
            if not page:
                return events
            events += page
            after = page[-1]["seq"]

    def test_the_idempotency_key_never_starts_twice(self):
        first = self.lab.start("luminance-spot", readings=1, idempotency_key="python-integration-once")
        again = self.lab.start("luminance-spot", readings=1, idempotency_key="python-integration-once")
        self.assertEqual(first.id, again.id)
        self.daemon.wait_terminal(first.id)

    def measurements(self, **filters):
        return skip_unless_served(self, lambda: self.lab.measurements(self.run_id, **filters),
                                  "GET /v1/runs/{id}/measurements")

    def test_measurements_frame_equals_the_stored_run(self):
        df = self.measurements()
        ref = self.stored
        self.assertEqual(len(df), READINGS)
        self.assertEqual(df["seq"].tolist(), [m["seq"] for m in ref])
        self.assertEqual(df["step"].tolist(), [f"reading/{i}" for i in range(READINGS)])
        self.assertEqual(df["step"].tolist(), [m["step"] for m in ref])
        # Exactly the stored doubles: both sides parse the daemon's JSON numbers.
        self.assertEqual(df["value"].tolist(), [m["value"] for m in ref])
        for col in ("quantity", "unit", "instrument_id"):
            self.assertEqual(df[col].tolist(), [m[col] for m in ref], col)
        self.assertTrue(df["simulated"].all())
        self.assertEqual(df["measured_at"].tolist(), pd.to_datetime([m["measured_at"] for m in ref], utc=True).tolist())
        self.assertEqual(df["data.raw"].tolist(), [m["data"]["raw"] for m in ref])
        # The daemon's own summary (computed by SQL) agrees with the frame's.
        run = self.lab.run(self.run_id)
        self.assertEqual(run["measurement_count"], READINGS)
        summary = run["summary"]["measurements"]["luminance"]
        self.assertEqual(summary["count"], len(df))
        self.assertAlmostEqual(summary["mean"], df["value"].mean(), delta=1e-9 * abs(summary["mean"]))
        self.assertAlmostEqual(summary["min"], df["value"].min())
        self.assertAlmostEqual(summary["max"], df["value"].max())
        # A luminance is a physical quantity: positive, in cd/m².
        self.assertTrue((df["value"] > 0).all())
        self.assertEqual(set(df["unit"]), {"cd/m2"})

    def test_small_pages_and_filters_give_the_same_rows(self):
        full = self.measurements()
        items = list(self.lab.measurement_items(self.run_id, page_size=2))  # 4 pages for 7 readings
        self.assertEqual([m["seq"] for m in items], full["seq"].tolist())
        one = self.measurements(step_prefix="reading/3")
        self.assertEqual(one["step"].tolist(), ["reading/3"])
        self.assertEqual(len(self.measurements(quantity="luminance")), READINGS)
        self.assertTrue(self.measurements(quantity="no-such-quantity").empty)
        self.assertEqual(len(self.measurements(instrument="ls110")), READINGS)

    def test_the_run_document(self):
        run = self.lab.run(self.run_id)
        self.assertEqual((run.id, run["campaign"], run["status"], run["simulated"]),
                         (self.run_id, "luminance-spot", "finished_ok", True))
        # The exact text that ran: it hashes to the run's script digest and is the shipped campaign.
        text = run.script()
        self.assertEqual(hashlib.sha256(text.encode()).hexdigest(), run["script"]["sha256"])
        self.assertEqual(text, (SOURCE_DIR / "campaigns" / "scripts" / "luminance-spot.lua").read_text())
        self.assertIn(self.run_id, self.lab.runs()["id"].tolist())

    def export(self, fmt, path=None):
        return skip_unless_served(self, lambda: self.lab.export(self.run_id, fmt, path),
                                  "GET /v1/runs/{id}/export")

    def test_exports_carry_the_stored_values(self):
        ref = self.stored
        doc = json.loads(self.export("json"))
        exported = doc["measurements"] if isinstance(doc, dict) else doc
        self.assertEqual([m["value"] for m in exported], [m["value"] for m in ref])
        csv = pd.read_csv(io.BytesIO(self.export("csv")))
        self.assertEqual(csv["step"].tolist(), [m["step"] for m in ref])
        np.testing.assert_allclose(csv["value"].to_numpy(), [m["value"] for m in ref], rtol=1e-12)
        with tempfile.TemporaryDirectory() as d:
            path = self.export("csv", d)
            self.assertEqual(path.parent, Path(d))
            self.assertEqual(path.suffix, ".csv")
            self.assertEqual(pd.read_csv(path)["value"].tolist(), csv["value"].tolist())
        # A .ti3 pairs patches with their colour: luminance readings have none, and the daemon says so.
        with self.assertRaises(colorlab.Unprocessable) as caught:
            self.export("ti3")
        self.assertIn("csv", caught.exception.hint)

    def test_refusals_are_typed_exceptions(self):
        with self.assertRaises(colorlab.NotFound) as caught:
            self.lab.run("01900000-0000-7000-8000-00000000dead")
        self.assertEqual(caught.exception.code, "not_found")
        self.assertIn("01900000-0000-7000-8000-00000000dead", caught.exception.detail)
        with self.assertRaises(colorlab.BadRequest) as caught:
            self.lab.start("luminance-spot", readings=0)
        self.assertIn("readings", caught.exception.detail)
        with self.assertRaises(colorlab.NotFound):
            self.lab.start("no-such-campaign")
        with self.assertRaises(colorlab.Conflict):
            self.lab.pause(self.done["id"])  # it has ended
        self.assertEqual(self.lab.requests(), [])
        self.assertIn(self.lab.queue()["state"], ("running", "stopped", "stopping"))



class AccessTest(unittest.TestCase):
    """Keys and scopes as a remote user meets them, over TCP; the admin is the Unix socket's user."""

    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon()
        cls.addClassCleanup(cls.daemon.cleanup)  # also when the rest of setUpClass fails
        cls.admin = cls.daemon.client
        cls.daemon.wait_ready("ls110")


    def test_loopback_reads_without_a_key_and_needs_one_to_start(self):
        with self.daemon.tcp_client() as anonymous:
            self.assertIn("items", anonymous.conn.get("/v1/runs"))
            # No key where one is needed is missing authentication (401), not too small a scope (403).
            with self.assertRaises(colorlab.Unauthorized) as caught:
                anonymous.start("luminance-spot", readings=1)
            self.assertEqual(caught.exception.status, 401)
            self.assertIn("control", caught.exception.detail)
            self.assertTrue(caught.exception.hint)
        with self.daemon.tcp_client(key="clk_not_a_key") as stranger:
            with self.assertRaises(colorlab.Unauthorized):
                stranger.runs()

    def test_a_control_key_starts_and_follows_and_revoked_it_is_refused(self):
        created = skip_unless_served(self, lambda: self.admin.create_key("python-tests", scope="control"),
                                     "POST /v1/keys")
        secret = created["secret"]
        listed = self.admin.keys()
        self.assertIn("python-tests", listed["name"].tolist())
        self.assertNotIn(secret, listed.to_string())  # the secret is shown once, in the answer that made it
        with self.daemon.tcp_client(key=secret) as operator:
            e = operator.start("luminance-spot", readings=2)
            self.assertEqual(self.daemon.wait_terminal(e.id)["status"], "finished_ok")
            with self.assertRaises(colorlab.Forbidden):  # control is not admin
                operator.keys()
            self.admin.revoke_key(created["id"])
            with self.assertRaises(colorlab.Unauthorized):
                operator.runs()


if __name__ == "__main__":
    unittest.main()
