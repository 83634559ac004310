"""Executions: start a campaign, follow it through the live event stream, pause, resume, abort."""
from __future__ import annotations

import time
import uuid
from dataclasses import dataclass
from typing import Any, Iterator

from . import events as _events
from .errors import ColorlabError, ConnectionFailed, ExecutionFailed

TERMINAL = frozenset({"finished_ok", "finished_error", "aborted", "interrupted"})  # protocol/states.hpp


def execution_id(execution) -> str:
    if isinstance(execution, str):
        return execution
    if isinstance(execution, dict):
        return execution["id"]
    raise TypeError(f"expected an execution id or an execution, got {type(execution).__name__}")


class Execution(dict):
    """``GET /v1/executions/{id}`` (a dict): ``id, run_id, campaign, status, progress, step, reason, …``."""

    def __init__(self, client, doc: dict):
        super().__init__(doc)
        self._client = client

    id = property(lambda self: self["id"])
    run_id = property(lambda self: self.get("run_id"))
    status = property(lambda self: self.get("status"))
    terminal = property(lambda self: self.get("status") in TERMINAL)

    def refresh(self) -> "Execution":
        return self._client.execution(self.id)

    def follow(self, **kw) -> Iterator["Progress"]:
        return self._client.follow(self, **kw)

    def wait(self, **kw) -> "Execution":
        return self._client.wait(self, **kw)

    def pause(self) -> "Execution":
        return self._client.pause(self)

    def resume(self) -> "Execution":
        return self._client.resume(self)

    def abort(self) -> "Execution":
        return self._client.abort(self)

    def run(self):
        return self._client.run(self.run_id)


@dataclass(frozen=True)
class Progress:
    """Where an execution stands after one event: the latest status, progress (0..1) and step seen so far.
    ``kind``: ``state`` (read when following began), ``progress`` (a step was committed; ``measurements``: how
    many it stored), ``execution`` (a status change or a requested pause/abort), ``operator`` (``request`` is
    the operator request)."""

    execution_id: str
    kind: str
    status: str | None
    progress: float | None
    step: str | None
    measurements: int | None = None
    reason: str | None = None
    request: dict | None = None
    event: _events.Event | None = None

    @property
    def terminal(self) -> bool:
        return self.status in TERMINAL

    def __str__(self) -> str:
        pct = f"{100 * self.progress:5.1f} %" if self.progress is not None else "   ?   "
        text = f"{self.status or '?':<14} {pct}  {self.step or ''}"
        if self.kind == "operator" and self.request:
            text += f"  [operator {self.request.get('action', '')}: {self.request.get('prompt', '')}]"
        elif self.reason:
            text += f"  ({self.reason})"
        return text


