"""Fig. 35 in a cabinet-grid run's report: every spot the run stored, at its stored row and column, numbered in the
order the run first measured it — read back from the daemon's SQLite file and compared with the report's listing,
and the figure shown by headless Chromium."""
from __future__ import annotations

import re
import unittest

from report_support import ReportCase, check_in_browser, make_report, parse


def short(run_id):
    return "r" + run_id.replace("-", "")[-12:]


class SpotsFigure(ReportCase):
    SEED = 5

    @classmethod
    def campaigns(cls, d):
        cls.run_id = d.run_to_end("cabinet-grid", rows=3, cols=4, lamps=["D65"], dimmer_levels=[100, 50],
                                  settle_s=0)["run_id"]
        cls.path = make_report(d, [cls.run_id], "cabinet-spots")
        cls.tables, cls.ids = parse(cls.path)

    def test_every_stored_spot_numbered_in_measuring_order(self):
        order = []
        for m in sorted(self.daemon.stored_measurements(self.run_id), key=lambda m: m["seq"]):
            r, c = map(int, re.match(r"^L/[^/]+/D[\d.]+/r(\d+)c(\d+)$", m["step"]).groups())
            self.assertEqual((m["data"]["row"], m["data"]["col"]), (r, c))
            if (r, c) not in order:
                order.append((r, c))
        self.assertEqual(sorted(order), [(r, c) for r in range(3) for c in range(4)])
        listing = self.tables[f"{short(self.run_id)}-fig35-spots"]
        self.assertEqual(len(listing), 2 * len(order))
        for n, (r, c) in enumerate(order, start=1):
            self.assertEqual(listing[(str(n), "row", "measured")], r)
            self.assertEqual(listing[(str(n), "col", "measured")], c)
        # The operator's walk: back and forth along the rows.
        self.assertEqual(order[:8], [(0, 0), (0, 1), (0, 2), (0, 3), (1, 3), (1, 2), (1, 1), (1, 0)])

    def test_figure_labels_every_spot(self):
        html = self.path.read_text(encoding="utf-8")
        fig = html[html.index(f'id="{short(self.run_id)}-fig35"'):]
        fig = fig[:fig.index("</figure>")]
        labels = re.findall(r"<text[^>]*>(\d+)</text>", fig)
        for n in range(1, 13):
            self.assertIn(str(n), labels)

    def test_in_a_browser(self):
        check_in_browser(self, self.path, [f"{short(self.run_id)}-fig35"], "cabinet-spots")


if __name__ == "__main__":
    unittest.main()
