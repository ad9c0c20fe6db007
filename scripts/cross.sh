#!/usr/bin/env bash
# scripts/cross.sh TARGET [LAST_STEP]: the reference conformance on another
# platform. Installs what is missing (Debian packages, as root with
# apt-get), builds the program for TARGET, and runs the seven course scenes
# of ../shared/reference (or $SCREENSAVER_REFERENCE) there: for every
# checkpoint step the reference has (1, 2, 11, 101, 1001, 4001), up to
# LAST_STEP if given, `screensaver STEP-1 SCENE.in --state-out` must print
# the reference's two counters for that step and write its state byte for
# byte. Prints one line a run and `N passed, M failed`; exits non-zero on
# any difference, on a missing scene, tool or build, and when nothing ran.
#
# TARGET is one of
#   aarch64-linux     aarch64-unknown-linux-gnu, run by qemu-aarch64 (qemu-user)
#   x86-64-baseline   the native release build, run by qemu-x86_64 -cpu Nehalem:
#                     an x86-64 without AVX2, where the sweep's runtime
#                     dispatch takes its portable path
#   windows           x86_64-pc-windows-gnu (mingw), run by Wine; also builds
#                     the Windows screensaver (screensaver.scr)
#   wasm32            scripts/wasm-conformance.sh (the library under Node,
#                     every step's counters; LAST_STEP does not apply)
#
# rustup cannot add targets here, so, as scripts/wasm.sh does, the other
# targets are built with Debian's second Rust compiler (rustc-web,
# cargo-web) and its standard library's sources (rust-web-src,
# -Zbuild-std). Every target shares one cargo target directory
# (target/cross, or $CROSS_TARGET_DIR), so the build scripts and procedural
# macros the host runs are compiled once for all of them.
set -euo pipefail
# A failed build inside $(cross_build ...) must end the script, not leave
# the last build's binary to be tested.
shopt -s inherit_errexit
cd "$(dirname "$0")/.."
root="$(pwd)"
say() { echo "cross.sh: $*" >&2; }
die() {
    say "$*"
    exit 1
}

target="${1:-}"
last_step="${2:-}"
case "$target" in
aarch64-linux | x86-64-baseline | windows | wasm32) ;;
*) die "usage: scripts/cross.sh aarch64-linux|x86-64-baseline|windows|wasm32 [LAST_STEP]" ;;
esac
[ -z "$last_step" ] || [[ "$last_step" =~ ^[1-9][0-9]*$ ]] || die "LAST_STEP must be a positive step, not '$last_step'"

if [ "$target" = wasm32 ]; then
    [ -z "$last_step" ] || die "wasm32 runs every scene to the reference's end: no LAST_STEP"
    exec scripts/wasm-conformance.sh
fi

reference="${SCREENSAVER_REFERENCE:-$root/../shared/reference}"
[ -d "$reference/inputs" ] && [ -d "$reference/expected" ] ||
    die "no reference data at $reference (set SCREENSAVER_REFERENCE)"
reference="$(cd "$reference" && pwd)"

# Installs the Debian packages missing among "$@" (all of them at once).
need_packages() {
    local missing=()
    for p in "$@"; do
        dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return
    say "installing ${missing[*]} with apt-get"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

cross_dir="${CROSS_TARGET_DIR:-$root/target/cross}"
mkdir -p "$cross_dir"
cross_dir="$(cd "$cross_dir" && pwd)"

# Builds the package's binaries for a Rust target with Debian's compiler
# and a standard library built for it; prints the release directory.
cross_build() {
    local rust_target="$1"
    shift
    say "building for $rust_target (the standard library too: several minutes the first time)"
    RUSTC=/usr/bin/rustc RUSTDOC=/usr/bin/rustdoc RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR="$cross_dir" \
        /usr/bin/cargo build --release --locked --target "$rust_target" \
        -Zbuild-std=std,panic_abort "$@" >&2
    echo "$cross_dir/$rust_target/release"
}

# How to run the built program, and how to spell a path for it.
runner=()
host_path() { printf '%s\n' "$1"; }
exe=""
case "$target" in
aarch64-linux)
    need_packages rustc-web cargo-web rust-web-src gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user
    export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
    exe="$(cross_build aarch64-unknown-linux-gnu)/screensaver"
    # The cross toolchain's loader and libc, unless arm64's own are
    # installed (multiarch): then -L would mix the two and hang at start.
    if [ -e /lib/ld-linux-aarch64.so.1 ]; then
        runner=(qemu-aarch64)
    else
        runner=(qemu-aarch64 -L /usr/aarch64-linux-gnu)
    fi
    ;;
