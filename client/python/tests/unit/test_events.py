"""The event stream reconnects with Last-Event-ID and yields every event exactly once, as it arrives."""
import json
import threading
import unittest

import colorlab
from fake_daemon import FakeDaemon


def sse(seq, topic, payload):
    doc = {"seq": seq, "time": "2026-01-02T03:04:05.000Z", "topic": topic, "payload": payload}
    return f"id: {seq}\nevent: {topic}\ndata: {json.dumps(doc)}\n\n".encode()


def snapshot(last_seq):
    doc = {"last_seq": last_seq, "executions": [], "queue": {}, "instruments": []}
    return f"id: {last_seq}\nevent: snapshot\ndata: {json.dumps(doc)}\n\n".encode()


class ReconnectTest(unittest.TestCase):
    def test_a_dropped_stream_resumes_after_the_last_event_without_loss_or_duplicate(self):
        connects = []

        def stream(h):
            last = h.headers.get("Last-Event-ID")
            connects.append(last)
            if last is None:  # fresh: snapshot, two events, then the daemon dies mid-event
                h.start_chunked()
                h.chunk(b"retry: 10\n")
                h.chunk(snapshot(3))
                h.chunk(sse(4, "progress", {"step": "a"}) + sse(5, "progress", {"step": "b"})[:7])
                h.chunk(sse(5, "progress", {"step": "b"})[7:] + b": keep-alive\n")
                h.chunk(sse(6, "progress", {"step": "c"})[:20])
                h.drop()
            elif last == "5":  # a restarted daemon briefly refusing, then the rest
                if connects.count("5") == 1:
                    h.send_problem(503, "io_error", "Storage failure", "starting up")
                    return
                h.start_chunked()
                # One event the client already has: a duplicate must not reach the caller.
                h.chunk(sse(5, "progress", {"step": "b"}) + sse(6, "progress", {"step": "c"}))
                h.chunk(sse(7, "execution", {"status": "finished_ok"}))
                h.end_chunked()
            else:  # after 7: nothing more will ever come
                h.send_bytes(204)

        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/events/stream")] = stream
            lab = self.enterContext(colorlab.Client(fake.url))
            got = [(e.seq, e.topic) for e in lab.events(give_up_after=30)]
        self.assertEqual(got, [(3, "snapshot"), (4, "progress"), (5, "progress"), (6, "progress"),
                               (7, "execution")])
        self.assertEqual(connects, [None, "5", "5", "7"])
        accepts = {r[3].get("Accept") for r in fake.requests_to("GET", "/v1/events/stream")}
        self.assertEqual(accepts, {"text/event-stream"})

    def test_after_starts_without_snapshot_and_topic_is_passed(self):
        def stream(h):
            h.start_chunked()
            h.chunk(sse(11, "queue", {"change": "enqueued"}))
            h.end_chunked()

        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/events/stream")] = stream
            lab = self.enterContext(colorlab.Client(fake.url))
            events = list(lab.events("queue", after=10, reconnect=False))
            self.assertEqual([(e.seq, e.topic, e.payload) for e in events], [(11, "queue", {"change": "enqueued"})])
            _, _, query, headers, _ = fake.requests_to("GET", "/v1/events/stream")[0]
            self.assertEqual((query.get("topic"), headers.get("Last-Event-ID")), ("queue", "10"))

    def test_each_event_is_yielded_when_it_arrives_not_when_a_buffer_fills(self):
        received = threading.Event()
        in_time = []

        def stream(h):
            h.start_chunked()
            h.chunk(snapshot(1))
            # The next event is sent only once the client has the snapshot; a client that waits for more
            # bytes would stall here until this wait gives up.
            in_time.append(received.wait(20))
            h.chunk(sse(2, "progress", {}))
            h.end_chunked()

        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/events/stream")] = stream
            lab = self.enterContext(colorlab.Client(fake.url))
            for e in lab.events(reconnect=False):
                if e.topic == "snapshot":
                    received.set()
        self.assertEqual(in_time, [True])

    def test_a_refusal_is_raised_not_retried(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/events/stream")] = lambda h: h.send_problem(
                401, "unauthorized", "Unauthorized", "no API key")
            lab = self.enterContext(colorlab.Client(fake.url))
            with self.assertRaises(colorlab.Unauthorized):
                next(lab.events())
            self.assertEqual(len(fake.requests_to("GET", "/v1/events/stream")), 1)

    def test_a_missing_route_says_so(self):
        with FakeDaemon() as fake:
            lab = self.enterContext(colorlab.Client(fake.url))
            with self.assertRaises(colorlab.NotFound) as caught:
                next(lab.events())
            self.assertIn("/v1/events/stream", str(caught.exception))

    def test_giving_up_after_the_daemon_stays_away(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/events/stream")] = lambda h: h.send_problem(
                503, "io_error", "Storage failure", "down")
            lab = self.enterContext(colorlab.Client(fake.url))
            with self.assertRaises(colorlab.ConnectionFailed):
                next(lab.events(give_up_after=0))

    def test_closing_the_generator_closes_the_connection(self):
        closed = threading.Event()

        def stream(h):
            h.start_chunked()
            h.chunk(snapshot(1))
            try:
                for _ in range(5000):  # keep-alives until the client hangs up (a bound, not a timing)
                    closed.wait(0.01)
                    h.chunk(b": keep-alive\n")
            except OSError:
                closed.set()

        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/events/stream")] = stream
            lab = self.enterContext(colorlab.Client(fake.url))
            gen = lab.events()
            self.assertEqual(next(gen).topic, "snapshot")
            gen.close()
            self.assertTrue(closed.wait(20))


if __name__ == "__main__":
    unittest.main()
