#!/usr/bin/python3
"""A week of nights (issue 27): the dissertation study queued night after night on colorlabd's embedded simulated
lab, time-scaled, with kill -9 of the daemon at seeded random moments on some nights, the console open in headless
Chromium and two followers on the event stream all along, sampled every --sample-every seconds.

  nice -n 19 /usr/bin/python3 bench/soak/week.py --out build/soak-week [--nights 7] [--time-scale 100]

Writes into --out: samples.csv (one row per sample), nights.json (each night: its items, runs, kills and ledger),
summary.json (the checks and the growth), week.png (bench/soak/plot.py). Night 1 is never killed: it is the
reference every other night's runs are compared with (rows and shape digest per run; bench/soak/ledger.py).
Exit 0 when every check held, 1 when one did not (printed), 2 for bad usage.
"""
from __future__ import annotations

import argparse
import random
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from checks import compare_nights, growth  # noqa: E402
from night import enqueue, run_night  # noqa: E402
from soak import Soak, wait_followers_caught_up, write_json  # noqa: E402


def parse(argv):
    p = argparse.ArgumentParser(prog="week.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, required=True, help="directory for samples.csv, nights.json, summary.json")
    p.add_argument("--nights", type=int, default=7)
    p.add_argument("--killed-nights", type=int, default=3, help="how many nights (never the first) get kills")
    p.add_argument("--kills-per-night", type=int, default=2)
    p.add_argument("--time-scale", type=float, default=100, help="lab seconds per wall second")
    p.add_argument("--seed", type=int, default=27, help="the simulated lab's seed and the kills' random seed")
    p.add_argument("--sample-every", type=float, default=60.0, help="seconds between samples")
    p.add_argument("--sequence", default="dissertation")
    p.add_argument("--small", action="store_true", help="the sequence's small variant (a quick look)")
    p.add_argument("--night-timeout", type=float, default=1800.0, help="a night that takes longer fails the soak")
    p.add_argument("--stop-by", help="UTC HH:MM: start no night that the first night's length says ends later")
    a = p.parse_args(argv)
    if a.nights < 1 or a.killed_nights >= a.nights and a.nights > 1 or a.killed_nights < 0:
        p.error("--killed-nights must be below --nights (night 1 is the unkilled reference)")
    return a


def without_kept(kill: dict) -> dict:
    """A kill as printed: its re-read of every run's rows is for the check, not the console."""
    return {k: v for k, v in kill.items() if k != "kept"}


def stop_by(hhmm: str | None) -> float | None:
    if not hhmm:
        return None
    now = datetime.now(timezone.utc)
    h, m = (int(x) for x in hhmm.split(":"))
    return now.replace(hour=h, minute=m, second=0, microsecond=0).timestamp()


def main(argv=None) -> int:
    a = parse(sys.argv[1:] if argv is None else argv)
    rng = random.Random(a.seed)
    killed = set(rng.sample(range(2, a.nights + 1), min(a.killed_nights, a.nights - 1)))
    deadline = stop_by(a.stop_by)
    soak = Soak(a.out, time_scale=a.time_scale, seed=a.seed, sample_every=a.sample_every)
    nights: list[dict] = []
    meta = {"command": " ".join(sys.argv), "time_scale": a.time_scale, "seed": a.seed, "sequence": a.sequence,
            "small": a.small, "sample_every_s": a.sample_every, "killed_nights": sorted(killed),
            "started_utc": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    try:
        soak.wait_instruments()
        for n in range(1, a.nights + 1):
            if deadline and nights and time.time() + nights[0]["wall_s"] * 1.2 > deadline:
                meta["stopped_early"] = f"night {n} would end after {a.stop_by} UTC; {len(nights)} nights run"
                print(f"soak: {meta['stopped_early']}", flush=True)
                break
            kill_at = []
            if n in killed:
                # Over the shortest unkilled night so far: a moment past a night's end would be no kill at all.
                span = min(x["wall_s"] for x in nights if not x["kills"])
                kill_at = sorted(round(rng.uniform(0.05, 0.9) * span, 1) for _ in range(a.kills_per_night))
            soak.sampler.night = n
            queued = enqueue(soak.lab, sequence=a.sequence, small=a.small)
            print(f"soak: night {n} queued (group {queued['group_id']}); kills at {kill_at or 'none'} s", flush=True)
            result = run_night(soak.lab, n, queued, kill_at, timeout=a.night_timeout,
                               on_kill=lambda k: print(f"soak: kill -9 {without_kept(k)}", flush=True))
            nights.append(result)
            write_json(a.out / "nights.json", {"meta": meta, "nights": nights})
            print(f"soak: night {n} {result['state']} in {result['wall_s']} s; rows "
                  f"{sum(v['rows'] for v in result['ledger'].values())}", flush=True)
        soak.sampler.night = -1  # after the last night: the idle tail, in no night's figures
        wait_followers_caught_up(soak)
        probes = soak.finish()
    finally:
        soak.close()
    meta["ended_utc"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
    checks = compare_nights(nights)
    summary = {"meta": meta, "probes": probes, "checks": checks,
               "growth": growth(a.out / "samples.csv", time_scale=a.time_scale)}
    write_json(a.out / "nights.json", {"meta": meta, "nights": nights})
    write_json(a.out / "summary.json", summary)
    from plot import plot
    plot(a.out / "samples.csv", a.out / "week.png", title=f"colorlabd soak: {len(nights)} {a.sequence} nights, "
         f"time scale {a.time_scale:g}, kills on nights {sorted(killed) or 'none'}")
    problems = checks["problems"] + [f"sample error: {e}" for e in probes["sample_errors"]] + \
        [f"follower {f['name']}: {f}" for f in probes["followers"]
         if f["duplicates"] or f["gaps"] or f["error"] or f["last_seq"] != probes["log_last_seq"]]
    for line in problems:
        print(f"soak: PROBLEM: {line}", flush=True)
    print(f"soak: {len(nights)} nights, {probes['samples']} samples, {len(probes['kills'])} kills; "
          f"{'all checks held' if not problems else f'{len(problems)} problems'}; {a.out}", flush=True)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
