#!/usr/bin/env bash
# The web page's tests in a real browser (scripts/web-test.mjs): installs
# Debian's Chromium, its driver and Node when missing, builds the page
# (scripts/web.sh) and the native binary it is compared with, and runs
# them. Needs ../shared/reference (or $SCREENSAVER_REFERENCE). Both builds
# are found where cargo puts them ($CARGO_TARGET_DIR is honoured), which
# is checked first.
set -euo pipefail
cd "$(dirname "$0")/.."
say() { echo "web-test.sh: $*" >&2; }
# Cargo's target directory for the crate in folder $1.
target_dir() { (cd "$1" && cargo metadata --format-version 1 --no-deps | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p'); }

scripts/browser-deps.sh
scripts/web.sh

# The module is taken from where cargo says it is: with the same target
# directory under another name as CARGO_TARGET_DIR (nothing to rebuild),
# the module must be reported under that name, not at a path assumed.
elsewhere="$(mktemp -d)"
trap 'rm -rf "$elsewhere"' EXIT
ln -s "$(target_dir wasm)" "$elsewhere/target"
moved="$(CARGO_TARGET_DIR="$elsewhere/target" scripts/wasm.sh)"
case "$moved" in
    "$elsewhere/target/"*) cmp "$moved" web/dist/screensaver.wasm ;;
    *) say "with CARGO_TARGET_DIR=$elsewhere/target, scripts/wasm.sh gave the module as '$moved'"; exit 1 ;;
esac
say "scripts/wasm.sh follows CARGO_TARGET_DIR"

say "building the native binary the page is compared with (cargo build --release)"
cargo build --release --quiet
node scripts/web-test.mjs web/dist "$(target_dir .)/release/screensaver"
