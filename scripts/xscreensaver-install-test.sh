#!/usr/bin/env bash
# The edit scripts/xscreensaver-install.sh makes to ~/.xscreensaver, without
# a daemon, a display or a build (seconds; scripts/xscreensaver-test.sh runs
# Debian's daemon on the result). A HOME with a space in its path (issue
# 47): the entry's path must reach the program as XScreenSaver reads and
# runs the entry (its file reader, then /bin/sh -c "exec COMMAND"); a second
# install changes nothing; --uninstall removes every entry of the program
# and leaves `selected:` on the entry the user had chosen, also from the
# files an earlier version left (the path unquoted, the entry added once a
# run). The program installed is a stand-in that answers --version.
#
# Usage: scripts/xscreensaver-install-test.sh
# As root it runs the install as `nobody` (setpriv), since the script
# refuses root. Ends with "N passed, M failed"; exits non-zero on a failure.
set -euo pipefail
cd "$(dirname "$0")/.."
install_script=$(pwd)/scripts/xscreensaver-install.sh

passed=0
failed=0
ok() {
    passed=$((passed + 1))
    echo "ok   $*"
}
not_ok() {
    failed=$((failed + 1))
    echo "FAIL $*"
}
check() {
    local what=$1
    shift
    if "$@"; then ok "$what"; else not_ok "$what"; fi
}

work=$(mktemp -d /tmp/screensaver-install-test.XXXXXX)
trap '[[ -n ${KEEP:-} ]] || rm -rf "$work"' EXIT
home="$work/my home"
mkdir -p "$home"
# The stand-in program: the install checks its --version.
fake=$work/fake-screensaver
printf '#!/bin/sh\necho "screensaver 0.1.0"\n' >"$fake"
chmod 755 "$fake"
chmod 755 "$work"

if ((EUID == 0)); then
    command -v setpriv >/dev/null || {
        echo "xscreensaver-install-test: as root, setpriv (util-linux) is needed to run the install as nobody" >&2
        exit 1
    }
    chown nobody "$home"
    as_user() {
        setpriv --reuid=nobody --regid="$(id -g nobody)" --clear-groups \
            env -i HOME="$home" PATH=/usr/bin:/bin "$@"
    }
else
    as_user() { env -i HOME="$home" PATH=/usr/bin:/bin "$@"; }
fi
rc=$home/.xscreensaver
installed=$home/.local/bin/screensaver
# The install's output, kept for a failure.
log=$work/log
run_install() { as_user bash "$install_script" "$@" >"$log" 2>&1 || { sed 's/^/  | /' "$log"; return 1; }; }
# Puts file $1 in place as ~/.xscreensaver.
put_rc() {
    cp "$1" "$rc"
    ((EUID != 0)) || chown nobody "$rc"
}

# The entries of programs: that run this program: their count.
entries() { grep -cF "$installed" "$rc" || true; }
selected() { sed -n 's/^selected:[[:space:]]*//p' "$rc"; }
mode() { sed -n 's/^mode:[[:space:]]*//p' "$rc"; }
# The command of the entry "Screensaver (lines)", as the daemon reads the
# file (a backslash takes the next character as it is), run as the daemon
# runs a command holding a quote: /bin/sh -c "exec COMMAND". It must run
# the installed program.
entry_runs() {
    local line command out
    line=$(grep -m1 -F '"Screensaver (lines)"' "$rc") || return 1
    command=$(sed -e 's/^[^"]*"Screensaver (lines)"[[:space:]]*//' -e 's/[[:space:]]*\\n\\$//' <<<"$line")
    command=$(sed -e 's/\\\(.\)/\1/g' <<<"$command")
    out=$(/bin/sh -c "exec $command --version" 2>&1) || {
        echo "  | the entry's command ($command) failed: $out"
        return 1
    }
    [[ $out == "screensaver 0.1.0" ]] || {
        echo "  | the entry's command ($command) printed: $out"
        return 1
    }
}

echo "== a new ~/.xscreensaver, HOME with a space: $home"
check "the install succeeds" run_install "$fake"
check "the program is in ~/.local/bin" test -x "$installed"
check "one entry" test "$(entries)" = 1
check "its command runs the program when /bin/sh reads it" entry_runs
check "mode: one, selected: 0" test "$(mode) $(selected)" = "one 0"
cp "$rc" "$work/first"
check "a second install succeeds" run_install "$fake"
check "a second install changes nothing" cmp -s "$rc" "$work/first"
check "--uninstall succeeds" run_install --uninstall
check "--uninstall removes the file it made" test ! -e "$rc"
check "--uninstall removes the program" test ! -e "$installed"

