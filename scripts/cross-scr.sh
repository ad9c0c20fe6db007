# The Windows screen saver (screensaver.scr) under Wine on a virtual X
# server, sourced by `scripts/cross.sh windows` after the conformance runs
# (it uses that script's $wine, $release, $cross_dir, $work, passed and
# failed): `/c` says it has no settings, `/s` fills the screen with red
# and gray lines and ends on a mouse move and on a key press, `/p HWND`
# draws into a window made for the test (contrib/wine/preview-host.c, the
# control panel's stand-in) and ends when that window closes.

scr="$release/screensaver.scr"
ok() {
    echo "ok   screensaver.scr: $*"
    passed=$((passed + 1))
}
not_ok() {
    echo "FAIL screensaver.scr: $*"
    failed=$((failed + 1))
}
# wait_until SECONDS COMMAND...: whether COMMAND succeeds within SECONDS.
wait_until() {
    local until=$((SECONDS + $1))
    shift
    until "$@"; do
        ((SECONDS < until)) || return 1
        sleep 0.5
    done
}
gone() { ! kill -0 "$1" 2>/dev/null; }
# Ends a process of this test that is still running (by its id).
end() {
    if kill -0 "$1" 2>/dev/null; then
        kill "$1" 2>/dev/null || true
    fi
    wait "$1" 2>/dev/null || true
}

# The pixels of the screen that are plainly the red lines' colour (170,
# 20, 20 at full strength) and plainly the gray lines' (150, 150, 150),
# judged by hue as anti-aliasing blends them with black (as
# scripts/xscreensaver-test.sh judges), within its WIDTH x HEIGHT top left
# corner and outside it: "RED GRAY RED_OUTSIDE GRAY_OUTSIDE".
colours() {
    local width=$1 height=$2 shot=$work/shot.xwd fields
    xwd -root -silent >"$shot" || return 1
    # The header: 25 big-endian words (X11/XWDFile.h).
    read -r -a fields <<<"$(od -An -v -tu4 --endian=big -N 100 "$shot" | tr -s ' \n' ' ')"
    local header=${fields[0]} screen=${fields[4]} order=${fields[7]} bpp=${fields[11]}
    local line=${fields[12]} ncolors=${fields[19]}
    # 24 bits of colour come 4 bytes a pixel, as 32 do.
    if ((line != 4 * screen || (bpp != 24 && bpp != 32))); then
        echo "unexpected xwd image: $bpp bits a pixel, $line bytes a line for $screen pixels" >&2
        return 1
    fi
    od -An -v -tu1 -w4 -j $((header + 12 * ncolors)) "$shot" | awk -v order="$order" \
        -v screen="$screen" -v width="$width" -v height="$height" '
        {
            i = NR - 1; x = i % screen; y = int(i / screen)
            k = x < width && y < height ? "in" : "out"
            if (order == 0) { b = $1; g = $2; r = $3 } else { r = $2; g = $3; b = $4 }
            gb = g > b ? g - b : b - g; rg = r > g ? r - g : g - r
            if (r >= 60 && r > 3 * g && gb <= 4) red[k]++
            else if (r >= 60 && r <= 200 && rg <= 4 && gb <= 4) gray[k]++
        }
        END { print red["in"] + 0, gray["in"] + 0, red["out"] + 0, gray["out"] + 0 }'
}
# Whether the WIDTH x HEIGHT corner shows at least MIN pixels of each
# colour, and none of either outside it.
red_and_gray() {
    local counts red gray red_out gray_out
    counts=$(colours "$1" "$2") || return 1
    last_colours=$counts
    read -r red gray red_out gray_out <<<"$counts"
    ((red >= $3 && gray >= $3 && red_out == 0 && gray_out == 0))
}
picture_moves() {
    local a b
    xwd -root -silent >"$work/a.xwd" || return 1
    sleep 1
    xwd -root -silent >"$work/b.xwd" || return 1
    a=$(md5sum <"$work/a.xwd")
    b=$(md5sum <"$work/b.xwd")
    [[ $a != "$b" ]]
}
has_window() { xwininfo -root -tree 2>/dev/null | grep -q "\"$1\""; }

