"""start() sends one idempotency key however often it retries; follow() reads progress from the stream."""
import json
import os
import tempfile
import threading
import unittest
from pathlib import Path

import colorlab
from fake_daemon import FakeDaemon

EID = "01900000-0000-7000-8000-0000000000e1"
RUN = "01900000-0000-7000-8000-0000000000a1"


def sse(seq, topic, payload):
    doc = {"seq": seq, "time": "2026-01-02T03:04:05.000Z", "topic": topic, "payload": payload}
    return f"id: {seq}\nevent: {topic}\ndata: {json.dumps(doc)}\n\n".encode()


def execution(status, progress=0.0, step=""):
    return {"id": EID, "run_id": RUN, "campaign": "luminance-spot", "status": status, "progress": progress,
            "step": step, "reason": ""}


class StartTest(unittest.TestCase):
    def test_a_lost_answer_is_retried_under_the_same_key(self):
        posts = []

        def post(h):
            posts.append(h.headers.get("Idempotency-Key"))
            if len(posts) == 1:
                h.drop()  # the daemon got it, the answer is lost
                return
            h.send_json(202, execution("waiting"), {"Location": f"/v1/executions/{EID}"})

        with FakeDaemon() as fake:
            fake.routes[("POST", "/v1/executions")] = post
            lab = self.enterContext(colorlab.Client(fake.url))
            e = lab.start("luminance-spot", readings=3, params={"interval_s": 0})
            self.assertEqual((e.id, e.run_id, e.status), (EID, RUN, "waiting"))
            self.assertEqual(len(posts), 2)
            self.assertEqual(posts[0], posts[1])
            body = json.loads(fake.requests_to("POST", "/v1/executions")[-1][4])
            self.assertEqual(body, {"campaign": "luminance-spot", "params": {"interval_s": 0, "readings": 3}})
            lab.start("luminance-spot", idempotency_key="night-42")
            self.assertEqual(fake.requests_to("POST", "/v1/executions")[-1][3]["Idempotency-Key"], "night-42")

    def test_a_refused_start_is_not_retried(self):
        with FakeDaemon() as fake:
            fake.routes[("POST", "/v1/executions")] = lambda h: h.send_problem(
                400, "bad_parameter", "Invalid request", "readings must be 1..1000")
            lab = self.enterContext(colorlab.Client(fake.url))
            with self.assertRaises(colorlab.BadRequest):
                lab.start("luminance-spot", readings=0)
            self.assertEqual(len(fake.requests_to("POST", "/v1/executions")), 1)


