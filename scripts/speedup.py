#!/usr/bin/env python3
"""Side-by-side speed comparison of screensaver configurations.

Runs every configuration on every workload, interleaved round by round (so
that machine noise hits all of them alike), reads the simulation time that
the program prints (`--json`: elapsed_seconds, the simulation loop only),
and prints a Markdown table of medians and of ratios to the first
configuration. With `--measure instructions` it counts the instructions
of whole runs under `valgrind --tool=callgrind` instead (repeatable on a
noisy machine; one run each is enough).

  scripts/speedup.py [--bin target/release/screensaver] [--runs 5]
                     [--measure time|instructions]
                     [--ref ../shared/reference]
                     [--work mit:400 --work koch:20 ...]
                     [--config "brute=--detector brute" --config "quadtree=" ...]

A workload is SCENE:FRAMES, SCENE being a course scene name (read from
REF/inputs) or `default` for the built-in scene. A configuration's
arguments may start with `@PATH` to run another binary (an older build,
say) instead of --bin: --config "before=@/tmp/old/screensaver --threads 1".
"""
import argparse
import json
import os
import re
import shlex
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run(binary, args, frames, scene_path, measure):
    cmd = [binary, "--json"] + args + [str(frames)] + ([scene_path] if scene_path else [])
    if measure == "instructions":
        cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null"] + cmd
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    result = json.loads(p.stdout)
    counts = (result["line_wall_collisions"], result["line_line_collisions"])
    if measure == "instructions":
        return int(re.search(r"Collected : (\d+)", p.stderr).group(1)), counts
    return result["elapsed_seconds"], counts


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "screensaver"))
    ap.add_argument("--ref", default=os.environ.get("SCREENSAVER_REFERENCE", os.path.join(ROOT, "..", "shared", "reference")))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--measure", choices=["time", "instructions"], default="time")
    ap.add_argument("--work", action="append", default=[])
    ap.add_argument("--config", action="append", default=[])
    a = ap.parse_args()
    works = a.work or ["mit:400", "koch:20"]
    configs = a.config or ["brute=--detector brute", "quadtree=--detector quadtree", "sweep=--detector sweep"]
    configs = [(c.split("=", 1)[0], shlex.split(c.split("=", 1)[1] if "=" in c else "")) for c in configs]
    binaries = {}
    for name, args in configs:
        binaries[name] = args.pop(0)[1:] if args and args[0].startswith("@") else a.bin

    rows = []
    for work in works:
        scene, frames = work.rsplit(":", 1)
        path = None if scene == "default" else os.path.join(a.ref, "inputs", scene + ".in")
        times = {name: [] for name, _ in configs}
        counts = {}
        for _ in range(a.runs):
            for name, args in configs:
                t, c = run(binaries[name], args, int(frames), path, a.measure)
                times[name].append(t)
                counts.setdefault(name, c)
        if len(set(counts.values())) != 1:
            sys.exit("configurations disagree on %s: %s" % (work, counts))
        base = statistics.median(times[configs[0][0]])
        for name, _ in configs:
            m = statistics.median(times[name])
            rows.append((work, name, m, base / m if m > 0 else float("inf"), counts[name]))

    what = "median simulation time" if a.measure == "time" else "instructions (whole run)"
    print("| workload | configuration | %s | speed-up vs %s | wall, line collisions |" % (what, configs[0][0]))
    print("| --- | --- | ---: | ---: | --- |")
    for work, name, m, ratio, c in rows:
        value = "%.6f s" % m if a.measure == "time" else "{:,}".format(int(m))
        print("| %s | %s | %s | %.2fx | %d, %d |" % (work, name, value, ratio, c[0], c[1]))


if __name__ == "__main__":
    main()
