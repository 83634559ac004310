#!/usr/bin/env python3
"""What a compile flag costs the build, in CPU seconds that machine load barely changes.

Draws compile units at random from a configured build's compile_commands.json and compiles each twice in a
row, once with each of two flag spellings (interleaved, so both see the same load), without ccache, timing
user + sys of the compiler. A whole cold build cannot be timed on a shared machine; its CPU seconds can be
estimated from a fair sample.

  bench/build/compile_flag_cost.py --build build --replace=-g1 --by=-g --sample 24 --seed 20261129
"""
import argparse
import json
import os
import random
import resource
import shlex
import subprocess
import sys
import tempfile


def compile_cpu_seconds(argv, cwd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def plain_command(entry, output):
    argv = shlex.split(entry["command"])
    if os.path.basename(argv[0]) == "ccache":
        argv = argv[1:]
    kept = []
    skip_next = False
    for i, arg in enumerate(argv):
        if skip_next:
            skip_next = False
            continue
        if arg in ("-MT", "-MF", "-o"):
            skip_next = True
            if arg == "-o":
                kept += ["-o", output]
            continue
        if arg == "-MD":
            continue
        kept.append(arg)
    return kept


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--replace", required=True, help="the flag as configured, e.g. -g1")
    ap.add_argument("--by", required=True, help="the flag to compare with, e.g. -g")
    ap.add_argument("--sample", type=int, default=24)
    ap.add_argument("--seed", type=int, default=20261129)
    args = ap.parse_args()

    entries = json.load(open(os.path.join(args.build, "compile_commands.json")))
    picked = random.Random(args.seed).sample(entries, min(args.sample, len(entries)))
    out = os.path.join(tempfile.mkdtemp(prefix="flagcost-"), "unit.o")
    total = {args.replace: 0.0, args.by: 0.0}
    for entry in picked:
        configured = plain_command(entry, out)
        if args.replace not in configured:
            sys.exit(f"{entry['file']}: {args.replace} is not in its command; configure the build with it")
        other = [args.by if a == args.replace else a for a in configured]
        a = compile_cpu_seconds(configured, entry["directory"])
        b = compile_cpu_seconds(other, entry["directory"])
        total[args.replace] += a
        total[args.by] += b
        print(f"{a:7.2f} {b:7.2f}  {os.path.relpath(entry['file'], entry['directory'])}", flush=True)
    os.remove(out)
    n = len(picked)
    ratio = total[args.replace] / total[args.by]
    print(f"{args.replace}: {total[args.replace]:.1f} CPU s over {n} units; {args.by}: {total[args.by]:.1f}; "
          f"ratio {ratio:.3f}; scaled to all {len(entries)} units: "
          f"{total[args.by] / n * len(entries):.0f} -> {total[args.replace] / n * len(entries):.0f} CPU s")


if __name__ == "__main__":
    main()
