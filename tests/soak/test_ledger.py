"""bench/soak/ledger.py's kill check against rows changed on purpose: what a kill left committed must be found again
whole at the night's end — rows added after it are fine, a lost, rewritten or re-recorded one is not."""
from __future__ import annotations

import os
import sqlite3
import sys
import tempfile
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("COLORLAB_SOURCE_DIR") or Path(__file__).resolve().parents[2])
sys.path.insert(0, str(SOURCE_DIR / "bench" / "soak"))

from ledger import check_kept, check_kills, committed_values  # noqa: E402

# The columns the ledger reads, as daemon/store/src/schema.cpp names them.
SCHEMA = ("CREATE TABLE measurements (run_id TEXT NOT NULL, seq INTEGER NOT NULL, step TEXT NOT NULL, "
          "instrument_id TEXT NOT NULL, quantity TEXT NOT NULL, value REAL, unit TEXT, data TEXT, "
          "PRIMARY KEY (run_id, step))")


class KillCheck(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)
        self.db = Path(self.dir.name) / "colorlab.db"
        self.con = sqlite3.connect(self.db)
        self.addCleanup(self.con.close)
        self.con.execute(SCHEMA)
        self.add("r1", 1, "L/D65/r0c0", 101.25)
        self.add("r1", 2, "L/D65/r0c1", 99.5)
        self.add("r0", 1, "frame-1", 0.5)
        self.kept = committed_values(self.db)

    def add(self, run, seq, step, value):
        self.con.execute("INSERT INTO measurements VALUES (?, ?, ?, 'ls110', 'luminance', ?, 'cd/m2', ?)",
                         (run, seq, step, value, f'{{"n":{seq}}}'))
        self.con.commit()

    def test_rows_after_the_kill_are_not_a_change(self):
        self.add("r1", 3, "L/D65/r0c2", 98.0)
        self.add("r2", 1, "frame-1", 0.25)
        self.assertEqual(check_kept(self.db, self.kept), {"runs": 2, "rows": 3, "changed": []})

    def test_a_rewritten_value_is_found(self):
        self.con.execute("UPDATE measurements SET value = 101.26 WHERE run_id = 'r1' AND seq = 1")
        self.con.commit()
        changed = check_kept(self.db, self.kept)["changed"]
        self.assertEqual(len(changed), 1, changed)
        self.assertIn("run r1", changed[0])

    def test_rewritten_data_is_found(self):
        self.con.execute("UPDATE measurements SET data = '{\"n\":9}' WHERE run_id = 'r0'")
        self.con.commit()
        self.assertEqual(len(check_kept(self.db, self.kept)["changed"]), 1)

    def test_a_lost_row_is_found(self):
        self.con.execute("DELETE FROM measurements WHERE run_id = 'r1' AND seq = 2")
        self.con.commit()
        changed = check_kept(self.db, self.kept)["changed"]
        self.assertEqual(changed, ["run r1: 2 rows up to seq 2 at the kill, now 1 rows there"])

    def test_a_step_recorded_again_under_its_seq_is_found(self):
        # A resume that re-measured a committed step and stored it over the old row keeps the count and the shape;
        # only the values tell.
        self.con.execute("DELETE FROM measurements WHERE run_id = 'r1' AND seq = 2")
        self.add("r1", 2, "L/D65/r0c1", 99.4)
        self.assertEqual(len(check_kept(self.db, self.kept)["changed"]), 1)

    def test_check_kills_replaces_the_snapshot_with_its_verdict(self):
        kills = [{"at_s": 3.0, "kept": self.kept}, {"at_s": 4.0}]
        check_kills(self.db, kills)
        self.assertEqual(kills, [{"at_s": 3.0, "kept_check": {"runs": 2, "rows": 3, "changed": []}}, {"at_s": 4.0}])


if __name__ == "__main__":
    unittest.main()
