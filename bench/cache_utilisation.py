#!/usr/bin/env python3
"""How busy a diagnosis kept the cores, read from its cache folder (issue 7's speed work).

    python3 bench/cache_utilisation.py CACHE_DIR [--cores 2]

Each cached rig result (CACHE_DIR/*.json, written by `clumpkit compare|diagnose|synth --cache`)
holds its repeats' wall seconds; the file's modification time is when the job ended. From these
the jobs' spans are rebuilt and the script prints the number of jobs and repeats, the span from
the first start to the last end, the busy seconds, the utilisation (busy / (cores x span)), the
time with only one job running and with none, and the mean wall time per repeat by rig. Copying
the folder without keeping modification times (cp -p, rsync -t) makes the figures meaningless."""
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
    jobs = []
    for f in sorted(glob.glob(os.path.join(a.cache, "*.json"))):
        try:
            result = json.load(open(f))["result"]
        except (OSError, ValueError, KeyError) as e:
            sys.exit(f"{f}: not a clumpkit cache entry ({e})")
        wall = sum(r.get("wall_seconds", 0.0) for r in result["repeats"])
        end = os.path.getmtime(f)
        rig = os.path.basename(f).rsplit("_", 1)[0]
        jobs.append((end - wall, end, wall, rig, len(result["repeats"])))
    if not jobs:
        sys.exit(f"{a.cache}: no cached rig results (*.json)")
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
    print(f"{len(jobs)} jobs, {sum(j[4] for j in jobs)} repeats, span {span:.0f} s, "
          f"busy {busy:.0f} s, utilisation {busy / (a.cores * span):.2f}")
    print(f"one job running {one:.0f} s, none {none:.0f} s")
    per = collections.defaultdict(list)
    for j in jobs:
        per[j[3]].append(j[2] / j[4])
    for rig, v in sorted(per.items()):
        print(f"{rig}: {len(v)} jobs, {sum(v) / len(v):.1f} s per repeat")


if __name__ == "__main__":
    main()
