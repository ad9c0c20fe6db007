#!/usr/bin/env bash
# The XScreenSaver install (scripts/xscreensaver-install.sh) against Debian's
# real daemon, under a virtual X server, as a new user meets it (issue 45,
# item 10): as a user who is not root (the daemon runs no hack as root), with
# an existing ~/.xscreensaver, and a PATH that does not hold the program.
# Checks that the install selects this program, that `xscreensaver-command
# -activate` runs it (a child of the daemon, drawing red and gray lines into
# the daemon's window), that -deactivate ends it and leaves nothing behind,
# that the daemon's cycle ends it with SIGTERM and logs that as a normal
# end (item 11: "exited normally with SIGTERM"), and that --uninstall gives
# the file back; then the same with the system-wide install.
#
# Usage: scripts/xscreensaver-test.sh [BINARY]
#   BINARY defaults to target/release/screensaver ($CARGO_TARGET_DIR's when
#   set), built with `cargo build --release --locked` when missing.
#
# Runs as root (CI does): it installs its packages, creates the test user
# and writes the system-wide files, and removes them all at the end, also
# on failure. Fails, never skips, when anything is missing. Ends with
# "N passed, N failed".
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

binary=""
for arg in "$@"; do
    case "$arg" in
    -h | --help)
        sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
        exit 0
        ;;
    -*)
        echo "xscreensaver-test: unknown option $arg" >&2
        exit 2
        ;;
    *) binary=$arg ;;
    esac
done

if ((EUID != 0)); then
    echo "xscreensaver-test: run it as root: it installs packages, creates a user and writes to XScreenSaver's system directories" >&2
    exit 1
fi

started=$SECONDS
passed=0
failed=0
summary_printed=0
ok() {
    passed=$((passed + 1))
    echo "ok   $*"
}
not_ok() {
    failed=$((failed + 1))
    echo "FAIL $*"
}
# Until the full clean-up below takes over: a set-up that fails still ends
# with the count, the failure in it.
early_exit() {
    local status=$?
    if ((status != 0 && !summary_printed)); then
        echo "xscreensaver-test: stopped early (status $status)"
        echo "$passed passed, $((failed + 1)) failed"
    fi
}
trap early_exit EXIT
# check DESCRIPTION COMMAND...: one check, counted.
check() {
    local what=$1
    shift
    if "$@"; then ok "$what"; else not_ok "$what"; fi
}
# Polls COMMAND until it succeeds or SECONDS pass.
wait_until() {
    local limit=$1 end
    shift
    end=$((SECONDS + limit))
    until "$@"; do
        ((SECONDS < end)) || return 1
        sleep 0.2
    done
}

echo "== packages: the daemon, a virtual X server, xwd, xwininfo, pgrep"
export DEBIAN_FRONTEND=noninteractive
missing=()
for pair in xscreensaver:xscreensaver xscreensaver-command:xscreensaver Xvfb:xvfb \
    xwd:x11-apps xwininfo:x11-utils pgrep:procps setpriv:util-linux useradd:passwd; do
    command -v "${pair%%:*}" >/dev/null || missing+=("${pair#*:}")
