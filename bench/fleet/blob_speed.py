#!/usr/bin/env python3
"""A blob through colorlab-central vs the same object straight from the bucket with curl, side by side in one run
(issue 22, "Speed"):

A one-replica Swift with s3api (tests/fleet/swift_aio.sh, storage on disk) and a throwaway PostgreSQL hold one
object of SIZE_MB random bytes under sha256/<hex> and its catalog row. Then, in rounds of A then B, curl
downloads it to /dev/null:
  A  straight from the bucket (a GET signed with SigV4 here, the headers handed to curl);
  B  through colorlab-central (GET /v1/blobs/<hex>, which relays the bucket's answer as it comes).
curl's own %{speed_download} is the figure; central's peak resident memory (VmHWM) when started and after all
rounds shows whether it held the object (the growth must stay far below SIZE_MB).

Usage: nice -n 10 python3 bench/fleet/blob_speed.py --build build [--size-mb 256] [--rounds 3]
Run as root (initdb runs as the `postgres` user), Swift and memcached installed. Prints one JSON document.
"""
import argparse
import datetime
import hashlib
import hmac
import http.client
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time

from central_load import PG_BIN, as_postgres, free_port, psql, start_postgres

ACCESS, SECRET, REGION = "test:tester", "testing", "us-east-1"
HERE = os.path.dirname(os.path.abspath(__file__))


def sigv4_headers(method, host, path, payload_sha256):
    """The headers of one path-style S3 request signed with SigV4 (AWS's documented algorithm)."""
    now = datetime.datetime.now(datetime.timezone.utc)
    amz_date, day = now.strftime("%Y%m%dT%H%M%SZ"), now.strftime("%Y%m%d")
    signed = "host;x-amz-content-sha256;x-amz-date"
    canonical = "\n".join([method, path, "", f"host:{host}", f"x-amz-content-sha256:{payload_sha256}",
                           f"x-amz-date:{amz_date}", "", signed, payload_sha256])
    scope = f"{day}/{REGION}/s3/aws4_request"
    to_sign = "\n".join(["AWS4-HMAC-SHA256", amz_date, scope, hashlib.sha256(canonical.encode()).hexdigest()])
    key = ("AWS4" + SECRET).encode()
    for part in (day, REGION, "s3", "aws4_request"):
        key = hmac.new(key, part.encode(), hashlib.sha256).digest()
    signature = hmac.new(key, to_sign.encode(), hashlib.sha256).hexdigest()
    return {"x-amz-date": amz_date, "x-amz-content-sha256": payload_sha256,
            "Authorization": f"AWS4-HMAC-SHA256 Credential={ACCESS}/{scope}, SignedHeaders={signed}, "
                             f"Signature={signature}"}


def s3(port, method, path, body=None, body_sha256=hashlib.sha256(b"").hexdigest(), length=0):
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=600)
    headers = sigv4_headers(method, f"127.0.0.1:{port}", path, body_sha256)
    headers["Content-Length"] = str(length)
    conn.request(method, path, body=body, headers=headers)
    r = conn.getresponse()
    text = r.read()
    conn.close()
    return r.status, text


