#!/usr/bin/env python3
"""Does a small file's fdatasync (the WAL's, at each commit) wait behind another file's large write being flushed
(the blob store writing a photograph and fsyncing it)? On ext4 with data=ordered, a sync of one file can wait for
another's dirty data in the same journal transaction; if it did here, a step's commit beside a photograph's write
would hold SQLite's write lock that long.

One thread appends 16 KB to a file and fdatasyncs it every 5 ms (an appended file: each sync also writes its new
size, a worse case than SQLite's reused WAL); after a second alone, the main thread writes --blob-mb MB of random
data to another file, fsyncs it, renames it and fsyncs the directory (as blob_store.cpp does), --blobs times, a
second apart. Prints the small syncs alone, and those that overlapped a large file's write-and-fsync window beside
that window's fsync. A small sync can only show a wait as long as the large flush it sat behind, so --blob-mb
sets how long a wait this can reveal; run it on the disk colorlabd's state is on.

Usage: bench/daemon/sync_beside_blob.py [--dir /var/tmp] [--blob-mb 20] [--blobs 5]
"""
import argparse
import os
import tempfile
import threading
import time


def pct(sorted_ms, p):
    return sorted_ms[min(len(sorted_ms) - 1, int(len(sorted_ms) * p))]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", default="/var/tmp")
    ap.add_argument("--blob-mb", type=int, default=20)
    ap.add_argument("--blobs", type=int, default=5)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(dir=a.dir, prefix="sync-beside-blob-") as d:
        small, stop = [], threading.Event()  # (start, end, ms) of each small sync, perf_counter seconds

        def small_syncs():
            fd = os.open(os.path.join(d, "wal"), os.O_WRONLY | os.O_CREAT | os.O_APPEND)
            while not stop.is_set():
                os.write(fd, b"w" * 16384)
                t = time.perf_counter()
                os.fdatasync(fd)
                e = time.perf_counter()
                small.append((t, e, (e - t) * 1000))
                time.sleep(0.005)
            os.close(fd)

        th = threading.Thread(target=small_syncs)
        th.start()
        time.sleep(1)
        alone = sorted(ms for _, _, ms in small)
        chunk = os.urandom(1 << 20)
        windows = []  # (start, end, the large fsync's ms)
        dfd = os.open(d, os.O_RDONLY | os.O_DIRECTORY)
        for i in range(a.blobs):
            w0 = time.perf_counter()
            tmp = os.path.join(d, f"blob{i}.part")
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            for _ in range(a.blob_mb):
                os.write(fd, chunk)
            t = time.perf_counter()
            os.fsync(fd)
            f_ms = (time.perf_counter() - t) * 1000
            os.close(fd)
            os.rename(tmp, os.path.join(d, f"blob{i}"))
            os.fsync(dfd)
            windows.append((w0, time.perf_counter(), f_ms))
            time.sleep(1)
        os.close(dfd)
        stop.set()
        th.join()
    print(f"small fdatasync alone: n={len(alone)} p50={pct(alone, .5):.1f} max={alone[-1]:.1f} ms")
    for i, (w0, w1, f_ms) in enumerate(windows):
        inside = sorted(ms for t, e, ms in small if t < w1 and e > w0)
        print(f"large write {i + 1} ({a.blob_mb} MB; its fsync {f_ms:.0f} ms, window {(w1 - w0) * 1000:.0f} ms): "
              f"{len(inside)} small syncs overlapped it, longest {max(inside, default=0):.1f} ms")


if __name__ == "__main__":
    main()
