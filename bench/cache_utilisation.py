#!/usr/bin/env python3
"""How busy a diagnosis kept the cores, read from its cache folder (issue 7's speed work).

    python3 bench/cache_utilisation.py CACHE_DIR [--cores 2]

Each rig run of the cache keeps its repeats in CACHE_DIR/run_<rig>_<id>/repeat_K/result.json
(written by `clumpkit compare|diagnose|synth --cache`), each with its wall seconds; the file's
modification time is when the repeat ended. From these the repeats' spans are rebuilt (since
session 48 the repeats of one run may run at the same time, so spans are per repeat, not per
run) and the script prints the number of runs and repeats, the span from the first start to
the last end, the busy seconds, the utilisation (busy / (cores x span)), the time with only one
repeat running and with none, and the mean wall time per repeat by rig. Copying the folder
without keeping modification times (cp -p, rsync -t) makes the figures meaningless."""
import argparse
import collections
import glob
import json
import os
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cache")
    ap.add_argument("--cores", type=int, default=2)
    a = ap.parse_args()
    runs = glob.glob(os.path.join(a.cache, "*.json"))
    jobs = []  # one per repeat: (start, end, wall, rig)
    for f in sorted(glob.glob(os.path.join(a.cache, "run_*", "repeat_*", "result.json"))):
        try:
            wall = float(json.load(open(f))["wall_seconds"])
        except (OSError, ValueError, KeyError) as e:
            sys.exit(f"{f}: not a clumpkit repeat result ({e})")
        end = os.path.getmtime(f)
        rig = os.path.basename(os.path.dirname(os.path.dirname(f)))[4:].rsplit("_", 1)[0]
        jobs.append((end - wall, end, wall, rig))
    if not jobs:
        sys.exit(f"{a.cache}: no repeats of cached rig runs (run_*/repeat_*/result.json)")
    start = min(j[0] for j in jobs)
    stop = max(j[1] for j in jobs)
    busy = sum(j[2] for j in jobs)
    events = sorted([(j[0], 1) for j in jobs] + [(j[1], -1) for j in jobs])
    running, last, one, none = 0, start, 0.0, 0.0
    for t, d in events:
        if running == 1:
            one += t - last
        elif running == 0:
            none += t - last
        running += d
        last = t
    span = stop - start
    print(f"{len(runs)} runs, {len(jobs)} repeats, span {span:.0f} s, "
          f"busy {busy:.0f} s, utilisation {busy / (a.cores * span):.2f}")
    print(f"one repeat running {one:.0f} s, none {none:.0f} s")
    per = collections.defaultdict(list)
    for j in jobs:
        per[j[3]].append(j[2])
    for rig, v in sorted(per.items()):
        print(f"{rig}: {len(v)} repeats, {sum(v) / len(v):.1f} s per repeat")


if __name__ == "__main__":
    main()
