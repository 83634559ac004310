"""Errors: the daemon's RFC 9457 problem+json as one exception class per kind of refusal.

Catch ``colorlab.ApiError`` for anything the daemon refused, or a subclass (``NotFound``, ``Conflict`` …)
for one kind; ``ConnectionFailed`` when the daemon could not be reached at all.
"""
from __future__ import annotations

import json


class ColorlabError(Exception):
    """Base of every exception this package raises."""


class ConnectionFailed(ColorlabError):
    """The daemon could not be reached (not running, wrong URL, TLS refused, endpoint file missing)."""

    def __init__(self, message: str, hint: str = ""):
        super().__init__(message + (f" (hint: {hint})" if hint else ""))
        self.hint = hint


class IntegrityError(ColorlabError):
    """A blob's bytes do not hash to the name they were asked for by."""


class ExecutionFailed(ColorlabError):
    """An execution ended other than ``finished_ok`` (raised by ``wait``, not by ``follow``)."""

    def __init__(self, execution: dict):
        self.execution = execution
        status = execution.get("status")
        why = execution.get("reason") or (execution.get("error") or {}).get("detail") or ""
        super().__init__(f"execution {execution.get('id')} ended {status}" + (f": {why}" if why else ""))


class ApiError(ColorlabError):
    """The daemon answered with an error status. ``problem`` is the full problem+json body."""

    status_code: int | None = None  # the HTTP status a subclass stands for

    def __init__(self, status: int, problem: dict | None = None, *, method: str = "", url: str = ""):
        problem = problem or {}
        self.status = status
        self.problem = problem
        self.code = problem.get("code", "")
        self.title = problem.get("title", "")
        self.detail = problem.get("detail", "")
        self.hint = problem.get("hint", "")
        self.category = problem.get("category", "")
        self.type = problem.get("type", "")
        self.instance = problem.get("instance", "")
        self.method = method
        self.url = url
        text = f"{status} {self.title or 'error'}"
        if self.detail:
            text += f": {self.detail}"
        if self.hint:
            text += f" (hint: {self.hint})"
        if method or url:
            text += f" [{method} {url}]".replace("[ ", "[")
        super().__init__(text)


class BadRequest(ApiError):
    status_code = 400


class Unauthorized(ApiError):
    """401: no API key, or one the daemon does not know (unknown, revoked)."""

    status_code = 401


class Forbidden(ApiError):
    """403: the key's scope does not allow this (``read`` < ``control`` < ``admin``)."""

    status_code = 403


class NotFound(ApiError):
    status_code = 404


class MethodNotAllowed(ApiError):
    status_code = 405


class Conflict(ApiError):
    """409: the thing is in a state that cannot take this (an ended execution, the control lock held …)."""

    status_code = 409


class PayloadTooLarge(ApiError):
    status_code = 413


class UnsupportedMediaType(ApiError):
    status_code = 415


class RangeNotSatisfiable(ApiError):
    status_code = 416


class Unprocessable(ApiError):
    """422: understood but not possible (a campaign script failed; a run that cannot take the export format)."""

    status_code = 422


class ServerError(ApiError):
    """500: the daemon failed internally."""

    status_code = 500


class InstrumentError(ApiError):
    """502: an instrument failed or could not be reached (``category`` says which)."""

    status_code = 502


class ServiceUnavailable(ApiError):
    """503: storage refused (disk full, I/O error) or the daemon is not ready."""

    status_code = 503


_BY_STATUS = {c.status_code: c for c in (BadRequest, Unauthorized, Forbidden, NotFound, MethodNotAllowed, Conflict,
                                         PayloadTooLarge, UnsupportedMediaType, RangeNotSatisfiable, Unprocessable,
                                         ServerError, InstrumentError, ServiceUnavailable)}


def error_class(status: int) -> type[ApiError]:
    """The exception class for an HTTP status: exact when known, else by its hundred."""
    if status in _BY_STATUS:
        return _BY_STATUS[status]
    return ServerError if status >= 500 else ApiError


def problem_from_body(status: int, content_type: str, body: bytes, reason: str = "") -> dict:
    """The problem document of an error answer; a non-problem body (a proxy's HTML) becomes a minimal one."""
    if body and ("json" in (content_type or "")):
        try:
            doc = json.loads(body.decode("utf-8"))
            if isinstance(doc, dict):
                return doc
        except (ValueError, UnicodeDecodeError):
            pass
    text = body.decode("utf-8", "replace").strip() if body else ""
    return {"status": status, "title": reason or "HTTP error", "detail": text[:500]}


def api_error(status: int, content_type: str, body: bytes, *, reason: str = "", method: str = "",
              url: str = "") -> ApiError:
    problem = problem_from_body(status, content_type, body, reason)
    return error_class(status)(status, problem, method=method, url=url)
