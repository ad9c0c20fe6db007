#!/usr/bin/env bash
# How the default thread count holds up beside other work: the tracked
# workloads at the default thread count and at --threads 1, on an idle
# machine, beside one busy process and beside two (`yes > /dev/null`),
# interleaved round by round; prints medians of the simulation time the
# program reports (--json elapsed_seconds) and the ratio of one thread's
# time to the default's (above 1: the default is faster). A benchmark, not
# a test.
#
#   scripts/contention.sh [--rounds N] [--loads "0 1 2"] [--only NAME,...]
#                         [--base OLD_BINARY]
#
# --base runs an older build's default thread count beside the current one
# in the same rounds (its ratio to the current build's default: above 1,
# the current build is faster). BIN (default target/release/screensaver,
# built if missing) and SCREENSAVER_REFERENCE (default ../shared/reference)
# may be set in the environment.
set -euo pipefail
cd "$(dirname "$0")/.."

rounds=5
loads="0 1 2"
only=""
base=""
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) rounds="$2"; shift 2 ;;
        --loads) loads="$2"; shift 2 ;;
        --only) only="$2"; shift 2 ;;
        --base) base="$2"; shift 2 ;;
        *) echo "unknown argument: $1" >&2; exit 2 ;;
    esac
done

bin="${BIN:-target/release/screensaver}"
[ -x "$bin" ] || cargo build --release --quiet
ref="${SCREENSAVER_REFERENCE:-$(cd .. && pwd)/shared/reference}"
scenes="$(mktemp -d)"
busy=()
cleanup() {
    for p in "${busy[@]}"; do kill "$p" 2>/dev/null || true; done
    rm -rf "$scenes"
}
trap cleanup EXIT

"$bin" gen --lines 10000 --seed 7 -o "$scenes/10k.in"
"$bin" gen --lines 100000 --seed 7 -o "$scenes/100k.in"
"$bin" gen --lines 1000000 --seed 7 -o "$scenes/1m.in"

# name frames scene (N frames run N + 1 steps)
workloads="mit 4000 $ref/inputs/mit.in
koch 1000 $ref/inputs/koch.in
sin_wave 4000 $ref/inputs/sin_wave.in
smalllines 4000 $ref/inputs/smalllines.in
10k 1000 $scenes/10k.in
100k 100 $scenes/100k.in
1m 99 $scenes/1m.in"

results="$scenes/results.tsv"
: >"$results"
for load in $loads; do
    busy=()
    for _ in $(seq 1 "$load"); do
        yes >/dev/null &
        busy+=("$!")
    done
    for round in $(seq 1 "$rounds"); do
        while read -r name frames scene; do
            if [ -n "$only" ] && [[ ",$only," != *",$name,"* ]]; then continue; fi
            configs=("default|$bin|" "one|$bin|--threads 1")
            [ -n "$base" ] && configs+=("base|$base|")
            for config in "${configs[@]}"; do
                IFS='|' read -r label binary args <<<"$config"
                # The output read once the run has ended: a reader started
                # beside it would be one more busy process.
                # shellcheck disable=SC2086
                out=$("$binary" --json $args "$frames" "$scene")
                seconds=$(python3 -c 'import json,sys; print(json.loads(sys.argv[1])["elapsed_seconds"])' "$out")
                printf '%s\t%s\t%s\t%s\n' "$load" "$name" "$label" "$seconds" >>"$results"
            done
        done <<<"$workloads"
    done
    for p in "${busy[@]}"; do kill "$p" 2>/dev/null || true; done
    busy=()
done

python3 - "$results" "$rounds" "$(nproc)" "$base" <<'EOF'
import collections, statistics, sys
path, rounds, cores, base = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
times = collections.defaultdict(list)
order = []
for row in open(path):
    load, name, label, seconds = row.split("\t")
    times[(int(load), name, label)].append(float(seconds))
    if (int(load), name) not in order:
        order.append((int(load), name))
print(f"Medians of {rounds} interleaved rounds, simulation seconds, {cores} cores.")
print()
head = "| busy processes | workload | `--threads 1` | default | one thread / default |"
rule = "| ---: | --- | ---: | ---: | ---: |"
if base:
    head += " base default | current / base |"
    rule += " ---: | ---: |"
print(head)
print(rule)
for load, name in order:
    one = statistics.median(times[(load, name, "one")])
    default = statistics.median(times[(load, name, "default")])
    row = f"| {load} | {name} | {one:.4f} | {default:.4f} | **{one / default:.2f}x** |"
    if base:
        b = statistics.median(times[(load, name, "base")])
        row += f" {b:.4f} | {b / default:.2f}x |"
    print(row)
EOF
