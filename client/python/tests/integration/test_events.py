"""The client's event stream across a daemon killed with -9 and started again: it reconnects by itself with
Last-Event-ID, and what it yielded is exactly the daemon's stored event log after the snapshot — nothing
lost, nothing twice."""
import queue
import threading
import unittest

from daemon_fixture import Daemon, free_port, skip_unless_served


class StreamAcrossRestartTest(unittest.TestCase):
    def setUp(self):
        self.daemon = Daemon(port=free_port())  # the restarted daemon listens where the stream reconnects
        self.addCleanup(self.daemon.cleanup)
        self.daemon.wait_ready("ls110")

    def test_no_event_lost_or_repeated_across_kill_9(self):
        # Over loopback TCP, as a remote reader's stream; the restarted daemon listens on the same port.
        reader_client = self.enterContext(self.daemon.tcp_client())
        stream = reader_client.events(give_up_after=120)
        first = skip_unless_served(self, lambda: next(stream), "GET /v1/events/stream")
        self.assertEqual(first.topic, "snapshot")
        got = queue.Queue()
        stop = threading.Event()

        def consume():
            try:
                for ev in stream:
                    got.put(ev)
                    if stop.is_set():
                        return
            except Exception as e:  # surfaced to the test below
                got.put(e)

        reader = threading.Thread(target=consume, daemon=True)
        reader.start()

        before = self.daemon.run_to_end("luminance-spot", readings=3)
        self.daemon.kill9()
        self.daemon.start()
        self.daemon.wait_ready("ls110")
        after = self.daemon.run_to_end("luminance-spot", readings=3)

        # Read until the second run's end has come through the stream.
        events = []
        while True:
            ev = got.get(timeout=120)
            if isinstance(ev, Exception):
                raise ev
            events.append(ev)
            if (ev.topic == "execution" and ev.payload.get("execution_id") == after["id"]
                    and ev.payload.get("status") == "finished_ok"):
                break
        stop.set()

        seqs = [e.seq for e in events]
        self.assertEqual(len(seqs), len(set(seqs)), "an event came twice")
        self.assertEqual(seqs, sorted(seqs))
        self.assertTrue(all(e.topic != "snapshot" for e in events), "a reconnect sent a snapshot: not resumed")
        # The stored log from the snapshot to the last event read, through the plain paged route.
        stored = []
        after_seq = first.seq
        while True:
            page = self.daemon.client.event_log(after=after_seq)
            page = [e for e in page if e["seq"] <= seqs[-1]]
            if not page:
                break
            stored += page
            after_seq = page[-1]["seq"]
        self.assertEqual(seqs, [e["seq"] for e in stored])
        self.assertEqual([(e.topic, e.payload) for e in events], [(e["topic"], e["payload"]) for e in stored])
        # Both runs are in it, the first before the kill.
        ids = {e.payload.get("execution_id") for e in events if isinstance(e.payload, dict)}
        self.assertTrue({before["id"], after["id"]} <= ids)


if __name__ == "__main__":
    unittest.main()