done
if ((${#missing[@]})); then
    mapfile -t missing < <(printf '%s\n' "${missing[@]}" | sort -u)
    echo "installing ${missing[*]}"
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
for tool in xscreensaver xscreensaver-command Xvfb xwd xwininfo pgrep setpriv useradd; do
    command -v "$tool" >/dev/null || {
        echo "xscreensaver-test: $tool is still missing after apt-get" >&2
        exit 1
    }
done
echo "xscreensaver $(dpkg-query -W -f='${Version}' xscreensaver)"

if [[ -z $binary ]]; then
    binary="${CARGO_TARGET_DIR:-$repo/target}/release/screensaver"
    if [[ ! -x $binary ]]; then
        echo "== $binary is missing: cargo build --release --locked"
        cargo build --release --locked
    fi
fi
[[ -x $binary ]] || {
    echo "xscreensaver-test: $binary is not an executable" >&2
    exit 1
}

# Where Debian's package puts the hacks and their settings files.
hack_dir=/usr/libexec/xscreensaver
config_dir=/usr/share/xscreensaver/config
for d in "$hack_dir" "$config_dir"; do
    [[ -d $d ]] || {
        echo "xscreensaver-test: $d is missing: not Debian's xscreensaver package?" >&2
        exit 1
    }
done
for f in "$hack_dir/screensaver" "$config_dir/screensaver.xml"; do
    if [[ -e $f ]]; then
        echo "xscreensaver-test: $f exists already (a real install?): not overwriting it" >&2
        exit 1
    fi
done

user=screensaver-xss
work=$(mktemp -d /tmp/screensaver-xss.XXXXXX)
xvfb_pid=""
daemon_pid=""
display=""

cleanup() {
    local status=$? pid
    set +e
    for pid in $daemon_pid $xvfb_pid; do
        kill -TERM "$pid" 2>/dev/null
    done
    for pid in $daemon_pid $xvfb_pid; do
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        kill -KILL "$pid" 2>/dev/null
        wait "$pid" 2>/dev/null
    done
    # Anything else the test user still runs was started by this test (the
    # daemon's children): ended by its id.
    if id "$user" >/dev/null 2>&1; then
        for pid in $(pgrep -u "$user"); do
            echo "cleanup: ending $(ps -o args= -p "$pid") ($pid)"
            kill -KILL "$pid" 2>/dev/null
        done
        sleep 0.2
        userdel --remove "$user" 2>/dev/null
    fi
    rm -f "$hack_dir/screensaver" "$config_dir/screensaver.xml"
    if ((status != 0 || failed)) && [[ -s $work/daemon.log ]]; then
        echo "== the daemon's last log lines"
        tail -n 40 "$work/daemon.log"
    fi
    rm -rf "$work"
    if ((!summary_printed)); then
        echo "xscreensaver-test: stopped early (status $status)"
        echo "$passed passed, $((failed + 1)) failed"
    fi
}
trap cleanup EXIT

echo "== a user who is not root: $user"
if id "$user" >/dev/null 2>&1; then
    # Left by a run that was killed: its home is this test's own.
    userdel --remove "$user"
fi
useradd --create-home --shell /bin/bash "$user"
home=$(getent passwd "$user" | cut -d: -f6)
uid=$(id -u "$user")
gid=$(id -g "$user")
# Its PATH holds neither ~/.local/bin nor ~/.cargo/bin: the entry's absolute
# path must be enough.
user_path=/usr/local/bin:/usr/bin:/bin
as_user() {
    setpriv --reuid="$uid" --regid="$gid" --init-groups \
        env -i HOME="$home" USER="$user" LOGNAME="$user" PATH="$user_path" \
        ${display:+DISPLAY="$display"} "$@"
}
# The same in place of the shell, so that a background job's $! is the
# program's own process id.
exec_as_user() {
    exec setpriv --reuid="$uid" --regid="$gid" --init-groups \
        env -i HOME="$home" USER="$user" LOGNAME="$user" PATH="$user_path" \
        ${display:+DISPLAY="$display"} "$@"
}
# xscreensaver-command, its chatter kept for when it fails.
command_ok() {
    local out
    out=$(as_user xscreensaver-command "$@" 2>&1) || {
        echo "$out" | sed 's/^/  | /'
        return 1
    }
}

# What the user runs is copied where the user can read it (the checkout may
# be under /root).
stage=$work/stage
mkdir -p "$stage/scripts" "$stage/contrib/xscreensaver"
cp scripts/xscreensaver-install.sh "$stage/scripts/"
cp contrib/xscreensaver/screensaver.xml "$stage/contrib/xscreensaver/"
cp "$binary" "$stage/screensaver"
chmod -R a+rX "$work"
install=$stage/scripts/xscreensaver-install.sh

# An existing ~/.xscreensaver as xscreensaver-settings 6.06 writes one
# (random mode, other hacks, a disabled one, a GL one), with what the
# daemon needs here: no lock (no password to type under Xvfb), no splash,
# no fades (the picture is checked at once).
before=$work/xscreensaver.before
cat >"$before" <<'EOF'
# XScreenSaver Preferences File
# Written by xscreensaver-settings 6.06 for a test.
# https://www.jwz.org/xscreensaver/

timeout:	0:10:00
cycle:		0:10:00
lock:		False
lockTimeout:	0:00:00
splash:		False
fade:		False
unfade:		False

mode:		random
selected:	5

textMode:	date

programs:								      \
				maze --root				    \n\
- GL: 				superquadrics --root			    \n\
-				noseguy --root				    \n\
  GL: 				gears --root				    \n\


pointerHysteresis:  10
EOF
install -o "$user" -g "$gid" -m 644 "$before" "$home/.xscreensaver"
rc=$home/.xscreensaver
installed=$home/.local/bin/screensaver

echo "== the per-user install"
check "the install refuses root (the daemon would not run the hack)" \
    bash -c "! HOME=$work '$install' '$stage/screensaver' >/dev/null 2>&1"
install_out=$(as_user "$install" "$stage/screensaver" 2>&1) && install_ok=1 || install_ok=0
echo "$install_out" | sed 's/^/  | /'
check "the install succeeds as the user" test "$install_ok" = 1
check "the program is in ~/.local/bin, executable" test -x "$installed"
check "it is the program given" cmp -s "$installed" "$stage/screensaver"
check "~/.xscreensaver says mode: one" grep -qxP 'mode:\t\tone' "$rc"
# The four entries of the file come first: this one is the fifth, index 4.
check "~/.xscreensaver says selected: 4" grep -qxP 'selected:\t4' "$rc"
entry_line=$(printf '  "Screensaver (lines)"\t%s\t\\n\\' "$installed")
check "the entry is the fifth in programs:, by its absolute path" \
    bash -c "grep -A5 -x 'programs:.*' '$rc' | sed -n 6p | grep -qxF '$entry_line'"
same_rest() {
    diff <(grep -v -E '^(mode|selected):' "$before") \
        <(grep -v -E '^(mode|selected):|^# screensaver-install:|"Screensaver \(lines\)"' "$rc")
}
check "every other line of the file is kept" same_rest
cp "$rc" "$work/xscreensaver.installed"
as_user "$install" "$stage/screensaver" >"$work/second.out" 2>&1 && second_ok=1 || second_ok=0
check "a second install succeeds" test "$second_ok" = 1
check "a second install changes nothing" cmp -s "$rc" "$work/xscreensaver.installed"

echo "== the daemon under Xvfb, as $user"
# Xvfb as the user, as a session's server would be; the socket directory
# is the system's (made here when no X server ever ran).
install -d -m 1777 /tmp/.X11-unix
setpriv --reuid="$uid" --regid="$gid" --init-groups \
    Xvfb -displayfd 3 -screen 0 640x480x24 -nolisten tcp -noreset \
    3>"$work/display" 2>"$work/xvfb.log" &
xvfb_pid=$!
display_known() { [[ -s $work/display ]]; }
if wait_until 20 display_known; then
    display=":$(tr -d '[:space:]' <"$work/display")"
    ok "Xvfb runs on $display"
else
    not_ok "Xvfb did not start: $(cat "$work/xvfb.log")"
    exit 1
fi

start_daemon() {
    : >"$work/daemon.log"
    (exec_as_user xscreensaver -no-splash -verbose >>"$work/daemon.log" 2>&1) &
    daemon_pid=$!
    wait_until 20 as_user xscreensaver-command -version >/dev/null 2>&1
}
check "the daemon starts and answers xscreensaver-command" start_daemon

# A new start of the program whose command is $1 in the daemon's log
# ("forked "CMD" in pid P on window W"), another than the last one found:
# sets hack_pid and hack_window.
hack_pid=""
hack_window=""
new_hack() {
    local line pid
    line=$(grep -E "forked \"$1( [^\"]*)?\" in pid [0-9]+ on window 0x[0-9a-fA-F]+" "$work/daemon.log" | tail -n 1)
    [[ -n $line ]] || return 1
    pid=$(sed -E 's/.* in pid ([0-9]+) .*/\1/' <<<"$line")
    [[ $pid != "$hack_pid" ]] || return 1
    hack_pid=$pid
    hack_window=$(sed -E 's/.* on window (0x[0-9a-fA-F]+).*/\1/' <<<"$line")
}
parent_of() { ps -o ppid= -p "$1" | tr -d ' '; }
name_of() { ps -o comm= -p "$1"; }
is_child_of_daemon() {
    local gfx
    gfx=$(parent_of "$hack_pid") || return 1
    # XScreenSaver 6 runs the hacks from xscreensaver-gfx, its child.
    [[ $(name_of "$gfx") == xscreensaver-gf* && $(parent_of "$gfx") == "$daemon_pid" ]]
}
runs_as_user() { [[ $(ps -o user= -p "$hack_pid") == "$user" ]]; }
exe_is() { [[ $(readlink "/proc/$hack_pid/exe") == "$1" ]]; }
has_window_env() {
    tr '\0' '\n' <"/proc/$hack_pid/environ" | grep -qixF "XSCREENSAVER_WINDOW=$hack_window"
}
window_on_screen() {
    local info
    info=$(as_user xwininfo -id "$hack_window") || return 1
    grep -q 'Map State: IsViewable' <<<"$info" &&
        grep -qE 'Width: 640$' <<<"$info" && grep -qE 'Height: 480$' <<<"$info" &&
        as_user xwininfo -root -children | grep -qi "^ *$hack_window "
}
# Every window on the screen is the daemon's: the program made none of its
# own (it draws into the daemon's), and none is left when it has gone.
only_daemon_windows() {
    local tree
    tree=$(as_user xwininfo -root -tree) || return 1
    ! grep -E '^ +0x[0-9a-f]+ ' <<<"$tree" | grep -vE '^ +0x[0-9a-f]+ "XScreenSaver( Daemon)?": \("xscreensaver" "XScreenSaver"\)'
}
only_daemon_window_left() {
    local windows
    windows=$(as_user xwininfo -root -children | grep -E '^ +0x[0-9a-f]+ ') || return 1
    [[ $(wc -l <<<"$windows") == 1 ]] && grep -q '"XScreenSaver Daemon"' <<<"$windows"
}

# The root window's pixels that are plainly the red lines' colour (170, 20,
# 20 at full strength) and plainly the gray lines' (150, 150, 150), judged
# by hue as anti-aliasing blends them with black: "RED GRAY".
colours() {
    local shot=$work/shot.xwd fields
    as_user xwd -root -silent >"$shot" || return 1
    # The header: 25 big-endian words (X11/XWDFile.h).
    read -r -a fields <<<"$(od -An -v -tu4 --endian=big -N 100 "$shot" | tr -s ' \n' ' ')"
    local header=${fields[0]} width=${fields[4]} order=${fields[7]} bpp=${fields[11]}
    local line=${fields[12]} ncolors=${fields[19]}
    if ((bpp != 32 || line != 4 * width)); then
        echo "unexpected xwd image: $bpp bits a pixel, $line bytes a line for $width pixels" >&2
        return 1
    fi
    od -An -v -tu1 -w4 -j $((header + 12 * ncolors)) "$shot" | awk -v order="$order" '
        {
            if (order == 0) { b = $1; g = $2; r = $3 } else { r = $2; g = $3; b = $4 }
            gb = g > b ? g - b : b - g; rg = r > g ? r - g : g - r
            if (r >= 60 && r > 3 * g && gb <= 4) red++
            else if (r >= 60 && r <= 200 && rg <= 4 && gb <= 4) gray++
        }
        END { print red + 0, gray + 0 }'
}
red_and_gray() {
    local counts
    counts=$(colours) || return 1
    last_colours=$counts
    # 1000 lines on 640 x 480 light about 7000 pixels of each colour.
    read -r red gray <<<"$counts"
    ((red >= 300 && gray >= 300))
}
picture_moves() {
    local a b
    as_user xwd -root -silent >"$work/a.xwd" || return 1
    sleep 1
    as_user xwd -root -silent >"$work/b.xwd" || return 1
    a=$(md5sum <"$work/a.xwd")
    b=$(md5sum <"$work/b.xwd")
    [[ $a != "$b" ]]
}
gone() { ! kill -0 "$1" 2>/dev/null; }
# The user's processes besides Xvfb and the daemon. A child of the daemon
# that has ended but is not yet reaped (state Z) runs nothing: the daemon
# collects its xscreensaver-gfx only at its next wake, seconds later.
others() {
    ps -u "$user" -o pid=,ppid=,stat= | awk -v xvfb="$xvfb_pid" -v daemon="$daemon_pid" '
        $1 != xvfb && $1 != daemon && !($2 == daemon && $3 ~ /^Z/) { print $1 }'
}
nothing_else_runs() { [[ -z $(others) ]]; }
# Checks, for up to 10 s, that nothing but the daemon and Xvfb runs as
# $user; a failure names what still runs.
check_nothing_else_runs() {
    if wait_until 10 nothing_else_runs; then
        ok "nothing but the daemon and Xvfb runs as $user"
    else
        not_ok "nothing but the daemon and Xvfb runs as $user; still running: $(others | xargs -r ps -o pid=,args= -p | tr '\n' ';')"
    fi
}

# One activation of the display mode whose command is $1: it runs, draws,
# and is gone after -deactivate.
activation() {
    local command=$1
    check "xscreensaver-command -activate" command_ok -activate
    if wait_until 20 new_hack "$command"; then
        ok "the daemon runs $command (pid $hack_pid, window $hack_window)"
    else
        not_ok "the daemon did not run $command; it ran: $(grep -E 'forked "|not launching' "$work/daemon.log" | grep -v xscreensaver-gl-visual | tail -n 2)"
        command_ok -deactivate >/dev/null 2>&1 || true
        return
    fi
    check "its process is the installed program" exe_is "$command"
    check "it runs as $user" runs_as_user
    check "it is the daemon's child (through xscreensaver-gfx)" is_child_of_daemon
    check "its XSCREENSAVER_WINDOW is the daemon's window $hack_window" has_window_env
    check "that window fills the screen, a child of the root" window_on_screen
    last_colours="none"
    if wait_until 15 red_and_gray; then
        ok "the screen shows red and gray lines (pixels: $last_colours)"
    else
        not_ok "the screen does not show red and gray lines (pixels red, gray: $last_colours)"
    fi
    check "the picture moves" picture_moves
    check "every window is the daemon's (the program drew into the daemon's)" only_daemon_windows

    local pid=$hack_pid
    check "xscreensaver-command -deactivate" command_ok -deactivate
    check "the program has exited within 10 s" wait_until 10 gone "$pid"
    check "it printed its results (the daemon's log)" grep -q -- '---- END RESULTS ----' "$work/daemon.log"
    check_nothing_else_runs
    check "no window is left but the daemon's own" wait_until 10 only_daemon_window_left
}

activation "$installed"

# The daemon's cycle (here forced: every 10 minutes by itself) ends the
# program with SIGTERM and starts it again; xscreensaver-gfx logs how the
# old one ended.
echo "== a cycle while active: the program ended and started again"
check "xscreensaver-command -activate" command_ok -activate
if wait_until 20 new_hack "$installed"; then
    first=$hack_pid
    check "xscreensaver-command -cycle" command_ok -cycle
    check "the program has exited within 10 s" wait_until 10 gone "$first"
    if wait_until 20 new_hack "$installed"; then
        ok "the daemon started it again (pid $hack_pid)"
    else
        not_ok "the daemon did not start it again"
    fi
    exit_line=$(grep -E "child pid $first \(" "$work/daemon.log" | grep -E 'exited|terminated' | tail -n 1 || true)
    echo "  | ${exit_line:-(the daemon logged no end of pid $first)}"
    check "the daemon logged the end of pid $first" test -n "$exit_line"
    check "the daemon logs it as a normal end by SIGTERM" grep -q 'exited normally with SIGTERM' <<<"$exit_line"
    second=$hack_pid
    check "xscreensaver-command -deactivate" command_ok -deactivate
    check "the program has exited within 10 s" wait_until 10 gone "$second"
    check_nothing_else_runs
else
    not_ok "the daemon did not run $installed"
fi

stop_daemon() {
    as_user xscreensaver-command -exit >/dev/null 2>&1 || return 1
    wait_until 10 gone "$daemon_pid" || return 1
    wait "$daemon_pid" 2>/dev/null || true
    daemon_pid=""
}
check "xscreensaver-command -exit ends the daemon" stop_daemon

echo "== the per-user uninstall"
as_user "$install" --uninstall >"$work/uninstall.out" 2>&1 && u_ok=1 || u_ok=0
sed 's/^/  | /' "$work/uninstall.out"
check "the uninstall succeeds" test "$u_ok" = 1
check "~/.xscreensaver is as it was before the install, byte for byte" cmp "$before" "$rc"
check "the program is gone from ~/.local/bin" test ! -e "$installed"

echo "== the system-wide install, then the user's selection of it"
system_out=$("$install" --system "$stage/screensaver" 2>&1) && s_ok=1 || s_ok=0
echo "$system_out" | sed 's/^/  | /'
check "the system-wide install succeeds as root" test "$s_ok" = 1
check "the program is in the hack directory $hack_dir" cmp -s "$stage/screensaver" "$hack_dir/screensaver"
check "screensaver.xml is where xscreensaver-settings reads it ($config_dir)" \
    cmp -s contrib/xscreensaver/screensaver.xml "$config_dir/screensaver.xml"
as_user "$install" "$hack_dir/screensaver" >"$work/select.out" 2>&1 && sel_ok=1 || sel_ok=0
sed 's/^/  | /' "$work/select.out"
check "the user's install of the system-wide program succeeds" test "$sel_ok" = 1
check "it copies nothing to ~/.local/bin" test ! -e "$installed"
check "the entry names the hack directory's program" grep -qF "$hack_dir/screensaver" "$rc"
check "the daemon starts again" start_daemon
activation "$hack_dir/screensaver"
check "xscreensaver-command -exit ends the daemon" stop_daemon
# Output shown as the install's above.
indented() { "$@" 2>&1 | sed 's/^/  | /'; }
check "the user's uninstall succeeds" indented as_user "$install" --uninstall
check "~/.xscreensaver is as it was before, byte for byte" cmp "$before" "$rc"
check "the system-wide uninstall succeeds" indented "$install" --system --uninstall
check "the hack directory and settings directory hold no screensaver" \
    test ! -e "$hack_dir/screensaver" -a ! -e "$config_dir/screensaver.xml"

echo "== done in $((SECONDS - started)) s"
summary_printed=1
echo "$passed passed, $failed failed"
((failed == 0))