class ExecutionsMixin:
    def start(self, campaign: str, *, idempotency_key: str | None = None, params: dict | None = None,
              **kwargs: Any) -> Execution:
        """Start ``campaign`` with its parameters as keywords (or ``params={...}``). The request carries an
        idempotency key (a fresh one unless given), so the retry after a lost answer can never start the
        campaign twice. One execution at a time on a lab: while another is unfinished (waiting, running, paused
        or suspended) this raises ``Conflict`` with ``code == "lab-busy"`` and ``problem["execution_id"]``
        naming it (after ``abort``, ``wait`` for it to end first); ``enqueue`` with the queue started
        (``start_queue``) has a campaign start when the lab is free."""
        body_params = dict(params or {})
        body_params.update(kwargs)
        key = idempotency_key or f"python-{uuid.uuid4()}"
        body = {"campaign": campaign, "params": body_params}
        for attempt in range(3):
            try:
                return Execution(self, self.conn.post("/v1/executions", body, headers={"Idempotency-Key": key}))
            except ConnectionFailed:
                if attempt == 2:
                    raise
                time.sleep(0.5 * (attempt + 1))

    def dry_run(self, campaign: str, *, params: dict | None = None, **kwargs: Any) -> dict:
        """The campaign checked against the lab without moving anything, and its estimated duration."""
        body_params = dict(params or {})
        body_params.update(kwargs)
        return self.conn.post("/v1/executions", {"campaign": campaign, "params": body_params, "dry_run": True})

    def execution(self, execution) -> Execution:
        return Execution(self, self.conn.get(f"/v1/executions/{execution_id(execution)}"))

    def _control(self, execution, action: str) -> Execution:
        return Execution(self, self.conn.post(f"/v1/executions/{execution_id(execution)}/{action}"))

    def pause(self, execution) -> Execution:
        """Pause at the next safe point (the step before is committed). ``Conflict`` if it cannot be."""
        return self._control(execution, "pause")

    def resume(self, execution) -> Execution:
        return self._control(execution, "resume")

    def abort(self, execution) -> Execution:
        """Abort at the next safe point; what was measured stays stored."""
        return self._control(execution, "abort")

    def follow(self, execution, *, give_up_after: float | None = 120.0) -> Iterator[Progress]:
        """Progress of an execution from the live event stream until it ends; the generator's return value
        is the final ``Execution``. Survives a daemon restart (the stream resumes by ``Last-Event-ID``)."""
        eid = execution_id(execution)
        stream = _events.stream(self.conn, give_up_after=give_up_after)
        try:
            # The stream is open before the execution is read: whatever happens after that read is an event.
            first = next(stream, None)
            if first is None:
                raise ColorlabError(f"the event stream of {self.conn.where} ended before it began")
            state = self.execution(eid)
            current = Progress(eid, "state", state.status, state.get("progress"), state.get("step"),
                               reason=state.get("reason"))
            yield current
            if current.terminal:
                return state
            # A request already waiting was posted before the stream: the snapshot lists it.
            posted = set()
            snapshot = first.payload if first.topic == "snapshot" and isinstance(first.payload, dict) else {}
            waiting = snapshot["requests"] if "requests" in snapshot else self.requests()
            for req in waiting:
                if req.get("execution_id") == eid and req.get("id") not in posted:
                    posted.add(req.get("id"))
                    yield Progress(eid, "operator", current.status, current.progress, current.step,
                                   reason=current.reason, request=dict(req, event="posted"))
            # A daemon that sends no snapshot: its first event is news like any other.
            for ev in _chain(None if first.topic == "snapshot" else first, stream):
                nxt = _apply(current, ev, eid)
                if nxt is not None and nxt.kind == "operator" and nxt.request.get("event") == "posted":
                    if nxt.request.get("id") in posted:
                        continue  # listed already (GET /v1/requests raced the event)
                    posted.add(nxt.request.get("id"))
                if ev.topic == "snapshot":  # reconnected without an id: re-read instead of guessing
                    state = self.execution(eid)
                    nxt = Progress(eid, "state", state.status, state.get("progress"), state.get("step"),
                                   reason=state.get("reason"), event=ev)
                if nxt is None:
                    continue
                current = nxt
                yield current
                if current.terminal:
                    return self.execution(eid)
        finally:
            stream.close()

    def wait(self, execution, *, check: bool = True, give_up_after: float | None = 120.0) -> Execution:
        """Follow quietly to the end; the final ``Execution``. ``check``: raise ``ExecutionFailed`` unless it
        ended ``finished_ok``."""
        gen = self.follow(execution, give_up_after=give_up_after)
        while True:
            try:
                next(gen)
            except StopIteration as stop:
                final = stop.value
                break
        if check and final.status != "finished_ok":
            raise ExecutionFailed(final)
        return final


def _chain(first, rest):
    if first is not None:
        yield first
    yield from rest


def _apply(current: Progress, ev: _events.Event, eid: str) -> Progress | None:
    """The progress after ``ev``, or None when the event is not about this execution."""
    p = ev.payload if isinstance(ev.payload, dict) else {}
    if ev.topic == "progress" and p.get("execution_id") == eid:
        return Progress(eid, "progress", "running" if current.status in (None, "waiting") else current.status,
                        p.get("progress", current.progress), p.get("step", current.step),
                        p.get("measurements"), current.reason, event=ev)
    if ev.topic == "execution" and p.get("execution_id") == eid:
        return Progress(eid, "execution", p.get("status", current.status), current.progress, current.step,
                        reason=p.get("reason", current.reason), event=ev)
    if ev.topic == "operator":
        req = p.get("request") or {}
        if req.get("execution_id") == eid:
            return Progress(eid, "operator", current.status, current.progress, current.step,
                            reason=current.reason, request=dict(req, event=p.get("event")), event=ev)
    return None
