#!/usr/bin/env bash
# The web page's tests in a real browser (scripts/web-test.mjs): installs
# Debian's Chromium, its driver and Node when missing, builds the page
# (scripts/web.sh) and the native binary it is compared with, and runs
# them. Needs ../shared/reference (or $SCREENSAVER_REFERENCE).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/browser-deps.sh
scripts/web.sh
cargo build --release --quiet
node scripts/web-test.mjs web/dist target/release/screensaver
