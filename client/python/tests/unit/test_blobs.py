"""Blobs: arrays from their dtype/shape/CFA headers, parts through Range, integrity by sha256."""
import hashlib
import json
import re
import tempfile
import unittest
from pathlib import Path

import numpy as np

import colorlab
from fake_daemon import FakeDaemon

FRAME = (np.arange(6 * 4, dtype="<u2") * 1000).reshape(6, 4)
DATA = FRAME.tobytes()
SHA = hashlib.sha256(DATA).hexdigest()
DNG = b"II*\x00" + b"\x01" * 100
DNG_SHA = hashlib.sha256(DNG).hexdigest()


def serve_blob(data, headers, honour_range=True):
    def handler(h):
        base = {"ETag": f'"{hashlib.sha256(data).hexdigest()}"', "Accept-Ranges": "bytes", **headers}
        m = re.fullmatch(r"bytes=(\d+)-(\d*)", h.headers.get("Range", ""))
        if m and honour_range:
            a = int(m.group(1))
            b = int(m.group(2)) if m.group(2) else len(data) - 1
            if a >= len(data):
                h.send_bytes(416, b"", headers={"Content-Range": f"bytes */{len(data)}"})
                return
            b = min(b, len(data) - 1)
            h.send_bytes(206, data[a:b + 1], headers={**base, "Content-Range": f"bytes {a}-{b}/{len(data)}"})
            return
        h.send_bytes(200, data, headers=base)
    return handler


class BlobTest(unittest.TestCase):
    def setUp(self):
        self.fake = self.enterContext(FakeDaemon())
        array_headers = {"X-Colorlab-Dtype": "<u2", "X-Colorlab-Shape": "6,4", "X-Colorlab-Cfa": "RGGB"}
        for method in ("GET", "HEAD"):
            self.fake.routes[(method, f"/v1/blobs/{SHA}")] = serve_blob(DATA, array_headers)
            self.fake.routes[(method, f"/v1/blobs/{DNG_SHA}")] = serve_blob(DNG, {})
        self.lab = self.enterContext(colorlab.Client(self.fake.url))

    def test_a_frame_is_its_array(self):
        a = self.lab.read_array(SHA)
        self.assertEqual((a.dtype, a.shape), (np.dtype("<u2"), (6, 4)))
        np.testing.assert_array_equal(a, FRAME)
        a[0, 0] = 7  # writable, like any array one computes with

    def test_info_from_head(self):
        info = self.lab.blob_info({"sha256": SHA, "name": "averaged"})
        self.assertEqual((info.size, info.dtype, info.shape, info.cfa, info.accept_ranges, info.etag),
                         (len(DATA), np.dtype("<u2"), (6, 4), "RGGB", True, f'"{SHA}"'))
        self.assertTrue(info.is_array)
        self.assertEqual(self.fake.requests_to("HEAD", f"/v1/blobs/{SHA}")[0][0], "HEAD")
        self.assertFalse(self.lab.blob_info(DNG_SHA).is_array)

    def test_rows_come_through_one_range_request(self):
        part = self.lab.read_array(SHA, rows=(2, 5))
        np.testing.assert_array_equal(part, FRAME[2:5])
        ranges = [r[3].get("Range") for r in self.fake.requests_to("GET", f"/v1/blobs/{SHA}")]
        self.assertEqual(ranges, ["bytes=16-39"])  # 4 columns × 2 bytes per row
        np.testing.assert_array_equal(self.lab.read_array(SHA, rows=slice(-2, None)), FRAME[-2:])
        self.assertEqual(self.lab.read_array(SHA, rows=(3, 3)).shape, (0, 4))

    def test_byte_ranges(self):
        self.assertEqual(self.lab.read_blob(DNG_SHA, 10, 20), DNG[10:20])
        self.assertEqual(self.lab.read_blob(DNG_SHA, 100), DNG[100:])
        self.assertEqual(self.lab.read_blob(DNG_SHA), DNG)
        with self.assertRaises(colorlab.RangeNotSatisfiable):
            self.lab.read_blob(DNG_SHA, 1000, 1001)
        with self.assertRaises(ValueError):
            self.lab.read_blob(DNG_SHA, 5, 5)

    def test_a_server_ignoring_range_still_gives_the_part(self):
        self.fake.routes[("GET", f"/v1/blobs/{DNG_SHA}")] = serve_blob(DNG, {}, honour_range=False)
        self.assertEqual(self.lab.read_blob(DNG_SHA, 10, 20), DNG[10:20])

    def test_bytes_that_do_not_hash_to_the_name_are_refused(self):
        wrong = "0" * 64
        self.fake.routes[("GET", f"/v1/blobs/{wrong}")] = serve_blob(DNG, {})
        with self.assertRaises(colorlab.IntegrityError):
            self.lab.read_blob(wrong)

    def test_a_file_that_is_not_an_array_says_to_read_its_bytes(self):
        with self.assertRaises(colorlab.ColorlabError) as caught:
            self.lab.read_array(DNG_SHA)
        self.assertIn("read_blob", str(caught.exception))

    def test_download_to_a_directory_is_named_by_the_digest(self):
        with tempfile.TemporaryDirectory() as d:
            path = self.lab.read_blob(DNG_SHA, path=d)
            self.assertEqual(path, Path(d) / DNG_SHA)
            self.assertEqual(path.read_bytes(), DNG)
            self.assertEqual(sorted(p.name for p in Path(d).iterdir()), [DNG_SHA])

    def test_a_runs_blobs_are_listed(self):
        items = [{"name": "averaged", "sha256": SHA, "kind": "frame", "step": "capture", "media_type":
                  "application/x-colorlab-array", "size": len(DATA), "meta": {}, "links": {}}]
        self.fake.routes[("GET", "/v1/runs/r1/blobs")] = lambda h: h.send_json(200, {"items": items})
        df = self.lab.blobs("r1")
        self.assertEqual(df["sha256"].tolist(), [SHA])
        np.testing.assert_array_equal(self.lab.read_array(df.iloc[0]), FRAME)  # a row is a blob too


