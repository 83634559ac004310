"""Running a study: its steps queued in the daemon's night queue, followed by the event stream, then reported.

The study's queue items are kept in a small JSON state file (study id, item id per step) and queued with an
``Idempotency-Key`` of ``colorlab-study/<study id>/<step>``: a re-run with ``--resume`` after this process or
the daemon was stopped finds its items again (the queue itself is durable and goes on by itself), and a retry
after a lost answer never queues a step twice.
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import sys
import time
import uuid

import colorlab

EXIT_OK, EXIT_USAGE, EXIT_DAEMON, EXIT_FAILED = 0, 2, 3, 4
ENDED_BAD = ("failed", "skipped", "removed")
PRINT_EVERY_S = 2.0


class StudyProblem(Exception):
    """The daemon or the study's bookkeeping: exit 3."""


class StudyFailed(Exception):
    """A campaign of the study failed or could not be queued: exit 4."""


def _duration(s: float | None) -> str:
    if s is None:
        return "?"
    s = int(round(s))
    h, rest = divmod(s, 3600)
    m, sec = divmod(rest, 60)
    return f"{h}h{m:02d}m{sec:02d}s" if h else f"{m}m{sec:02d}s" if m else f"{sec}s"


class Study:
    def __init__(self, client: colorlab.Client, name: str, steps: list[dict], *, state_file: str,
                 resume: bool = False, json_output: bool = False):
        self.client, self.name, self.steps, self.state_file = client, name, steps, state_file
        # With --json, stdout carries one JSON object at the end: progress goes to stderr.
        self.json_output = json_output
        self.started = time.monotonic()
        self.timings: dict = {}
        if resume:
            with open(state_file) as f:
                self.state = json.load(f)
            if self.state.get("study") != name:
                raise StudyProblem(f"{state_file} is the state of study {self.state.get('study')!r}, not {name!r}")
            # The steps as first queued: a resumed study keeps its parameters.
            self.steps = self.state.get("steps") or steps
        else:
            self.state = {"study": name, "id": str(uuid.uuid4()), "steps": steps, "items": {}, "runs": {}}
        self._progress: dict = {}  # execution id -> (first seen monotonic, its progress then)
        self._last_print = 0.0

    def _say(self, *a) -> None:
        print(*a, flush=True, file=sys.stderr if self.json_output else sys.stdout)

    def _emit(self, obj: dict) -> None:
        print(json.dumps(obj, indent=2), flush=True)

    # -- state ------------------------------------------------------------------------------------------
    def _save(self) -> None:
        tmp = f"{self.state_file}.tmp"
        with open(tmp, "w") as f:
            json.dump(self.state, f, indent=1)
        os.replace(tmp, self.state_file)

    def _params(self, step: dict) -> dict | None:
        """The step's parameters, with its reference filled in; None while the referenced run is not there."""
        params = dict(step["params"])
        ref = step.get("reference")
        if ref:
            run_id = self.state["runs"].get(ref["step"])
            if not run_id:
                return None
            params[ref["param"]] = run_id
        return params

    def _enqueue(self, step: dict, params: dict) -> dict:
        key = f"colorlab-study/{self.state['id']}/{step['name']}"
        body = {"campaign": step["campaign"], "params": params, "on_failure": "stop"}
        for attempt in range(3):
            try:
                item = self.client.conn.post("/v1/queue", body, headers={"Idempotency-Key": key})
                break
            except colorlab.ConnectionFailed:
                if attempt == 2:
                    raise
                time.sleep(1 + attempt)
            except (colorlab.BadRequest, colorlab.NotFound, colorlab.Unprocessable) as e:
                raise StudyFailed(f"campaign {step['name']} ({step['campaign']}) could not be queued: "
                                  f"{e.detail or e}") from e
        self.state["items"][step["name"]] = item["id"]
        self._save()
        self._say(f"study {self.name}: queued {step['name']} as item {item['id']} (position {item.get('position')})")
        return item

    # -- running ----------------------------------------------------------------------------------------
    def _queue_ready_steps(self) -> None:
        for step in self.steps:
            if step["name"] in self.state["items"]:
                continue
            params = self._params(step)
            if params is None:
                continue  # waits for its reference; the queue keeps order for the rest
            self._enqueue(step, params)

    def _check(self) -> dict | None:
        """Reads every item of the study; records the runs of the done ones; raises for a failed one.
        Returns the step that is not done yet (the first), or None when all are done."""
        pending = None
        for step in self.steps:
            item_id = self.state["items"].get(step["name"])
            if item_id is None:
                pending = pending or step
                continue
            item = self.client.conn.get(f"/v1/queue/{item_id}")
            if item["state"] == "done":
                if step["name"] not in self.state["runs"]:
                    ex = self.client.conn.get(f"/v1/executions/{item['execution_id']}")
                    self.state["runs"][step["name"]] = ex["run_id"]
                    self._save()
                    self._say(f"study {self.name}: {step['name']} finished ok: run {ex['run_id']}")
                continue
            if item["state"] in ENDED_BAD:
                problem = item.get("reason") or item["state"]
                if item.get("execution_id"):
                    ex = self.client.conn.get(f"/v1/executions/{item['execution_id']}")
                    err = ex.get("error")
                    if isinstance(err, dict):
                        err = err.get("detail") or err.get("title") or json.dumps(err)
                    problem = f"execution {ex['id']} {ex['status']}: {err or ex.get('reason') or problem}"
                self._drop_rest()
                raise StudyFailed(f"campaign {step['name']} ({step['campaign']}) of study {self.name} "
                                  f"{item['state']}: {problem}")
            pending = pending or {**step, "_item": item}
        return pending

    def _drop_rest(self) -> None:
        """After a failure the queue is halted: take the study's still-queued items out (kept in the history)."""
        for name, item_id in self.state["items"].items():
            with contextlib.suppress(colorlab.ColorlabError):
                if self.client.conn.get(f"/v1/queue/{item_id}")["state"] == "queued":
                    self.client.conn.delete(f"/v1/queue/{item_id}")
                    self._say(f"study {self.name}: removed {name} (item {item_id}) from the queue")

    def _progress_line(self, step: dict, progress: float, label: str, execution_id: str, force=False) -> None:
        now = time.monotonic()
        first = self._progress.setdefault(execution_id, (now, progress))
        if not force and now - self._last_print < PRINT_EVERY_S:
            return
        self._last_print = now
        eta = None
        if progress > first[1] and now > first[0]:
            eta = (now - first[0]) / (progress - first[1]) * (1 - progress)
        index = [s["name"] for s in self.steps].index(step["name"]) + 1
        self._say(f"[{index}/{len(self.steps)}] {step['name']:<20} {progress * 100:5.1f} %  "
                  f"ETA {_duration(eta):>8}  {label or ''}")

    def run(self) -> list[str]:
        """Queues the study, follows it to its end; returns the run ids in the study's order."""
        if self.state["items"]:
            self._say(f"study {self.name}: re-attaching to study {self.state['id']} ({self.state_file})")
        else:
            self._say(f"study {self.name} {self.state['id']}: {len(self.steps)} campaigns, state in {self.state_file}")
        self._save()
        events = self.client.events(give_up_after=300.0)
        try:
            snapshot = next(events)  # subscribed before the first look: nothing can slip between
            if snapshot.topic != "snapshot":
                raise StudyProblem(f"the event stream did not start with a snapshot: {snapshot.topic}")
            self._queue_ready_steps()
            queue = self.client.conn.get("/v1/queue")
            ours = set(self.state["items"].values())
            ahead = [i for i in queue.get("items") or [] if i["id"] not in ours]
            if ahead:
                self._say(f"study {self.name}: {len(ahead)} other queue item(s) run first: "
                          f"{', '.join(i['campaign'] for i in ahead)}")
            if queue.get("state") != "running":
                # A running queue starts an item as soon as it is queued: one of ours may already have failed and
                # halted it, and starting the queue would clear that halt. Look first.
                self._check()
                self.client.conn.post("/v1/queue/start")
                self._say(f"study {self.name}: queue started")
            current = None
            while True:
                pending = self._check()
                if pending is None:
                    break
                self._queue_ready_steps()
                item = pending.get("_item") or {}
                if item.get("execution_id") and (current is None or current[1] != item["execution_id"]):
                    current = (pending, item["execution_id"])
                    ex = self.client.conn.get(f"/v1/executions/{item['execution_id']}")
                    self._progress_line(pending, ex.get("progress") or 0.0, ex.get("step") or "started",
                                        ex["id"], force=True)
                # Wait for something about the study: its queue items, its running execution's progress.
                for ev in events:
                    if ev.topic == "progress" and current and ev.payload.get("execution_id") == current[1]:
                        self._progress_line(current[0], float(ev.payload.get("progress") or 0.0),
                                            ev.payload.get("step") or "", current[1])
                        continue
                    if ev.topic in ("queue", "execution"):
                        break
                else:  # the stream ended (the daemon said stop): look again in a moment on a fresh one
                    events.close()
                    time.sleep(1.0)
                    events = self.client.events(give_up_after=300.0)
        except colorlab.ConnectionFailed as e:
            raise StudyProblem(f"lost the daemon ({self.client.url}): {e}; the queue goes on — re-attach with "
                               f"--resume --state-file {self.state_file}") from e
        finally:
            events.close()
        self.timings["campaigns"] = time.monotonic() - self.started
        return [self.state["runs"][s["name"]] for s in self.steps]

    def report(self, run_ids: list[str], args) -> int:
        from ..report.__main__ import main as report_main
        argv = list(run_ids)
        if args.output:
            argv += ["-o", args.output]
        if args.url:
            argv += ["--url", args.url]
        elif args.socket:
            argv += ["--socket", args.socket]
        elif self.client.socket:
            argv += ["--socket", self.client.socket]
        else:
            argv += ["--url", self.client.url]
        if args.key:
            argv += ["--key", args.key]
        if self.json_output:
            argv.append("--json")
        self._say(f"study {self.name}: all {len(run_ids)} campaigns finished ok; writing the report of "
                  f"{' '.join(run_ids)}")
        started = time.monotonic()
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rc = report_main(argv)
        lines = out.getvalue().splitlines()
        if rc != 0 or not lines:
            print(f"colorlab study: the report failed (exit {rc})", file=sys.stderr)
            return EXIT_DAEMON
        self.timings["report"] = time.monotonic() - started
        if self.json_output:
            written = json.loads(out.getvalue())
            self._say(f"study {self.name}: report written in {self.timings['report']:.1f} s")
            self._emit({"study": self.name, "id": self.state["id"], "state_file": os.path.abspath(self.state_file),
                        "runs": {s["name"]: self.state["runs"][s["name"]] for s in self.steps},
                        "run_ids": run_ids, "report": written["report"],
                        "seconds": {**self.timings, "report_detail": written["seconds"],
                                    "total": time.monotonic() - self.started}})
            return EXIT_OK
        for line in lines[:-1]:
            self._say(line)
        self._say(f"study {self.name}: report written in {self.timings['report']:.1f} s")
        self._say(lines[-1])
        return EXIT_OK

    # -- dry run ----------------------------------------------------------------------------------------
    def dry_run(self) -> int:
        total, problems, estimates = 0.0, [], []
        for step in self.steps:
            params = self._params(step)
            if params is None:
                ref = step["reference"]
                found = self._latest_run(self.steps_by_name()[ref["step"]]["campaign"])
                if not found:
                    self._say(f"{step['name']:<20} not estimated: needs a finished {ref['step']} run "
                              f"(the study's own, once it ran)")
                    estimates.append({"step": step["name"], "campaign": step["campaign"], "estimated": False,
                                      "reason": f"needs a finished {ref['step']} run"})
                    continue
                params = {**step["params"], ref["param"]: found}
            try:
                r = self.client.dry_run(step["campaign"], params=params)
            except (colorlab.BadRequest, colorlab.NotFound, colorlab.Unprocessable) as e:
                raise StudyFailed(f"campaign {step['name']} ({step['campaign']}): {e.detail or e}") from e
            est = r.get("estimate") or {}
            wall = float(est.get("wall_seconds") or 0.0)
            total += wall
            share = est.get("measured_share")
            self._say(f"{step['name']:<20} {_duration(wall):>9} wall ({_duration(est.get('lab_seconds'))} lab at "
                      f"time scale {est.get('time_scale')}; measured share "
                      f"{'?' if share is None else f'{share * 100:.0f} %'})  {'ok' if r.get('ok') else 'PROBLEMS'}")
            estimates.append({"step": step["name"], "campaign": step["campaign"], "estimated": True,
                              "wall_seconds": wall, "lab_seconds": est.get("lab_seconds"),
                              "time_scale": est.get("time_scale"), "measured_share": share, "ok": bool(r.get("ok")),
                              "problems": r.get("problems") or []})
            for p in r.get("problems") or []:
                problems.append(f"{step['name']}: {p.get('kind')}: {p.get('message')}")
                self._say(f"  problem: {p.get('kind')}: {p.get('message')}")
        self._say(f"study {self.name}: estimated total {_duration(total)} ({total:.0f} s wall)")
        if self.json_output:
            self._emit({"study": self.name, "dry_run": True, "steps": estimates, "total_wall_seconds": total,
                        "ok": not problems, "seconds": {"total": time.monotonic() - self.started}})
        if problems:
            print("colorlab study: the dry run found problems:\n  " + "\n  ".join(problems), file=sys.stderr)
            return EXIT_FAILED
        return EXIT_OK

    def steps_by_name(self) -> dict:
        return {s["name"]: s for s in self.steps}

    def _latest_run(self, campaign: str) -> str | None:
        for run in self.client.conn.paged("/v1/runs", max_items=200):
            if run.get("campaign") == campaign and run.get("status") == "finished_ok":
                return run["id"]
        return None
