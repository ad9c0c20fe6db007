#!/usr/bin/env bash
# What the project's own atan2 (correctly rounded) changes in whole runs,
# against the platform's (glibc 2.36's on the reference's platform): 100
# generated scenes (every kind, 500 to 20,000 lines), 1000 frames each, run
# by a build with our maths and one with the platform's (the
# `platform-libm` feature); prints how many final states and counts differ.
# Our hypot is the platform's there, bit for bit, so only atan2 can differ.
#
#   scripts/libm-runs.sh [SCENES]
set -euo pipefail
cd "$(dirname "$0")/.."
scenes="${1:-100}"
cargo build --release --quiet
cargo build --release --quiet --features platform-libm --target-dir target/platform-libm
ours=target/release/screensaver
platform=target/platform-libm/release/screensaver
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
kinds=(uniform clustered ring grid)
states=0
counts=0
for i in $(seq 0 $((scenes - 1))); do
    kind="${kinds[$((i % 4))]}"
    # 500 to 20,000 lines, evenly on a log scale.
    lines=$(python3 -c "print(round(500 * 40 ** ($i / max(1, $scenes - 1))))")
    args=(--lines "$lines" --kind "$kind" --seed "$i" 1000)
    a=$("$ours" "${args[@]}" --state-out "$work/ours.state" | grep Collisions)
    b=$("$platform" "${args[@]}" --state-out "$work/platform.state" | grep Collisions)
    cmp -s "$work/ours.state" "$work/platform.state" || { states=$((states + 1)); echo "state differs: ${args[*]}"; }
    [ "$a" = "$b" ] || { counts=$((counts + 1)); echo "counts differ: ${args[*]}"; }
done
echo "$scenes scenes, 1000 frames each: $states final states differ, $counts pairs of counts differ"
