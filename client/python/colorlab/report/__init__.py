"""colorlab.report: stored runs as one self-contained HTML report — the dissertation's tables beside its
published numbers, and its figures as inline SVG (matplotlib). ``python3 -m colorlab.report RUN_ID...``;
see docs/reports.md."""
from .build import load_runs, render

__all__ = ["load_runs", "render"]
