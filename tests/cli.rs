//! The command line: the results block, JSON, and errors on bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

fn screensaver(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .output()
        .expect("running the screensaver binary")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn temp_file(name: &str, contents: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("screensaver-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

const TWO_LINES: &str =
    "2\n(600, 400), (600, 420), 1, 0, 0\n(602.5, 400), (602.5, 420), -1, 0, 1\n";

#[test]
fn prints_the_original_results_block() {
    let path = temp_file("two.in", TWO_LINES);
    let out = screensaver(&["3", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let rows: Vec<&str> = stdout.lines().collect();
    assert_eq!(rows.len(), 7, "{stdout}");
    assert_eq!(rows[0], "Number of frames = 3");
    assert_eq!(rows[1], format!("Input file path is: {}", path.display()));
    assert_eq!(rows[2], "---- RESULTS ----");
    let time = rows[3].strip_prefix("Elapsed execution time: ").unwrap();
    let secs = time.strip_suffix('s').unwrap();
    assert_eq!(secs.split('.').nth(1).map(str::len), Some(6), "{time}");
    assert!(secs.parse::<f64>().is_ok());
    // Two lines 2.5 px apart closing at 1 px per step meet
    // within the four steps that three frames run, exactly once.
    assert_eq!(rows[4], "0 Line-Wall Collisions");
    assert_eq!(rows[5], "1 Line-Line Collisions");
    assert_eq!(rows[6], "---- END RESULTS ----");
}

#[test]
fn json_gives_the_same_results() {
    let path = temp_file("two-json.in", TWO_LINES);
    let out = screensaver(&["3", path.to_str().unwrap(), "--json", "--detector", "brute"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["frames"], 3);
    assert_eq!(v["steps"], 4);
    assert_eq!(v["lines"], 2);
    assert_eq!(v["detector"], "brute");
    assert_eq!(v["line_wall_collisions"], 0);
    assert_eq!(v["line_line_collisions"], 1);
    assert_eq!(v["input"], path.to_str().unwrap());
    assert!(v["elapsed_seconds"].as_f64().unwrap() >= 0.0);
}

#[test]
fn runs_the_built_in_scene_without_input() {
    let out = screensaver(&["2", "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["lines"], 1000);
    assert!(v["input"].is_null());
    let out = screensaver(&["0"]);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("Input file path is: (none: built-in scene"),
        "{stdout}"
    );
}

#[test]
fn writes_the_final_state() {
    let path = temp_file("two-state.in", TWO_LINES);
    let state = path.with_extension("state");
    let out = screensaver(&[
        "0",
        path.to_str().unwrap(),
        "--state-out",
        state.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let written = std::fs::read_to_string(&state).unwrap();
    let rows: Vec<&str> = written.lines().collect();
    assert_eq!(rows.len(), 2);
    assert!(rows[0].starts_with("0 0.75"), "{written}");
    assert_eq!(rows[1].split(' ').count(), 7);
}

fn assert_input_error(contents: &str, expected: &str) {
    let path = temp_file("bad.in", contents);
    let out = screensaver(&["10", path.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        out.stdout.is_empty(),
        "partial output: {}",
        text(&out.stdout)
    );
    let stderr = text(&out.stderr);
    let wanted = format!("screensaver: error: {}:{expected}", path.display());
    assert!(stderr.starts_with(&wanted), "{stderr}\nwanted: {wanted}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn bad_inputs_name_the_file_line_and_problem() {
    assert_input_error("", "1: the file is empty");
    assert_input_error("abc\n", "1: expected the number of lines");
    assert_input_error(
        "2\n(1, 2), (3, 4), 0, 0, 0\n",
        "2: the file declares 2 lines but ends after 1",
    );
    assert_input_error(
        "1\n(1, 2), (3, 4), 0, 0, 0\n(1, 2), (3, 4), 0, 0, 0\n",
        "3: the file declares 1 line but has more rows",
    );
    assert_input_error(
        "1\n(1, 2), (3, 4), 0, 0\n",
        "2: row 1: expected `,` after vy",
    );
    assert_input_error(
        "1\n(1, 2), (3, nan), 0, 0, 0\n",
        "2: row 1: y2 must be a finite number",
    );
    assert_input_error(
        "1\n(1, 2), (3, 4), 0, 0, 7\n",
        "2: row 1: colour must be 0 (red) or 1 (gray)",
    );
}

#[test]
fn missing_file_is_an_error() {
    let out = screensaver(&["10", "/nonexistent/scene.in"]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    assert!(text(&out.stderr).contains("/nonexistent/scene.in: cannot read the file"));
}

#[test]
fn bad_arguments_are_usage_errors() {
    let out = screensaver(&["lots"]);
    assert_eq!(out.status.code(), Some(2));
    let out = screensaver(&["10", "--detector", "magic"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("unknown detector `magic`"));
    let out = screensaver(&[]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn help_and_version() {
    let out = screensaver(&["--help"]);
    assert!(out.status.success());
    let help = text(&out.stdout);
    assert!(
        help.contains("--detector") && help.contains("FRAMES"),
        "{help}"
    );
    let out = screensaver(&["--version"]);
    assert!(text(&out.stdout).starts_with("screensaver "));
}

#[test]
fn no_progress_bar_in_pipes() {
    // stderr is a pipe here: nothing may be drawn on it.
    let out = screensaver(&["1", "--json"]);
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
}

#[test]
fn graphics_without_a_display_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["-g", "5"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("cannot open a window: no display"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
    // A display that does not answer: said before anything is printed.
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["-g", "5"])
        .env("DISPLAY", ":42")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("cannot connect to the X display `:42`"),
        "{stderr}"
    );
}

#[test]
fn stats_count_the_work_and_time_every_phase() {
    let out = screensaver(&["50", "--stats", "--detector", "quadtree"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let stats = stdout
        .split("---- STATS ----\n")
        .nth(1)
        .and_then(|s| s.split("---- END STATS ----").next())
        .unwrap_or_else(|| panic!("no stats block: {stdout}"));
    assert!(stats.contains("lines: 1000, steps: 51"), "{stats}");
    let phases: Vec<&str> = stats
        .lines()
        .skip_while(|l| *l != "time per phase:")
        .skip(1)
        .map(|l| l.trim_start().split("  ").next().unwrap().trim_end())
        .collect();
    let expected = [
        "detect",
        "fill",
        "sort",
        "walk and test",
        "reorder",
        "resolve",
        "move and walls",
    ];
    assert_eq!(phases, expected, "{stats}");
}

#[test]
fn stats_tell_what_the_thread_teams_hand_offs_cost() {
    // A scene large enough for the team (from 384 lines).
    let dir = std::env::temp_dir().join(format!("screensaver-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("team.in");
    let path = path.to_str().unwrap();
    let out = screensaver(&["gen", "--lines", "3000", "--seed", "3", "-o", path]);
    assert!(out.status.success(), "{}", text(&out.stderr));

    let out = screensaver(&["40", path, "--threads", "2", "--stats"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let team = stdout
        .lines()
        .find(|l| l.starts_with("team: "))
        .unwrap_or_else(|| panic!("no team line: {stdout}"));
    assert!(team.contains(" hand-offs a step, "), "{team}");
    assert!(
        team.contains(" pieces each; the other threads ran "),
        "{team}"
    );
    assert!(
        team.contains(" hand-offs ran wholly on the stepping thread; "),
        "{team}"
    );

    // Sweeping every step (a kept step hands off two jobs: the move with
    // the boxes' check, and the comparison).
    let args = [
        "40",
        path,
        "--threads",
        "2",
        "--stats",
        "--json",
        "--keep-pairs",
        "never",
    ];
    let out = screensaver(&args);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let team = &v["stats"]["team"];
    // Hull, layout and sweep, and move: at least three a step.
    assert!(team["hand_offs"].as_u64().unwrap() >= 3 * 40, "{team}");
    let (jobs, pieces) = (
        team["hand_offs"].as_u64().unwrap(),
        team["pieces"].as_u64().unwrap(),
    );
    assert!(pieces >= 2 * jobs, "{team}");
    assert!(team["member_pieces"].as_u64().unwrap() <= pieces, "{team}");
    assert!(team["alone"].as_u64().unwrap() <= jobs, "{team}");
    assert!(team["parked_waits"].as_u64().unwrap() <= jobs, "{team}");
    assert!(team["wait_seconds"].as_f64().unwrap() >= 0.0, "{team}");

    // One thread has no team to hand to.
    let out = screensaver(&["40", path, "--threads", "1", "--stats", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["stats"].get("team").is_none(), "{}", v["stats"]);
    let out = screensaver(&["40", path, "--threads", "1", "--stats"]);
    assert!(!text(&out.stdout).contains("team: "));
}

#[test]
fn json_stats_split_detection_into_the_detectors_phases() {
    let out = screensaver(&["50", "--stats", "--json", "--detector", "quadtree"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let seconds = &v["stats"]["seconds"];
    let detect = seconds["detect"].as_f64().unwrap();
    let phases = seconds["detect_phases"].as_object().unwrap();
    assert!(phases["walk and test"].as_f64().unwrap() > 0.0, "{seconds}");
    // The phases are laps within detection.
    let sum: f64 = phases.values().map(|p| p.as_f64().unwrap()).sum();
    assert!(sum > 0.0 && sum <= detect, "{sum} against {detect}");

    // The all-pairs detector has no phases of its own.
    let out = screensaver(&["5", "--stats", "--json", "--detector", "brute"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["stats"]["seconds"]["detect_phases"],
        serde_json::json!({})
    );
}

#[test]
fn the_sweep_reports_its_plan_and_phases() {
    let out = screensaver(&["30", "--stats", "--detector", "sweep"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("detector: sweep (along "), "{text}");
    for phase in ["hulls", "sort", "layout", "sweep and test"] {
        assert!(text.contains(&format!("    {phase} ")), "{phase}: {text}");
    }
    // The same counts as the default detector.
    let counts = |args: &[&str]| {
        let out = screensaver(args);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["line_line_collisions"].clone(),
            v["line_wall_collisions"].clone(),
        )
    };
    assert_eq!(
        counts(&["30", "--json", "--detector", "sweep"]),
        counts(&["30", "--json"])
    );
}

/// A line sliding along its own supporting line past a segment on it (the
/// scene of `fuzz/README.md`): the all-pairs detector reports an event the
/// sweep does not, and `--verify` counts it as the documented exception.
#[test]
fn verify_counts_a_sliver_as_the_documented_exception() {
    let dir = std::env::temp_dir().join(format!("screensaver-sliver-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sliver.in");
    std::fs::write(
        &path,
        "2\n(326.48754280359094, 397.9042764560127), (483.41485719909036, 588.7549257112979), \
         -0.34456612463588515, -0.41905176833907615, 0\n(648.6215019711842, 789.6746670418462), \
         (695.9871948952746, 847.2795096520144), 1.1492390849429215, 1.3976727146309766, 1\n",
    )
    .unwrap();
    let path = path.to_str().unwrap();
    let out = screensaver(&["3", path, "--verify"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("but 1 sliver event, the documented exception")
            && stderr.contains("the first at step 1, lines 0 and 1"),
        "{stderr}"
    );
    let out = screensaver(&["3", path, "--verify", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["sliver_events"], 1, "{v}");
    // The all-pairs detector verifies against itself: nothing to except.
    let out = screensaver(&["3", path, "--verify", "--json", "--detector", "brute"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["sliver_events"], 0, "{v}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn speed_is_for_runs_on_screen_and_must_be_a_pace() {
    let out = screensaver(&["10", "--speed", "100"]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(
        err.contains("--speed sets the pace of a run on screen"),
        "{err}"
    );
    for bad in ["0", "fast", "2.5"] {
        let out = screensaver(&["-g", "10", "--speed", bad]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = text(&out.stderr);
        assert!(err.contains("is not a pace"), "{bad}: {err}");
    }
}

#[test]
fn misplaced_arguments_get_messages_that_say_what_to_do() {
    let path = temp_file("two-args.in", TWO_LINES);
    let path = path.to_str().unwrap();
    // A negative FRAMES is a bad FRAMES, not an unknown option.
    let out = screensaver(&["-1", path]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(
        err.contains("`-1` is not a whole number of frames"),
        "{err}"
    );
    assert!(!err.contains("-- -1"), "{err}");
    // A third positional argument is not a subcommand.
    let out = screensaver(&["10", path, "extra"]);
    assert_eq!(out.status.code(), Some(2));
    let err = text(&out.stderr);
    assert!(err.contains("unexpected argument `extra`"), "{err}");
    assert!(!err.contains("subcommand"), "{err}");
    // --cycle in a run of one scene.
    let out = screensaver(&["10", "--cycle", "5"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("--cycle sets how long"),
        "{}",
        text(&out.stderr)
    );
    // An SVG sequence.
    let dir = std::env::temp_dir().join(format!("screensaver-cli-svg-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("s.svg");
    let out = screensaver(&[
        "10",
        "--render",
        svg.to_str().unwrap(),
        "--render-every",
        "5",
    ]);
    // A bad argument: status 2.
    assert_eq!(out.status.code(), Some(2));
    assert!(
        text(&out.stderr).contains("an SVG holds one picture"),
        "{}",
        text(&out.stderr)
    );
    assert!(!svg.exists());
    // -h says nothing of text it does not show.
    let out = screensaver(&["-h"]);
    assert!(out.status.success());
    assert!(
        !text(&out.stdout).contains("see above"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn xscreensavers_spellings_and_window_are_understood() {
    // `-root`, as XScreenSaver hands it: read as --root, which needs a
    // display.
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .arg("-root")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("XSCREENSAVER_WINDOW")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("cannot open a window: no display"), "{err}");
    // Under XScreenSaver's window (a run without FRAMES), pictures in
    // files are refused, not skipped.
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["--render", "x.png"])
        .env("XSCREENSAVER_WINDOW", "0x200007")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(err.contains("XSCREENSAVER_WINDOW is set"), "{err}");
    // A run of so many frames goes off screen as asked, whatever the
    // environment it inherited.
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["5", "--lines", "20"])
        .env("XSCREENSAVER_WINDOW", "0x200007")
        .env_remove("DISPLAY")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("---- END RESULTS ----"));
}

#[test]
fn a_png_sequence_times_the_simulation() {
    let dir = std::env::temp_dir().join(format!("screensaver-cli-seq-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = screensaver(&[
        "300",
        "--render",
        dir.join("s.png").to_str().unwrap(),
        "--render-every",
        "10",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    // 301 steps of the built-in scene take time; the pictures' time is
    // left out, not the steps' (the time of the first picture, drawn
    // before the loop, was taken off the loop's time too, leaving 0).
    let seconds: f64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("Elapsed execution time: "))
        .and_then(|t| t.strip_suffix('s'))
        .unwrap()
        .parse()
        .unwrap();
    assert!(seconds > 0.0, "{stdout}");
    let written = std::fs::read_dir(&dir).unwrap().count();
    assert_eq!(written, 32, "steps 0, 10, ..., 300, and the last, 301");
}

#[test]
fn every_option_the_xscreensaver_settings_offer_is_accepted() {
    let xml = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("contrib/xscreensaver/screensaver.xml"),
    )
    .unwrap();
    // Each arg-set as it is; each number control at its low, default and
    // high values.
    let attribute = |element: &str, name: &str| {
        let start = element.find(&format!("{name}=\""))? + name.len() + 2;
        let end = element[start..].find('"')? + start;
        Some(element[start..end].to_string())
    };
    let mut sets = Vec::new();
    for element in xml.split('<').skip(1) {
        if let Some(set) = attribute(element, "arg-set") {
            sets.push(set);
        }
        if let Some(arg) = attribute(element, "arg") {
            for bound in ["low", "default", "high"] {
                let value = attribute(element, bound).expect("a number control's bounds");
                sets.push(arg.replace('%', &value));
            }
        }
    }
    assert!(sets.len() >= 20, "{sets:?}");
    for set in sets {
        // On the root window with no display: past the command line, the
        // run stops at the display (status 1); a refused option is a usage
        // error (status 2).
        let mut args = vec!["--root"];
        args.extend(set.split_whitespace());
        let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
            .args(&args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("XSCREENSAVER_WINDOW")
            .output()
            .unwrap();
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{set}: {err}");
        assert!(err.contains("no display"), "{set}: {err}");
    }
}

/// Refused with status 2, the message saying `expected`.
fn assert_usage_error(args: &[&str], expected: &str) {
    let out = screensaver(args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?}");
    assert!(stderr.contains(expected), "{args:?}: {stderr}");
}

#[test]
fn a_flag_that_cannot_apply_is_refused_with_why() {
    assert_usage_error(
        &["10", "--hud"],
        "--hud shows the heads-up display on screen",
    );
    assert_usage_error(&["10", "--speed", "100"], "--speed sets the pace");
    assert_usage_error(&["10", "--fps", "30"], "--fps sets the frames a second");
    assert_usage_error(
        &["10", "--leaf-size", "8"],
        "--leaf-size and --max-depth tune the quadtree; this run uses the sweep detector",
    );
    assert_usage_error(
        &["10", "--max-depth", "4", "--detector", "brute"],
        "this run uses the brute detector",
    );
    assert_usage_error(
        &["10", "--keep-pairs", "always", "--detector", "quadtree"],
        "--keep-pairs tunes the sweep; this run uses the quadtree detector",
    );
    assert_usage_error(
        &["10", "--keep-pairs", "sometimes"],
        "expected one of: auto, always, never",
    );
    // Where they apply, they are taken.
    let dir = std::env::temp_dir().join(format!("screensaver-cli-fps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gif = dir.join("a.gif");
    for args in [
        vec![
            "3",
            "--detector",
            "quadtree",
            "--leaf-size",
            "8",
            "--max-depth",
            "4",
        ],
        vec!["3", "--keep-pairs", "never"],
        vec![
            "3",
            "--lines",
            "20",
            "--render",
            gif.to_str().unwrap(),
            "--fps",
            "10",
        ],
    ] {
        let out = screensaver(&args);
        assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
    }
}

#[test]
fn numbers_out_of_range_get_plain_messages() {
    assert_usage_error(
        &["18446744073709551616", "x.in"],
        "`18446744073709551616` frames are more than a run can count (at most 18446744073709551614)",
    );
    assert_usage_error(
        &["18446744073709551615"],
        "frames are more than a run can count",
    );
    assert_usage_error(
        &["10", "--seed", "-1"],
        "`-1` is not a seed: give a whole number from 0",
    );
    assert_usage_error(
        &["gen", "--lines", "-1"],
        "`-1` is not a number of lines: give a whole number from 0 to 100000000",
    );
    assert_usage_error(&["gen", "--lines", "5", "--seed", "x"], "`x` is not a seed");
    assert_usage_error(
        &["-g", "--cycle", "1e9"],
        "is not a number of seconds from 0.1 to 86400",
    );
    assert_usage_error(
        &["-g", "--cycle", "0.05"],
        "is not a number of seconds from 0.1 to 86400",
    );
    // A folder named as gen's output: said as a run says it.
    let dir = std::env::temp_dir().join(format!("screensaver-cli-dir-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = screensaver(&["gen", "--lines", "5", "-o", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("cannot write: it is a folder"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn conflicts_show_the_usage_as_the_readme_writes_it() {
    let out = screensaver(&["-g", "--hold", "10", "--render", "a.png"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("Usage: screensaver [OPTIONS] <FRAMES> [INPUT]")
            && stderr.contains("screensaver [-g | --fullscreen | --root | --window-id ID] [OPTIONS] [FRAMES] [INPUT]"),
        "{stderr}"
    );
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    assert!(readme.contains("screensaver [OPTIONS] <FRAMES> [INPUT]"));
}

#[test]
fn json_says_which_scene_ran_and_what_it_resumed() {
    let out = screensaver(&[
        "3", "--lines", "100", "--seed", "5", "--kind", "ring", "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["input"], serde_json::Value::Null);
    assert_eq!(v["generated"]["kind"], "ring");
    assert_eq!(v["generated"]["lines"], 100);
    assert_eq!(v["generated"]["seed"], 5);
    assert_eq!(v["resumed_from"], serde_json::Value::Null);
    let out = screensaver(&["3", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["generated"]["kind"], "uniform");
    assert_eq!(v["generated"]["seed"], 6172);
    let path = temp_file("two-resume.in", TWO_LINES);
    let checkpoint = path.with_extension("ckpt");
    let (scene, ckpt) = (path.to_str().unwrap(), checkpoint.to_str().unwrap());
    assert!(screensaver(&["2", scene, "--checkpoint", ckpt])
        .status
        .success());
    let out = screensaver(&["5", scene, "--resume", ckpt, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["generated"], serde_json::Value::Null);
    assert_eq!(v["resumed_from"]["checkpoint"], ckpt);
    assert_eq!(v["resumed_from"]["step"], 3);
    assert_eq!(v["steps_run"], 6);
    let out = screensaver(&["5", scene, "--resume", ckpt]);
    assert!(
        text(&out.stderr).contains(&format!("resumed from {ckpt} at step 3")),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn gen_writes_the_scene_a_run_makes_by_default() {
    let dir = std::env::temp_dir().join(format!("screensaver-cli-gen-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("g.in");
    let out = screensaver(&["gen", "--lines", "1000", "-o", scene.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let counts = |out: Output| {
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["line_wall_collisions"].clone(),
            v["line_line_collisions"].clone(),
        )
    };
    let from_file = counts(screensaver(&["20", scene.to_str().unwrap(), "--json"]));
    let built_in = counts(screensaver(&["20", "--json"]));
    assert_eq!(from_file, built_in);
}

#[test]
fn scene_errors_name_extra_fields_and_blank_files_and_pass_over_a_bom() {
    let path = temp_file("extra.in", "1\n(1, 2), (3, 4), 0.1, 0.2, 0, 7\n");
    let out = screensaver(&["3", path.to_str().unwrap()]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.contains("extra.in:2: row 1: an extra field after the colour, `, 7`"),
        "{stderr}"
    );
    let path = temp_file("blank.in", "\n\n");
    let stderr = text(&screensaver(&["3", path.to_str().unwrap()]).stderr);
    assert!(
        stderr.contains("blank.in:1: the file has only blank lines"),
        "{stderr}"
    );
    let path = temp_file("bom.in", &format!("\u{feff}{TWO_LINES}"));
    let out = screensaver(&["3", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("1 Line-Line Collisions"));
}

#[test]
fn an_edited_checkpoint_says_it_was_changed() {
    let path = temp_file("edit.in", TWO_LINES);
    let checkpoint = path.with_extension("ckpt");
    let (scene, ckpt) = (path.to_str().unwrap(), checkpoint.to_str().unwrap());
    assert!(screensaver(&["2", scene, "--checkpoint", ckpt])
        .status
        .success());
    let text_of = std::fs::read_to_string(&checkpoint).unwrap();
    // A coordinate on line 6 spelt with a trailing zero: that row is named.
    let row: Vec<&str> = text_of.lines().nth(5).unwrap().split(' ').collect();
    let edited = text_of.replacen(row[1], &format!("{}0", row[1]), 1);
    std::fs::write(&checkpoint, edited).unwrap();
    let out = screensaver(&["5", scene, "--resume", ckpt]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr.contains(&format!(
            "{ckpt}:6: the file was changed after it was written"
        )),
        "{stderr}"
    );
}

#[test]
fn stats_show_only_what_the_detector_has() {
    let out = screensaver(&["3", "--stats"]);
    let stdout = text(&out.stdout);
    assert!(
        !stdout.contains("tree nodes") && !stdout.contains("tree depth"),
        "{stdout}"
    );
    // The plan in words a user knows: x, y or a diagonal, spelt out.
    let plan = (stdout.lines())
        .find_map(|l| l.strip_prefix("detector: sweep (along "))
        .unwrap_or_else(|| panic!("{stdout}"));
    let directions = ["x,", "y,", "the diagonal x+y,", "the diagonal x-y,"];
    assert!(directions.iter().any(|d| plan.starts_with(d)), "{plan}");
    let out = screensaver(&["3", "--stats", "--detector", "quadtree"]);
    assert!(text(&out.stdout).contains("tree nodes"));
    let out = screensaver(&["3", "--stats", "--json", "--detector", "brute"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["leaf_size", "max_depth", "tree_nodes", "tree_depth"] {
        assert!(v["stats"].get(key).is_none(), "{key} in {}", v["stats"]);
    }
    let out = screensaver(&["3", "--stats", "--json", "--detector", "quadtree"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["stats"]["leaf_size"], 16);
}

#[test]
fn a_large_scene_reads_the_same_on_two_threads_and_its_errors_name_their_line() {
    // 20,000 lines are about 1.5 MB: read in pieces on two threads.
    let path = temp_file("large.in", "");
    let made = screensaver(&[
        "gen",
        "--lines",
        "20000",
        "--seed",
        "5",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert!(made.status.success(), "{}", text(&made.stderr));
    let scene = std::fs::read_to_string(&path).unwrap();
    assert!(scene.len() > 1 << 20, "{} bytes", scene.len());
    let states: Vec<String> = ["1", "2"]
        .iter()
        .map(|threads| {
            let state = path.with_extension(format!("{threads}.state"));
            let args = [
                "2",
                path.to_str().unwrap(),
                "--threads",
                threads,
                "--state-out",
            ];
            let out = screensaver(&[&args[..], &[state.to_str().unwrap()]].concat());
            assert!(out.status.success(), "{}", text(&out.stderr));
            std::fs::read_to_string(&state).unwrap()
        })
        .collect();
    assert_eq!(states[0].lines().count(), 20_000);
    assert!(
        states[0] == states[1],
        "one thread and two read another scene"
    );

    // A row late in the file broken: the error is the one thread's.
    let mut rows: Vec<&str> = scene.lines().collect();
    let broken = rows[19_000].replacen("), (", ") (", 1);
    rows[19_000] = &broken;
    let bad = temp_file("large-bad.in", &rows.join("\n"));
    for threads in ["1", "2"] {
        let out = screensaver(&["1", bad.to_str().unwrap(), "--threads", threads]);
        let wanted = format!(
            "screensaver: error: {}:19001: row 19000: expected `,` after the first point, found `(`",
            bad.display()
        );
        assert!(
            text(&out.stderr).starts_with(&wanted),
            "{}",
            text(&out.stderr)
        );
        assert!(!out.status.success() && out.stdout.is_empty());
    }
}
