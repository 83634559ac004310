#!/usr/bin/env python3
"""Records the committed simulator transcripts (sim-<kind>.jsonl) with colorlab doctor and gives each
its expected values from colorlab-sim's ground truth, read on its control channel — never from
colorlab's own decoding, which is what the replay then checks.

    python3 tests/transcripts/record_from_sim.py [--build build] [--out tests/transcripts]

Run it again when the probing order or a driver's requests change (the replay says so); the
recordings of real instruments in this folder are never re-recorded by it.
"""
import argparse
import json
import os
import pathlib
import socket
import subprocess
import sys
import tempfile

SEED = 7
TIME_SCALE = 1000
SOURCE = ("simulator ground truth: colorlab-sim's control channel {\"cmd\":\"truth\"} (seed %d, time scale %d), "
          "read around the reading; not colorlab's decoding" % (SEED, TIME_SCALE))


def truth(sock):
    s = socket.socket(socket.AF_UNIX)
    s.settimeout(30)
    s.connect(str(sock))
    s.sendall(b'{"cmd":"truth"}\n')
    buf = b""
    while not buf.endswith(b"\n"):
        chunk = s.recv(65536)
        if not chunk:
            raise RuntimeError("the simulator closed its control channel")
        buf += chunk
    s.close()
    return json.loads(buf)


def expected_for(kind, before, after):
    base = {"verdict": {"value": "identified"}, "kind": {"value": kind}}
    if kind == "ls110":
        a, b = before["ls110"], after["ls110"]
        # The meter's noise (5 sigma), any change of the true luminance between the two looks (lamps
        # warming up), and the reply's two decimals ("OK00,%9.2f").
        value = (a["luminance"] + b["luminance"]) / 2
        tol = 5 * max(a["noise_sigma"], b["noise_sigma"]) + abs(a["luminance"] - b["luminance"]) / 2 + 0.005
        base["luminance"] = {"value": value, "tolerance": tol, "unit": "cd/m2"}
        note = ("luminance: the true luminance at the meter's aim (truth.ls110.luminance, mean of before and after), "
                "tolerance 5 x truth.ls110.noise_sigma + half their difference + the reply's rounding")
    elif kind == "spectrolino":
        s = after["spectrolino"]
        base["serial"] = {"value": s["serial"]}
        if "table_serial" in s:
            base["table_serial"] = {"value": s["table_serial"]}
        base["spectrum"] = {"value": s["last_spectrum"], "tolerance": 1e-6}
        note = ("serial, table_serial: the simulated devices' configured serials (truth.spectrolino); spectrum: the "
                "spectrum the simulator sent for the white-tile reading (truth.spectrolino.last_spectrum, float32)")
    elif kind == "dmx":
        base["serial"] = {"value": after["dmx"]["serial"]}
        # The firmware the simulated widget is documented to run (docs/simulator.md), written here as a
        # person reads it off the widget's label, not derived from any codec: OLA's detection of the
        # simulated widget (tests/clients) reads the same.
        base["firmware"] = {"value": "1.44"}
        note = ("serial: as printed on the widget's label (truth.dmx.serial); firmware: the simulated widget's "
                "documented 1.44 (docs/simulator.md), as OLA 0.10 also reads it")
    else:
        raise ValueError(kind)
    return base, note


def main():
    ap = argparse.ArgumentParser()
    here = pathlib.Path(__file__).resolve().parent
    ap.add_argument("--build", default=str(here.parent.parent / "build"))
    ap.add_argument("--out", default=str(here))
    args = ap.parse_args()
    bindir = pathlib.Path(args.build) / "bin"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        (tmp / "lab.toml").write_text("[genicam]\nenabled = false\n")
        sim = subprocess.Popen([str(bindir / "colorlab-sim"), "--config", str(tmp / "lab.toml"), "--seed", str(SEED),
                                "--time-scale", str(TIME_SCALE), "--control", str(tmp / "sim.sock")],
                               stdout=subprocess.PIPE, stderr=open(tmp / "sim.log", "w"), text=True)
        try:
            announcement = json.loads(sim.stdout.readline())
            ports = {i["kind"]: i["port"] for i in announcement["instruments"] if "port" in i}
            for kind in ("ls110", "spectrolino", "dmx"):
                before = truth(tmp / "sim.sock")
                rec = tmp / kind
                r = subprocess.run([str(bindir / "colorlab"), "--json", "doctor", "--no-host", "--no-gige", "--measure", "--yes",
                                    "--port", "%s=%s" % (ports[kind], kind), "--record", str(rec)],
                                   capture_output=True, text=True, timeout=300)
                if r.returncode != 0:
                    sys.exit("colorlab doctor on the simulated %s: exit %d\n%s%s" % (kind, r.returncode, r.stdout, r.stderr))
                after = truth(tmp / "sim.sock")
                files = sorted(rec.glob("*.jsonl"))
                lines = [json.loads(l) for l in files[0].read_text().splitlines()]
                expected, note = expected_for(kind, before, after)
                lines[0]["recorded_from"] = "colorlab-sim (simulated lab), by tests/transcripts/record_from_sim.py"
                lines[-1] = {"expected": expected, "source": SOURCE, "note": note}
                out = pathlib.Path(args.out) / ("sim-%s.jsonl" % kind)
                out.write_text("".join(json.dumps(l, separators=(",", ":")) + "\n" for l in lines))
                print("wrote", out)
        finally:
            sim.terminate()
            sim.wait(timeout=30)


if __name__ == "__main__":
    main()
