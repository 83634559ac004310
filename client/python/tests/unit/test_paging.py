"""A run's measurements paged by cursor into one DataFrame; data flattened; spectra by wavelength."""
import unittest

import numpy as np
import pandas as pd

import colorlab
from colorlab import tables
from fake_daemon import FakeDaemon

RUN = "01900000-0000-7000-8000-000000000001"


def measurement(seq, **extra):
    m = {"seq": seq, "step": f"reading/{seq}", "instrument_id": "ls110", "quantity": "luminance",
         "value": 100.0 + seq, "unit": "cd/m2", "measured_at": f"2026-01-02T03:04:{seq % 60:02d}.125Z",
         "simulated": True}
    m.update(extra)
    return m


class PagedMeasurements:
    """Serves ``items`` ``limit`` at a time, the cursor being the last seq sent (keyset, as the daemon)."""

    def __init__(self, fake, items):
        self.items = items
        fake.routes[("GET", f"/v1/runs/{RUN}/measurements")] = self

    def __call__(self, h):
        limit = int(h.query.get("limit", 50))
        after = int(h.query.get("cursor", "0"))
        rest = [m for m in self.items if m["seq"] > after
                and m["step"].startswith(h.query.get("step_prefix", ""))
                and ("quantity" not in h.query or m["quantity"] == h.query["quantity"])]
        page = rest[:limit]
        more = len(rest) > limit
        cursor = str(page[-1]["seq"]) if more else None
        h.send_json(200, {"items": page, "next_cursor": cursor,
                          "links": {"next": f"/v1/runs/{RUN}/measurements?cursor={cursor}" if more else None}})


class PagingTest(unittest.TestCase):
    def test_all_pages_in_order_with_the_filters_on_every_page(self):
        items = [measurement(i) for i in range(1, 2501)]
        with FakeDaemon() as fake:
            PagedMeasurements(fake, items)
            lab = self.enterContext(colorlab.Client(fake.url))
            df = lab.measurements(RUN, step_prefix="reading/", quantity="luminance")
            self.assertEqual(df["seq"].tolist(), list(range(1, 2501)))
            calls = fake.requests_to("GET", f"/v1/runs/{RUN}/measurements")
            self.assertEqual(len(calls), 3)  # 1000 + 1000 + 500: the daemon's default page
            for _, _, query, _, _ in calls:
                self.assertEqual((query["step_prefix"], query["quantity"], query["limit"]),
                                 ("reading/", "luminance", "1000"))
            self.assertNotIn("cursor", calls[0][2])
            self.assertEqual([q["cursor"] for _, _, q, _, _ in calls[1:]], ["1000", "2000"])
            self.assertNotIn("instrument", calls[0][2])  # None filters are not sent

    def test_an_empty_run_is_an_empty_frame_with_the_columns(self):
        with FakeDaemon() as fake:
            PagedMeasurements(fake, [])
            df = self.enterContext(colorlab.Client(fake.url)).measurements(RUN)
            self.assertTrue(df.empty)
            self.assertEqual(list(df.columns), tables.MEASUREMENT_COLUMNS)

    def test_a_repeated_cursor_stops_instead_of_looping(self):
        with FakeDaemon() as fake:
            fake.routes[("GET", f"/v1/runs/{RUN}/measurements")] = lambda h: h.send_json(
                200, {"items": [measurement(1)], "next_cursor": "same"})
            with self.assertRaises(colorlab.ColorlabError):
                self.enterContext(colorlab.Client(fake.url)).measurements(RUN)

    def test_runs_are_paged_too_and_limit_stops_early(self):
        runs = [{"id": f"run-{i}", "campaign": "luminance-spot", "status": "finished_ok", "simulated": True,
                 "created_at": "2026-01-02T03:04:05.000Z"} for i in range(10)]

        def serve(h):
            start = int(h.query.get("cursor", "0"))
            limit = int(h.query["limit"])
            end = start + limit
            h.send_json(200, {"items": runs[start:end], "next_cursor": str(end) if end < len(runs) else None})

        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/runs")] = serve
            lab = self.enterContext(colorlab.Client(fake.url))
            self.assertEqual(lab.runs()["id"].tolist(), [r["id"] for r in runs])
            self.assertEqual(lab.runs(limit=3)["id"].tolist(), ["run-0", "run-1", "run-2"])
            self.assertEqual(fake.requests_to("GET", "/v1/runs")[-1][2]["limit"], "3")
            self.assertEqual(str(lab.runs()["created_at"].dtype), "datetime64[ns, UTC]")


class FrameTest(unittest.TestCase):
    def test_types_and_flattened_data(self):
        df = tables.measurements_frame([
            measurement(1, data={"raw": "L 100.1", "row": 2, "nested": {"a": 1, "b": {"c": "x"}},
                                 "rgb": [0.1, 0.2, 0.3], "corners": [[0, 0], [1, 0], [1, 1], [0, 1]],
                                 "names": ["a", "b"], "mixed": [1, "a"], "flag": True}),
            measurement(2),
        ])
        self.assertEqual(list(df.columns[:8]), tables.MEASUREMENT_COLUMNS)
        self.assertEqual(str(df["seq"].dtype), "int64")
        self.assertEqual(str(df["value"].dtype), "float64")
        self.assertEqual(str(df["simulated"].dtype), "bool")
        self.assertEqual(df["measured_at"][0], pd.Timestamp("2026-01-02T03:04:01.125Z"))
        row = df.iloc[0]
        self.assertEqual(row["data.raw"], "L 100.1")
        self.assertEqual(row["data.nested.a"], 1)
        self.assertEqual(row["data.nested.b.c"], "x")
        np.testing.assert_array_equal(row["data.rgb"], np.array([0.1, 0.2, 0.3]))
        self.assertEqual(row["data.corners"].shape, (4, 2))
        self.assertEqual(row["data.names"], ["a", "b"])  # not numbers: kept as a list
        self.assertEqual(row["data.mixed"], [1, "a"])
        self.assertIs(row["data.flag"], True)
        self.assertTrue(pd.isna(df.iloc[1]["data.raw"]))  # a measurement without data

    def test_spectra_by_wavelength_one_column_per_step(self):
        a = measurement(1, step="patch/A1", data={"first_nm": 380, "step_nm": 10, "values": [0.1, 0.2, 0.3]})
        b = measurement(2, step="patch/A2", data={"first_nm": 390, "step_nm": 10, "values": [0.5, 0.6, 0.7]})
        c = measurement(3, step="reading/0", data={"raw": "x"})
        s = tables.spectra_frame([a, b, c])
        self.assertEqual(s.index.name, "wavelength_nm")
        self.assertEqual(s.index.tolist(), [380.0, 390.0, 400.0, 410.0])
        self.assertEqual(list(s.columns), ["patch/A1", "patch/A2"])
        self.assertEqual(s.loc[390.0, "patch/A1"], 0.2)
        self.assertEqual(s.loc[410.0, "patch/A2"], 0.7)
        self.assertTrue(np.isnan(s.loc[380.0, "patch/A2"]))
        self.assertTrue(tables.spectra_frame([c]).empty)

    def test_fractional_grids_line_up(self):
        a = measurement(1, step="a", data={"first_nm": 380.0, "step_nm": 3.3, "values": [1.0] * 31})
        b = measurement(2, step="b", data={"first_nm": 380.0, "step_nm": 3.3, "values": [2.0] * 31})
        self.assertEqual(len(tables.spectra_frame([a, b])), 31)


if __name__ == "__main__":
    unittest.main()
