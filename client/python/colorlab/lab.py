"""The lab's state and the night: daemon status, instruments, campaigns, the queue, operator requests."""
from __future__ import annotations

import uuid
from typing import Any

import pandas as pd

from . import tables


# GET /v1/lab/lenses' fields (docs/API.md), the columns of an empty lenses() frame.
LENS_COLUMNS = ["name", "camera", "lens", "focal_length_mm", "focus", "width_px", "height_px", "fx", "fy", "cx", "cy", "k1",
                "k2", "sigma.fx", "sigma.fy", "sigma.cx", "sigma.cy", "sigma.k1", "sigma.k2", "rms_px", "photographs",
                "points", "source", "date"]


def _item_id(item) -> str:
    return item if isinstance(item, str) else item["id"]


class LabMixin:
    def status(self) -> dict:
        """``GET /v1``: server version, API version, whether the lab is simulated, features, limits."""
        return self.conn.get("/v1")

    def instruments(self) -> pd.DataFrame:
        return tables.items_frame(self.conn.get("/v1/instruments").get("items", []))

    def lenses(self) -> pd.DataFrame:
        """``GET /v1/lab/lenses``: the lab's lens calibrations, as colorlabd's configuration holds them (``[[lens]]``;
        docs/verify.md "The lens calibration"), one row each — ``name``, ``camera``, ``lens``, ``focal_length_mm``,
        ``focus``, ``width_px``, ``height_px``, ``fx``, ``fy``, ``cx``, ``cy``, ``k1``, ``k2`` (pixels, OpenCV's model),
        their one-σ uncertainties as ``sigma.fx`` … ``sigma.k2``, ``rms_px``, ``photographs``, ``points``, ``source``,
        ``date``. No calibration configured: an empty frame with those columns."""
        items = self.conn.get("/v1/lab/lenses").get("items", [])
        rows = []
        for item in items:
            row = {k: v for k, v in item.items() if k != "sigma"}
            row.update(tables.flatten_data(item.get("sigma") or {}, "sigma"))
            rows.append(row)
        return pd.DataFrame(rows, columns=None if rows else LENS_COLUMNS)

    def campaigns(self) -> pd.DataFrame:
        """The campaigns the daemon can run (re-read on every call), with their parameter declarations."""
        return tables.items_frame(self.conn.get("/v1/campaigns").get("items", []))

    # The night's queue: campaigns that run one after another, across restarts.
    def queue(self, history: int | None = None) -> dict:
        """``{state, reason, halted, autostart, current, waiting_for, items[], history[]}``."""
        return self.conn.get("/v1/queue", {"history": history})

    def queue_items(self) -> pd.DataFrame:
        """The running item, then the queued ones by position."""
        return tables.items_frame(self.queue().get("items", []),
                                  ("created_at", "updated_at", "started_at", "finished_at"))

    def enqueue(self, campaign: str, *, on_failure: str = "stop", idempotency_key: str | None = None,
                params: dict | None = None, **kwargs: Any) -> dict:
        body_params = dict(params or {})
        body_params.update(kwargs)
        return self.conn.post("/v1/queue", {"campaign": campaign, "params": body_params, "on_failure": on_failure},
                              headers={"Idempotency-Key": idempotency_key or f"python-{uuid.uuid4()}"})

    def dequeue(self, item) -> dict:
        return self.conn.delete(f"/v1/queue/{_item_id(item)}")

    def move(self, item, position: int) -> dict:
        return self.conn.post(f"/v1/queue/{_item_id(item)}/move", {"position": position})

    def start_queue(self) -> dict:
        return self.conn.post("/v1/queue/start")

    def stop_queue(self) -> dict:
        return self.conn.post("/v1/queue/stop")

    # Operator requests: a campaign waiting for a person (load a chart, aim the meter …).
    def requests(self) -> list[dict]:
        """Open operator requests: ``{id, execution_id, action, prompt, options, default, deadline, …}``."""
        return self.conn.get("/v1/requests").get("items", [])

    def answer(self, request, answer: str, by: str | None = None) -> dict:
        body = {"answer": answer}
        if by:
            body["by"] = by
        return self.conn.post(f"/v1/requests/{_item_id(request)}", body)
