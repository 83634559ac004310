"""colorlab: colorlabd's data from Python — runs and measurements as pandas DataFrames, spectra and frames as
numpy arrays, live progress from the event stream, campaigns started and followed. See docs/python-client.md.

    import colorlab
    lab = colorlab.Client.local()          # or colorlab.Client("https://lab:8765", key=..., cacert=...)
    df = lab.measurements(lab.runs(limit=1).id[0])
"""
from .blobs import BlobInfo
from .client import Client
from .errors import (ApiError, BadRequest, ColorlabError, Conflict, ConnectionFailed, ExecutionFailed, Forbidden,
                     InstrumentError, IntegrityError, MethodNotAllowed, NotFound, PayloadTooLarge,
                     RangeNotSatisfiable, Unprocessable, ServerError, ServiceUnavailable, Unauthorized,
                     UnsupportedMediaType)
from .events import Event
from .executions import TERMINAL, Execution, Progress
from .runs import Run
from .sse import SseEvent, SseParser
from .verify import VerifyFailed

__version__ = "0.1.0"

__all__ = [
    "Client", "Run", "Execution", "Progress", "Event", "BlobInfo", "SseParser", "SseEvent", "TERMINAL",
    "ColorlabError", "ConnectionFailed", "IntegrityError", "ExecutionFailed", "ApiError", "BadRequest",
    "Unauthorized", "Forbidden", "NotFound", "MethodNotAllowed", "Conflict", "PayloadTooLarge",
    "UnsupportedMediaType", "RangeNotSatisfiable", "Unprocessable", "ServerError", "InstrumentError",
    "ServiceUnavailable", "VerifyFailed",
]
