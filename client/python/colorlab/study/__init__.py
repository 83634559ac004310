"""Built-in studies: a sequence of the daemon's catalogue (e.g. ``dissertation``) queued as one group in the night
queue, followed, then one report. ``python3 -m colorlab.study dissertation`` (docs/reports.md, "The dissertation
study"); the steps are the daemon's (campaigns/scripts/dissertation.sequence.lua)."""
from .definition import UnknownStudy, sequence, steps

__all__ = ["UnknownStudy", "sequence", "steps"]