x86-64-baseline)
    need_packages qemu-user
    # The build users install and CI tests (rustup's toolchain): its
    # portable path is what the emulated CPU without AVX2 runs.
    say "building the native release binary"
    # The program is taken from where cargo reports it, as scripts/wasm.sh
    # takes the module: $CARGO_TARGET_DIR (or the build.target-dir of a
    # cargo config) is honoured, not target/ assumed. Cargo names each
    # artifact in a JSON line on stdout; its progress and any diagnostics
    # go to stderr.
    exe="$(cargo build --release --locked --bin screensaver --message-format=json-render-diagnostics |
        sed -n 's/.*"executable":"\([^"]*\/screensaver\)".*/\1/p' | tail -n 1)"
    [ -n "$exe" ] || die "cargo reported no screensaver executable (CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-unset})"
    # Nehalem: SSE4.2, no AVX. Check that the emulated CPU has no AVX2 (a
    # C program asks the CPU as the dispatch does), or the run would prove
    # nothing about the portable path.
    need_packages gcc
    printf 'int main(void) { __builtin_cpu_init(); return __builtin_cpu_supports("avx2") ? 3 : 0; }\n' >"$cross_dir/avx2.c"
    gcc -O1 -o "$cross_dir/avx2" "$cross_dir/avx2.c"
    qemu-x86_64 -cpu Nehalem "$cross_dir/avx2" || die "the CPU qemu-x86_64 -cpu Nehalem emulates has AVX2 (or runs nothing)"
    runner=(qemu-x86_64 -cpu Nehalem)
    ;;
windows)
    need_packages rustc-web cargo-web rust-web-src gcc-mingw-w64-x86-64 wine64 xvfb x11-apps x11-utils xdotool
    export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER=x86_64-w64-mingw32-gcc
    # The program and the screen saver (feature `scr`), in one build.
    release="$(cross_build x86_64-pc-windows-gnu --features scr)"
    exe="$release/screensaver.exe"
    cp "$release/screensaver-scr.exe" "$release/screensaver.scr"
    say "built $exe and $release/screensaver.scr"
    wine=/usr/lib/wine/wine64
    [ -x "$wine" ] || wine="$(command -v wine64 || command -v wine)" || die "no wine64"
    # A prefix of its own (made on first use), without the Mono and Gecko
    # installers Wine would otherwise offer.
    export WINEPREFIX="${WINEPREFIX:-$cross_dir/wine}" WINEDEBUG="${WINEDEBUG:--all}" WINEDLLOVERRIDES="mscoree,mshtml="
    if [ ! -d "$WINEPREFIX/drive_c/windows/system32" ]; then
        say "making the Wine prefix $WINEPREFIX"
        "$wine" wineboot --init >/dev/null 2>&1 || die "wineboot failed"
    fi
    # Rust's standard library needs ProcessPrng (bcryptprimitives.dll),
    # which Wine 8 lacks: contrib/wine/processprng.c gives it.
    if [ -z "$(find /usr/lib -path '*wine*' -iname bcryptprimitives.dll -print -quit)" ]; then
        shim="$WINEPREFIX/drive_c/windows/system32/bcryptprimitives.dll"
        if [ ! -f "$shim" ] || [ "$shim" -ot contrib/wine/processprng.c ]; then
            say "Wine lacks ProcessPrng: building contrib/wine/processprng.c into $shim"
            x86_64-w64-mingw32-gcc -O2 -Wall -Werror -shared -s -o "$shim" contrib/wine/processprng.c -ladvapi32
        fi
    fi
    runner=("$wine")
    # Wine's drive Z: is the root of the file system.
    host_path() { printf 'Z:%s\n' "${1//\//\\}"; }
    ;;
esac
[ -x "$exe" ] || [ -f "$exe" ] || die "no program at $exe"
command -v "${runner[0]}" >/dev/null || die "no ${runner[0]}"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
say "running the reference scenes with ${runner[*]} $exe"

