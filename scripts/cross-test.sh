#!/usr/bin/env bash
# scripts/cross-test.sh [SUITE...]: the test suite itself (`cargo test
# --release`: the library's and the program's unit tests and every suite
# in tests/, doc tests aside) built for aarch64 Linux and run under QEMU;
# SUITEs (`lib`, `bin:screensaver`, `cli`, `conformance`, ...) run only
# those. Prints each suite's result and
# `N passed, M failed` (suites); exits non-zero if any fails.
#
# Too slow for CI: about 75 minutes on two cores, `conformance` alone 49
# (the emulation is 40 to 65 times slower than the host). Run it by hand
# when the maths, the detectors or the platform code change.
#
# Installs what is missing (as root, with apt-get), beside what
# scripts/cross.sh aarch64-linux needs: arm64's own X11 client libraries
# (multiarch: `dpkg --add-architecture arm64`), which the window tests
# load, and Xvfb and the X tools for those tests. With arm64's libc
# installed, qemu runs without `-L` (with it, the cross toolchain's loader
# would read the host's cache and mix two libcs).
#
# The tests that start the program run it by the path cargo compiled into
# them; this host cannot run an aarch64 program directly (no binfmt_misc
# here), so once built, that path becomes a script that runs the program
# under qemu-aarch64, and the test programs are run here, one by one,
# under qemu-aarch64 from the package's folder, as cargo runs them.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
say() { echo "cross-test.sh: $*" >&2; }
die() {
    say "$*"
    exit 1
}

export SCREENSAVER_REFERENCE="${SCREENSAVER_REFERENCE:-$root/../shared/reference}"
export SCREENSAVER_REQUIRE_REFERENCE=1 SCREENSAVER_REQUIRE_DISPLAY=1

packages=(rustc-web cargo-web rust-web-src gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user
    xvfb x11-apps x11-utils procps)
arm64=(libc6:arm64 libgcc-s1:arm64 libx11-6:arm64 libx11-xcb1:arm64 libxcb1:arm64 libxcursor1:arm64
    libxrandr2:arm64 libxi6:arm64 libxkbcommon-x11-0:arm64)
missing=()
for p in "${packages[@]}" "${arm64[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    say "installing ${missing[*]} with apt-get"
    export DEBIAN_FRONTEND=noninteractive
    dpkg --print-foreign-architectures | grep -qx arm64 || dpkg --add-architecture arm64
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[ -e /lib/ld-linux-aarch64.so.1 ] || die "arm64's loader (libc6:arm64) is not installed"

cross_dir="${CROSS_TARGET_DIR:-$root/target/cross}"
triple=aarch64-unknown-linux-gnu
say "building the tests for $triple (the standard library and every dev-dependency: many minutes the first time)"
# Cargo names each test program it builds in a JSON line on stdout.
tests="$(RUSTC=/usr/bin/rustc RUSTDOC=/usr/bin/rustdoc RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR="$cross_dir" \
    CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc \
    /usr/bin/cargo test --release --locked --target "$triple" -Zbuild-std=std,panic_abort \
    --lib --tests --no-run --message-format=json-render-diagnostics |
    sed -n 's/.*"target":{"kind":\["\([a-z-]*\)"\][^}]*"name":"\([^"]*\)".*"profile":{[^}]*"test":true}.*"executable":"\([^"]*\)".*/\1 \2 \3/p' |
    # Named as a SUITE argument names them: `lib`, `bin:NAME`, the test's name.
    sed 's/^lib [^ ]* /lib /; s/^bin \([^ ]*\) /bin:\1 /; s/^test //')"
[ -n "$tests" ] || die "cargo built no test programs"

# The program the tests start, by the path compiled into them: a script
# that runs the aarch64 build under qemu (kept beside it).
program="$cross_dir/$triple/release/screensaver"
[ -f "$program" ] || die "no $program"
# Cargo links the build there anew each time, over the script.
if ! head -c 2 "$program" | grep -q '#!'; then
    rm -f "$program.aarch64"
    mv "$program" "$program.aarch64"
fi
printf '#!/bin/sh\nexec qemu-aarch64 "%s" "$@"\n' "$program.aarch64" >"$program"
chmod +x "$program"

passed=0
failed=0
while read -r name executable; do
    if [ $# -gt 0 ]; then
        wanted=false
        for suite in "$@"; do
            if [ "$suite" = "$name" ]; then
                wanted=true
            fi
        done
        $wanted || continue
    fi
    started=$SECONDS
    extra=()
    # This test starts its own test program again (to see a skipped
    # test's message), by its path: an aarch64 program that this host
    # starts only where binfmt_misc hands such programs to qemu. Said
    # aloud, never passed over in silence.
    if [ "$name" = window ] && [ ! -e /proc/sys/fs/binfmt_misc/qemu-aarch64 ]; then
        extra=(--skip a_skipped_window_test_says_so)
        echo "skip window::a_skipped_window_test_says_so: it re-runs its own aarch64 test program, which this host cannot start without binfmt_misc"
    fi
    say "running $name ($executable) under qemu-aarch64"
    if qemu-aarch64 "$executable" "${extra[@]}"; then
        echo "ok   $name ($((SECONDS - started)) s)"
        passed=$((passed + 1))
    else
        echo "FAIL $name ($((SECONDS - started)) s)"
        failed=$((failed + 1))
    fi
done <<<"$tests"

echo "aarch64 tests: $passed passed, $failed failed (suites)"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
