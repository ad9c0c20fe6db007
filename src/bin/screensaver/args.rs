//! The command line's arguments, as clap reads them.

use clap::{Args, Parser, Subcommand};
use screensaver::generate::SceneKind;
use screensaver::render::{Pace, Screen, Size};
use screensaver::Scene;
use screensaver::{DetectorConfig, DetectorKind, KeepPairs};
use std::path::PathBuf;

/// Line segments bouncing in a box, with exact collision counts.
///
/// Runs FRAMES frames of the scene in INPUT (or of a built-in scene) and
/// prints the line-wall and line-line collision counts. Like the original
/// program, N frames run N + 1 simulation steps. `screensaver gen` writes
/// generated scenes of any size.
///
/// As a screensaver (`-g`, `--fullscreen`, `--root`, `--window-id`, or
/// under XScreenSaver, which names its window in XSCREENSAVER_WINDOW),
/// FRAMES may be left out: the run goes on until the window is closed or
/// the program is signalled, and without INPUT it shows generated scenes,
/// a new one every --cycle seconds or as soon as one has died out.
#[derive(Debug, Parser)]
#[command(
    version,
    about,
    long_about,
    override_usage = "screensaver [OPTIONS] <FRAMES> [INPUT]\n       \
        screensaver [-g | --fullscreen | --root | --window-id ID] [OPTIONS] [FRAMES] [INPUT]\n       \
        screensaver gen --lines N [--seed S] [--kind K] [-o FILE]",
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    allow_negative_numbers = true
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Option<Command>,

    /// Number of frames to run (the simulation runs FRAMES + 1 steps);
    /// may be left out on screen (-g, --fullscreen, --root, --window-id,
    /// XScreenSaver): the run then goes on until closed.
    #[arg(value_name = "FRAMES")]
    pub(crate) frames: Option<String>,

    /// Scene file to run; without it, a generated scene (by default the
    /// built-in one: 1000 uniform lines, seed 6172).
    pub(crate) input: Option<PathBuf>,

    /// Anything after INPUT: refused with a message that says so.
    #[arg(hide = true)]
    pub(crate) extra: Vec<String>,

    /// Without INPUT: lines in the generated scene.
    #[arg(long, value_name = "N", value_parser = line_count)]
    pub(crate) lines: Option<usize>,

    /// Without INPUT: the generated scene's arrangement (uniform,
    /// clustered, ring or grid); endless runs take turns through all four
    /// unless one is given.
    #[arg(long, value_parser = scene_kind)]
    pub(crate) kind: Option<SceneKind>,

    /// Without INPUT: the seed of the generated scene (endless runs: of the
    /// first, each next one adding 1; by default taken from the clock).
    #[arg(long, value_name = "S", value_parser = parse_seed)]
    pub(crate) seed: Option<u64>,

    /// Endless runs on screen without INPUT: seconds each generated scene
    /// is shown, from 0.1 to 86400 (a day) [default: 60].
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub(crate) cycle: Option<f64>,

    /// Collision detector: `quadtree` (the design write-up's tree), `sweep`
    /// (sort and sweep; fastest on the course scenes) or `brute` (all
    /// pairs, the original algorithm).
    #[arg(long, default_value = DetectorKind::DEFAULT.name(), value_parser = detector)]
    pub(crate) detector: DetectorKind,

    /// Quadtree: most lines a leaf holds before it splits.
    #[arg(long, value_name = "N", default_value_t = DetectorConfig::default().leaf_size, value_parser = at_least_one)]
    pub(crate) leaf_size: usize,

    /// Quadtree: deepest level a node may split at.
    #[arg(long, value_name = "N", default_value_t = DetectorConfig::default().max_depth)]
    pub(crate) max_depth: u32,

    /// Sweep: keep the pairs a sweep finds for the steps after it, sweeping
    /// again only when a line leaves the room it was given: `auto` (where
    /// that pays, judged as the run goes), `always` or `never`.
    #[arg(long, value_name = "WHEN", default_value = KeepPairs::default().name(), value_parser = keep_pairs)]
    pub(crate) keep_pairs: KeepPairs,

    /// Threads to run on (default: all cores). Results are the same for any
    /// number; 1 runs everything on one thread with no pool.
    #[arg(long, value_name = "N", value_parser = thread_count)]
    pub(crate) threads: Option<usize>,

    /// The smallest piece of work handed to a thread, in lines (or events,
    /// when resolving).
    #[arg(long, value_name = "N", default_value_t = DetectorConfig::default().grain, value_parser = at_least_one)]
    pub(crate) grain: usize,

    /// Run the all-pairs detector beside the chosen one at every step and
    /// stop at the first step whose events differ, printing both lists.
    #[arg(long)]
    pub(crate) verify: bool,

    /// After the results, print the detector's work (pairs, exact tests,
    /// events, tree nodes and depth) and the time spent in each phase.
    #[arg(long)]
    pub(crate) stats: bool,

    /// Print the results as one JSON object instead of the text block.
    #[arg(long)]
    pub(crate) json: bool,

    /// Show the run in a window (keys: Space pause, Right step, +/- speed,
    /// H heads-up display, Q or Esc quit).
    #[arg(short = 'g', long, conflicts_with_all = ["render", "verify"])]
    pub(crate) graphics: bool,

    /// Show the run in a window filling the screen (the box stretched over
    /// it); the keys of -g.
    #[arg(long, conflicts_with_all = ["render", "verify", "root", "window_id"])]
    pub(crate) fullscreen: bool,

    /// Show the heads-up display (step, counters, steps and frames per
    /// second) from the start; H toggles it in the window.
    #[arg(long, conflicts_with_all = ["render", "verify"])]
    pub(crate) hud: bool,

    /// Draw on the root window (the desktop), filling it.
    #[arg(long, conflicts_with_all = ["render", "verify", "graphics", "window_id"])]
    pub(crate) root: bool,

    /// Draw into the existing X window ID (hex 0x... or decimal), filling
    /// it and following its size.
    #[arg(long, value_name = "ID", value_parser = Screen::parse_window_id, conflicts_with_all = ["render", "verify", "graphics"])]
    pub(crate) window_id: Option<u32>,

    /// Window: most frames drawn per second; GIFs: frames shown per second.
    #[arg(long, value_name = "N", default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub(crate) fps: u32,

    /// Window and screen modes: how fast the run goes: N steps a second at
    /// most, `frame` for one step a picture drawn (the original -g's pace;
    /// the default), or `max` for as fast as it can; + and - change it.
    #[arg(long, value_name = "N|frame|max", value_parser = pace, conflicts_with_all = ["render", "verify"])]
    pub(crate) speed: Option<Pace>,

    /// Window: keep the last picture until the window is closed.
    #[arg(long, requires = "graphics")]
    pub(crate) hold: bool,

    /// Write pictures: FILE.png (the last frame), FILE.gif (an animation),
    /// FILE.svg (the last frame as vectors).
    #[arg(long, value_name = "FILE")]
    pub(crate) render: Option<PathBuf>,

    /// With --render: a frame every K steps (for .png, a numbered sequence
    /// FILE-000000.png, FILE-000010.png, ...).
    #[arg(long, value_name = "K", requires = "render", value_parser = at_least_one_u64)]
    pub(crate) render_every: Option<u64>,

    /// With --render: picture size.
    #[arg(long, value_name = "WxH", default_value = "1180x800", requires = "render", value_parser = size)]
    pub(crate) size: Size,

    /// Write the final state to FILE, in the reference's state format.
    #[arg(long, value_name = "FILE")]
    pub(crate) state_out: Option<PathBuf>,

    /// Write a checkpoint of the run to FILE (every K steps with
    /// --checkpoint-every, and when the run ends or is stopped), from which
    /// --resume continues it.
    #[arg(long, value_name = "FILE")]
    pub(crate) checkpoint: Option<PathBuf>,

    /// With --checkpoint: write it every K steps as well.
    #[arg(long, value_name = "K", requires = "checkpoint", value_parser = at_least_one_u64)]
    pub(crate) checkpoint_every: Option<u64>,

    /// Continue the run recorded in the checkpoint FILE (written by
    /// --checkpoint from the same INPUT) up to FRAMES, counted from the
    /// start: the run ends exactly where the uninterrupted run would.
    #[arg(long, value_name = "FILE")]
    pub(crate) resume: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Write a generated scene (the same arguments always give the same
    /// scene), with the density and speeds of the course scenes at any size.
    #[command(allow_negative_numbers = true)]
    Gen(GenArgs),
}

