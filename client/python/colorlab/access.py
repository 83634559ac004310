"""Access control: the one control lock (who drives the instruments) and API keys (admin scope)."""
from __future__ import annotations

import pandas as pd

from . import tables


class AccessMixin:
    def control(self) -> dict:
        """Who holds the control lock, if anyone."""
        return self.conn.get("/v1/control")

    def acquire_control(self, holder: str, *, force: bool = False) -> dict:
        """Take the control lock for ``holder`` (a name others see); ``Conflict`` while someone else holds it,
        unless ``force`` (an admin breaking a forgotten lock)."""
        return self.conn.post("/v1/control/acquire", {"holder": holder, "force": force})

    def release_control(self, *, force: bool = False) -> dict:
        return self.conn.post("/v1/control/release", {"force": force})

    def keys(self) -> pd.DataFrame:
        """API keys (never their secrets): needs an ``admin`` key."""
        return tables.items_frame(self.conn.get("/v1/keys").get("items", []), ("created_at", "revoked_at"))

    def create_key(self, name: str, scope: str = "read") -> dict:
        """A new key (``scope``: read, control or admin); its ``secret`` is in this answer and nowhere else."""
        return self.conn.post("/v1/keys", {"name": name, "scope": scope})

    def revoke_key(self, key) -> dict | None:
        return self.conn.delete(f"/v1/keys/{key if isinstance(key, str) else key['id']}")
