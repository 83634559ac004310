"""A tiny in-process HTTP/1.1 server standing in for colorlabd in unit tests: routes are functions."""
from __future__ import annotations

import json
import socketserver
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qs, urlsplit


class Handler(BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"

    def log_message(self, *args):  # quiet
        pass

    def _dispatch(self):
        parts = urlsplit(self.path)
        self.route_path = parts.path
        self.query = {k: v[-1] for k, v in parse_qs(parts.query, keep_blank_values=True).items()}
        n = int(self.headers.get("Content-Length") or 0)
        self.body = self.rfile.read(n) if n else b""
        fake = self.server.fake
        with fake.lock:
            fake.requests.append((self.command, self.route_path, dict(self.query), dict(self.headers), self.body))
        fn = fake.routes.get((self.command, self.route_path))
        if fn is None:
            self.send_problem(404, "not_found", "Not found", f"no route for {self.command} {self.route_path}")
            return
        fn(self)

    do_GET = do_POST = do_HEAD = do_DELETE = _dispatch

    def json_body(self):
        return json.loads(self.body or b"null")

    def send_bytes(self, status, body=b"", content_type="application/octet-stream", headers=None):
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        for k, v in (headers or {}).items():
            self.send_header(k, v)
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def send_json(self, status, doc, headers=None):
        self.send_bytes(status, json.dumps(doc).encode(), "application/json", headers)

    def send_problem(self, status, code, title, detail, hint=""):
        doc = {"type": f"https://colorlab.invalid/problems/{code}", "title": title, "status": status,
               "detail": detail, "category": "validation", "code": code}
        if hint:
            doc["hint"] = hint
        self.send_bytes(status, json.dumps(doc).encode(), "application/problem+json")

    def start_chunked(self, status=200, content_type="text/event-stream", headers=None):
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Transfer-Encoding", "chunked")
        for k, v in (headers or {}).items():
            self.send_header(k, v)
        self.end_headers()

    def chunk(self, data: bytes):
        self.wfile.write(b"%x\r\n%s\r\n" % (len(data), data))
        self.wfile.flush()

    def end_chunked(self):
        self.wfile.write(b"0\r\n\r\n")
        self.wfile.flush()

    def drop(self):
        """End the connection abruptly, as a daemon killed mid-stream would."""
        self.close_connection = True
        self.wfile.flush()
        self.connection.shutdown(2)


class _QuietErrors:
    def handle_error(self, request, client_address):
        # A client that hangs up mid-answer is what several tests do on purpose.
        if not isinstance(sys.exc_info()[1], (ConnectionError, BrokenPipeError)):
            super().handle_error(request, client_address)


class _TcpServer(_QuietErrors, ThreadingHTTPServer):
    pass


class _UnixServer(_QuietErrors, socketserver.ThreadingMixIn, socketserver.UnixStreamServer):
    def get_request(self):
        sock, _ = super().get_request()
        return sock, ("unix", 0)  # BaseHTTPRequestHandler expects a (host, port) peer


class FakeDaemon:
    """On 127.0.0.1:<free port>, or on a Unix socket at ``unix_path``."""

    def __init__(self, unix_path=None):
        self.routes = {}
        self.requests = []
        self.lock = threading.Lock()
        self.unix_path = unix_path
        if unix_path:
            self.server = _UnixServer(unix_path, Handler)
        else:
            self.server = _TcpServer(("127.0.0.1", 0), Handler)
        self.server.daemon_threads = True
        self.server.fake = self
        self.thread = threading.Thread(target=self.server.serve_forever, args=(0.02,), daemon=True)

    @property
    def url(self):
        return f"http://127.0.0.1:{self.server.server_address[1]}"

    def route(self, method, path):
        def add(fn):
            self.routes[(method, path)] = fn
            return fn
        return add

    def requests_to(self, method, path):
        with self.lock:
            return [r for r in self.requests if r[0] == method and r[1] == path]

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.server.shutdown()
        self.server.server_close()
