"""Frames and spectra from real campaigns on the simulated lab: frame-average's kept frames as numpy arrays
(checked byte for byte against the blob store's files), and chart-read's spectra by wavelength (checked
against the same run read from the daemon's database file)."""
import unittest

import numpy as np

import colorlab
from daemon_fixture import Daemon, skip_unless_served

FRAMES = 2


class FrameTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon()
        cls.addClassCleanup(cls.daemon.cleanup)  # also when the rest of setUpClass fails
        cls.lab = cls.daemon.client
        cls.daemon.wait_ready("dslr")
        cls.run_id = cls.daemon.run_to_end("frame-average", frames=FRAMES)["run_id"]


    def stored_file(self, sha):
        """The blob's file in the daemon's content-addressed store (<state>/blobs/ab/cdef…), read without HTTP."""
        path = self.daemon.state / "blobs" / sha[:2] / sha[2:]
        self.assertTrue(path.is_file(), f"{path} missing")
        return path

    def test_kept_frames_are_arrays_with_their_headers_and_bytes(self):
        blobs = skip_unless_served(self, lambda: self.lab.blobs(self.run_id), "GET /v1/runs/{id}/blobs")
        self.assertFalse(blobs.empty, "frame-average kept no frames")
        arrays = blobs[blobs["media_type"] == "application/x-colorlab-array"]
        self.assertFalse(arrays.empty, blobs[["name", "kind", "media_type"]].to_string())
        for _, blob in arrays.iterrows():
            info = self.lab.blob_info(blob)
            self.assertTrue(info.is_array, info)
            self.assertEqual(info.size, blob["size"])
            self.assertEqual(info.etag, f'"{blob["sha256"]}"')
            self.assertTrue(info.accept_ranges)
            meta = blob["meta"]
            self.assertEqual(info.shape, tuple(meta["shape"]))
            self.assertEqual(info.dtype, np.dtype(meta["dtype"]))
            if meta.get("cfa"):
                self.assertEqual(info.cfa, meta["cfa"])
            frame = self.lab.read_array(blob)  # checked against its sha256 by the client
            self.assertEqual((frame.shape, frame.dtype), (info.shape, info.dtype))
            self.assertTrue(np.isfinite(frame).all())
            self.assertGreaterEqual(float(frame.min()), 0.0)  # counts, dark-subtracted or not, are not negative
            self.assertGreater(float(frame.mean()), 0.0)
            self.assertEqual(frame.tobytes(), self.stored_file(blob["sha256"]).read_bytes())
            # A band of rows through Range is the same band of the whole frame.
            h = info.shape[0]
            band = self.lab.read_array(blob, rows=(h // 3, h // 3 + 7))
            np.testing.assert_array_equal(band, frame[h // 3:h // 3 + 7])

    def test_the_averaged_frame_reproduces_the_campaigns_noise_figures(self):
        """frame-average records, per CFA channel, the spread of the N-frame average over its most uniform
        window; numpy on the frame served here must find the same figures."""
        blobs = skip_unless_served(self, lambda: self.lab.blobs(self.run_id), "GET /v1/runs/{id}/blobs")
        average = blobs[blobs["kind"] == "average"].iloc[0]
        frame = self.lab.read_array(average)
        self.assertLessEqual(float(frame.max()), average["meta"]["white_level"])
        cfa = self.lab.blob_info(average).cfa  # the colours of (row % 2, col % 2), e.g. RGGB
        noise = self.lab.measurements(self.run_id, step_prefix=f"noise/N{FRAMES}/")
        self.assertEqual(sorted(noise["data.channel"]), ["B", "G", "R"])
        x, y, w, h = (int(v) for v in noise["data.region"].iloc[0])
        planes = {}
        for dy in (0, 1):
            for dx in (0, 1):
                colour = cfa[2 * dy + dx]
                if colour not in planes:  # the first green only, as the campaign keeps it
                    planes[colour] = frame[y + (dy - y) % 2:y + h:2, x + (dx - x) % 2:x + w:2]
        for _, m in noise.iterrows():
            spread = float(np.std(planes[m["data.channel"]], ddof=1, dtype=np.float64))
            self.assertAlmostEqual(spread, m["value"], delta=1e-4 * m["value"], msg=m["step"])

    def test_raw_files_and_previews(self):
        blobs = skip_unless_served(self, lambda: self.lab.blobs(self.run_id), "GET /v1/runs/{id}/blobs")
        for _, blob in blobs.iterrows():
            if blob["media_type"] == "application/x-colorlab-array":
                png = self.lab.preview(blob)
                self.assertEqual(png[:8], b"\x89PNG\r\n\x1a\n")
                continue
            data = self.lab.read_blob(blob)
            self.assertEqual(len(data), blob["size"])
            self.assertEqual(self.lab.read_blob(blob, 0, 16), data[:16])
            self.assertEqual(self.lab.read_blob(blob, len(data) - 5), data[-5:])
            if blob["media_type"] in ("image/x-adobe-dng", "image/tiff"):
                self.assertIn(data[:4], (b"II*\x00", b"MM\x00*"))  # TIFF's byte-order mark (a DNG is a TIFF)
            if blob["media_type"] == "image/jpeg":
                self.assertEqual(data[:2], b"\xff\xd8")
            if blob["media_type"] == "image/png":
                self.assertEqual(data[:8], b"\x89PNG\r\n\x1a\n")
            self.assertEqual(data, self.stored_file(blob["sha256"]).read_bytes())

    def test_an_unknown_blob_is_not_found(self):
        skip_unless_served(self, lambda: self.lab.blobs(self.run_id), "GET /v1/runs/{id}/blobs")
        with self.assertRaises(colorlab.NotFound) as caught:
            self.lab.read_blob("0" * 64)
        self.assertNotIn("no route", caught.exception.detail)


class SpectraTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.daemon = Daemon()
        cls.addClassCleanup(cls.daemon.cleanup)  # also when the rest of setUpClass fails
        cls.lab = cls.daemon.client
        cls.daemon.wait_ready("spectrolino")
        cls.run_id = cls.daemon.run_to_end("chart-read", chart="cc24", confirm_load=False)["run_id"]
        cls.reference = cls.daemon.stored_measurements(cls.run_id)


    def test_spectra_by_wavelength_equal_the_stored_readings(self):
        spectra = skip_unless_served(self, lambda: self.lab.spectra(self.run_id), "GET /v1/runs/{id}/measurements")
        self.assertEqual(list(spectra.columns), [m["step"] for m in self.reference])
        self.assertEqual(len(spectra.columns), 24)
        for m in self.reference:
            d = m["data"]
            wl = d["first_nm"] + d["step_nm"] * np.arange(len(d["values"]))
            np.testing.assert_array_equal(spectra.index.to_numpy(), wl)
            self.assertEqual(spectra[m["step"]].tolist(), d["values"])
        # The Spectrolino's range (380–730 nm in 10 nm bands) and reflectance factors of a printed chart.
        self.assertEqual((spectra.index[0], spectra.index[-1], len(spectra)), (380.0, 730.0, 36))
        self.assertTrue(((spectra.to_numpy() > 0) & (spectra.to_numpy() < 1.2)).all())

    def test_the_frame_holds_the_colorimetry_as_arrays(self):
        df = skip_unless_served(self, lambda: self.lab.measurements(self.run_id, quantity="reflectance_spectrum"),
                                "GET /v1/runs/{id}/measurements")
        self.assertEqual(len(df), 24)
        for (_, row), m in zip(df.iterrows(), self.reference):
            np.testing.assert_array_equal(row["data.XYZ"], m["data"]["XYZ"])
            np.testing.assert_array_equal(row["data.Lab"], m["data"]["Lab"])
            self.assertEqual(row["value"], m["data"]["Lab"][0])  # the script records L* as the value
            self.assertEqual(row["data.values"].shape, (36,))

    def test_the_ti3_export_carries_the_stored_spectra(self):
        ti3 = skip_unless_served(self, lambda: self.lab.export(self.run_id, "ti3"), "GET /v1/runs/{id}/export")
        table = read_cgats(ti3.decode())
        self.assertEqual(table["keywords"]["NUMBER_OF_SETS"], "24")
        self.assertEqual(len(table["rows"]), 24)
        norm = float(table["keywords"].get("SPECTRAL_NORM", '"1"').strip('"'))
        rows = {row["SAMPLE_ID"].strip('"'): row for row in table["rows"]}
        self.assertEqual(sorted(rows), sorted(m["data"]["id"] for m in self.reference))
        for m in self.reference:
            d = m["data"]
            row = rows[d["id"]]
            spectrum = [float(row[f"SPEC_{int(d['first_nm'] + i * d['step_nm'])}"]) / norm for i in range(len(d["values"]))]
            # Printed with 6 decimals (spectra on the 0..SPECTRAL_NORM scale): within half the last digit.
            np.testing.assert_allclose(spectrum, d["values"], rtol=0, atol=0.51e-6 / norm)
            np.testing.assert_allclose([float(row[f"LAB_{c}"]) for c in "LAB"], d["Lab"], rtol=0, atol=0.51e-6)


def read_cgats(text: str) -> dict:
    """Just enough CGATS to read a table: keywords, the data format's field names, the rows by field."""
    keywords, fields, rows, section = {}, [], [], None
    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] in ("BEGIN_DATA_FORMAT", "BEGIN_DATA"):
            section = parts[0]
        elif parts[0] in ("END_DATA_FORMAT", "END_DATA"):
            section = None
        elif section == "BEGIN_DATA_FORMAT":
            fields += parts
        elif section == "BEGIN_DATA":
            rows.append(dict(zip(fields, parts)))
        elif len(parts) >= 2:
            keywords[parts[0]] = line.split(None, 1)[1].strip()
    return {"keywords": keywords, "fields": fields, "rows": rows}


if __name__ == "__main__":
    unittest.main()
