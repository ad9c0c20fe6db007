#!/usr/bin/env bash
# Builds the library for WebAssembly (wasm32-unknown-unknown): the crate in
# wasm/, into cargo's target directory (wasm/target, or $CARGO_TARGET_DIR
# or whatever else cargo is told). Prints the module's path, as cargo
# reports it, on stdout; what it is doing, on stderr.
#
# rustup cannot add targets here, so the route is Debian's: its Rust
# compiler for the web (rustc-web, cargo-web) with its standard library's
# sources (rust-web-src), the standard library built for the target
# (-Zbuild-std), and the rust-lld linker rustup's toolchain ships. Installs
# the packages when missing (as root, with apt-get).
set -euo pipefail
cd "$(dirname "$0")/.."
say() { echo "wasm.sh: $*" >&2; }

if ! dpkg -s rustc-web cargo-web rust-web-src >/dev/null 2>&1; then
    say "installing Debian's Rust compiler for the web (rustc-web, cargo-web, rust-web-src) with apt-get"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends rustc-web cargo-web rust-web-src >/dev/null
fi
lld="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin/rust-lld"
[ -x "$lld" ] || { say "no rust-lld at $lld"; exit 1; }

say "building the standard library and the module for wasm32-unknown-unknown (a few minutes the first time)"
cd wasm
# WebAssembly's 128-bit SIMD (every current browser and Node since 16.4):
# the simulation 1.2x to 1.5x faster in V8 than without it.
# Cargo names each artifact it builds or finds fresh in a JSON line on
# stdout (its progress and any diagnostics go to stderr): the module is
# the file of the screensaver_wasm target that ends in .wasm.
# --locked: the versions in wasm/Cargo.lock, as the native builds take
# Cargo.lock's; a lock file that no longer matches the manifests fails the
# build instead of being rewritten in the work tree.
module="$(RUSTFLAGS="${RUSTFLAGS:-} -C target-feature=+simd128" RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 \
    CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER="$lld" \
    /usr/bin/cargo build --release --locked --target wasm32-unknown-unknown -Zbuild-std=std,panic_abort \
    --message-format=json-render-diagnostics "$@" |
    sed -n 's/.*"filenames":\[[^]]*"\([^"]*\/screensaver_wasm\.wasm\)".*/\1/p' | tail -n 1)"
[ -n "$module" ] && [ -f "$module" ] || { say "cargo reported no screensaver_wasm.wasm"; exit 1; }
say "built $module ($(stat -c %s "$module") bytes)"
echo "$module"
