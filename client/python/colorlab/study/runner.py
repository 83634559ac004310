"""Running a study: its sequence queued in the daemon's night queue as one group, followed by the event stream, then
reported.

The daemon queues every step at once (POST /v1/queue {"sequence": ..., "start": true}); a step that takes an earlier
step's run gets it from the daemon when it comes up ({"$run_of": item}), so the night completes whatever happens to
this process. A small JSON state file keeps the study's id and its group; the group is queued with an
``Idempotency-Key`` of ``colorlab-study/<study id>``, so a re-run with ``--resume`` re-attaches to the group (or, if
this process died before it saw the answer, gets the same group back) and never queues the study twice.
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
                 resume: bool = False, json_output: bool = False, small: bool = False,
                 overrides: dict | None = None):
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
        else:
            self.state = {"study": name, "id": str(uuid.uuid4()), "small": small, "overrides": overrides or {},
                          "group": None, "items": {}, "runs": {}}
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

    def _enqueue(self) -> dict:
        """The study's sequence queued as one group, the queue started in the same request."""
        body = {"sequence": self.name, "small": bool(self.state.get("small")),
                "overrides": self.state.get("overrides") or {}, "on_failure": "stop", "start": True}
        key = f"colorlab-study/{self.state['id']}"
        for attempt in range(3):
            try:
                group = self.client.conn.post("/v1/queue", body, headers={"Idempotency-Key": key})
                break
            except colorlab.ConnectionFailed:
                if attempt == 2:
                    raise
                time.sleep(1 + attempt)
            except (colorlab.BadRequest, colorlab.NotFound, colorlab.Unprocessable) as e:
                raise StudyFailed(f"study {self.name} could not be queued: {e.detail or e}") from e
        self._remember(group)
        self._say(f"study {self.name}: queued its {len(group['items'])} campaigns as group {group['id']} "
                  f"(the daemon runs them; this process only follows)")
        return group

    def _remember(self, group: dict) -> None:
        self.state["group"] = group["id"]
        self.state["items"] = {i["step"]: i["id"] for i in group["items"]}
        self.state["steps"] = [i["step"] for i in group["items"]]
        self._save()

    def _group(self) -> dict:
        group = self.client.conn.get(f"/v1/queue/groups/{self.state['group']}")
        for item in group["items"]:  # in the study's order
            step, run_id = item["step"], item.get("run_id")
            if item["state"] == "done" and step not in self.state["runs"]:
                self.state["runs"][step] = run_id
                self._save()
                self._say(f"study {self.name}: {step} finished ok: run {run_id}")
        return group

    def _failure(self, group: dict) -> StudyFailed:
        """The first item of the group that ended badly, with its execution's problem."""
        item = next(i for i in group["items"] if i["state"] in ("failed", "skipped", "removed"))
        problem = item.get("reason") or item["state"]
        if item.get("execution_id"):
            ex = self.client.conn.get(f"/v1/executions/{item['execution_id']}")
            err = ex.get("error")
            if isinstance(err, dict):
                err = err.get("detail") or err.get("title") or json.dumps(err)
            problem = f"execution {ex['id']} {ex['status']}: {err or ex.get('reason') or problem}"
        return StudyFailed(f"campaign {item['step']} ({item['campaign']}) of study {self.name} {item['state']}: "
                           f"{problem}")

    def _drop_rest(self, group: dict) -> None:
        """After a failure the queue is halted: take the study's still-queued items out (kept in the history)."""
        for item in group["items"]:
            if item["state"] == "queued":
                with contextlib.suppress(colorlab.ColorlabError):
                    self.client.conn.delete(f"/v1/queue/{item['id']}")
                    self._say(f"study {self.name}: removed {item['step']} (item {item['id']}) from the queue")

    def _progress_line(self, step: str, progress: float, label: str, execution_id: str, force=False) -> None:
        now = time.monotonic()
        first = self._progress.setdefault(execution_id, (now, progress))
        if not force and now - self._last_print < PRINT_EVERY_S:
            return
        self._last_print = now
        eta = None
        if progress > first[1] and now > first[0]:
            eta = (now - first[0]) / (progress - first[1]) * (1 - progress)
        names = self.state.get("steps") or [s["name"] for s in self.steps]
        self._say(f"[{names.index(step) + 1}/{len(names)}] {step:<20} {progress * 100:5.1f} %  "
                  f"ETA {_duration(eta):>8}  {label or ''}")

    # -- running ----------------------------------------------------------------------------------------
    def run(self) -> list[str]:
        """Queues the study (or re-attaches to its group), follows it to its end; returns the run ids in order."""
        if self.state.get("group"):
            self._say(f"study {self.name}: re-attaching to study {self.state['id']}, group {self.state['group']} "
                      f"({self.state_file})")
        else:
            self._say(f"study {self.name} {self.state['id']}: state in {self.state_file}")
        self._save()  # the study's id (its idempotency key) is on disk before anything is queued
        events = self.client.events(give_up_after=300.0)
        try:
            snapshot = next(events)  # subscribed before the first look: nothing can slip between
            if snapshot.topic != "snapshot":
                raise StudyProblem(f"the event stream did not start with a snapshot: {snapshot.topic}")
            if not self.state.get("group"):
                self._enqueue()  # (again, after a kill before the answer: the same key returns the same group)
            group = self._group()
            ours = [i["position"] for i in group["items"] if i["state"] == "queued"]
            ahead = [i for i in self.client.conn.get("/v1/queue").get("items") or []
                     if i.get("group_id") != group["id"] and (i["state"] == "running" or
                                                              (ours and (i.get("position") or 0) < min(ours)))]
            if ahead:
                self._say(f"study {self.name}: {len(ahead)} other queue item(s) run first: "
                          f"{', '.join(i['campaign'] for i in ahead)}")
            current = None
            while True:
                group = self._group()
                if group["state"] == "done":
                    break
                if group["state"] == "failed":
                    failure = self._failure(group)
                    self._drop_rest(group)
                    raise failure
                running = next((i for i in group["items"] if i["state"] == "running" and i.get("execution_id")), None)
                if running and (current is None or current[1] != running["execution_id"]):
                    current = (running["step"], running["execution_id"])
                    ex = self.client.conn.get(f"/v1/executions/{running['execution_id']}")
                    self._progress_line(current[0], ex.get("progress") or 0.0, ex.get("step") or "started",
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
        return list(group["run_ids"])

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
                        "group": self.state["group"],
                        "runs": {step: self.state["runs"][step] for step in self.state["steps"]},
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
            params = dict(step["params"])
            ref = step.get("reference")
            if ref:
                # The study's own run of the referenced step is not there before the study ran: the latest finished
                # run of that campaign stands in for it (the estimate does not depend on which run it is).
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
