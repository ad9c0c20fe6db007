#!/usr/bin/env bash
# Installs `screensaver` as an XScreenSaver display mode ("hack") and selects
# it, so that the daemon runs it when the screen blanks. Written after a new
# user followed the README and got another hack (issue 45, item 10): the
# daemon appends its own ~240 hacks to `programs:`, and `mode: random` picks
# among them; it looks programs up in its hack directory and the PATH it was
# started with (~/.cargo/bin is rarely on it); and it runs no hack as root.
set -euo pipefail

usage() {
    cat <<'EOF'
Usage:
  scripts/xscreensaver-install.sh [OPTIONS] [BINARY]     install for yourself (not as root)
  scripts/xscreensaver-install.sh --uninstall            undo that
  sudo scripts/xscreensaver-install.sh --system [BINARY] system-wide files
  sudo scripts/xscreensaver-install.sh --system --uninstall

BINARY is the program to install. By default it is this repository's
target/release/screensaver ($CARGO_TARGET_DIR/release/screensaver when that
is set), built with `cargo build --release --locked` if it is missing.
A `cargo install` copy is ~/.cargo/bin/screensaver.

For yourself (run it as the user who runs XScreenSaver; the daemon runs
no display mode as root):
  - copies BINARY to ~/.local/bin/screensaver (a BINARY already in
    XScreenSaver's hack directory, as --system puts it, is used in place);
  - edits ~/.xscreensaver: adds "Screensaver (lines)" with that absolute
    path to `programs:` (in single quotes when it holds a space or another
    character a shell would read: the daemon then runs the entry through
    /bin/sh), or updates an existing screensaver entry, keeping its
    options, and removes any other; and selects it alone: `mode: one`,
    `selected: N`. The rest of the file is kept. The mode and selection it
    replaces are noted in a comment, and --uninstall removes every
    screensaver entry and puts them back (or, when you have chosen another
    since, keeps yours, renumbered). Running it twice changes nothing the
    second time. A copy of the file before each change is left in
    ~/.xscreensaver.bak. A running daemon rereads the file the next time it
    blanks the screen. (With a space in its path, the program runs when
    selected alone, as here; in `mode: random` the daemon passes over it,
    as it looks for the program by the command's text up to its first
    space.)

System-wide (as root; edits no one's ~/.xscreensaver):
  - copies BINARY into XScreenSaver's hack directory (/usr/libexec/xscreensaver
    on Debian 12 and later, /usr/lib/xscreensaver before), which the daemon
    puts first on its PATH;
  - copies contrib/xscreensaver/screensaver.xml into the directory where
    xscreensaver-settings reads a hack's settings
    (/usr/share/xscreensaver/config), for its Settings dialog.
  Each user then selects it with
    scripts/xscreensaver-install.sh /usr/libexec/xscreensaver/screensaver

Options:
  --uninstall       remove what the install put in place
  --system          the system-wide files, as root
  --hack-dir DIR    XScreenSaver's hack directory (default: found)
  --config-dir DIR  xscreensaver-settings' hack settings directory (default: found)
  -h, --help        this text
EOF
}

die() {
    echo "xscreensaver-install: $*" >&2
    exit 1
}

say() { echo "xscreensaver-install: $*"; }

repo=$(cd "$(dirname "$0")/.." && pwd)
xml_source="$repo/contrib/xscreensaver/screensaver.xml"
label="Screensaver (lines)"
name=screensaver

system=0
uninstall=0
binary=""
hack_dir=""
config_dir=""
while (($#)); do
    case "$1" in
    --system) system=1 ;;
    --uninstall) uninstall=1 ;;
    --hack-dir)
        (($# >= 2)) || die "--hack-dir needs a directory"
        hack_dir=$2
        shift
        ;;
    --config-dir)
        (($# >= 2)) || die "--config-dir needs a directory"
        config_dir=$2
        shift
        ;;
    -h | --help)
        usage
        exit 0
        ;;
    -*) die "unknown option $1 (see --help)" ;;
    *)
        [[ -z $binary ]] || die "one BINARY only (see --help)"
        binary=$1
        ;;
    esac
    shift
