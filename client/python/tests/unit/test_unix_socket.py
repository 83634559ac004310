"""The client over a Unix socket, as Client.local() uses the daemon's: requests, errors and the event stream."""
import json
import os
import tempfile
import unittest
from pathlib import Path

import colorlab
from fake_daemon import FakeDaemon


class UnixSocketTest(unittest.TestCase):
    def setUp(self):
        self.dir = self.enterContext(tempfile.TemporaryDirectory())
        self.path = os.path.join(self.dir, "colorlabd.sock")
        self.fake = self.enterContext(FakeDaemon(unix_path=self.path))

    def test_requests_errors_and_the_stream_go_through_the_socket(self):
        self.fake.routes[("GET", "/v1")] = lambda h: h.send_json(200, {"server": "colorlabd"})
        self.fake.routes[("POST", "/v1/executions")] = lambda h: h.send_problem(
            400, "bad_parameter", "Invalid request", "readings must be 1..1000")

        def stream(h):
            h.start_chunked()
            h.chunk(b'id: 4\nevent: snapshot\ndata: {"last_seq": 4}\n\n')
            h.end_chunked()

        self.fake.routes[("GET", "/v1/events/stream")] = stream
        lab = self.enterContext(colorlab.Client(socket=self.path))
        self.assertEqual(repr(lab), f"Client(socket={self.path!r})")
        self.assertEqual(lab.status(), {"server": "colorlabd"})
        with self.assertRaises(colorlab.BadRequest):
            lab.start("luminance-spot", readings=0)
        self.assertEqual([(e.seq, e.topic) for e in lab.events(reconnect=False)], [(4, "snapshot")])
        self.assertEqual(self.fake.requests_to("GET", "/v1")[0][3]["Host"], "localhost")

    def test_local_prefers_the_socket_and_falls_back_to_the_url(self):
        Path(self.dir, "colorlabd.endpoint").write_text(json.dumps(
            {"pid": os.getpid(), "url": "http://127.0.0.1:9", "unix_socket": self.path}))
        with colorlab.Client.local(self.dir) as lab:
            self.assertEqual(lab.socket, self.path)
        with colorlab.Client.local(self.dir, use_socket=False) as lab:
            self.assertEqual((lab.socket, lab.url), (None, "http://127.0.0.1:9"))
        Path(self.dir, "colorlabd.endpoint").write_text(json.dumps(
            {"pid": os.getpid(), "url": "http://127.0.0.1:9", "unix_socket": self.path + ".gone"}))
        with colorlab.Client.local(self.dir) as lab:
            self.assertEqual(lab.url, "http://127.0.0.1:9")


if __name__ == "__main__":
    unittest.main()
