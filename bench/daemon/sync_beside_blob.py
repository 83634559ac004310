#!/usr/bin/env python3
"""Does a small file's fdatasync (the WAL's, at each commit) wait behind another file's large write being flushed
(the blob store writing a photograph and fsyncing it)? On ext4 with data=ordered, a sync of one file can wait for
another's dirty data in the same journal transaction; if it did here, a step's commit beside a photograph's write
would hold SQLite's write lock that long.

One thread appends 16 KB to a file and fdatasyncs it every 5 ms; after a second alone, the main thread writes
--blob-mb MB of random data to another file and fsyncs it, --blobs times, a second apart. Prints the small sync's
latency alone and during the writes, and each large fsync's time. Run it on the disk colorlabd's state is on.

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
        small_ms, stop = [], threading.Event()

        def small():
            fd = os.open(os.path.join(d, "wal"), os.O_WRONLY | os.O_CREAT | os.O_APPEND)
            while not stop.is_set():
                os.write(fd, b"w" * 16384)
                t = time.perf_counter()
                os.fdatasync(fd)
                small_ms.append((time.perf_counter() - t) * 1000)
                time.sleep(0.005)
            os.close(fd)

        th = threading.Thread(target=small)
        th.start()
        time.sleep(1)
        alone = sorted(small_ms)
        n_alone = len(small_ms)
        chunk = os.urandom(1 << 20)
        blob_ms = []
        for i in range(a.blobs):
            fd = os.open(os.path.join(d, f"blob{i}"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            for _ in range(a.blob_mb):
                os.write(fd, chunk)
            t = time.perf_counter()
            os.fsync(fd)
            blob_ms.append((time.perf_counter() - t) * 1000)
            os.close(fd)
            time.sleep(1)
        stop.set()
        th.join()
        during = sorted(small_ms[n_alone:])
    print(f"small fdatasync alone: n={len(alone)} p50={pct(alone, .5):.1f} max={alone[-1]:.1f} ms")
    print(f"small fdatasync beside {a.blobs} x {a.blob_mb} MB writes: n={len(during)} p50={pct(during, .5):.1f} "
          f"p99={pct(during, .99):.1f} max={during[-1]:.1f} ms, over 50 ms: {sum(1 for x in during if x > 50)}")
    print("the large writes' fsyncs: " + ", ".join(f"{x:.0f}" for x in blob_ms) + " ms")


if __name__ == "__main__":
    main()
