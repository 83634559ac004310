"""Blobs (frames, raw files, previews) from the content-addressed store: ``GET``/``HEAD /v1/blobs/{sha256}``.

Raw arrays carry their numpy dtype, shape and CFA pattern in ``X-Colorlab-Dtype``, ``X-Colorlab-Shape`` and
``X-Colorlab-Cfa``; ``Range`` reads a part (a band of rows) without fetching the whole frame.
"""
from __future__ import annotations

import hashlib
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import ColorlabError, IntegrityError
from .runs import run_id
from . import tables

_CONTENT_RANGE = re.compile(r"bytes (\d+)-(\d+)/(\d+|\*)")
_SHA256 = re.compile(r"[0-9a-f]{64}")


@dataclass(frozen=True)
class BlobInfo:
    sha256: str
    size: int
    media_type: str
    etag: str | None
    dtype: np.dtype | None  # None unless the blob is a raw array
    shape: tuple[int, ...] | None
    cfa: str | None  # e.g. "RGGB" for a Bayer mosaic
    accept_ranges: bool

    @property
    def is_array(self) -> bool:
        return self.dtype is not None and self.shape is not None


def blob_sha(blob) -> str:
    """The sha256 from the digest itself, a ``blobs()`` row or listing item, or a ``BlobInfo``."""
    if isinstance(blob, str):
        return blob
    if isinstance(blob, BlobInfo):
        return blob.sha256
    try:
        return blob["sha256"]
    except (KeyError, TypeError, IndexError):
        raise TypeError(f"expected a blob's sha256 or a blob listing entry, got {type(blob).__name__}") from None


def _info(sha: str, headers) -> BlobInfo:
    dtype = headers.get("X-Colorlab-Dtype")
    shape = headers.get("X-Colorlab-Shape")
    size = headers.get("Content-Length")
    m = _CONTENT_RANGE.fullmatch(headers.get("Content-Range", ""))
    if m and m.group(3) != "*":
        size = m.group(3)  # a 206 carries the part's length; the whole is after the slash
    return BlobInfo(sha256=sha, size=int(size) if size is not None else -1,
                    media_type=headers.get("Content-Type", "application/octet-stream"),
                    etag=headers.get("ETag"), dtype=np.dtype(dtype) if dtype else None,
                    shape=tuple(int(x) for x in shape.split(",") if x.strip()) if shape else None,
                    cfa=headers.get("X-Colorlab-Cfa") or None,
                    accept_ranges=headers.get("Accept-Ranges", "").lower() == "bytes")


def _range_header(start: int | None, stop: int | None) -> str | None:
    if start is None and stop is None:
        return None
    start = start or 0
    if start < 0 or (stop is not None and stop <= start):
        raise ValueError(f"byte range [{start}, {stop}) is empty or negative")
    return f"bytes={start}-" + ("" if stop is None else str(stop - 1))


