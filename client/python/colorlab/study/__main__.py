"""python3 -m colorlab.study dissertation [--url URL | --socket PATH] [--key KEY] [-o report.html] [--dry-run]
                                        [--small] [--set STEP.KEY=VALUE …] [--state-file FILE] [--resume] [--json]

Queues the study — the daemon's sequence STUDY (GET /v1/campaigns, kind "sequence"; the one definition of its steps) —
as one group in the night queue, where it runs to its end whatever happens to this process (or to colorlabd: the
queue is durable); follows the group by the event stream printing progress lines, then writes the report of all
the study's runs; the report's
path is the last line of stdout. With --json the progress lines go to stderr and stdout is one JSON object: the
study's runs by step, the report's path and the timings (a dry run: each step's estimate). Exit codes: 0 ok, 2 usage, 3 daemon/run problem, 4 a campaign of the study
failed (named, with its problem on stderr).
"""
from __future__ import annotations

import argparse
import json
import os
import sys

import colorlab

from . import definition
from .runner import EXIT_DAEMON, EXIT_FAILED, EXIT_OK, EXIT_USAGE, Study, StudyFailed, StudyProblem


def parse(argv):
    p = argparse.ArgumentParser(prog="python3 -m colorlab.study",
                                description="Run a built-in study (its campaigns through the night queue) and write its report.")
    p.add_argument("study", help="the study: a sequence of the daemon's catalogue, e.g. dissertation")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--url", help="the daemon's URL (default: COLORLAB_URL, then the local daemon's endpoint file)")
    where.add_argument("--socket", help="the daemon's Unix socket (default: COLORLAB_SOCKET)")
    p.add_argument("--key", help="API key (default: COLORLAB_API_KEY); needs the control scope (the queue)")
    p.add_argument("-o", "--output", help="the report's HTML file (default: report-<first run id>.html here)")
    p.add_argument("--dry-run", action="store_true",
                   help="post each campaign's dry run and print the estimated total duration; nothing is queued")
    p.add_argument("--small", action="store_true", help="a reduced study (tests, a first look): smaller grid, fewer frames")
    p.add_argument("--set", action="append", default=[], metavar="STEP.KEY=VALUE",
                   help="override one parameter of one step (VALUE as JSON, else a string), e.g. cabinet-grid.rows=4")
    p.add_argument("--state-file", help="where the study keeps its queue group (default: ./colorlab-study-STUDY.json)")
    p.add_argument("--resume", action="store_true",
                   help="re-attach to the study in --state-file (after this command or the daemon was stopped)")
    p.add_argument("--json", action="store_true",
                   help="progress on stderr; stdout one JSON object (runs, report path, timings) at the end")
    args = p.parse_args(argv)
    overrides: dict = {}
    for item in args.set:
        key, eq, raw = item.partition("=")
        step, dot, param = key.partition(".")
        if not eq or not dot or not step or not param:
            p.error(f"--set {item!r}: expected STEP.KEY=VALUE (colorlab campaigns lists the study's steps)")
        try:
            value = json.loads(raw)
        except ValueError:
            value = raw
        overrides.setdefault(step, {})[param] = value
    args.overrides = overrides
    args.state_file = args.state_file or f"colorlab-study-{args.study}.json"
    if args.resume and not os.path.exists(args.state_file):
        p.error(f"--resume: no study state in {args.state_file}")
    return args


def main(argv=None) -> int:
    try:
        args = parse(sys.argv[1:] if argv is None else argv)
    except SystemExit as e:  # argparse: 0 for --help, 2 for bad usage
        return int(e.code or 0)
    try:
        client = colorlab.Client.from_options(args.url, args.socket, args.key)
    except Exception as e:
        print(f"colorlab study: cannot reach the daemon: {e}", file=sys.stderr)
        return EXIT_DAEMON
    try:
        try:
            steps = definition.steps(definition.sequence(client, args.study), small=args.small,
                                     overrides=args.overrides)
        except definition.UnknownStudy as e:
            print(f"colorlab study: {e}", file=sys.stderr)
            return EXIT_USAGE
        study = Study(client, args.study, steps, state_file=args.state_file, resume=args.resume,
                      json_output=args.json, small=args.small, overrides=args.overrides)
        if args.dry_run:
            return study.dry_run()
        run_ids = study.run()
        return study.report(run_ids, args)
    except StudyFailed as e:
        print(f"colorlab study: {e}", file=sys.stderr)
        return EXIT_FAILED
    except StudyProblem as e:
        print(f"colorlab study: {e}", file=sys.stderr)
        return EXIT_DAEMON
    except (colorlab.Unauthorized, colorlab.Forbidden) as e:
        print(f"colorlab study: the daemon refused the key: {e}", file=sys.stderr)
        return EXIT_DAEMON
    except colorlab.ColorlabError as e:
        print(f"colorlab study: {client.url}: {e}", file=sys.stderr)
        return EXIT_DAEMON
    except KeyboardInterrupt:
        print(f"colorlab study: interrupted; the queue goes on — re-attach with --resume --state-file {args.state_file}",
              file=sys.stderr)
        return 130
    finally:
        client.close()


if __name__ == "__main__":
    sys.exit(main())
