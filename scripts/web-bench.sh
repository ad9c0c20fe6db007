#!/usr/bin/env bash
# The web page's speed in headless Chromium (scripts/web-bench.mjs): builds
# the page and the native binary it is compared with, installs Chromium,
# its driver and Node when missing, and prints the tables that
# docs/PERFORMANCE.md holds. Usage: scripts/web-bench.sh [ROUNDS]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/browser-deps.sh
scripts/web.sh >/dev/null
cargo build --release --quiet
node scripts/web-bench.mjs web/dist target/release/screensaver "${1:-5}"
