"""A Server-Sent Events parser (WHATWG HTML, "Parsing an event stream"), fed bytes as they arrive.

Pure: no I/O. Chunks may split a line, a CRLF pair or a UTF-8 sequence anywhere. Lines end in CRLF, LF or
CR; ``:`` starts a comment; ``data`` lines join with ``\\n``; ``id`` persists across events (one holding NUL is
ignored); ``retry`` takes ASCII digits only; an event is dispatched by a blank line, and one the stream ends
in the middle of is dropped, as the spec says.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

_LINE_END = re.compile(rb"\r\n|\r|\n")


@dataclass(frozen=True)
class SseEvent:
    event: str  # "message" when the stream named none
    data: str
    id: str  # the last event ID when it was dispatched ("" if the stream never set one)


class SseParser:
    def __init__(self, last_event_id: str = ""):
        self.last_event_id = last_event_id
        self.retry_ms: int | None = None
        self.comments = 0  # keep-alives seen; a caller can tell a quiet stream from a dead one
        self._pending = b""  # the start of a line whose end has not arrived
        self._after_cr = False  # the last chunk ended in CR: an LF opening the next one belongs to it
        self._first_line = True
        self._data: list[str] = []
        self._event = ""

    def feed(self, chunk: bytes) -> list[SseEvent]:
        """The events this chunk completes, in order."""
        if self._after_cr and chunk[:1] == b"\n":
            chunk = chunk[1:]
            self._after_cr = False
        if not chunk:
            return []
        self._after_cr = False
        buf = self._pending + chunk
        events: list[SseEvent] = []
        start = 0
        for m in _LINE_END.finditer(buf):
            # A CR at the very end may be the first half of a CRLF: the next chunk decides.
            if m.group() == b"\r" and m.end() == len(buf):
                self._after_cr = True
            ev = self._line(buf[start:m.start()])
            if ev is not None:
                events.append(ev)
            start = m.end()
        self._pending = buf[start:]
        return events

    def _line(self, raw: bytes) -> SseEvent | None:
        line = raw.decode("utf-8", "replace")
        if self._first_line:
            self._first_line = False
            if line.startswith("\ufeff"):
                line = line[1:]
        if not line:
            return self._dispatch()
        if line.startswith(":"):
            self.comments += 1
            return None
        field, sep, value = line.partition(":")
        if sep and value.startswith(" "):
            value = value[1:]
        if field == "event":
            self._event = value
        elif field == "data":
            self._data.append(value)
        elif field == "id":
            if "\0" not in value:
                self.last_event_id = value
        elif field == "retry":
            if value and all("0" <= c <= "9" for c in value):
                self.retry_ms = int(value)
        return None

    def _dispatch(self) -> SseEvent | None:
        data, event = self._data, self._event
        self._data, self._event = [], ""
        if not data:
            return None
        return SseEvent(event=event or "message", data="\n".join(data), id=self.last_event_id)