done
if ((uninstall)) && [[ -n $binary ]]; then
    die "--uninstall takes no BINARY"
fi

# Where the packages put the hacks: Debian 12 and Fedora /usr/libexec, Debian
# 11 and Arch /usr/lib, a build from source /usr/local/libexec. The daemon
# (xscreensaver-gfx) puts the one it was built with first on the hacks' PATH.
hack_dir_candidates=(/usr/libexec/xscreensaver /usr/lib/xscreensaver
    /usr/local/libexec/xscreensaver /usr/lib64/xscreensaver)
find_hack_dir() {
    local d
    for d in "${hack_dir_candidates[@]}"; do
        [[ -d $d ]] && { echo "$d"; return; }
    done
    return 1
}
# xscreensaver-settings reads DIR/NAME.xml, NAME the program's file name.
find_config_dir() {
    local d
    for d in /usr/share/xscreensaver/config /usr/local/share/xscreensaver/config; do
        [[ -d $d ]] && { echo "$d"; return; }
    done
    return 1
}

# The program to install: checked to be this program, so that a wrong path
# fails here and not silently at the next screen blank.
resolve_binary() {
    if [[ -z $binary ]]; then
        binary="${CARGO_TARGET_DIR:-$repo/target}/release/$name"
        if [[ ! -e $binary ]]; then
            say "$binary is missing: building it (cargo build --release --locked)"
            command -v cargo >/dev/null ||
                die "cargo is not on PATH: build the program first, or give its path (see --help)"
            (cd "$repo" && cargo build --release --locked)
        fi
    fi
    [[ -f $binary ]] || die "$binary: no such file"
    [[ -x $binary ]] || die "$binary: not executable"
    binary=$(readlink -f -- "$binary")
    local version
    version=$("$binary" --version 2>/dev/null) || die "$binary --version failed: is it this program?"
    [[ $version == "$name "* ]] || die "$binary --version says \"$version\", not \"$name ...\""
}

# Copies $1 to $2 through a temporary file beside it, so that a display mode
# running the old copy keeps it (no "Text file busy") and no half-written
# file is ever under the final name.
put() {
    local from=$1 to=$2 mode=$3 tmp
    tmp=$(mktemp "$(dirname "$to")/.$(basename "$to").XXXXXX")
    if ! install -m "$mode" "$from" "$tmp"; then
        rm -f "$tmp"
        die "could not write $to"
    fi
    mv -f "$tmp" "$to"
}