class FollowTest(unittest.TestCase):
    waiting = []  # operator requests in the snapshot

    def serve(self, fake, first_status, events, final_status):
        state = {"status": first_status}
        snapshot_sent = threading.Event()

        def get_execution(h):
            # follow() must read the execution after the stream is open, or an event could slip between.
            if not snapshot_sent.is_set():
                h.send_problem(500, "internal", "Test", "execution read before the stream was open")
                return
            h.send_json(200, execution(state["status"]))

        def stream(h):
            h.start_chunked()
            snapshot = b"id: 10\nevent: snapshot\ndata: " + json.dumps(
                {"last_seq": 10, "executions": [], "requests": self.waiting}).encode() + b"\n\n"
            # Set once the snapshot is taken, before it is sent: set after, a client that read the execution as
            # soon as the snapshot arrived (as it should) could be answered before this thread ran again.
            snapshot_sent.set()
            h.chunk(snapshot)
            # Wait until follow() has read the execution, as a real run would go on meanwhile.
            for _ in range(2000):
                if fake.requests_to("GET", f"/v1/executions/{EID}"):
                    break
                threading.Event().wait(0.005)
            state["status"] = final_status
            for seq, (topic, payload) in enumerate(events, start=11):
                h.chunk(sse(seq, topic, payload))
            h.end_chunked()

        fake.routes[("GET", f"/v1/executions/{EID}")] = get_execution
        fake.routes[("GET", "/v1/events/stream")] = stream

    def test_progress_of_this_execution_to_its_end(self):
        other = "01900000-0000-7000-8000-0000000000e2"
        events = [
            ("execution", {"execution_id": EID, "run_id": RUN, "status": "running", "reason": ""}),
            ("progress", {"execution_id": other, "progress": 0.9, "step": "theirs"}),
            ("progress", {"execution_id": EID, "run_id": RUN, "progress": 0.0, "step": "reading/0", "measurements": 0}),
            ("instrument", {"event": "added", "id": "ls110"}),
            ("operator", {"event": "posted", "request": {"id": "q1", "execution_id": EID, "action": "aim_meter",
                                                         "prompt": "Aim the LS-110 at the tile"}}),
            ("progress", {"execution_id": EID, "run_id": RUN, "progress": 0.5, "step": "reading/1", "measurements": 1}),
            ("execution", {"execution_id": EID, "run_id": RUN, "status": "finished_ok", "reason": ""}),
            ("progress", {"execution_id": EID, "progress": 1.0, "step": "never seen"}),
        ]
        with FakeDaemon() as fake:
            self.serve(fake, "waiting", events, "finished_ok")
            lab = self.enterContext(colorlab.Client(fake.url))
            gen = lab.follow(EID)
            seen = []
            try:
                while True:
                    seen.append(next(gen))
            except StopIteration as stop:
                final = stop.value
        self.assertEqual([(p.kind, p.status, p.progress, p.step) for p in seen], [
            ("state", "waiting", 0.0, ""),
            ("execution", "running", 0.0, ""),
            ("progress", "running", 0.0, "reading/0"),
            ("operator", "running", 0.0, "reading/0"),
            ("progress", "running", 0.5, "reading/1"),
            ("execution", "finished_ok", 0.5, "reading/1"),
        ])
        self.assertEqual(seen[3].request["action"], "aim_meter")
        self.assertEqual(seen[4].measurements, 1)
        self.assertTrue(seen[-1].terminal)
        self.assertEqual(final.status, "finished_ok")
        self.assertIn("reading/1", str(seen[4]))

    def test_a_request_waiting_before_the_stream_opened_is_yielded_once(self):
        req = {"id": "q7", "execution_id": EID, "action": "load_chart", "prompt": "Load the SG"}
        self.waiting = [req, dict(req, id="q8", execution_id="someone-else")]
        events = [
            # The same request's event, had the log raced the snapshot: not yielded twice.
            ("operator", {"event": "posted", "request": req}),
            ("operator", {"event": "answered", "request": dict(req, answer="loaded")}),
            ("execution", {"execution_id": EID, "status": "finished_ok"}),
        ]
        with FakeDaemon() as fake:
            self.serve(fake, "running", events, "finished_ok")
            lab = self.enterContext(colorlab.Client(fake.url))
            seen = [(p.kind, p.request and (p.request["id"], p.request["event"])) for p in lab.follow(EID)]
        self.assertEqual(seen, [("state", None), ("operator", ("q7", "posted")), ("operator", ("q7", "answered")),
                                ("execution", None)])

    def test_an_execution_that_already_ended_yields_once(self):
        with FakeDaemon() as fake:
            self.serve(fake, "aborted", [], "aborted")
            lab = self.enterContext(colorlab.Client(fake.url))
            self.assertEqual([p.status for p in lab.follow(EID)], ["aborted"])
            with self.assertRaises(colorlab.ExecutionFailed) as caught:
                lab.wait(EID)
            self.assertEqual(caught.exception.execution["status"], "aborted")
            self.assertEqual(lab.wait(EID, check=False).status, "aborted")

    def test_control_routes(self):
        with FakeDaemon() as fake:
            for action, status in (("pause", "paused"), ("resume", "running"), ("abort", "aborted")):
                fake.routes[("POST", f"/v1/executions/{EID}/{action}")] = (
                    lambda h, s=status: h.send_json(202, execution(s)))
            lab = self.enterContext(colorlab.Client(fake.url))
            e = colorlab.Execution(lab, execution("running"))
            self.assertEqual([e.pause().status, e.resume().status, lab.abort(EID).status],
                             ["paused", "running", "aborted"])

    def test_operator_requests_are_listed_and_answered(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/requests")] = lambda h: h.send_json(200, {"items": [{"id": "q1"}]})
            fake.routes[("POST", "/v1/requests/q1")] = lambda h: h.send_json(200, dict(h.json_body(), id="q1"))
            lab = self.enterContext(colorlab.Client(fake.url))
            [req] = lab.requests()
            self.assertEqual(lab.answer(req, "loaded", by="ada"), {"id": "q1", "answer": "loaded", "by": "ada"})


class LocalTest(unittest.TestCase):
    def test_the_endpoint_file_names_the_url(self):
        with tempfile.TemporaryDirectory() as d:
            Path(d, "colorlabd.endpoint").write_text(json.dumps({"pid": os.getpid(), "url": "http://127.0.0.1:9"}))
            self.assertEqual(colorlab.Client.local(d).url, "http://127.0.0.1:9")

    def test_no_file_or_a_dead_daemons_file_is_a_connection_failure(self):
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(colorlab.ConnectionFailed) as caught:
                colorlab.Client.local(d)
            self.assertIn(str(Path(d, "colorlabd.endpoint")), str(caught.exception))
            # A pid that cannot exist (above the kernel's pid_max limit of 2^22).
            Path(d, "colorlabd.endpoint").write_text(json.dumps({"pid": 2 ** 22 + 1, "url": "http://x:1"}))
            with self.assertRaises(colorlab.ConnectionFailed) as caught:
                colorlab.Client.local(d)
            self.assertIn("not running", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
