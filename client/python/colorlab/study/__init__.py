"""Built-in studies: several campaigns run through the daemon's night queue, then one report.
``python3 -m colorlab.study dissertation`` (docs/reports.md, "The dissertation study")."""
from .definition import DISSERTATION, STUDIES, steps

__all__ = ["DISSERTATION", "STUDIES", "steps"]