#[derive(Debug, Args)]
pub(crate) struct GenArgs {
    /// Number of lines (up to 100,000,000).
    #[arg(long, value_name = "N", value_parser = line_count)]
    pub(crate) lines: usize,

    /// Seed of the random generator (the runs' default, so that a scene
    /// written with the defaults is the one `screensaver` runs without
    /// INPUT).
    #[arg(long, value_name = "S", default_value_t = Scene::BUILT_IN_SEED, value_parser = parse_seed)]
    pub(crate) seed: u64,

    /// Arrangement: uniform, clustered, ring or grid.
    #[arg(long, default_value = "uniform", value_parser = scene_kind)]
    pub(crate) kind: SceneKind,

    /// Write to FILE instead of standard output.
    #[arg(short, long, value_name = "FILE")]
    pub(crate) output: Option<PathBuf>,
}

/// `found`, the value named `s`, or the error naming `what` and the
/// names there are, `all`.
fn named<T: Copy>(
    found: Option<T>,
    all: &[T],
    name: fn(T) -> &'static str,
    what: &str,
    s: &str,
) -> Result<T, String> {
    found.ok_or_else(|| {
        let names: Vec<_> = all.iter().map(|&v| name(v)).collect();
        format!(
            "unknown {what} `{s}`; expected one of: {}",
            names.join(", ")
        )
    })
}

