#!/usr/bin/env bash
# Frames drawn per second in the 1180 x 800 window, with the simulation
# running beside it, for generated scenes of 10^4, 10^5 and 10^6 lines
# (or the sizes in SIZES). Each size runs SECONDS (default 10) under a
# virtual 1920 x 1080 X server and is stopped by SIGTERM; the figures are
# the program's own --stats. Extra options go to every run: --speed max
# for the simulation as fast as it goes beside the drawing (by default a
# step a picture), --fullscreen for the whole screen.
# Usage: [SIZES="N ..."] scripts/drawn_fps.sh [SECONDS] [extra screensaver options...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-10}
shift || true
cargo build --release --quiet
bin=target/release/screensaver
display=:$((90 + RANDOM % 9))
Xvfb "$display" -screen 0 1920x1080x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null' EXIT
sleep 1
echo "| lines | frames drawn per second | ms to draw a frame | steps per second |"
echo "| ---: | ---: | ---: | ---: |"
for n in ${SIZES:-10000 100000 1000000}; do
    DISPLAY=$display $bin -g --lines "$n" --seed 1 --stats --json "$@" >/tmp/drawn_fps.$$ 2>/dev/null &
    pid=$!
    sleep "$seconds"
    kill -TERM $pid
    wait $pid || true
    python3 - "$n" /tmp/drawn_fps.$$ <<'PY'
import json, sys
n, path = int(sys.argv[1]), sys.argv[2]
d = json.load(open(path))
s = d["stats"]
print(f"| {n:,} | {s['drawn_fps']:.1f} | {s['draw_seconds_per_frame'] * 1e3:.1f} | {d['steps_run'] / d['elapsed_seconds']:.1f} |")
PY
done
rm -f /tmp/drawn_fps.$$
