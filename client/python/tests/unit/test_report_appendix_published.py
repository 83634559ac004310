"""The dissertation's per-patch appendix tables (16-20) as colorlab.report quotes them: every value found, as printed,
at the line it cites, and each quoted column shown to be what the report takes it for by recomputing the published
statistics (Tables 9-13, themselves checked against the text by test_report_published) from it."""
from __future__ import annotations

import os
import unittest
from pathlib import Path

import numpy as np

from colorlab.report import published as pub

THESIS = Path(os.environ.get("COLORLAB_DISSERTATION", "/work/shared/seed/ulbricht-2006-dissertation.txt"))
# A statistic of values printed to 0.01 differs from the one computed from the unrounded values by at most 0.005
# (min, max, mean; the median of an even count averages two such values) and the statistic itself is printed to
# 0.01 (another 0.005): 0.01, plus float slack. The standard deviation moves by less than the rounding's own
# (0.01/√12 spread on a spread of ≥ 1): the same bound holds.
TOL = 0.0100001


class AppendixQuotes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not THESIS.exists():
            raise unittest.SkipTest(f"{THESIS} is absent")
        cls.lines = THESIS.read_text(encoding="utf-8").splitlines()

    def test_every_patch_value_at_its_line(self):
        quoted = 0
        for t in pub.PATCH_TABLES:
            self.assertEqual([r[0] for r in t.rows], list(range(1, 141)), t.number)
            for n, line, *cells in t.rows:
                fields = self.lines[line - 1].split("\t")
                self.assertEqual(fields[0], str(n), f"{t.number} patch {n} line {line}")
                self.assertEqual(fields[1:], list(cells), f"{t.number} patch {n} line {line}")
                self.assertEqual(len(cells), len(t.printed))
                quoted += len(cells)
            # The table's caption closes it, after its last row and before the next table's first.
            after = "\n".join(self.lines[t.rows[-1][1]:t.rows[-1][1] + 3])
            self.assertIn(f"{t.number}:", after)
        self.assertEqual(quoted, 140 * (3 + 3 + 4 + 7 + 3))

    def test_printed_column_headers(self):
        for t in pub.PATCH_TABLES:
            first = t.rows[0][1]
            header = next(self.lines[k] for k in range(first - 2, first - 6, -1) if self.lines[k].strip())
            # The text's "B" is a Cyrillic "В".
            self.assertEqual(header.replace("\u0412", "B").split("\t")[1:], list(t.printed), t.number)

    def test_page_of_table_16(self):
        first = self.lines.index("List of Tables")
        entry = next(k for k in range(first, first + 60) if self.lines[k].startswith("16\t"))
        self.assertTrue(self.lines[entry + 1].rstrip().endswith("\t110"))
        self.assertEqual(pub.TABLE16.page, 110)

    def stats(self, values):
        v = np.array(sorted(values))
        return {"Min": v.min(), "Max": v.max(), "Median": np.median(v), "Mean": v.mean(), "Stdev": v.std(ddof=1)}

    def check(self, patch_table, holds, stats_table, column, absolute=False):
        values = list(patch_table.column(holds).values())
        if absolute:
            values = [abs(x) for x in values]
        got = self.stats(values)
        k = stats_table.columns.index(column)
        for row in stats_table.rows:
            want = float(row.cells[k])
            self.assertLessEqual(abs(got[row.label] - want), TOL,
                                 f"{patch_table.number} column {holds} {row.label}: {got[row.label]} vs "
                                 f"{stats_table.number} {column} {want}")

    def test_columns_reproduce_the_published_statistics(self):
        for case in ("tiff8", "jpeg", "tiff16"):
            self.check(pub.TABLE16, case, pub.TABLE9, case)
            self.check(pub.TABLE17, case, pub.TABLE10, case)
        for n in ("2", "3", "4"):
            self.check(pub.TABLE18, n, pub.TABLE11, n)
        self.check(pub.TABLE18, "5", pub.TABLE12, "5")
        for n in ("5", "6", "7", "8", "9", "10", "11"):
            self.check(pub.TABLE19, n, pub.TABLE12, n)
        for ch in "RGB":
            self.check(pub.TABLE20, ch, pub.TABLE13, ch, absolute=True)

    def test_table_18_is_not_polynomials_1_to_4(self):
        # Read as printed ("1" = polynomial 1), its first column would have Table 11's polynomial-1 minimum 1.44.
        first = list(pub.TABLE18.column("2").values())
        self.assertNotAlmostEqual(min(first), float(pub.TABLE11.row("Min").cells[0]), places=2)
        # Its last column is Table 19's first, patch by patch.
        self.assertEqual(pub.TABLE18.column("5"), pub.TABLE19.column("5"))

    def test_patch_numbering(self):
        self.assertEqual(pub.PatchTable.patch_id(1), "A1")
        self.assertEqual(pub.PatchTable.patch_id(14), "N1")
        self.assertEqual(pub.PatchTable.patch_id(15), "A2")
        self.assertEqual(pub.PatchTable.patch_id(140), "N10")


if __name__ == "__main__":
    unittest.main()
