"""bench/soak/ledger.py's kill check against rows changed on purpose: what a kill left committed must be found again
whole at the night's end — rows added after it are fine, a lost, rewritten or re-recorded one is not."""
from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("COLORLAB_SOURCE_DIR") or Path(__file__).resolve().parents[2])
sys.path.insert(0, str(SOURCE_DIR / "bench" / "soak"))

from ledger import check_kept, check_kills, committed_values  # noqa: E402

# The columns the ledger reads, as daemon/store/src/schema.cpp names them.
SCHEMA = ("CREATE TABLE measurements (run_id TEXT NOT NULL, seq INTEGER NOT NULL, step TEXT NOT NULL, "
          "instrument_id TEXT NOT NULL, simulated INTEGER NOT NULL, quantity TEXT NOT NULL, value REAL, unit TEXT, "
          "data TEXT, measured_at TEXT NOT NULL, PRIMARY KEY (run_id, step))")


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
        self.con.execute("INSERT INTO measurements VALUES (?, ?, ?, 'ls110', 1, 'luminance', ?, 'cd/m2', ?, ?)",
                         (run, seq, step, value, f'{{"n":{seq}}}', f"2026-11-30T22:00:{seq:02d}.000Z"))
        self.con.commit()

    def test_rows_after_the_kill_are_not_a_change(self):
        self.add("r1", 3, "L/D65/r0c2", 98.0)
        self.add("r2", 1, "frame-1", 0.25)
        self.assertEqual(check_kept(self.db, self.kept), {"runs": 2, "rows": 3, "rows_by_run": {"r0": 1, "r1": 2},
                                                        "changed": []})

    def test_a_rewritten_value_is_found(self):
        self.con.execute("UPDATE measurements SET value = 101.26 WHERE run_id = 'r1' AND seq = 1")
        self.con.commit()
        changed = check_kept(self.db, self.kept)["changed"]
        self.assertEqual(len(changed), 1, changed)
        self.assertIn("run r1", changed[0])

    def test_a_rewritten_measuring_time_is_found(self):
        self.con.execute("UPDATE measurements SET measured_at = '2026-11-30T23:00:01.000Z' WHERE run_id = 'r1' "
                         "AND seq = 1")
        self.con.commit()
        self.assertEqual(len(check_kept(self.db, self.kept)["changed"]), 1)

    def test_an_unreadable_file_leaves_the_kill_unchecked_not_the_soak_ended(self):
        kills = [{"at_s": 3.0, "kept": self.kept}]
        check_kills(Path(self.dir.name) / "gone.db", kills)
        self.assertEqual(list(kills[0]), ["at_s", "kept_error"])
        self.assertIn("OperationalError", kills[0]["kept_error"])

    def test_rewritten_data_is_found(self):
        self.con.execute("UPDATE measurements SET data = '{\"n\":9}' WHERE run_id = 'r0'")
        self.con.commit()
        self.assertEqual(len(check_kept(self.db, self.kept)["changed"]), 1)

    def test_a_lost_row_is_found(self):
        self.con.execute("DELETE FROM measurements WHERE run_id = 'r1' AND seq = 2")
        self.con.commit()
        changed = check_kept(self.db, self.kept)["changed"]
        self.assertEqual(changed, ["run r1: 2 rows up to seq 2 at the kill, now 1 rows there"])

    def test_a_run_gone_whole_is_found(self):
        self.con.execute("DELETE FROM measurements WHERE run_id = 'r0'")
        self.con.commit()
        self.assertEqual(check_kept(self.db, self.kept)["changed"],
                         ["run r0: 1 rows up to seq 1 at the kill, now 0 rows there"])

    def test_a_step_recorded_again_under_its_seq_is_found(self):
        # A resume that re-measured a committed step and stored it over the old row keeps the count and the shape;
        # only the values tell.
        self.con.execute("DELETE FROM measurements WHERE run_id = 'r1' AND seq = 2")
        self.add("r1", 2, "L/D65/r0c1", 99.4)
        self.assertEqual(len(check_kept(self.db, self.kept)["changed"]), 1)

    def test_check_kills_replaces_the_snapshot_with_its_verdict(self):
        kills = [{"at_s": 3.0, "kept": self.kept}, {"at_s": 4.0}]
        check_kills(self.db, kills)
        verdict = {"runs": 2, "rows": 3, "rows_by_run": {"r0": 1, "r1": 2}, "changed": []}
        self.assertEqual(kills, [{"at_s": 3.0, "kept_check": verdict}, {"at_s": 4.0}])


class AfterAKill(unittest.TestCase):
    def test_a_wal_file_left_by_a_killed_writer_is_read_with_its_commits(self):
        """As the soak reads it: a WAL database whose writer died by SIGKILL with its commits still in the -wal file
        (no checkpoint, no close), opened read-only."""
        with tempfile.TemporaryDirectory() as d:
            db = Path(d) / "colorlab.db"
            writer = (f"import os, signal, sqlite3\ncon = sqlite3.connect({str(db)!r})\n"
                      "con.execute('PRAGMA journal_mode=WAL')\ncon.execute('PRAGMA wal_autocheckpoint=0')\n"
                      f"con.execute({SCHEMA!r})\ncon.commit()\n"
                      "for seq in range(1, 4):\n"
                      "    con.execute(\"INSERT INTO measurements VALUES ('r1', ?, ?, 'ls110', 1, 'luminance', ?, "
                      "'cd/m2', NULL, '2026-11-30T22:00:00Z')\", (seq, f'spot/{seq}', 100.0 + seq))\n"
                      "    con.commit()\n"
                      "con.execute(\"INSERT INTO measurements VALUES ('r1', 4, 'spot/4', 'ls110', 1, 'luminance', 0, "
                      "'cd/m2', NULL, '2026-11-30T22:00:00Z')\")\n"  # begun, never committed: not a row the kill left
                      "os.kill(os.getpid(), signal.SIGKILL)\n")
            died = subprocess.run([sys.executable, "-c", writer])
            self.assertEqual(died.returncode, -signal.SIGKILL)
            self.assertGreater(Path(f"{db}-wal").stat().st_size, 0, "the commits should still be in the WAL")
            kept = committed_values(db)
            self.assertEqual({run: e["rows"] for run, e in kept.items()}, {"r1": 3})
            self.assertEqual(check_kept(db, kept)["changed"], [])


if __name__ == "__main__":
    unittest.main()
