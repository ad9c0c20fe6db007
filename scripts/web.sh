#!/usr/bin/env bash
# Builds the web page into web/dist/: the simulation for WebAssembly
# (scripts/wasm.sh, which installs what it needs and says where cargo put
# the module) and the page's files.
# Serve it with `python3 -m http.server --bind 127.0.0.1 -d web/dist` (on
# this machine only) and open http://127.0.0.1:8000/.
set -euo pipefail
cd "$(dirname "$0")/.."
module="$(scripts/wasm.sh)"
rm -rf web/dist
mkdir -p web/dist
cp web/index.html web/screensaver.js web/worker.js web/module.js web/screensaver.css web/dist/
cp "$module" web/dist/screensaver.wasm
du -b web/dist/* | awk '{ total += $1; print } END { print total, "bytes in all" }'
