"""A run's measurements exported by the daemon: ``GET /v1/runs/{id}/export?format=ti3|csv|json``."""
from __future__ import annotations

import os
import re
from pathlib import Path

from .runs import run_id

FORMATS = ("ti3", "csv", "json")
_FILENAME = re.compile(r'filename="?([^";]+)"?')


class ExportsMixin:
    def export(self, run, format: str = "ti3", path: str | os.PathLike | None = None):
        """The export's bytes; with ``path`` written there instead (a directory: under the daemon's file name,
        from ``Content-Disposition``) and the file's path returned. ``.ti3`` is CGATS that ArgyllCMS reads."""
        if format not in FORMATS:
            raise ValueError(f"format must be one of {', '.join(FORMATS)}, got {format!r}")
        rid = run_id(run)
        r = self.conn.request("GET", f"/v1/runs/{rid}/export", params={"format": format})
        if path is None:
            return r.content
        target = Path(path)
        if target.is_dir():
            m = _FILENAME.search(r.headers.get("Content-Disposition", ""))
            # Only a bare name: a header is no place to choose a directory.
            name = os.path.basename(m.group(1)) if m else ""
            target = target / (name or f"{rid}.{format}")
        target.write_bytes(r.content)
        return target
