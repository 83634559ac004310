"""Running ``colorlab analyze …`` (the C++ analysis library's command-line front end) from the report.

The binary is found the way the CLI finds this package, the other way round: ``COLORLAB_BIN`` (set by ``colorlab
report``/``colorlab study`` to the binary that runs them), else ``COLORLAB_BIN_DIR``/colorlab (the tests), else beside
this package's installation (``<prefix>/lib/python3/dist-packages`` → ``<prefix>/bin``) or its source tree
(``client/python`` → ``build/bin``), else ``colorlab`` on PATH.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

TIMEOUT_S = 300


class AnalyzeFailed(RuntimeError):
    """colorlab analyze could not be run, or refused its input."""


def colorlab_binary() -> Path:
    if os.environ.get("COLORLAB_BIN"):
        return Path(os.environ["COLORLAB_BIN"])
    if os.environ.get("COLORLAB_BIN_DIR"):
        return Path(os.environ["COLORLAB_BIN_DIR"]) / "colorlab"
    package = Path(__file__).resolve().parents[1]  # …/colorlab
    for candidate in (package.parents[3] / "bin" / "colorlab",  # <prefix>/lib/python3/dist-packages/colorlab
                      package.parents[2] / "build" / "bin" / "colorlab"):  # <source>/client/python/colorlab
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return candidate
    found = shutil.which("colorlab")
    if found:
        return Path(found)
    raise AnalyzeFailed("the colorlab binary was not found (set COLORLAB_BIN to it)")


def run_json(*args: str) -> dict:
    """``colorlab analyze ARGS… --json``: its tables as {name: [row, …]}."""
    cmd = [str(colorlab_binary()), "analyze", *args, "--json"]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S, env=dict(os.environ, LC_ALL="C"))
    except (OSError, subprocess.TimeoutExpired) as e:
        raise AnalyzeFailed(f"{' '.join(cmd[:3])}: {e}") from e
    if p.returncode != 0:
        raise AnalyzeFailed(f"{' '.join(cmd[:3])} exited {p.returncode}: {p.stderr.strip()}")
    return json.loads(p.stdout)


def write_chart(path: Path, ids, rgb, lab, xyz=None) -> Path:
    """A chart file `colorlab analyze` reads (CSV: id,R,G,B[,X,Y,Z],L,a,b), numbers at full precision."""
    cols = ["id", "R", "G", "B"] + (["X", "Y", "Z"] if xyz is not None else []) + ["L", "a", "b"]
    lines = [",".join(cols)]
    for k, i in enumerate(ids):
        values = list(rgb[k]) + (list(xyz[k]) if xyz is not None else []) + list(lab[k])
        if "," in str(i) or '"' in str(i):
            raise AnalyzeFailed(f"patch id {i!r} cannot be written to a chart file")
        lines.append(",".join([str(i)] + [repr(float(v)) for v in values]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
