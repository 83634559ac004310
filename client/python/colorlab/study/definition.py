"""A study's definition, as the daemon's catalogue has it: the sequence NAME (campaigns/scripts/NAME.sequence.lua,
GET /v1/campaigns with ``kind: "sequence"``) — which campaigns, in which order, with which parameters, which earlier
step's run each ``reference`` takes, and the ``small`` variant's overrides. The sequence is the one place the study's
steps are written; this module only reads it (docs/campaigns.md, "Sequences").
"""
from __future__ import annotations

import colorlab


class UnknownStudy(Exception):
    """No sequence of that name, or an override of a step it does not have: a usage error (exit 2)."""


def sequence(client: colorlab.Client, study: str) -> dict:
    """The sequence as GET /v1/campaigns lists it: {name, kind, description, steps: [...], small: {...}}."""
    items = client.conn.get("/v1/campaigns").get("items") or []
    for item in items:
        if item.get("name") == study and item.get("kind") == "sequence":
            return item
    names = sorted(i["name"] for i in items if i.get("kind") == "sequence")
    raise UnknownStudy(f"the daemon has no study (sequence) named {study!r}; sequences: {', '.join(names) or 'none'}")


def steps(seq: dict, *, small: bool = False, overrides: dict | None = None) -> list[dict]:
    """The sequence's steps as the daemon queues them (small overrides, then ``--set STEP.KEY=VALUE``), for a dry run
    and for display. Each: {name, campaign, params, reference: {param, step} or None, covers}."""
    names = [s["name"] for s in seq["steps"]]
    unknown = sorted(set(overrides or {}) - set(names))
    if unknown:
        raise UnknownStudy(f"study {seq['name']} has no step {', '.join(unknown)}; steps: {', '.join(names)}")
    out = []
    for step in seq["steps"]:
        params = dict(step.get("params") or {})
        if small:
            params.update((seq.get("small") or {}).get(step["name"], {}))
        params.update((overrides or {}).get(step["name"], {}))
        out.append({**step, "params": params})
    return out
