"""Runs and their measurements: ``GET /v1/runs``, ``/v1/runs/{id}`` and the paged ``/measurements``."""
from __future__ import annotations

from typing import Iterator

import pandas as pd

from . import tables

MEASUREMENT_PAGE = 1000  # protocol::kDefaultMeasurementPageLimit (at most kMaxMeasurementPageLimit, 5000)


def run_id(run) -> str:
    """A run's id from the id itself, a ``Run`` or any dict with ``id`` (an execution gives its ``run_id``)."""
    if isinstance(run, str):
        return run
    if isinstance(getattr(run, "run_id", None), str):  # an Execution
        return run.run_id
    if isinstance(run, dict):
        return run["id"]
    raise TypeError(f"expected a run id or a run, got {type(run).__name__}")


class Run(dict):
    """``GET /v1/runs/{id}`` (a dict), with its data a method away: ``run.measurements()`` …"""

    def __init__(self, client, doc: dict):
        super().__init__(doc)
        self._client = client

    @property
    def id(self) -> str:
        return self["id"]

    def measurements(self, **filters) -> pd.DataFrame:
        return self._client.measurements(self.id, **filters)

    def spectra(self, **filters) -> pd.DataFrame:
        return self._client.spectra(self.id, **filters)

    def blobs(self) -> pd.DataFrame:
        return self._client.blobs(self.id)

    def export(self, format: str = "ti3", path=None):
        return self._client.export(self.id, format, path)

    def script(self) -> str:
        return self._client.conn.request("GET", f"/v1/runs/{self.id}/script").text


class RunsMixin:
    def runs(self, limit: int | None = None) -> pd.DataFrame:
        """Stored runs, newest first, as a DataFrame (all of them, or the newest ``limit``)."""
        return tables.runs_frame(self.conn.paged("/v1/runs", max_items=limit))

    def run(self, run) -> Run:
        return Run(self, self.conn.get(f"/v1/runs/{run_id(run)}"))

    def measurement_items(self, run, *, step_prefix: str | None = None, quantity: str | None = None,
                          instrument: str | None = None, page_size: int = MEASUREMENT_PAGE) -> Iterator[dict]:
        """A run's measurements as the daemon sends them, in order, a page at a time."""
        params = {"step_prefix": step_prefix, "quantity": quantity, "instrument": instrument}
        return self.conn.paged(f"/v1/runs/{run_id(run)}/measurements", params, page_size=page_size)

    def measurements(self, run, *, step_prefix: str | None = None, quantity: str | None = None,
                     instrument: str | None = None) -> pd.DataFrame:
        """A run's measurements (filtered on the daemon): ``seq, step, instrument_id, quantity, value, unit,
        measured_at, simulated`` and the flattened ``data.*`` columns (numeric lists as ndarrays)."""
        return tables.measurements_frame(self.measurement_items(run, step_prefix=step_prefix, quantity=quantity,
                                                                instrument=instrument))

    def spectra(self, run, *, step_prefix: str | None = None, quantity: str | None = None,
                instrument: str | None = None) -> pd.DataFrame:
        """The run's spectra: index = wavelength (nm), one column per step."""
        return tables.spectra_frame(self.measurement_items(run, step_prefix=step_prefix, quantity=quantity,
                                                           instrument=instrument))
