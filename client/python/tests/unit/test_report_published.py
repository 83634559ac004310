"""Every number colorlab.report quotes from the dissertation is found, as printed, at the place it cites."""
from __future__ import annotations

import os
import re
import unittest
from pathlib import Path

from colorlab.report import published as pub

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))


class PublishedNumbers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not THESIS.exists():
            print(f"skipped: {THESIS} is absent", flush=True)
            raise unittest.SkipTest(f"{THESIS} is absent")
        cls.lines = THESIS.read_text(encoding="utf-8").splitlines()

    def line(self, n: int) -> str:
        return self.lines[n - 1]

    def test_table_cells_stand_in_their_row_and_column(self):
        quoted = 0
        for t in pub.ALL_TABLES:
            # The table's caption follows its rows within a few lines: the rows belong to that table.
            after = "\n".join(self.lines[t.rows[-1].line:t.rows[-1].line + 4])
            self.assertIn(f"{t.number}:", after, t.number)
            for row in t.rows:
                fields = self.line(row.line).split("\t")
                self.assertEqual(len(fields), len(t.columns) + 1, f"{t.number} row {row.label} line {row.line}")
                self.assertEqual(len(row.cells), len(t.columns))
                for k, printed in enumerate(row.cells):
                    if printed is None:
                        continue
                    # Table 13's cells carry a relative error in brackets after the quoted number.
                    self.assertEqual(fields[k + 1].split(" ")[0], printed,
                                     f"{t.number} row {row.label} column {t.columns[k]} (line {row.line})")
                    quoted += 1
        self.assertGreater(quoted, 350)

    def test_table_rows_are_labelled_as_in_the_text(self):
        labels = {"R median": "R Median", "G median": "G Median", "B median": "B Median",
                  "R mean": "R Mean Value", "G mean": "G Mean Value", "B mean": "B Mean Value"}
        for row in pub.TABLE2.rows:
            self.assertEqual(self.line(row.line).split("\t")[0], labels[row.label])
        for t in pub.WINDOW_TABLES.values():
            for row in t.rows:
                self.assertEqual(self.line(row.line).split("\t")[0], row.label, t.number)
        for t in (pub.TABLE9, pub.TABLE10, pub.TABLE11, pub.TABLE12, pub.TABLE13):
            self.assertEqual([self.line(r.line).split("\t")[0] for r in t.rows], [r.label for r in t.rows])

    def test_running_text_numbers(self):
        for s in pub.ALL_SCALARS:
            self.assertRegex(self.line(s.line), r"(?<![\d.])" + re.escape(s.text) + r"(?![\d])", s.label)

    def test_pages_match_the_list_of_tables(self):
        # An entry is "N<TAB>title…" over one or more lines, the last of which ends "<TAB>page".
        first = self.lines.index("List of Tables")
        entries, current = {}, None
        for line in self.lines[first + 1:first + 60]:
            m = re.match(r"^(\d+)\t", line)
            if m:
                current = m[1]
            if current:
                entries.setdefault(current, []).append(line)
        for t in pub.ALL_TABLES:
            last = entries[t.number.split()[1]][-1]
            self.assertEqual(int(last.rsplit("\t", 1)[1]), t.page, t.number)


if __name__ == "__main__":
    unittest.main()
