"""HTTP over colorlabd's Unix socket for requests (which speaks only TCP): a connection pool whose
connections open the socket, mounted on the session. The socket's file permissions are its access control,
so a local user who can open it drives the lab without an API key, as the CLI does with --socket."""
from __future__ import annotations

import socket

import requests.adapters
import urllib3.connection
import urllib3.connectionpool
import urllib3.exceptions


class _UnixConnection(urllib3.connection.HTTPConnection):
    def __init__(self, *args, socket_path: str, **kwargs):
        self.socket_path = socket_path
        super().__init__(*args, **kwargs)

    def _new_conn(self):
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        if isinstance(self.timeout, (int, float)):
            sock.settimeout(self.timeout)
        try:
            sock.connect(self.socket_path)
        except OSError as e:
            sock.close()
            raise urllib3.exceptions.NewConnectionError(self, f"cannot connect to {self.socket_path}: {e}") from e
        return sock


class _UnixPool(urllib3.connectionpool.HTTPConnectionPool):
    ConnectionCls = _UnixConnection


class UnixSocketAdapter(requests.adapters.HTTPAdapter):
    def __init__(self, socket_path: str, pool_size: int = 10):
        super().__init__()
        # Extra pool keywords reach each connection: that is how the path gets there.
        self._pool = _UnixPool("localhost", maxsize=pool_size, socket_path=socket_path)

    def get_connection(self, url, proxies=None):
        return self._pool

    def get_connection_with_tls_context(self, request, verify, proxies=None, cert=None):  # requests ≥ 2.32
        return self._pool

    def close(self):
        self._pool.close()
        super().close()
