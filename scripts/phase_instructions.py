#!/usr/bin/env python3
"""Instructions per line per step, by phase of the step, for whole runs
under callgrind (one thread): the table docs/PERFORMANCE.md holds.

    scripts/phase_instructions.py [--bin BINARY] SCENE:FRAMES ...

SCENE is a course scene's name (read from $SCREENSAVER_REFERENCE, default
../shared/reference) or `gen:LINES` for `screensaver gen --lines LINES
--seed 7`. Each function callgrind reports is put in a phase by its name
(what the compiler inlined counts where it was inlined to); the reading
and writing of files and everything else outside the steps is `rest`.
Callgrind runs the program some 50 times slower than it runs alone.
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

# Phases in the order a step runs them, each with the patterns of the
# functions (self cost) that make it up.
PHASES = [
    ("hulls", [r"hull::make", r"make_hulls", r"MoverCheck::note", r"update::close_up",
               r"near::settle", r"Near::make", r"Near::widen", r"near::widen",
               r"Near::gather", r"Near::mend", r"MendIndex", r"mend::find_runs"]),
    ("layout", [r"boxes::insert", r"__mem(cpy|move)", r"end_guests", r"Layout>::lay_out",
                r"radix_sort", r"BoxSliceMut::copy", r"BoxList::extend", r"sort_nearly_sorted",
                r"sweep::plan::", r"Boxes::sort", r"layout::"]),
    ("sweep and exact tests", [r"scan::", r"lay_out_and_sweep", r"sweep_chunks", r"pairs::",
                               r"lanes::intersect", r"lanes::blocks",
                               r"narrow::", r"geometry::", r"test_wild", r"near::"]),
    ("resolution", [r"response::", r"hypot", r"atan2", r"storage::Storage::name_by_id",
                    r"slice::sort"]),
    ("move and walls", [r"advance_and_bounce", r"advance_in_order", r"advance_and_make",
                        r"advance_by_slot"]),
]


def phase_of(name):
    for phase, patterns in PHASES:
        if any(re.search(p, name) for p in patterns):
            return phase
    return "rest"


def run(binary, scene, frames, reference, scratch):
    if scene.startswith("gen:"):
        lines = int(scene[4:])
        path = os.path.join(scratch, f"gen{lines}.in")
        if not os.path.exists(path):
            subprocess.run([binary, "gen", "--lines", str(lines), "--seed", "7", "-o", path],
                           check=True, stdout=subprocess.DEVNULL)
    else:
        path = os.path.join(reference, "inputs", f"{scene}.in")
        with open(path) as f:
            lines = int(f.readline())
    out = os.path.join(scratch, "callgrind.out")
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", binary,
                    str(frames), path, "--threads", "1"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    text = subprocess.run(["callgrind_annotate", "--threshold=100", "--auto=no", out],
                          check=True, capture_output=True, text=True).stdout
    totals = {}
    for row in text.splitlines():
        m = re.match(r"^\s*([\d,]+)\s+\([^)]*\)\s+(.*)$", row)
        if not m or "PROGRAM TOTALS" in row:
            continue
        cost = int(m.group(1).replace(",", ""))
        phase = phase_of(m.group(2))
        totals[phase] = totals.get(phase, 0) + cost
    return lines, totals


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default="target/release/screensaver")
    parser.add_argument("work", nargs="+", help="SCENE:FRAMES")
    args = parser.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    reference = os.environ.get("SCREENSAVER_REFERENCE",
                               os.path.join(here, "..", "..", "shared", "reference"))
    names = [p for p, _ in PHASES]
    print("| scene, frames | " + " | ".join(names) + " | a step in all | rest (whole run) |")
    print("| --- |" + " ---: |" * (len(names) + 2))
    with tempfile.TemporaryDirectory() as scratch:
        for work in args.work:
            scene, frames = work.rsplit(":", 1)
            lines, totals = run(args.bin, scene, int(frames), reference, scratch)
            per = lines * (int(frames) + 1)
            cells = [f"{totals.get(p, 0) / per:.1f}" for p in names]
            step = sum(totals.get(p, 0) for p in names) / per
            rest = totals.get("rest", 0)
            label = f"{lines:,} lines (`gen`)" if scene.startswith("gen:") else f"`{scene}`"
            print(f"| {label}, {frames} | " + " | ".join(cells) +
                  f" | {step:.1f} | {rest / 1e6:.1f} M |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