class LocateChartTest(unittest.TestCase):
    def setUp(self):
        self.fake = self.enterContext(FakeDaemon())
        self.lab = self.enterContext(colorlab.Client(self.fake.url))
        self.path = f"/v1/blobs/{DNG_SHA}/locate-chart"

    def test_the_operators_corners_and_reference_go_in_the_body(self):
        located = {"chart": {"kind": "sg", "confidence": 0.97, "from_corners": True}, "patches": []}
        self.fake.routes[("POST", self.path)] = lambda h: h.send_json(200, located)
        got = self.lab.locate_chart({"sha256": DNG_SHA}, "sg", corners=[(10, 20), (110, 20), (110, 90), (10, 90)],
                                    reference_run={"id": "r7"}, sample_fraction=0.5)
        self.assertEqual(got, located)
        (_, _, _, headers, body), = self.fake.requests_to("POST", self.path)
        self.assertEqual(headers.get("Content-Type"), "application/json")
        self.assertEqual(json.loads(body), {"chart": "sg", "corners": [[10.0, 20.0], [110.0, 20.0], [110.0, 90.0],
                                                                       [10.0, 90.0]],
                                            "reference_run": "r7", "sample_fraction": 0.5})

    def test_a_refusal_is_unprocessable_with_the_daemons_hint(self):
        self.fake.routes[("POST", self.path)] = lambda h: h.send_problem(
            422, "chart-needs-corners", "Chart needs corners", "the locator is not sure (confidence 0.41)",
            hint='give "corners"')
        with self.assertRaises(colorlab.Unprocessable) as caught:
            self.lab.locate_chart(DNG_SHA)
        self.assertEqual((caught.exception.code, caught.exception.hint), ("chart-needs-corners", 'give "corners"'))
        self.assertEqual(json.loads(self.fake.requests_to("POST", self.path)[0][4]), {"chart": "sg"})


class ExportTest(unittest.TestCase):
    def test_export_bytes_or_a_file_under_the_daemons_name(self):
        body = b"CTI3\n\nBEGIN_DATA_FORMAT\n"
        with FakeDaemon() as fake:
            fake.routes[("GET", "/v1/runs/r1/export")] = lambda h: h.send_bytes(
                200, body, "application/x-cgats",
                {"Content-Disposition": 'attachment; filename="../luminance-spot-r1.ti3"'})
            lab = self.enterContext(colorlab.Client(fake.url))
            self.assertEqual(lab.export("r1"), body)
            self.assertEqual(fake.requests_to("GET", "/v1/runs/r1/export")[0][2], {"format": "ti3"})
            with tempfile.TemporaryDirectory() as d:
                path = lab.export("r1", "ti3", d)
                self.assertEqual(path, Path(d) / "luminance-spot-r1.ti3")  # never outside the directory
                self.assertEqual(path.read_bytes(), body)
            with self.assertRaises(ValueError):
                lab.export("r1", "xlsx")


if __name__ == "__main__":
    unittest.main()
