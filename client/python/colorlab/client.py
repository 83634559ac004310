"""``Client``: one daemon, everything it serves."""
from __future__ import annotations

import os
from typing import Iterator

from . import events as _events
from .access import AccessMixin
from .blobs import BlobsMixin
from .connection import Connection, read_endpoint
from .executions import ExecutionsMixin
from .exports import ExportsMixin
from .lab import LabMixin
from .runs import RunsMixin
from .verify import VerifyMixin


class Client(RunsMixin, BlobsMixin, ExportsMixin, ExecutionsMixin, LabMixin, AccessMixin, VerifyMixin):
    """``Client(url=None, key=None, cacert=None)``: url from ``COLORLAB_URL`` (else http://127.0.0.1:8765), key
    from ``COLORLAB_API_KEY`` (sent as ``Authorization: Bearer``), ``cacert`` for an https daemon whose
    certificate your system does not trust; or ``socket=``, the daemon's Unix socket, instead of a URL.
    ``Client.local()`` finds a daemon on this machine."""

    def __init__(self, url: str | None = None, key: str | None = None, cacert: str | os.PathLike | None = None,
                 *, socket: str | os.PathLike | None = None, timeout: float = 30.0):
        self.conn = Connection(url, key, cacert, timeout=timeout, socket=socket)

    @classmethod
    def local(cls, state_dir: str | os.PathLike | None = None, *, key: str | None = None,
              cacert: str | os.PathLike | None = None, use_socket: bool = True, timeout: float = 30.0) -> "Client":
        """The daemon whose ``<state_dir>/colorlabd.endpoint`` says where it listens. Without ``state_dir``:
        ``./colorlab-state`` (colorlabd's default), then ``/var/lib/colorlabd`` (the systemd service's).
        Through its Unix socket when this user may open it — the socket's permissions are its access control,
        so no key is needed to start campaigns — else (or with ``use_socket=False``) through its ``url``."""
        endpoint = read_endpoint(state_dir)
        path = endpoint.get("unix_socket")
        if use_socket and path and os.path.exists(path) and os.access(path, os.R_OK | os.W_OK):
            return cls(key=key, cacert=cacert, socket=path, timeout=timeout)
        return cls(endpoint["url"], key, cacert, timeout=timeout)

    @classmethod
    def from_options(cls, url: str | None = None, socket: str | None = None, key: str | None = None) -> "Client":
        """What a command line names, in the order the colorlab commands document: ``socket`` (or
        ``COLORLAB_SOCKET`` when no ``url``), else ``url`` (or ``COLORLAB_URL``), else the local daemon's endpoint
        file (``Client.local()``), else http://127.0.0.1:8765."""
        if socket or (not url and os.environ.get("COLORLAB_SOCKET")):
            return cls(socket=socket or os.environ["COLORLAB_SOCKET"], key=key)
        if url or os.environ.get("COLORLAB_URL"):
            return cls(url, key=key)
        try:
            return cls.local(key=key)
        except Exception:  # no endpoint file here: the documented default URL
            return cls(key=key)

    def close(self) -> None:
        """Closes the pooled connections (also at the end of ``with Client(...) as lab:``)."""
        self.conn.session.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def url(self) -> str:
        """The base URL (``http://localhost`` through a Unix socket)."""
        return self.conn.url

    @property
    def socket(self) -> str | None:
        return self.conn.socket

    def __repr__(self) -> str:
        return repr(self.conn).replace("Connection", "Client", 1)

    def events(self, topic: str | None = None, *, after: int | None = None, reconnect: bool = True,
               give_up_after: float | None = 60.0) -> Iterator[_events.Event]:
        """The live event stream: a snapshot (unless ``after``), then every event, reconnecting by itself with
        ``Last-Event-ID`` so none is lost or repeated. ``topic``: only that topic's events."""
        return _events.stream(self.conn, topic=topic, after=after, reconnect=reconnect,
                              give_up_after=give_up_after)

    def event_log(self, after: int = 0, topic: str | None = None, limit: int = 300) -> list[dict]:
        """One page of the stored event log (``GET /v1/events``), oldest first."""
        return self.conn.get("/v1/events", {"after": after, "topic": topic, "limit": limit}).get("items", [])
