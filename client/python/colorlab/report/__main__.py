"""python3 -m colorlab.report RUN_ID... [-o report.html] [--url URL | --socket PATH] [--key KEY] [--json]

Writes one self-contained HTML report of the stored runs and prints its path as the last line of stdout (with
--json: one JSON object instead, {"report": path, "runs": [...], "seconds": {"load", "render", "write", "total"}}).
Exit codes: 0 written, 2 bad usage, 3 a run not found or the daemon unreachable (with the reason on stderr).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import colorlab

EXIT_OK, EXIT_USAGE, EXIT_NOT_FOUND = 0, 2, 3


def parse(argv):
    p = argparse.ArgumentParser(prog="python3 -m colorlab.report",
                                description="Write an HTML report (tables beside the dissertation's, SVG plots) of stored runs.")
    p.add_argument("runs", nargs="+", metavar="RUN_ID", help="stored runs, in the order their sections appear")
    p.add_argument("-o", "--output", help="HTML file to write (default: report-<first run id>.html here)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--url", help="the daemon's URL (default: COLORLAB_URL, then the local daemon's endpoint file)")
    where.add_argument("--socket", help="the daemon's Unix socket (default: COLORLAB_SOCKET)")
    p.add_argument("--key", help="API key (default: COLORLAB_API_KEY); reading needs the read scope")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (the report's path, the runs, the timings) instead of the path")
    return p.parse_args(argv)


def main(argv=None) -> int:
    try:
        args = parse(sys.argv[1:] if argv is None else argv)
    except SystemExit as e:  # argparse: 0 for --help, 2 for bad usage
        return int(e.code or 0)
    from . import build
    started = time.monotonic()
    try:
        client = colorlab.Client.from_options(args.url, args.socket, args.key)
    except Exception as e:
        print(f"colorlab report: cannot reach the daemon: {e}", file=sys.stderr)
        return EXIT_NOT_FOUND
    try:
        runs = build.load_runs(client, args.runs)
    except colorlab.NotFound as e:
        print(f"colorlab report: run not found: {e.detail or e}", file=sys.stderr)
        return EXIT_NOT_FOUND
    except colorlab.ConnectionFailed as e:
        print(f"colorlab report: the daemon is not reachable ({client.url}): {e}", file=sys.stderr)
        return EXIT_NOT_FOUND
    except (colorlab.Unauthorized, colorlab.Forbidden) as e:
        print(f"colorlab report: the daemon refused: {e.title}: {e.detail} {e.hint or ''}".rstrip(), file=sys.stderr)
        return EXIT_NOT_FOUND
    except colorlab.BadRequest as e:
        print(f"colorlab report: {e.detail or e}", file=sys.stderr)
        return EXIT_USAGE
    finally:
        client.close()
    loaded = time.monotonic()
    out = Path(args.output or f"report-{args.runs[0]}.html")
    html = build.render(runs)
    rendered = time.monotonic()
    if out.parent and not out.parent.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".tmp")
    tmp.write_text(html, encoding="utf-8")
    os.replace(tmp, out)  # whole or not at all: a reader never sees half a report
    done = time.monotonic()
    if args.json:
        print(json.dumps({"report": str(out.resolve()), "runs": [{"id": r.id, "kind": build.fetch.kind_of(r),
                                                                  "campaign": r.campaign} for r in runs],
                          "bytes": out.stat().st_size,
                          "seconds": {"load": loaded - started, "render": rendered - loaded, "write": done - rendered,
                                      "total": done - started}}, indent=2))
    else:
        print(out.resolve())
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