def curl(url, headers):
    argv = ["curl", "-s", "-o", "/dev/null", "-w", "%{http_code} %{size_download} %{speed_download} %{time_total}"]
    for k, v in headers.items():
        argv += ["-H", f"{k}: {v}"]
    code, size, speed, total = subprocess.run(argv + [url], capture_output=True, text=True, check=True).stdout.split()
    if code != "200":
        raise SystemExit(f"{url}: HTTP {code}")
    return {"bytes": int(size), "mb_per_s": round(float(speed) / 1e6, 1), "s": round(float(total), 3)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--size-mb", type=int, default=256)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    root = tempfile.mkdtemp(prefix="colorlab-blob-speed-", dir="/var/tmp")  # Swift needs xattrs: not tmpfs
    os.chmod(root, 0o755)
    swift = central = data = None
    try:
        base = free_port()  # and the four after it (swift_aio.sh); a clash shows as a start-up failure
        swift_log = open(os.path.join(root, "swift.log"), "w")
        swift = subprocess.Popen(["bash", os.path.join(HERE, "..", "..", "tests", "fleet", "swift_aio.sh"),
                                  os.path.join(root, "swift"), str(base)], stdout=swift_log, stderr=swift_log,
                                 start_new_session=True)
        deadline = time.monotonic() + 300
        while True:
            try:
                status, _ = s3(base, "PUT", "/central")
                if status in (200, 409):
                    break
            except OSError:
                pass
            if swift.poll() is not None or time.monotonic() > deadline:
                raise SystemExit("Swift did not start; see " + os.path.join(root, "swift.log"))
            time.sleep(0.5)

        blob = os.path.join(root, "blob.bin")
        h = hashlib.sha256()
        with open(blob, "wb") as f:
            for _ in range(a.size_mb):
                chunk = os.urandom(1 << 20)
                h.update(chunk)
                f.write(chunk)
        sha = h.hexdigest()
        size = a.size_mb << 20
        with open(blob, "rb") as f:
            status, text = s3(base, "PUT", f"/central/sha256/{sha}", body=f, body_sha256=sha, length=size)
        if status not in (200, 201):
            raise SystemExit(f"upload: HTTP {status} {text[:300]!r}")
        os.remove(blob)

        data, port = start_postgres(root)
        psql(port, "postgres", "CREATE DATABASE central")
        c = os.path.join(root, "central")
        os.makedirs(c)
        with open(os.path.join(c, "ak"), "w") as f:
            f.write(ACCESS + "\n")
        with open(os.path.join(c, "sk"), "w") as f:
            f.write(SECRET + "\n")
        conf = os.path.join(c, "central.toml")
        with open(conf, "w") as f:
            f.write(f"state_dir = \"{c}/state\"\n[central]\nport = 0\nthreads = 2\n"
                    f"postgres = \"host=127.0.0.1 port={port} dbname=central user=postgres\"\n"
                    f"s3_endpoint = \"http://127.0.0.1:{base}\"\nbucket = \"central\"\nregion = \"{REGION}\"\n"
                    f"access_key_file = \"ak\"\nsecret_key_file = \"sk\"\n")
        ship = os.path.join(root, "ship.toml")
        with open(ship, "w") as f:
            f.write(f"state_dir = \"{root}/bench\"\n[ship]\nbench_id = \"bench-1\"\n"
                    f"postgres = \"host=127.0.0.1 port={port} dbname=central user=postgres\"\n"
                    f"s3_endpoint = \"http://127.0.0.1:{base}\"\nbucket = \"central\"\n"
                    f"access_key_file = \"central/ak\"\nsecret_key_file = \"central/sk\"\n")
        subprocess.run([os.path.join(build, "bin", "colorlab-ship"), "--config", ship, "central-init"], check=True,
                       stdout=subprocess.DEVNULL)
        psql(port, "central", f"INSERT INTO blobs (sha256, size, media_type, meta) VALUES "
                              f"('{sha}', {size}, 'application/octet-stream', '{{}}')")
        central = subprocess.Popen([os.path.join(build, "bin", "colorlab-central"), "--config", conf, "serve"],
                                   stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        central_url = json.loads(central.stdout.readline())["url"]

        def peak_rss_mb():
            with open(f"/proc/{central.pid}/status") as f:
                return round(int(next(line.split()[1] for line in f if line.startswith("VmHWM"))) / 1024, 1)

        idle_rss = peak_rss_mb()

        rounds = []
        for _ in range(a.rounds):
            load = os.getloadavg()
            direct = curl(f"http://127.0.0.1:{base}/central/sha256/{sha}",
                          sigv4_headers("GET", f"127.0.0.1:{base}", f"/central/sha256/{sha}",
                                        hashlib.sha256(b"").hexdigest()))
            relayed = curl(f"{central_url}/v1/blobs/{sha}", {})
            for r in (direct, relayed):
                if r["bytes"] != size:
                    raise SystemExit(f"a download got {r['bytes']} bytes of {size}")
            rounds.append({"bucket_curl": direct, "central": relayed,
                           "ratio": round(relayed["mb_per_s"] / direct["mb_per_s"], 3), "loadavg_before": load})
        print(json.dumps({"size_mb": a.size_mb, "rounds": rounds,
                          "mean_ratio": round(sum(r["ratio"] for r in rounds) / len(rounds), 3),
                          "central_peak_rss_mb": {"started": idle_rss, "after_rounds": peak_rss_mb()},
                          "loadavg_after": os.getloadavg()},
                         indent=1))
    finally:
        if central:
            central.kill()
            central.wait()
        if swift:
            os.killpg(swift.pid, signal.SIGKILL)
            swift.wait()
        if data:
            subprocess.run(as_postgres([f"{PG_BIN}/pg_ctl", "-D", data, "-m", "immediate", "stop"]),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
