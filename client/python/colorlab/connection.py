"""The HTTP connection to colorlabd: base URL, API key, TLS trust, errors, and cursor paging."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Iterator

import requests

from .errors import ColorlabError, ConnectionFailed, api_error
from .unix_socket import UnixSocketAdapter

DEFAULT_URL = "http://127.0.0.1:8765"  # protocol::kDefaultListen
# Where a daemon writes colorlabd.endpoint: its own default (protocol::kDefaultStateDir, relative to the
# directory it was started in), then the packaged service's (systemd/colorlabd.example.toml).
DEFAULT_STATE_DIRS = (Path("colorlab-state"), Path("/var/lib/colorlabd"))
ENDPOINT_FILE = "colorlabd.endpoint"
MAX_PAGE_LIMIT = 300  # protocol::kMaxPageLimit


def read_endpoint(state_dir: str | os.PathLike | None = None) -> dict:
    """The running daemon's ``{"pid", "url", "port", "unix_socket", ...}`` from its state directory."""
    dirs = [Path(state_dir)] if state_dir is not None else list(DEFAULT_STATE_DIRS)
    for d in dirs:
        path = d / ENDPOINT_FILE
        try:
            endpoint = json.loads(path.read_text())
        except FileNotFoundError:
            continue
        except (OSError, ValueError) as e:
            raise ConnectionFailed(f"cannot read {path}: {e}") from e
        pid = endpoint.get("pid")
        # The daemon removes the file when it stops; after kill -9 or a power cut it stays behind.
        if isinstance(pid, int) and pid > 0 and not _alive(pid):
            raise ConnectionFailed(f"{path} names colorlabd pid {pid}, which is not running",
                                   hint="start colorlabd (it rewrites the file)")
        if not endpoint.get("url"):
            raise ConnectionFailed(f"{path} has no url")
        return endpoint
    raise ConnectionFailed("no colorlabd endpoint file in " + ", ".join(str(d / ENDPOINT_FILE) for d in dirs),
                           hint="start colorlabd, or pass state_dir= (the daemon's --state or state_dir setting)")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # someone else's process (the service user's): alive
    return True


class Connection:
    """One daemon: ``url`` (``COLORLAB_URL``, else 127.0.0.1:8765), ``key`` (``COLORLAB_API_KEY``), sent as
    ``Authorization: Bearer``, and ``cacert`` (a CA bundle for an https daemon with its own certificate);
    or ``socket``, the daemon's Unix socket, instead of a URL."""

    def __init__(self, url: str | None = None, key: str | None = None, cacert: str | os.PathLike | None = None,
                 *, timeout: float = 30.0, socket: str | os.PathLike | None = None,
                 session: requests.Session | None = None):
        self.socket = os.fspath(socket) if socket is not None else None
        self.timeout = timeout
        self.session = session or requests.Session()
        self.session.headers["User-Agent"] = "colorlab-python"
        if self.socket is not None:
            # Every request to this base goes through the socket; no proxy may take it elsewhere.
            self.url = "http://localhost"
            self.session.trust_env = False
            self.session.mount(self.url + "/", UnixSocketAdapter(self.socket))
        else:
            self.url = (url or os.environ.get("COLORLAB_URL") or DEFAULT_URL).rstrip("/")
            if not self.url.startswith(("http://", "https://")):
                raise ColorlabError(f"url must start with http:// or https://, got {self.url!r}")
        key = key if key is not None else os.environ.get("COLORLAB_API_KEY")
        if key:
            self.session.headers["Authorization"] = f"Bearer {key}"
        # Passed with every request: requests lets REQUESTS_CA_BUNDLE override a session's verify (psf/requests
        # #3829), and a CA given here must win.
        self.verify = os.fspath(cacert) if cacert is not None else None
        self._has_key = bool(key)

    def __repr__(self) -> str:
        where = f"socket={self.socket!r}" if self.socket is not None else repr(self.url)
        return f"{type(self).__name__}({where}{', key=…' if self._has_key else ''})"

    @property
    def where(self) -> str:
        return self.socket if self.socket is not None else self.url

    def absolute(self, path: str) -> str:
        """A route (``/v1/...``) or a link the daemon returned, as a full URL."""
        return path if path.startswith(("http://", "https://")) else self.url + path

    def request(self, method: str, path: str, *, params: dict | None = None, json_body: Any = None,
                headers: dict | None = None, stream: bool = False, timeout: Any = None) -> requests.Response:
        """One request; a 4xx/5xx answer raises the ``ApiError`` subclass of its status."""
        url = self.absolute(path)
        if params:
            params = {k: v for k, v in params.items() if v is not None}
        try:
            r = self.session.request(method, url, params=params, json=json_body, headers=headers, stream=stream,
                                     timeout=self.timeout if timeout is None else timeout, verify=self.verify)
        except requests.exceptions.SSLError as e:
            raise ConnectionFailed(f"TLS with {self.url} failed: {e}",
                                   hint="pass cacert= the CA certificate that signed the daemon's") from e
        except (requests.ConnectionError, requests.Timeout) as e:
            raise ConnectionFailed(f"cannot talk to colorlabd at {self.where}: {e}",
                                   hint="is colorlabd running? Client.local() finds a local one") from e
        if r.status_code >= 400:
            try:
                body = r.content
            except requests.RequestException:
                body = b""
            finally:
                r.close()
            raise api_error(r.status_code, r.headers.get("Content-Type", ""), body, reason=r.reason,
                            method=method, url=r.url)
        return r

    def get(self, path: str, params: dict | None = None) -> Any:
        return self.request("GET", path, params=params).json()

    def post(self, path: str, body: Any = None, *, headers: dict | None = None) -> Any:
        r = self.request("POST", path, json_body=body, headers=headers)
        return r.json() if r.content else None

    def delete(self, path: str) -> Any:
        r = self.request("DELETE", path)
        return r.json() if r.content else None

    def paged(self, path: str, params: dict | None = None, *, page_size: int = MAX_PAGE_LIMIT,
              max_items: int | None = None) -> Iterator[dict]:
        """Every item of a cursor-paged list (``{items, next_cursor}``), fetched a page at a time.
        The filters go with every page; only the cursor changes."""
        params = dict(params or {})
        params["limit"] = min(page_size, max_items) if max_items else page_size
        seen_cursors = set()
        n = 0
        while True:
            page = self.get(path, params)
            for item in page.get("items", []):
                yield item
                n += 1
                if max_items is not None and n >= max_items:
                    return
            cursor = page.get("next_cursor")
            if not cursor:
                return
            if cursor in seen_cursors:  # a server bug must not become an endless loop
                raise ColorlabError(f"{path} returned the cursor {cursor!r} twice")
            seen_cursors.add(cursor)
            params["cursor"] = cursor