passed=0
failed=0
# One run: STEP steps of SCENE; its counters and state against the reference's.
check() {
    local scene="$1" step="$2"
    local input="$reference/inputs/$scene.in" state="$work/$scene.$step.state"
    local want got out started=$SECONDS
    want="$(sed -n "s/^$step,\([0-9]*\),\([0-9]*\)\$/\1 \2/p" "$reference/expected/$scene.counts.csv")"
    if [ -z "$want" ]; then
        echo "FAIL $scene step $step: no row for it in $scene.counts.csv"
        failed=$((failed + 1))
        return
    fi
    # N frames run N + 1 steps, as in the original.
    if ! out="$("${runner[@]}" "$exe" "$((step - 1))" "$(host_path "$input")" \
        --state-out "$(host_path "$state")" 2>"$work/stderr")"; then
        echo "FAIL $scene step $step: the program failed: $(tr -d '\r' <"$work/stderr" | tail -n 3)"
        failed=$((failed + 1))
        return
    fi
    out="$(tr -d '\r' <<<"$out")"
    got="$(sed -n 's/^\([0-9]*\) Line-Wall Collisions$/\1/p' <<<"$out") $(sed -n 's/^\([0-9]*\) Line-Line Collisions$/\1/p' <<<"$out")"
    if [ "$got" != "$want" ]; then
        echo "FAIL $scene step $step: wall, line collisions $got, reference $want"
        failed=$((failed + 1))
    elif ! cmp -s "$state" "$reference/expected/$scene.$step.state"; then
        echo "FAIL $scene step $step: state differs from $scene.$step.state ($(cmp "$state" "$reference/expected/$scene.$step.state" 2>&1 | head -n 1))"
        failed=$((failed + 1))
    else
        echo "ok   $scene step $step: $got, state identical ($((SECONDS - started)) s)"
        passed=$((passed + 1))
    fi
}

for scene in beaver box explosion koch mit sin_wave smalllines; do
    [ -f "$reference/inputs/$scene.in" ] || {
        echo "FAIL $scene: no $scene.in"
        failed=$((failed + 1))
        continue
    }
    steps="$(ls "$reference/expected" | sed -n "s/^$scene\.\([0-9]*\)\.state\$/\1/p" | sort -n)"
    [ -n "$steps" ] || {
        echo "FAIL $scene: no reference states"
        failed=$((failed + 1))
        continue
    }
    for step in $steps; do
        [ -z "$last_step" ] || [ "$step" -le "$last_step" ] || continue
        check "$scene" "$step"
    done
done

if [ "$target" = windows ]; then
    # Ctrl-C: Wine hands a SIGINT to the console's handler routine as
    # Windows hands Ctrl-C. The run stops after its step with the results
    # block and its state written whole, and ends with Windows' status for
    # an interrupted program, 0xC000013A, whose low byte (58) is what Wine
    # passes on.
    state="$work/interrupted.state"
    "${runner[@]}" "$exe" 100000000 "$(host_path "$reference/inputs/mit.in")" \
        --state-out "$(host_path "$state")" >"$work/int.out" 2>"$work/int.err" &
    pid=$!
    # Long enough for Wine to start it and the handler to be in place.
    sleep 8
    kill -INT "$pid"
    status=0
    wait "$pid" || status=$?
    tr -d '\r' <"$work/int.out" >"$work/int.txt"
    if [ "$status" -eq 58 ] && grep -q '^---- END RESULTS ----$' "$work/int.txt" &&
        grep -q 'stopped by SIGINT after step' "$work/int.err" &&
        [ "$(wc -l <"$state")" -eq "$(wc -l <"$reference/expected/mit.1.state")" ]; then
        echo "ok   Ctrl-C stops a run: results block, state written whole, status 0xC000013A"
        passed=$((passed + 1))
    else
        echo "FAIL Ctrl-C: status $status, $(tail -n 2 "$work/int.txt" | tr '\n' ' ') $(tr -d '\r' <"$work/int.err" | tail -n 1)"
        failed=$((failed + 1))
    fi
    # shellcheck source=scripts/cross-scr.sh
    . scripts/cross-scr.sh
fi

echo "$target: $passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