fn detector(s: &str) -> Result<DetectorKind, String> {
    let found = DetectorKind::from_name(s);
    named(found, DetectorKind::ALL, DetectorKind::name, "detector", s)
}

fn keep_pairs(s: &str) -> Result<KeepPairs, String> {
    named(
        KeepPairs::from_name(s),
        KeepPairs::ALL,
        KeepPairs::name,
        "choice",
        s,
    )
}

fn scene_kind(s: &str) -> Result<SceneKind, String> {
    named(
        SceneKind::from_name(s),
        SceneKind::ALL,
        SceneKind::name,
        "scene kind",
        s,
    )
}

/// Largest side of a picture, in pixels.
const MOST_PIXELS: u32 = 16384;

/// A picture's size, `WxH`, each side from 1 to [`MOST_PIXELS`].
fn size(s: &str) -> Result<Size, String> {
    let bad = || format!("expected a size like 1180x800, found `{s}`");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (width, height) = (
        w.parse::<u32>().map_err(|_| bad())?,
        h.parse::<u32>().map_err(|_| bad())?,
    );
    if !(1..=MOST_PIXELS).contains(&width) || !(1..=MOST_PIXELS).contains(&height) {
        return Err(format!(
            "sizes run from 1x1 to {MOST_PIXELS}x{MOST_PIXELS}, found `{s}`"
        ));
    }
    Ok(Size { width, height })
}

/// A pace: `frame`, `max`, or a number of steps a second.
fn pace(s: &str) -> Result<Pace, String> {
    match s {
        "frame" => Ok(Pace::PerFrame),
        "max" => Ok(Pace::Max),
        n => match n.parse::<u64>() {
            Ok(n) if n > 0 => Ok(Pace::Rate(n)),
            _ => Err(format!(
                "`{s}` is not a pace: give steps a second (a whole number from 1), \
                 `frame` (one step a picture) or `max`"
            )),
        },
    }
}

/// Most frames a run may ask for: FRAMES + 1 steps must be counted.
pub(crate) const MOST_FRAMES: u64 = u64::MAX - 1;

