#!/usr/bin/env bash
# The web page's tests in a real browser (scripts/web-test.mjs): installs
# Debian's Chromium, its driver and Node when missing, builds the page
# (scripts/web.sh) and the native binary it is compared with, and runs
# them. Needs ../shared/reference (or $SCREENSAVER_REFERENCE).
set -euo pipefail
cd "$(dirname "$0")/.."
missing=()
command -v node >/dev/null 2>&1 || missing+=(nodejs)
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
command -v chromedriver >/dev/null 2>&1 || missing+=(chromium-driver)
if [ ${#missing[@]} -gt 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
scripts/web.sh
cargo build --release --quiet
node scripts/web-test.mjs web/dist target/release/screensaver
