"""The live event stream (``GET /v1/events/stream``) as a generator that survives reconnects.

A fresh connection starts with a ``snapshot`` of the daemon's state; every event after it carries the
event log's sequence number as its SSE id. When the connection drops (daemon restart, network, or the
daemon dropping a client that fell behind) the generator reconnects with ``Last-Event-ID`` set to the last
sequence it yielded: the daemon sends every later event and no snapshot, so nothing is lost, and any event
at or below that sequence is skipped, so nothing is yielded twice.
"""
from __future__ import annotations

import http.client
import json
import time
from dataclasses import dataclass, field
from typing import Any, Iterator

import requests
import urllib3

from .connection import Connection
from .errors import ApiError, ColorlabError, ConnectionFailed, api_error
from .sse import SseParser

STREAM_PATH = "/v1/events/stream"
# Three missed keep-alives (the daemon sends one every 15 s) mean the connection is dead, not quiet.
READ_TIMEOUT_S = 45.0
DEFAULT_RETRY_S = 1.0  # until the daemon sends `retry:`
MAX_BACKOFF_S = 10.0
_READ_ERRORS = (requests.RequestException, urllib3.exceptions.HTTPError, http.client.HTTPException, OSError)


@dataclass(frozen=True)
class Event:
    """One event of the log (``topic`` instrument, execution, progress, queue, operator, …), or the
    ``snapshot`` a fresh connection starts with (``payload`` = ``{last_seq, executions, queue, instruments}``)."""

    seq: int
    topic: str
    payload: Any
    time: str | None = None
    raw: dict = field(default_factory=dict, repr=False, compare=False)


def _chunks(raw) -> Iterator[bytes]:
    """The response body as it arrives, never waiting to fill a buffer (requests' iter_lines would hold
    back the latest event: psf/requests #3577)."""
    if hasattr(raw, "read1"):  # urllib3 2: returns whatever has arrived
        while True:
            b = raw.read1(65536)
            if not b:
                return
            yield b
    if getattr(raw, "chunked", False) and raw.supports_chunked_reads():  # urllib3 1.26: one HTTP chunk each
        yield from raw.read_chunked(65536, decode_content=True)
        return
    fp = raw._fp  # a body without chunking: http.client's read1 returns what is buffered or arrives
    while True:
        b = fp.read1(65536)
        if not b:
            return
        yield b


def _event(sse) -> Event:
    try:
        doc = json.loads(sse.data) if sse.data else None
    except ValueError as e:
        raise ColorlabError(f"event {sse.id!r} ({sse.event}) is not JSON: {sse.data[:200]!r}") from e
    if sse.event == "snapshot":
        seq = int(sse.id) if sse.id.isdigit() else int((doc or {}).get("last_seq", 0))
        return Event(seq=seq, topic="snapshot", payload=doc, raw=doc if isinstance(doc, dict) else {})
    if isinstance(doc, dict) and "seq" in doc:
        return Event(seq=int(doc["seq"]), topic=doc.get("topic", sse.event), payload=doc.get("payload"),
                     time=doc.get("time"), raw=doc)
    if not sse.id.isdigit():
        raise ColorlabError(f"event ({sse.event}) carries no sequence number: {sse.data[:200]!r}")
    return Event(seq=int(sse.id), topic=sse.event, payload=doc, raw={})


def stream(conn: Connection, *, topic: str | None = None, after: int | None = None, reconnect: bool = True,
           give_up_after: float | None = 60.0, read_timeout: float = READ_TIMEOUT_S) -> Iterator[Event]:
    """Events as they happen. ``after=N`` starts after sequence N (no snapshot); otherwise the stream starts
    with a snapshot. ``give_up_after``: seconds of failing to reconnect before ``ConnectionFailed``
    (None: keep trying). Close the generator (or leave the ``for`` loop) to disconnect."""
    last_seq = after
    retry_s = DEFAULT_RETRY_S
    failing_since: float | None = None
    failures = 0
    while True:
        headers = {"Accept": "text/event-stream", "Cache-Control": "no-cache", "Accept-Encoding": "identity"}
        if last_seq is not None:
            headers["Last-Event-ID"] = str(last_seq)
        problem: Exception | None = None
        try:
            resp = conn.session.get(conn.absolute(STREAM_PATH), params={"topic": topic} if topic else None,
                                    headers=headers, stream=True, timeout=(conn.timeout, read_timeout),
                                    verify=conn.verify)
        except requests.exceptions.SSLError as e:
            raise ConnectionFailed(f"TLS with {conn.url} failed: {e}",
                                   hint="pass cacert= the CA certificate that signed the daemon's") from e
        except _READ_ERRORS as e:
            resp, problem = None, e
        if resp is not None:
            try:
                if resp.status_code == 204:  # the spec's "stop reconnecting"
                    return
                if resp.status_code != 200:
                    err = api_error(resp.status_code, resp.headers.get("Content-Type", ""), resp.content,
                                    reason=resp.reason, method="GET", url=resp.url)
                    # A daemon restarting or briefly overloaded is worth waiting for; a refusal is not.
                    if resp.status_code not in (502, 503, 504):
                        raise err
                    problem = err
                elif not resp.headers.get("Content-Type", "").startswith("text/event-stream"):
                    raise ColorlabError(f"{STREAM_PATH} answered {resp.headers.get('Content-Type')!r}, "
                                        "not text/event-stream")
                else:
                    failing_since, failures = None, 0
                    parser = SseParser(str(last_seq) if last_seq is not None else "")
                    try:
                        for chunk in _chunks(resp.raw):
                            for sse in parser.feed(chunk):
                                if parser.retry_ms is not None:
                                    retry_s = parser.retry_ms / 1000.0
                                ev = _event(sse)
                                if ev.topic != "snapshot" and last_seq is not None and ev.seq <= last_seq:
                                    continue  # already yielded before a reconnect
                                last_seq = ev.seq
                                yield ev
                    except _READ_ERRORS as e:
                        problem = e
            finally:
                resp.close()
        if not reconnect:
            if problem is not None and not isinstance(problem, ApiError):
                raise ConnectionFailed(f"event stream from {conn.where} failed: {problem}") from problem
            if isinstance(problem, ApiError):
                raise problem
            return
        if problem is not None:
            now = time.monotonic()
            failing_since = failing_since or now
            failures += 1
            if give_up_after is not None and now - failing_since > give_up_after:
                raise ConnectionFailed(f"event stream from {conn.where} lost for {now - failing_since:.0f} s: "
                                       f"{problem}", hint="is colorlabd running?") from problem
        # The spec's reconnection time after a clean end (the daemon dropped a slow client); after failures,
        # growing from it, so a daemon that is down is not hammered.
        time.sleep(retry_s if problem is None else min(retry_s * 2 ** (failures - 1), MAX_BACKOFF_S))