/// Most lines a generated scene may have.
const MOST_LINES: u64 = 100_000_000;

/// A frame count: a whole number, written out, up to [`MOST_FRAMES`].
pub(crate) fn parse_frames(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if n <= MOST_FRAMES => Ok(n),
        _ if is_whole(s) && !s.starts_with('-') => Err(format!(
            "`{s}` frames are more than a run can count (at most {MOST_FRAMES})"
        )),
        _ => {
            let hint = match s.parse::<f64>() {
                Ok(x) if x >= 0.0 && x.fract() == 0.0 && x < 1e19 => {
                    format!("; write it out, as {}", x as u64)
                }
                _ => String::new(),
            };
            Err(format!("`{s}` is not a whole number of frames{hint}"))
        }
    }
}

/// Whether `s` is written as a whole number (an optional sign, then
/// digits), whatever its size.
fn is_whole(s: &str) -> bool {
    let digits = s.strip_prefix(['-', '+']).unwrap_or(s);
    !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
}

/// A whole number from 0 to `most`, named `what` in the message.
fn whole_up_to(s: &str, most: u64, what: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if n <= most => Ok(n),
        _ => Err(format!(
            "`{s}` is not {what}: give a whole number from 0 to {most}"
        )),
    }
}

/// A generated scene's line count, 0 to [`MOST_LINES`].
fn line_count(s: &str) -> Result<usize, String> {
    let n = whole_up_to(s, MOST_LINES, "a number of lines")?;
    usize::try_from(n).map_err(|_| format!("{n} lines are more than this machine can hold"))
}

/// A generator's seed: any 64-bit whole number from 0.
fn parse_seed(s: &str) -> Result<u64, String> {
    whole_up_to(s, u64::MAX, "a seed")
}

/// Most seconds a generated scene is shown: a day.
const MOST_CYCLE: f64 = 86_400.0;

/// Fewest seconds a generated scene is shown.
const LEAST_CYCLE: f64 = 0.1;

/// A number of seconds from [`LEAST_CYCLE`] to [`MOST_CYCLE`].
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if (LEAST_CYCLE..=MOST_CYCLE).contains(&x) => Ok(x),
        _ => Err(format!(
            "`{s}` is not a number of seconds from {LEAST_CYCLE} to {MOST_CYCLE}"
        )),
    }
}

/// A count of one or more.
fn at_least_one_u64(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(_) => Err(format!("`{s}` is not a whole number")),
    }
}

/// A count of one or more, as a size.
fn at_least_one(s: &str) -> Result<usize, String> {
    let n = at_least_one_u64(s)?;
    usize::try_from(n).map_err(|_| format!("{n} is too large"))
}

/// A thread count, 1 to 1024.
fn thread_count(s: &str) -> Result<usize, String> {
    match at_least_one(s)? {
        n if n > 1024 => Err(format!("{n} is more than 1024 threads")),
        n => Ok(n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_sizes_and_paces_read() {
        for &kind in DetectorKind::ALL {
            assert_eq!(detector(kind.name()), Ok(kind));
        }
        assert!(detector("nope").unwrap_err().contains("brute"));
        assert!(scene_kind("spiral").unwrap_err().contains("uniform"));
        assert_eq!(keep_pairs("never"), Ok(KeepPairs::Never));
        let expected = Size {
            width: 590,
            height: 400,
        };
        assert_eq!(size("590x400"), Ok(expected));
        assert!(size("590").is_err());
        assert!(size("0x10").unwrap_err().contains("1x1"));
        assert!(size("axb").unwrap_err().contains("`axb`"));
        assert_eq!(pace("frame"), Ok(Pace::PerFrame));
        assert_eq!(pace("max"), Ok(Pace::Max));
        assert_eq!(pace("240"), Ok(Pace::Rate(240)));
        for bad in ["0", "-3", "fast", "1.5", ""] {
            assert!(pace(bad).unwrap_err().contains("is not a pace"), "{bad}");
        }
    }
}
