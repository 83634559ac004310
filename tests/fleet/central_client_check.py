"""The Python client against a bench and against colorlab-central, with only the URL changed: the same
DataFrames (measurements, spectra, a run's blobs) and the same export bytes. Run by central_test.cpp:
central_client_check.py BENCH_URL CENTRAL_URL KEY RUN_ID [RUN_ID ...]; exits non-zero on any difference."""
import sys

import pandas.testing as pdt

from colorlab import Client


def main() -> int:
    bench_url, central_url, key, *runs = sys.argv[1:]
    bench = Client(bench_url, key=None)  # loopback reads need no key on a bench
    central = Client(central_url, key=key)
    for run in runs:
        pdt.assert_frame_equal(central.measurements(run), bench.measurements(run))
        pdt.assert_frame_equal(central.spectra(run), bench.spectra(run))
        blobs_c, blobs_b = central.blobs(run), bench.blobs(run)
        # Central renders no previews, so its blob rows carry no preview link.
        keep = [c for c in blobs_b.columns if "preview" not in c and not c.startswith("links")]
        pdt.assert_frame_equal(blobs_c[[c for c in keep if c in blobs_c.columns]], blobs_b[keep])
        assert len(blobs_c) == len(blobs_b), f"run {run}: {len(blobs_c)} blobs on central, {len(blobs_b)} on the bench"
        for sha in (blobs_b["sha256"] if len(blobs_b) else []):
            assert central.read_blob(sha) == bench.read_blob(sha), f"blob {sha} differs"
            assert central.read_blob(sha, 10, 100) == bench.read_blob(sha, 10, 100), f"blob {sha}[10:100] differs"
        doc_c, doc_b = dict(central.run(run)), dict(bench.run(run))
        doc_c.pop("bench")
        doc_c["links"].pop("report", None)
        doc_b["links"].pop("report", None)
        assert doc_c == doc_b, f"run {run}: {doc_c} != {doc_b}"
        assert central.export(run, "csv") == bench.export(run, "csv"), f"run {run}: csv exports differ"
    runs_c = central.runs()
    assert set(runs) <= set(runs_c["id"]), "central's run list lacks the bench's runs"
    print(f"equal DataFrames for {len(runs)} runs from {bench_url} and {central_url}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