# A file as xscreensaver-settings 6.06 writes one: random mode, four other
# hacks (one disabled, one GL).
before=$work/before
cat >"$before" <<'EOF'
# XScreenSaver Preferences File
# Written by xscreensaver-settings 6.06 for a test.
# https://www.jwz.org/xscreensaver/

timeout:	0:10:00
lock:		False

mode:		random
selected:	2

programs:								      \
				maze --root				    \n\
- GL: 				superquadrics --root			    \n\
-				noseguy --root				    \n\
  GL: 				gears --root				    \n\


pointerHysteresis:  10
EOF

echo "== an existing ~/.xscreensaver"
put_rc "$before"
check "the install succeeds" run_install "$fake"
check "one entry" test "$(entries)" = 1
check "its command runs the program when /bin/sh reads it" entry_runs
check "mode: one, selected: 4 (after the file's four)" test "$(mode) $(selected)" = "one 4"
cp "$rc" "$work/first"
check "a second install succeeds" run_install "$fake"
check "a second install changes nothing" cmp -s "$rc" "$work/first"
check "--uninstall succeeds" run_install --uninstall
check "the file is as it was, byte for byte" cmp "$before" "$rc"

# (Entries reach awk through its environment: -v would read their \n.)
# What an earlier version left after two installs: the path unquoted
# (which the daemon splits at the space), the entry added twice, the second
# selected.
legacy_entry=$(printf '  "Screensaver (lines)"\t%s\t\\n\\' "$installed")
legacy=$work/legacy
ENTRY=$legacy_entry awk '
    BEGIN { entry = ENVIRON["ENTRY"] }
    /^mode:/ { print "# screensaver-install: before it, mode: random, selected: 2"; print "mode:\t\tone"; next }
    /^selected:/ { print "selected:\t5"; next }
    /gears --root/ { print; print entry; print entry; next }
    { print }' "$before" >"$legacy"

echo "== the file an earlier version left: two unquoted entries"
put_rc "$legacy"
check "--uninstall succeeds" run_install --uninstall
check "--uninstall removes both entries and restores the selection: the file as before" cmp "$before" "$rc"
put_rc "$legacy"
check "the install succeeds" run_install "$fake"
check "one entry is left" test "$(entries)" = 1
check "its command runs the program when /bin/sh reads it" entry_runs
check "selected: 4, the entry kept" test "$(mode) $(selected)" = "one 4"
check "--uninstall succeeds" run_install --uninstall
check "the file is as it was before the first install, byte for byte" cmp "$before" "$rc"

echo "== --uninstall after the user chose another hack"
# Two entries of this program before the hack chosen (gears, now index 5).
ENTRY=$legacy_entry awk '
    BEGIN { entry = ENVIRON["ENTRY"] }
    /^mode:/ { print "mode:\t\tone"; next }
    /^selected:/ { print "selected:\t5"; next }
    /noseguy --root/ { print; print entry; print entry; next }
    { print }' "$before" >"$work/chosen"
put_rc "$work/chosen"
check "--uninstall succeeds" run_install --uninstall
check "no entry of this program is left" test "$(entries)" = 0
check "the user's choice stays selected: mode one, selected 3 (gears)" test "$(mode) $(selected)" = "one 3"
check "the entry at index 3 is gears" \
    bash -c "grep -A4 '^programs:' '$rc' | sed -n 5p | grep -q 'gears --root'"

echo "== an entry of this program with options, disabled, in double quotes"
ENTRY=$(printf -- '-\t"Screensaver (lines)"\t"%s" --lines 5000\t\\n\\' "$installed") awk '
    BEGIN { entry = ENVIRON["ENTRY"] }
    /gears --root/ { print; print entry; next }
    { print }' "$before" >"$work/options"
put_rc "$work/options"
check "the install succeeds" run_install "$fake"
check "one entry" test "$(entries)" = 1
check "it is enabled, in single quotes, with its options kept" \
    grep -qF "$(printf '  "Screensaver (lines)"\t%s --lines 5000\t\\n\\' "'$installed'")" "$rc"
check "mode: one, selected: 4" test "$(mode) $(selected)" = "one 4"

echo "$passed passed, $failed failed"
((failed == 0))
