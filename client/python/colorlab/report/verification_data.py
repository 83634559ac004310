"""A stored verification (campaign ``verify``, verify/compare/src/stored.cpp) read back as the report needs it:
one dict per comparison, rebuilt from its measurement row (step ``<kind>/<where>``, ``data`` the comparison with
its verdict and budget, flattened by the client into ``data.*`` columns), and the run's summary."""
from __future__ import annotations

import math
import re

import numpy as np

KINDS = ("colour_7_3", "colour_7_4", "light_spot", "light_floor")
KIND_NAMES = {"colour_7_3": "colour, §7.3 (ΔE00 through the characterization)",
              "colour_7_4": "colour, §7.4 (raw counts through the black box)",
              "light_spot": "light at the LS-110 spots",
              "light_floor": "light over the floor map"}
# Grid pitch of §6.2's spots on the 1200 × 600 mm floor (docs/verify.md "Using it").
PITCH_MM = (60.0, 54.0)

_SPOT = re.compile(r"^r(\d+)c(\d+)$")
_PATCH = re.compile(r"^([A-Z])(\d{1,2})$")


def _plain(v):
    if isinstance(v, np.ndarray):
        return [float(x) for x in v.ravel()]
    if isinstance(v, (np.floating, np.integer, np.bool_)):
        return v.item()
    if isinstance(v, float) and math.isnan(v):
        return None
    return v


def comparisons(run) -> list[dict]:
    """The stored comparisons in stored order: kind, where, rendered, measured, difference, expanded,
    mahalanobis, threshold, verdict, cannot_tell, noise_left_out (None when stored before it was), budget {source:
    standard uncertainty}."""
    m = run.measurements
    if m.empty:
        return []
    out = []
    budget_cols = [c for c in m.columns if c.startswith("data.budget.")]
    for _, row in m.iterrows():
        kind = row.get("data.kind")
        if not isinstance(kind, str):
            kind, _, where = str(row.step).partition("/")
        else:
            where = row.get("data.where")
        c = {"kind": kind, "where": str(where), "step": row.step}
        for key in ("rendered", "measured", "difference", "expanded", "mahalanobis", "threshold", "verdict",
                    "cannot_tell", "noise_left_out"):
            c[key] = _plain(row.get(f"data.{key}"))
        if c["difference"] is None:
            c["difference"] = float(row.value)
        c["budget"] = {col[len("data.budget."):]: float(row[col]) for col in budget_cols
                       if row[col] is not None and not (isinstance(row[col], float) and math.isnan(row[col]))}
        out.append(c)
    return out


def by_kind(items) -> dict:
    out = {k: [] for k in KINDS}
    for c in items:
        out.setdefault(c["kind"], []).append(c)
    return {k: v for k, v in out.items() if v}


def summary(run, items) -> dict:
    """The stored summary; the per-kind counts recomputed from the rows when it lacks them."""
    s = run.doc.get("summary")
    s = dict(s) if isinstance(s, dict) else {}
    if not isinstance(s.get("kinds"), dict):
        kinds = {}
        for kind, list_ in by_kind(items).items():
            differ = sum(1 for c in list_ if c["verdict"] == "differs")
            kinds[kind] = {"compared": len(list_), "agree": len(list_) - differ, "differ": differ,
                           "agree_fraction": 1 - differ / len(list_)}
        s["kinds"] = kinds
    if "verdict" not in s:
        s["verdict"] = "differs" if any(c["verdict"] == "differs" for c in items) else "agrees"
    return s


def noise_left_out(kind, k, items) -> list[str]:
    """Where the rendering-noise screen left a region out (its own spread its band's rendering noise): the summary's
    list for the kind, else the comparisons' flags; [] for a verification stored before either existed."""
    listed = k.get("rendering_noise_left_out") if isinstance(k, dict) else None
    if isinstance(listed, list):
        return [str(w) for w in listed]
    return [c["where"] for c in items if c.get("noise_left_out") is True]


def spot_rc(where: str):
    """(row, col) of a spot named r<row>c<col>, else None."""
    m = _SPOT.match(where)
    return (int(m.group(1)), int(m.group(2))) if m else None


def patch_rc(where: str):
    """(row, column) on the chart's layout of a patch named <column letter><row number> (A1 … N10), else None."""
    m = _PATCH.match(where)
    return (int(m.group(2)), ord(m.group(1)) - ord("A") + 1) if m else None


def dominant(c) -> str:
    return max(c["budget"].items(), key=lambda kv: kv[1])[0] if c["budget"] else ""


def is_relative(kind: str) -> bool:
    return kind != "colour_7_3"
