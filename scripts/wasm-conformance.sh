#!/usr/bin/env bash
# The course scenes of ../shared/reference (or $SCREENSAVER_REFERENCE) in
# the WebAssembly build under Node: builds it (scripts/wasm.sh, which
# installs what is missing and says where cargo put the module), installs
# Node if it is missing, and runs scripts/wasm-conformance.mjs, which
# compares the counts after every step and every checkpoint state with the
# reference's, bit for bit, and prints one line a scene and
# `N passed, M failed` (non-zero exit on any difference).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v node >/dev/null 2>&1; then
    echo "wasm-conformance.sh: installing Node (nodejs) with apt-get" >&2
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs >/dev/null
fi
node --version
module="$(scripts/wasm.sh)"
node scripts/wasm-conformance.mjs "$module"