class BlobsMixin:
    def blobs(self, run) -> pd.DataFrame:
        """A run's blobs: ``name, sha256, kind, step, media_type, size, meta, links``."""
        doc = self.conn.get(f"/v1/runs/{run_id(run)}/blobs")
        return tables.items_frame(doc.get("items", []))

    def blob_info(self, blob) -> BlobInfo:
        """What a blob is, from ``HEAD`` (no body is sent)."""
        sha = blob_sha(blob)
        r = self.conn.request("HEAD", f"/v1/blobs/{sha}")
        r.close()
        return _info(sha, r.headers)

    def read_blob(self, blob, start: int | None = None, stop: int | None = None, *,
                  path: str | os.PathLike | None = None):
        """A blob's bytes, or bytes ``[start, stop)`` of it through ``Range``. A whole blob is checked against
        its sha256 name. With ``path``, the bytes stream into that file (a directory: named by the sha256)
        and the path is returned."""
        sha = blob_sha(blob)
        rng = _range_header(start, stop)
        r = self.conn.request("GET", f"/v1/blobs/{sha}", headers={"Range": rng} if rng else None,
                              stream=True)
        try:
            whole = r.status_code == 200
            if rng and r.status_code == 206:
                m = _CONTENT_RANGE.fullmatch(r.headers.get("Content-Range", ""))
                if not m or int(m.group(1)) != (start or 0):
                    raise ColorlabError(f"blob {sha}: asked for {rng}, got Content-Range "
                                        f"{r.headers.get('Content-Range')!r}")
            check = hashlib.sha256() if whole and _SHA256.fullmatch(sha) else None
            skip = (start or 0) if (rng and whole) else 0  # a server may ignore Range: cut the part here
            want = None if stop is None else stop - (start or 0)
            if path is not None:
                target = Path(path)
                if target.is_dir():
                    target = target / sha
                tmp = target.with_name(target.name + ".part")
                with open(tmp, "wb") as out:
                    for piece in self._pieces(r, check, skip, want):
                        out.write(piece)
                self._verify(sha, check)
                os.replace(tmp, target)
                return target
            data = b"".join(self._pieces(r, check, skip, want))
            self._verify(sha, check)
            return data
        finally:
            r.close()

    @staticmethod
    def _pieces(r, check, skip: int, want: int | None):
        for chunk in r.iter_content(1 << 20):
            if check is not None:
                check.update(chunk)
            if skip:
                cut = min(skip, len(chunk))
                chunk, skip = chunk[cut:], skip - cut
            if want is not None:
                chunk, want = chunk[:want], want - min(want, len(chunk))
            if chunk:
                yield chunk

    @staticmethod
    def _verify(sha: str, check) -> None:
        if check is not None and check.hexdigest() != sha:
            raise IntegrityError(f"blob {sha} arrived as bytes hashing to {check.hexdigest()}")

    def read_array(self, blob, rows: slice | tuple[int, int] | None = None) -> np.ndarray:
        """A raw-array blob (a frame) as an ndarray of its dtype and shape. ``rows=(a, b)`` or ``slice(a, b)``
        fetches only rows a..b-1 through ``Range``. The CFA pattern is in ``blob_info(blob).cfa``."""
        sha = blob_sha(blob)
        if rows is None:
            r = self.conn.request("GET", f"/v1/blobs/{sha}")
            info = _info(sha, r.headers)
            self._need_array(info)
            data = r.content
            if _SHA256.fullmatch(sha):
                self._verify(sha, hashlib.sha256(data))
            return self._shape(data, info.dtype, info.shape, sha)
        info = self.blob_info(sha)
        self._need_array(info)
        first, last = (rows.start, rows.stop) if isinstance(rows, slice) else rows
        if isinstance(rows, slice) and rows.step not in (None, 1):
            raise ValueError("rows must be a contiguous slice")
        n = info.shape[0]
        first, last, _ = slice(first, last).indices(n)
        if last <= first:
            return np.empty((0,) + info.shape[1:], dtype=info.dtype)
        row_bytes = int(np.prod(info.shape[1:], dtype=np.int64)) * info.dtype.itemsize
        data = self.read_blob(sha, first * row_bytes, last * row_bytes)
        return self._shape(data, info.dtype, (last - first,) + info.shape[1:], sha)

    @staticmethod
    def _need_array(info: BlobInfo) -> None:
        if not info.is_array:
            raise ColorlabError(f"blob {info.sha256} ({info.media_type}) is not a raw array "
                                "(no X-Colorlab-Dtype/Shape); read_blob() gives its bytes")

    @staticmethod
    def _shape(data: bytes, dtype: np.dtype, shape: tuple[int, ...], sha: str) -> np.ndarray:
        expected = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        if len(data) != expected:
            raise ColorlabError(f"blob {sha}: {len(data)} bytes for shape {shape} of {dtype} ({expected} bytes)")
        # bytearray: a writable array (frombuffer over bytes is read-only), at the cost of one copy.
        return np.frombuffer(bytearray(data), dtype=dtype).reshape(shape)

    def locate_chart(self, blob, chart: str = "sg", *, corners=None, reference_run=None,
                     sample_fraction: float | None = None, min_confidence: float | None = None) -> dict:
        """Find the chart in a kept photograph (``POST /v1/blobs/{sha256}/locate-chart``): its corners, confidence,
        orientation and every patch's centre and robust value, as ``colorlab locate-chart --json`` prints them.

        ``corners`` are the operator's four ``(x, y)`` (A1's corner first, clockwise) when the locator is unsure;
        ``reference_run`` a chart-read run whose luminances tell light patches from the chart's surround. A refusal
        raises ``Unprocessable`` whose ``code`` is ``chart-not-found`` or ``chart-needs-corners`` and whose
        ``hint`` says how to give corners."""
        body: dict = {"chart": chart}
        if corners is not None:
            body["corners"] = [[float(x), float(y)] for x, y in corners]
        if reference_run is not None:
            body["reference_run"] = run_id(reference_run)
        if sample_fraction is not None:
            body["sample_fraction"] = sample_fraction
        if min_confidence is not None:
            body["min_confidence"] = min_confidence
        return self.conn.post(f"/v1/blobs/{blob_sha(blob)}/locate-chart", body)

    def preview(self, blob) -> bytes:
        """A frame's PNG preview (``IPython.display.Image(client.preview(sha))`` shows it)."""
        return self.conn.request("GET", f"/v1/blobs/{blob_sha(blob)}/preview.png").content
