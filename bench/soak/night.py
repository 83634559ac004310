"""One night: a queue group (a sequence of the daemon's catalogue, or a list of campaigns) queued over the Unix socket
and started, followed to its end, with kill -9 of the daemon at the given moments (seconds after the start) and
the daemon restarted at once on the same state — the queue is durable, so the night goes on by itself."""
from __future__ import annotations

import time
import uuid

from lab import Lab, SoakError
from ledger import check_kills, group_ledger

ENDED = ("done", "failed")


def enqueue(lab: Lab, *, sequence: str | None = None, campaigns: list[dict] | None = None,
            small: bool = False, overrides: dict | None = None, on_failure: str = "continue") -> dict:
    """The night's work as queue items; returns {group_id or None, item ids}. An Idempotency-Key makes a retry after
    a restart return the same items rather than queue the night twice."""
    key = f"soak/{uuid.uuid4()}"
    if sequence:
        group = lab.call("POST", "/v1/queue", {"sequence": sequence, "small": small, "overrides": overrides or {},
                                               "on_failure": on_failure, "start": True},
                         headers={"Idempotency-Key": key})
        return {"group_id": group["id"], "items": [i["id"] for i in group["items"]]}
    items = []
    for n, c in enumerate(campaigns or []):
        item = lab.call("POST", "/v1/queue", {"campaign": c["campaign"], "params": c.get("params") or {},
                                              "on_failure": on_failure}, headers={"Idempotency-Key": f"{key}/{n}"})
        items.append(item["id"])
    lab.call("POST", "/v1/queue/start", {})
    return {"group_id": None, "items": items}


def status(lab: Lab, queued: dict) -> dict:
    """The night as one group-like document: {state, items: [{id, step, campaign, state, run_id, execution_id}]}."""
    if queued["group_id"]:
        return lab.call("GET", f"/v1/queue/groups/{queued['group_id']}")
    items = []
    for item_id in queued["items"]:
        item = lab.call("GET", f"/v1/queue/{item_id}")
        run_id = None
        if item.get("execution_id"):
            run_id = lab.call("GET", f"/v1/executions/{item['execution_id']}").get("run_id")
        items.append({**item, "step": item.get("step") or item["campaign"], "run_id": run_id})
    states = {i["state"] for i in items}
    state = "done" if states <= {"done"} else "failed" if states & {"failed", "skipped", "removed"} and \
        not states & {"queued", "running"} else "running"
    return {"state": state, "items": items}


def run_night(lab: Lab, night: int, queued: dict, kill_at: list[float], *, timeout: float,
              on_kill=None) -> dict:
    """Follows the night to its end, killing the daemon at each moment of ``kill_at`` that comes before it; at the
    end, checks that what every kill left committed is still there unchanged (ledger.check_kills)."""
    t0 = time.monotonic()
    pending = sorted(kill_at)
    kills = []
    while True:
        elapsed = time.monotonic() - t0
        if elapsed > timeout:
            raise SoakError(f"night {night} did not end in {timeout:.0f} s: {status(lab, queued)}\n"
                            f"{lab.daemon.log_text()}")
        if pending and elapsed >= pending[0]:
            pending.pop(0)
            doc = status(lab, queued)
            running = next((i for i in doc["items"] if i["state"] == "running"), None)
            step = None
            if running and running.get("execution_id"):
                step = lab.call("GET", f"/v1/executions/{running['execution_id']}").get("step")
            kill = lab.kill_and_restart({"night": night, "at_s": round(elapsed, 1),
                                         "item": running and running["step"], "execution_step": step})
            kills.append(kill)
            if on_kill:
                on_kill(kill)
            continue
        doc = status(lab, queued)
        # A group is "failed" as soon as one item failed; the night goes on (on_failure continue) until none runs.
        if doc["state"] in ENDED and not any(i["state"] in ("queued", "running") for i in doc["items"]):
            break
        time.sleep(0.5)
    wall = time.monotonic() - t0
    check_kills(lab.state / "colorlab.db", kills)
    return {"night": night, "state": doc["state"], "wall_s": round(wall, 1), "kills": kills,
            "missed_kills": pending, "items": [{k: i.get(k) for k in ("step", "campaign", "state", "run_id", "reason")}
                                               for i in doc["items"]],
            "ledger": group_ledger(lab.state / "colorlab.db", doc)}
