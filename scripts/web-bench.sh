#!/usr/bin/env bash
# The web page's speed in headless Chromium (scripts/web-bench.mjs): builds
# the page and the native binary it is compared with, installs Chromium,
# its driver and Node when missing, and prints the tables that
# docs/PERFORMANCE.md holds. Usage: scripts/web-bench.sh [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/browser-deps.sh
scripts/web.sh >/dev/null
echo "web-bench.sh: building the native binary the page is compared with (cargo build --release)" >&2
cargo build --release --quiet
# Where cargo puts it ($CARGO_TARGET_DIR is honoured).
target="$(cargo metadata --format-version 1 --no-deps | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')"
node scripts/web-bench.mjs web/dist "$target/release/screensaver" "${1:-5}"