host="$cross_dir/preview-host.exe"
if ! x86_64-w64-mingw32-gcc -O2 -Wall -Werror -o "$host" contrib/wine/preview-host.c -lgdi32; then
    not_ok "cannot build contrib/wine/preview-host.c"
fi

# A virtual X server of our own, on the first free display from :71.
display=71
while [ -e "/tmp/.X11-unix/X$display" ] || [ -e "/tmp/.X$display-lock" ]; do
    display=$((display + 1))
done
Xvfb ":$display" -screen 0 640x480x24 -nolisten tcp >"$work/xvfb.log" 2>&1 &
xvfb_pid=$!
trap 'end "$xvfb_pid"; rm -rf "$work"' EXIT
export DISPLAY=":$display"
wait_until 20 xwininfo -root >/dev/null 2>&1 || not_ok "Xvfb did not start: $(cat "$work/xvfb.log")"

# /c: a message saying there are no settings; closing it ends the program.
"$wine" "$scr" /c >"$work/c.log" 2>&1 &
pid=$!
if wait_until 60 has_window Screensaver; then
    ok "/c shows its message"
    # Return presses the message's OK button.
    xdotool search --name '^Screensaver$' windowfocus --sync key Return 2>/dev/null || true
    if wait_until 20 gone "$pid" && wait "$pid"; then
        ok "/c ends, with status 0, when its message is closed"
    else
        not_ok "/c did not end when its message was closed"
    fi
else
    not_ok "/c showed no window named Screensaver: $(tail -n 3 "$work/c.log")"
fi
end "$pid"

# /s, twice: once ended by the mouse, once by a key.
for ender in "mouse move" "key press"; do
    if [ "$ender" = "mouse move" ]; then flag=/S; else flag=-s; fi
    "$wine" "$scr" "$flag" >"$work/s.log" 2>&1 &
    pid=$!
    last_colours=none
    # 1000 lines on 640 x 480 light thousands of pixels of each colour.
    if wait_until 60 red_and_gray 640 480 300; then
        ok "$flag fills the screen with red and gray lines (pixels: $last_colours)"
        if picture_moves; then ok "$flag: the picture moves"; else not_ok "$flag: the picture does not move"; fi
        if gone "$pid"; then
            not_ok "$flag ended before any input"
        else
            if [ "$ender" = "mouse move" ]; then
                xdotool mousemove 100 100 && sleep 0.5 && xdotool mousemove 400 300
            else
                xdotool key space
            fi
            if wait_until 20 gone "$pid"; then
                ok "$flag ends on a $ender"
            else
                not_ok "$flag did not end on a $ender"
            fi
        fi
    else
        not_ok "$flag: no red and gray lines on the screen (pixels red, gray: $last_colours): $(tail -n 3 "$work/s.log")"
    fi
    end "$pid"
done

# /p HWND: into the test's own 320 x 240 window at the top left, which
# closes after 25 seconds; the screen saver must end with it.
"$wine" "$host" 25 >"$work/host.out" 2>"$work/host.log" &
host_pid=$!
if wait_until 60 grep -q '^[0-9]' "$work/host.out"; then
    hwnd="$(tr -d '\r' <"$work/host.out" | head -n 1)"
    "$wine" "$scr" /p "$hwnd" >"$work/p.log" 2>&1 &
    pid=$!
    last_colours=none
    # 1000 lines on 320 x 240 light a few thousand pixels of each colour.
    if wait_until 20 red_and_gray 320 240 150; then
        ok "/p $hwnd draws red and gray lines into the preview window, none outside (pixels in, out: $last_colours)"
    else
        not_ok "/p $hwnd: no red and gray lines in the preview window (pixels red, gray: $last_colours): $(tail -n 3 "$work/p.log")"
    fi
    if wait_until 40 gone "$host_pid" && wait_until 20 gone "$pid"; then
        ok "/p ends when the preview window closes"
    else
        not_ok "/p still runs after the preview window closed"
    fi
    end "$pid"
else
    not_ok "the preview window did not start: $(tail -n 3 "$work/host.log")"
fi
end "$host_pid"

# /p:HWND must name a window.
if "$wine" "$scr" /p:12345 >/dev/null 2>&1; then
    not_ok "/p:12345 (no such window) succeeded"
else
    ok "/p:12345 (no such window) fails"
fi
