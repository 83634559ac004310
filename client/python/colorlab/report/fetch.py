"""A stored run as the report needs it: the run document and its measurements, fetched once."""
from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd


@dataclass
class RunData:
    doc: dict
    measurements: pd.DataFrame
    extra: dict = field(default_factory=dict)  # other runs a section refers to (characterize-camera's reference)

    @property
    def id(self) -> str:
        return self.doc["id"]

    @property
    def short(self) -> str:
        return "r" + self.id.replace("-", "")[-12:]

    @property
    def campaign(self) -> str:
        return self.doc.get("campaign") or ""

    @property
    def result(self) -> dict:
        """What the campaign's script returned (its own analyses), {} when it returned nothing."""
        summary = self.doc.get("summary") or {}
        script = summary.get("script")
        return script if isinstance(script, dict) else {}

    def steps(self, prefix: str) -> pd.DataFrame:
        m = self.measurements
        if m.empty:
            return m
        return m[m.step.str.startswith(prefix)]


def load(client, run_id: str) -> RunData:
    doc = dict(client.run(run_id))
    return RunData(doc, client.measurements(run_id))


def kind_of(run: RunData) -> str:
    """The campaign by name; a lab's own copy under another name by the steps it stored."""
    known = {"frame-average", "cabinet-grid", "characterize-camera", "chart-read", "luminance-spot", "floor-luminance",
             "dimmer-exposure", "verify"}
    if run.campaign in known:
        return run.campaign
    steps = run.measurements.step if not run.measurements.empty else pd.Series([], dtype=str)
    for prefix, kind in (("noise/N", "frame-average"), ("L/", "cabinet-grid"),
                         ("characterization/", "characterize-camera"), ("reading/", "luminance-spot"), ("interval/", "dimmer-exposure")):
        if steps.str.startswith(prefix).any():
            return kind
    if not run.measurements.empty and (run.measurements.quantity == "reflectance_spectrum").any():
        return "chart-read"
    return "other"
