"""Measurements and runs as pandas DataFrames, spectra as a wavelength-indexed DataFrame. Pure: no I/O."""
from __future__ import annotations

import numbers
from typing import Any, Iterable

import numpy as np
import pandas as pd

MEASUREMENT_COLUMNS = ["seq", "step", "instrument_id", "quantity", "value", "unit", "measured_at", "simulated"]
RUN_TIME_COLUMNS = ("created_at", "started_at", "finished_at", "updated_at")


def _numeric_leaves(v: Any) -> bool:
    if isinstance(v, list):
        return all(_numeric_leaves(x) for x in v)
    return isinstance(v, numbers.Real) and not isinstance(v, bool) or v is None


def _cell(v: list) -> Any:
    """A JSON list as an ndarray when it is a (possibly nested, rectangular) list of numbers."""
    if v and _numeric_leaves(v):
        try:
            a = np.array(v, dtype=float)  # None → nan
        except ValueError:  # ragged
            return v
        if a.dtype != object:
            return a
    return v


def flatten_data(data: Any, prefix: str = "data") -> dict:
    """A measurement's ``data`` as flat columns: nested objects become ``data.a.b``, numeric lists ndarrays."""
    out: dict = {}

    def walk(v: Any, name: str) -> None:
        if isinstance(v, dict) and v:
            for k, x in v.items():
                walk(x, f"{name}.{k}")
        elif isinstance(v, list):
            out[name] = _cell(v)
        else:
            out[name] = v

    if isinstance(data, dict):
        for k, x in data.items():
            walk(x, f"{prefix}.{k}")
    elif data is not None:
        out[prefix] = data
    return out


def _times(df: pd.DataFrame, columns: Iterable[str]) -> None:
    for c in columns:
        if c in df.columns:
            df[c] = pd.to_datetime(df[c], utc=True, errors="coerce")


def measurements_frame(items: Iterable[dict]) -> pd.DataFrame:
    """One row per measurement: the fixed columns, then the flattened ``data`` columns in order of appearance."""
    rows, extra = [], {}
    for m in items:
        row = {c: m.get(c) for c in MEASUREMENT_COLUMNS}
        flat = flatten_data(m.get("data"))
        for k in flat:
            extra.setdefault(k, None)
        row.update(flat)
        rows.append(row)
    df = pd.DataFrame(rows, columns=MEASUREMENT_COLUMNS + list(extra))
    df["seq"] = df["seq"].astype("int64")
    df["value"] = pd.to_numeric(df["value"], errors="coerce").astype("float64")
    df["simulated"] = df["simulated"].astype(bool)
    _times(df, ["measured_at"])
    return df


def spectrum_of(measurement: dict) -> pd.Series | None:
    """A measurement's spectrum (``data.first_nm``, ``data.step_nm``, ``data.values``) indexed by wavelength."""
    data = measurement.get("data")
    if not isinstance(data, dict):
        return None
    values, first, step = data.get("values"), data.get("first_nm"), data.get("step_nm")
    if not isinstance(values, list) or not values or first is None or step is None:
        return None
    # Rounded so grids that agree in nm share index labels after float arithmetic.
    wavelengths = np.round(float(first) + float(step) * np.arange(len(values)), 6)
    return pd.Series(np.asarray(values, dtype=float), index=pd.Index(wavelengths, name="wavelength_nm"),
                     name=measurement.get("step"))


def spectra_frame(items: Iterable[dict]) -> pd.DataFrame:
    """Every spectrum among ``items``: index = wavelength in nm, one column per step (NaN off a grid)."""
    series = [s for s in (spectrum_of(m) for m in items) if s is not None]
    if not series:
        return pd.DataFrame(index=pd.Index([], name="wavelength_nm", dtype=float))
    df = pd.concat(series, axis=1).sort_index()
    df.index.name = "wavelength_nm"
    df.columns.name = "step"
    return df


def runs_frame(items: Iterable[dict]) -> pd.DataFrame:
    """One row per run (its own fields; ``params`` and ``summary`` stay dicts), times as UTC datetimes."""
    df = pd.DataFrame(list(items))
    if df.empty:
        return pd.DataFrame(columns=["id", "campaign", "status", "simulated", "created_at"])
    _times(df, RUN_TIME_COLUMNS)
    return df


def items_frame(items: Iterable[dict], time_columns: Iterable[str] = ()) -> pd.DataFrame:
    df = pd.DataFrame(list(items))
    _times(df, time_columns)
    return df