# ---------------------------------------------------------------------------
# The edit of ~/.xscreensaver, in awk (present on every system that has a
# shell). The file is X resources: `key: value`, a value continued on the
# next line by a final backslash; `programs:` holds one entry a `\n`, each
# `[-] [VISUAL:] ["Label"] command args` ("-" leaves it out of random
# selection). `selected:` counts the entries from 0 (disabled ones too), and
# the daemon appends its own hacks after the file's, so an index into the
# file's list is the daemon's index.
#
# Only the `programs:` block and the `mode:` and `selected:` lines change;
# every other line is copied as it is. Entries are kept as written; the
# block is written back as xscreensaver-settings writes it (an entry a line,
# each ending in `\n\`, then a blank line), so a file that
# xscreensaver-settings wrote comes back byte for byte.
#
# How the daemon reads a command: the file reader turns `\X` into X (`\t`
# a tab, `\r` a return); a command holding any of *?$&!<>[];`'\"= is run
# by /bin/sh -c "exec COMMAND", any other is split at spaces and tabs and
# run directly. So a path with a space is written in single quotes (see
# entry_command), and an entry is this hack's when the first word of its
# command, as the shell reads it, names a file called NAME. The entries an
# earlier version of this script wrote unquoted (a path with a space, taken
# apart by the daemon) are recognised too, by the paths it wrote: CMD and
# LEGACY.
#
# ENVIRON: ACTION (install or uninstall), CMD (the absolute path for the
# entry), WORD (CMD as the entry writes it, quoted where it must be),
# LEGACY (the path a user install writes, ~/.local/bin/NAME), LABEL, NAME
# (the program's file name that marks this hack's entries), FRESH (1 when
# there was no file). Prints the new file on stdout and what it did on
# stderr.
# shellcheck disable=SC2016 # awk's own $ signs
edit_program='
function trim(s) { sub(/^[ \t]+/, "", s); sub(/[ \t]+$/, "", s); return s }
# The daemon'"'"'s reading of the file'"'"'s backslashes: sets U (the text
# read) and UAT[k] (the characters of s that give U'"'"'s first k).
function unescape(s,   i, c, m) {
    U = ""; m = length(s); UAT[0] = 0
    for (i = 1; i <= m; i++) {
        c = substr(s, i, 1)
        if (c == "\\" && i < m) {
            c = substr(s, ++i, 1)
            if (c == "t") c = "\t"; else if (c == "r") c = "\r"; else if (c == "n") c = "\n"
        }
        U = U c; UAT[length(U)] = i
    }
}
# The first word of command c as /bin/sh reads it (quotes taken off): sets
# W, and WEND (the characters of c it takes).
function first_word(c,   i, m, ch, q) {
    W = ""; m = length(c); i = 1
    while (i <= m) {
        ch = substr(c, i, 1)
        if (ch == " " || ch == "\t") break
        if (ch == SQ) {
            q = index(substr(c, i + 1), SQ)
            if (!q) { W = W substr(c, i + 1); i = m + 1; break }
            W = W substr(c, i + 1, q - 1); i += q + 1
        } else if (ch == "\"") {
            for (i++; i <= m && substr(c, i, 1) != "\""; i++) {
                ch = substr(c, i, 1)
                if (ch == "\\" && i < m && index("\"\\$`", substr(c, i + 1, 1))) ch = substr(c, ++i, 1)
                W = W ch
            }
            i++
        } else if (ch == "\\" && i < m) {
            W = W substr(c, i + 1, 1); i += 2
        } else { W = W ch; i++ }
    }
    WEND = (i > m) ? m : i - 1
}
# Whether command c (as read) starts with path p as a word of its own.
function starts_with(c, p) {
    return p != "" && (c == p || (substr(c, 1, length(p)) == p && substr(c, length(p) + 1, 1) ~ /[ \t]/))
}
# Parses an entry: sets E_DISABLED, E_PROG (the program the command runs,
# its first word as the shell reads it), E_WORD (that word as written) and
# E_ARGS (the rest, as written).
function parse(t,   s, c, w, q) {
    s = trim(t)
    E_DISABLED = 0
    if (s ~ /^-/) { E_DISABLED = 1; s = trim(substr(s, 2)) }
    if (match(s, /^[A-Za-z0-9_.-]+:[ \t]/)) s = trim(substr(s, RLENGTH + 1))
    if (substr(s, 1, 1) == "\"") {
        q = index(substr(s, 2), "\"")
        s = (q == 0) ? "" : trim(substr(s, q + 2))
    }
    unescape(s); c = U
    # A path with a space, written unquoted by an earlier version.
    if (starts_with(c, cmd) && cmd ~ /[ \t]/) { E_PROG = cmd; w = length(cmd) }
    else if (starts_with(c, legacy) && legacy ~ /[ \t]/) { E_PROG = legacy; w = length(legacy) }
    else { first_word(c); E_PROG = W; w = WEND }
    E_WORD = substr(s, 1, UAT[w])
    E_ARGS = trim(substr(s, UAT[w] + 1))
}
function ours(t,   b) { parse(t); b = E_PROG; sub(/.*\//, "", b); return b == NAME }
function value(line) { sub(/^[^:]*:[ \t]*/, "", line); return trim(line) }
function prefix(line) { match(line, /^[^:]*:[ \t]*/); return substr(line, 1, RLENGTH) }
function out(s) { print s }
function note(s) { print s > "/dev/stderr" }

{ L[++n] = $0 }

END {
    action = ENVIRON["ACTION"]; cmd = ENVIRON["CMD"]; label = ENVIRON["LABEL"]
    word = ENVIRON["WORD"]; legacy = ENVIRON["LEGACY"]
    NAME = ENVIRON["NAME"]; mark = "# screensaver-install: before it,"
    SQ = "\047"

    # The programs block: from its key to the first line that does not end
    # in a backslash.
    ps = 0
    for (i = 1; i <= n; i++) if (L[i] ~ /^[ \t]*programs[ \t]*:/) { ps = i; break }
    pe = ps
    if (ps) while (pe < n && L[pe] ~ /\\$/) pe++
    ne = 0
    if (ps) {
        joined = ""
        for (i = ps; i <= pe; i++) {
            s = L[i]
            if (i == ps) sub(/^[ \t]*programs[ \t]*:/, "", s)
            if (s ~ /\\$/) s = substr(s, 1, length(s) - 1)
            # The key line'"'"'s own spacing is not part of the first entry.
            if (i == ps && s ~ /^[ \t]*$/) { head = L[ps]; continue }
            joined = joined s
        }
        cnt = split(joined, P, /\\n/)
        for (k = 1; k <= cnt; k++) if (trim(P[k]) != "") E[++ne] = P[k]
    }
    if (head == "") head = "programs:\t\t\t\t\t\t\t\t      \\"

    mi = si = ci = 0
    for (i = 1; i <= n; i++) {
        if (ps && i >= ps && i <= pe) continue
        if (!mi && L[i] ~ /^[ \t]*mode[ \t]*:/) mi = i
        if (!si && L[i] ~ /^[ \t]*selected[ \t]*:/) si = i
        if (!ci && index(L[i], mark) == 1) ci = i
    }
    mode = mi ? value(L[mi]) : "unset"
    sel = si ? value(L[si]) : "unset"

    # Entries of this hack, by their index from 0.
    nours = 0
    for (k = 1; k <= ne; k++) if (ours(E[k])) { OURS[k - 1] = 1; nours++ }

    if (action == "install") {
        entry = "  \"" label "\"\t" word
        at = 0
        for (k = 1; k <= ne; k++) if (ours(E[k])) { at = k; break }
        if (at) {
            parse(E[at])
            if (E_PROG != cmd || E_WORD != word || E_DISABLED) {
                E[at] = entry (E_ARGS != "" ? " " E_ARGS : "") "\t"
                note("entry " (at - 1) " updated: " trim(E[at]))
            } else note("entry " (at - 1) " is already this program: " trim(E[at]))
            # One entry of this hack: any other (as an earlier version added
            # on a second run) goes. All come after the one kept.
            j = 0
            for (k = 1; k <= ne; k++) {
                if (k != at && (k - 1) in OURS) { note("entry " (k - 1) " removed (another entry of " NAME "): " trim(E[k])); continue }
                F[++j] = E[k]
            }
            ne = j; for (k = 1; k <= ne; k++) E[k] = F[k]
        } else {
            E[++ne] = entry "\t"; at = ne
            note("entry " (at - 1) " added: " trim(E[at]))
        }
        newmode = "one"; newsel = at - 1
        # What the selection was, as an index into the list that --uninstall
        # leaves (without any of this hack'"'"'s entries).
        keep = ci ? L[ci] : ""
        if (!ci && (mode != newmode || sel != newsel "")) {
            psel = sel
            if (sel ~ /^[0-9]+$/) {
                if ((sel + 0) in OURS) psel = -1
                else { d = 0; for (j in OURS) if (j + 0 < sel + 0) d++; psel = sel - d }
            }
            keep = mark " mode: " mode ", selected: " psel (ENVIRON["FRESH"] == "1" ? ", file: new" : "")
        }
        if (mode == newmode && sel == newsel "") note("already selected: mode one, selected " newsel)
        else note("selected: mode " mode " -> one, selected " sel " -> " newsel)
    } else {
        if (!nours && !ci) { note("no entry of " NAME " in the file; nothing to do"); for (i = 1; i <= n; i++) out(L[i]); exit }
        j = 0
        for (k = 1; k <= ne; k++) {
            if ((k - 1) in OURS) { note("entry " (k - 1) " removed: " trim(E[k])); continue }
            F[++j] = E[k]
        }
        ne = j; for (k = 1; k <= ne; k++) E[k] = F[k]
        was_ours = (sel ~ /^[0-9]+$/) && ((sel + 0) in OURS)
        newmode = mode; newsel = sel
        if (sel ~ /^[0-9]+$/ && !was_ours) { d = 0; for (j in OURS) if (j + 0 < sel + 0) d++; newsel = sel - d }
        fresh = 0
        if (was_ours) {
            if (ci) {
                c = L[ci]
                newmode = c; sub(/.*mode: /, "", newmode); sub(/,.*/, "", newmode)
                newsel = c; sub(/.*selected: /, "", newsel); sub(/,.*/, "", newsel)
                fresh = index(c, ", file: new") > 0
            } else { newmode = "random"; newsel = -1 }
            note("selection restored: mode " newmode ", selected " newsel)
        }
        keep = ""
    }

    # The block, as xscreensaver-settings writes it.
    nb = 0
    if (ne) {
        B[++nb] = head
        for (k = 1; k <= ne; k++) B[++nb] = E[k] "\\n\\"
        B[++nb] = ""
    }

    # The new file: settings lines in place; missing ones before the block.
    if (action == "uninstall" && fresh) {
        # Nothing but what the install wrote is left: no file.
        rest = 0
        for (i = 1; i <= n; i++) {
            if ((ps && i >= ps && i <= pe) || i == mi || i == si || i == ci) continue
            if (trim(L[i]) != "" && L[i] !~ /^[ \t]*#/) rest = 1
        }
        if (!rest && !nb) { note("the file held only the install'"'"'s lines: removed"); print "REMOVE-FILE" > "/dev/stderr"; exit }
    }
    set_mode = (newmode != "unset"); set_sel = (newsel != "unset")
    # The comment goes just before the mode line; the lines a file lacks go
    # just before the programs block, or at the end when it has none.
    added = 0
    # An uninstall that empties the list takes out the blank line the
    # install put before a block it appended at the end.
    drop = 0
    if (action == "uninstall" && ps && !nb && pe == n) {
        for (i = ps - 1; i >= 1; i--) {
            if (i == ci || (i == mi && !set_mode) || (i == si && !set_sel)) continue
            if (trim(L[i]) == "") drop = i
            break
        }
    }
    for (i = 1; i <= n; i++) {
        if (i == ci || i == drop) continue
        if (i == mi) {
            if (keep != "") out(keep)
            if (set_mode) out(prefix(L[i]) newmode)
            continue
        }
        if (i == si) { if (set_sel) out(prefix(L[i]) newsel); continue }
        if (ps && i >= ps && i <= pe) {
            if (i == ps) { add_missing(); for (k = 1; k <= nb; k++) out(B[k]) }
            continue
        }
        out(L[i])
    }
    if (!ps) {
        if (n && trim(L[n]) != "" && (nb || (!mi && (keep != "" || set_mode)) || (!si && set_sel))) out("")
        add_missing()
        for (k = 1; k <= nb; k++) out(B[k])
    }
}
function add_missing() {
    if (added++) return
    if (!mi) { if (keep != "") out(keep); if (set_mode) out("mode:\t\t" newmode) }
    if (!si && set_sel) out("selected:\t" newsel)
}
'

# Writes $2 (a file) as the new ~/.xscreensaver when it differs from the old
# one, keeping a copy of the old, and writing through a link (a dotfiles
# repository's) rather than replacing it.
replace_config() {
    local config=$1 new=$2 target
    if [[ -e $config ]] && cmp -s "$config" "$new"; then
        say "$config: unchanged"
        return
    fi
    target=$(readlink -f -- "$config")
    if [[ -e $target ]]; then
        cp -p -- "$target" "$config.bak"
        say "$config: changed (the previous file is $config.bak)"
    else
        say "$config: written"
    fi
    local tmp
    tmp=$(mktemp "$(dirname "$target")/.xscreensaver.XXXXXX")
    cat "$new" >"$tmp"
    if [[ -e $target ]]; then
        chmod --reference="$target" "$tmp"
    else
        # mktemp made it private; a new file gets the usual permissions.
        chmod "$(printf '%o' $((0666 & ~$(umask))))" "$tmp"
    fi
    mv -f "$tmp" "$target"
}

# The entry's command for path $1, as the daemon must read it: the path as
# it is when it holds nothing a shell would read otherwise, else in single
# quotes (the daemon then runs it through /bin/sh), or in double quotes if
# it holds a single quote. A path that neither can carry (a backslash, which
# the daemon's file reader takes away and xscreensaver-settings does not
# write back; a newline; a single quote beside one of "$`) is refused.
entry_command() {
    local path=$1
    if [[ $path =~ ^[A-Za-z0-9_./+-]+$ ]]; then
        printf '%s\n' "$path"
    elif [[ $path == *[$'\\\n']* ]]; then
        return 1
    elif [[ $path != *\'* ]]; then
        printf "'%s'\n" "$path"
    elif [[ $path != *[\"\$\`]* ]]; then
        printf '"%s"\n' "$path"
    else
        return 1
    fi
}

die_unquotable() {
    die "$1: XScreenSaver cannot run a program by this path (it holds a backslash, a newline, or a single quote beside one of \"\$\`): install it system-wide instead (--system, see --help)"
}

edit_config() {
    local action=$1 entry=${2:-} config="$HOME/.xscreensaver" fresh=0 new log word=""
    if [[ -n $entry ]]; then
        word=$(entry_command "$entry") || die_unquotable "$entry"
    fi
    # xscreensaver-settings writes the whole file when it saves, which would
    # undo this edit (or this edit its unsaved changes).
    if command -v pgrep >/dev/null &&
        pgrep -u "$(id -u)" -f '(^|/)xscreensaver-(settings|demo)( |$)' >/dev/null; then
        die "xscreensaver-settings is open: close it first (it rewrites $config when it saves)"
    fi
    [[ -e $config ]] || fresh=1
    new=$(mktemp)
    log=$(mktemp)
    if ! { [[ -e $config ]] && cat -- "$config"; true; } |
        ACTION=$action CMD=$entry WORD=$word LEGACY=$bin_dir/$name LABEL=$label NAME=$name FRESH=$fresh \
            awk "$edit_program" >"$new" 2>"$log"; then
        cat "$log" >&2
        rm -f "$new" "$log"
        die "could not edit $config"
    fi
    grep -v '^REMOVE-FILE$' "$log" | sed "s|^|xscreensaver-install: $config: |" || true
    if grep -q '^REMOVE-FILE$' "$log"; then
        cp -p -- "$(readlink -f -- "$config")" "$config.bak"
        rm -f -- "$config"
        say "$config: removed (the previous file is $config.bak)"
    elif ((fresh)) && [[ $action == uninstall ]]; then
        say "$config: no such file; nothing to do"
    else
        replace_config "$config" "$new"
    fi
    rm -f "$new" "$log"
}

# ---------------------------------------------------------------------------

if ((system)); then
    ((EUID == 0)) || die "--system writes to the system's directories: run it as root (sudo)"
    if [[ -z $hack_dir ]]; then
        hack_dir=$(find_hack_dir) ||
            die "no XScreenSaver hack directory (looked in ${hack_dir_candidates[*]}): install xscreensaver, or give --hack-dir"
    fi
    if [[ -z $config_dir ]]; then
        config_dir=$(find_config_dir) ||
            die "no XScreenSaver settings directory (looked in /usr/share/xscreensaver/config and /usr/local/share/xscreensaver/config): install xscreensaver, or give --config-dir"
    fi
    if ((uninstall)); then
        for f in "$hack_dir/$name" "$config_dir/$name.xml"; do
            if [[ -e $f ]]; then
                rm -f -- "$f"
                say "removed $f"
            else
                say "$f: not there"
            fi
        done
        say "users who selected it: scripts/xscreensaver-install.sh --uninstall"
        exit 0
    fi
    resolve_binary
    [[ -f $xml_source ]] || die "$xml_source is missing"
    if [[ $binary != "$hack_dir/$name" ]]; then
        put "$binary" "$hack_dir/$name" 755
    fi
    say "installed $hack_dir/$name ($("$hack_dir/$name" --version))"
    put "$xml_source" "$config_dir/$name.xml" 644
    say "installed $config_dir/$name.xml (the Settings dialog's controls)"
    say "each user selects it with: scripts/xscreensaver-install.sh $hack_dir/$name"
    exit 0
fi

if ((EUID == 0)); then
    die "XScreenSaver runs no display mode as root (it logs \"running as root: not launching hacks\"): run this as the user who runs XScreenSaver, or use --system for the system-wide files"
fi
[[ -n ${HOME:-} && -d $HOME ]] || die "HOME is not set to a directory"
bin_dir="$HOME/.local/bin"

if ((uninstall)); then
    edit_config uninstall
    if [[ -e $bin_dir/$name ]]; then
        rm -f -- "$bin_dir/$name"
        say "removed $bin_dir/$name"
    fi
    exit 0
fi

resolve_binary
if [[ -z $hack_dir ]]; then
    hack_dir=$(find_hack_dir) || hack_dir=""
fi
if [[ -n $hack_dir && $(dirname "$binary") == "$(readlink -f -- "$hack_dir")" ]]; then
    # A system-wide install: the entry names it where it is.
    installed=$binary
    say "using $installed where it is (XScreenSaver's hack directory)"
else
    installed="$bin_dir/$name"
    # Refused before anything is copied.
    entry_command "$installed" >/dev/null || die_unquotable "$installed"
    mkdir -p -- "$bin_dir"
    if [[ -e $installed ]] && cmp -s "$binary" "$installed"; then
        say "$installed is already this program ($("$installed" --version))"
    else
        put "$binary" "$installed" 755
        say "installed $installed ($("$installed" --version))"
    fi
fi
# The entry's absolute path works whatever PATH the daemon was started with.
edit_config install "$installed"

if [[ -z $config_dir ]]; then
    config_dir=$(find_config_dir) || config_dir=/usr/share/xscreensaver/config
fi
if [[ -f $config_dir/$name.xml ]] && cmp -s "$config_dir/$name.xml" "$xml_source"; then
    say "$config_dir/$name.xml is in place (the Settings dialog's controls)"
else
    say "for the Settings dialog's controls, as root: install -m 644 $xml_source $config_dir/"
fi
if command -v xscreensaver-command >/dev/null && xscreensaver-command -version >/dev/null 2>&1; then
    say "the running daemon uses it from the next blank; try: xscreensaver-command -activate"
else
    say "no XScreenSaver daemon answers on this display: start it with \`xscreensaver &\` in your session"
fi
