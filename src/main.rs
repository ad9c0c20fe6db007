//! The `screensaver` command: runs a scene for a number of frames and prints
//! the collision counts, compatible with the original program's output.

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use screensaver::checkpoint::{self, Checkpoint};
use screensaver::detect::{DEFAULT_GRAIN, DEFAULT_LEAF_SIZE, DEFAULT_MAX_DEPTH};
use screensaver::generate::{generate, generate_iter, SceneKind, DEFAULT_LINES, DEFAULT_SEED};
use screensaver::render::live::{Pace, Scenes};
use screensaver::render::{embedded, window, Frames, Recorder, Size, Target};
use screensaver::report::Stats;
use screensaver::run::{Checkpoints, Ran, Run};
use screensaver::stop::Signal;
use screensaver::{output, report};
use screensaver::{DetectorConfig, DetectorKind, Scene, World};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

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
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    allow_negative_numbers = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    /// Number of frames to run (the simulation runs FRAMES + 1 steps);
    /// may be left out on screen (-g, --fullscreen, --root, --window-id,
    /// XScreenSaver): the run then goes on until closed.
    #[arg(value_name = "FRAMES")]
    frames: Option<String>,

    /// Scene file to run; without it, a generated scene (by default the
    /// built-in one: 1000 uniform lines, seed 6172).
    input: Option<PathBuf>,

    /// Anything after INPUT: refused with a message that says so.
    #[arg(hide = true)]
    extra: Vec<String>,

    /// Without INPUT: lines in the generated scene.
    #[arg(long, value_name = "N", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=100_000_000))]
    lines: Option<usize>,

    /// Without INPUT: the generated scene's arrangement (uniform,
    /// clustered, ring or grid); endless runs take turns through all four
    /// unless one is given.
    #[arg(long, value_parser = parse::<SceneKind>)]
    kind: Option<SceneKind>,

    /// Without INPUT: the seed of the generated scene (endless runs: of the
    /// first, each next one adding 1; by default taken from the clock).
    #[arg(long, value_name = "S")]
    seed: Option<u64>,

    /// Endless runs on screen without INPUT: seconds each generated scene
    /// is shown [default: 60].
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    cycle: Option<f64>,

    /// Collision detector: `quadtree` (the design write-up's tree), `sweep`
    /// (sort and sweep; fastest on the course scenes) or `brute` (all
    /// pairs, the original algorithm).
    #[arg(long, default_value = DetectorKind::DEFAULT.name(), value_parser = parse::<DetectorKind>)]
    detector: DetectorKind,

    /// Quadtree: most lines a leaf holds before it splits.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_LEAF_SIZE, value_parser = at_least_one)]
    leaf_size: usize,

    /// Quadtree: deepest level a node may split at.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_DEPTH)]
    max_depth: u32,

    /// Threads to run on (default: all cores). Results are the same for any
    /// number; 1 runs everything on one thread with no pool.
    #[arg(long, value_name = "N", value_parser = thread_count)]
    threads: Option<usize>,

    /// The smallest piece of work handed to a thread, in lines (or events,
    /// when resolving).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_GRAIN, value_parser = at_least_one)]
    grain: usize,

    /// Run the all-pairs detector beside the chosen one at every step and
    /// stop at the first step whose events differ, printing both lists.
    #[arg(long)]
    verify: bool,

    /// After the results, print the detector's work (pairs, exact tests,
    /// events, tree nodes and depth) and the time spent in each phase.
    #[arg(long)]
    stats: bool,

    /// Print the results as one JSON object instead of the text block.
    #[arg(long)]
    json: bool,

    /// Show the run in a window (keys: Space pause, Right step, +/- speed,
    /// H heads-up display, Q or Esc quit).
    #[arg(short = 'g', long, conflicts_with_all = ["render", "verify"])]
    graphics: bool,

    /// Show the run in a window filling the screen (the box stretched over
    /// it); the keys of -g.
    #[arg(long, conflicts_with_all = ["render", "verify", "root", "window_id"])]
    fullscreen: bool,

    /// Show the heads-up display (step, counters, steps and frames per
    /// second) from the start; H toggles it in the window.
    #[arg(long, conflicts_with_all = ["render", "verify"])]
    hud: bool,

    /// Draw on the root window (the desktop), filling it.
    #[arg(long, conflicts_with_all = ["render", "verify", "graphics", "window_id"])]
    root: bool,

    /// Draw into the existing X window ID (hex 0x... or decimal), filling
    /// it and following its size.
    #[arg(long, value_name = "ID", value_parser = embedded::parse_window_id, conflicts_with_all = ["render", "verify", "graphics"])]
    window_id: Option<u32>,

    /// Window: most frames drawn per second; GIFs: frames shown per second.
    #[arg(long, value_name = "N", default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=1000))]
    fps: u32,

    /// Window and screen modes: how fast the run goes: N steps a second at
    /// most, `frame` for one step a picture drawn (the original -g's pace;
    /// the default), or `max` for as fast as it can; + and - change it.
    #[arg(long, value_name = "N|frame|max", conflicts_with_all = ["render", "verify"])]
    speed: Option<Pace>,

    /// Window: keep the last picture until the window is closed.
    #[arg(long, requires = "graphics")]
    hold: bool,

    /// Write pictures: FILE.png (the last frame), FILE.gif (an animation),
    /// FILE.svg (the last frame as vectors).
    #[arg(long, value_name = "FILE")]
    render: Option<PathBuf>,

    /// With --render: a frame every K steps (for .png, a numbered sequence
    /// FILE-000000.png, FILE-000010.png, ...).
    #[arg(long, value_name = "K", requires = "render", value_parser = at_least_one_u64)]
    render_every: Option<u64>,

    /// With --render: picture size.
    #[arg(long, value_name = "WxH", default_value = "1180x800", requires = "render", value_parser = parse::<Size>)]
    size: Size,

    /// Write the final state to FILE, in the reference's state format.
    #[arg(long, value_name = "FILE")]
    state_out: Option<PathBuf>,

    /// Write a checkpoint of the run to FILE (every K steps with
    /// --checkpoint-every, and when the run ends or is stopped), from which
    /// --resume continues it.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,

    /// With --checkpoint: write it every K steps as well.
    #[arg(long, value_name = "K", requires = "checkpoint", value_parser = at_least_one_u64)]
    checkpoint_every: Option<u64>,

    /// Continue the run recorded in the checkpoint FILE (written by
    /// --checkpoint from the same INPUT) up to FRAMES, counted from the
    /// start: the run ends exactly where the uninterrupted run would.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Write a generated scene (the same arguments always give the same
    /// scene), with the density and speeds of the course scenes at any size.
    Gen(GenArgs),
}

#[derive(Debug, Args)]
struct GenArgs {
    /// Number of lines (up to 100,000,000).
    #[arg(long, value_name = "N", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(0..=100_000_000))]
    lines: usize,

    /// Seed of the random generator.
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,

    /// Arrangement: uniform, clustered, ring or grid.
    #[arg(long, default_value = "uniform", value_parser = parse::<SceneKind>)]
    kind: SceneKind,

    /// Write to FILE instead of standard output.
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

/// Parses a named choice or a size for clap, keeping its own message.
fn parse<T: std::str::FromStr<Err = String>>(s: &str) -> Result<T, String> {
    s.parse()
}

/// A frame count: a whole number, written out.
fn parse_frames(s: &str) -> Result<u64, String> {
    s.parse::<u64>().map_err(|_| {
        let hint = match s.parse::<f64>() {
            Ok(x) if x >= 0.0 && x.fract() == 0.0 && x < 1e19 => {
                format!("; write it out, as {}", x as u64)
            }
            _ => String::new(),
        };
        format!("`{s}` is not a whole number of frames{hint}")
    })
}

/// A positive number of seconds.
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x <= 1e9 => Ok(x),
        _ => Err(format!("`{s}` is not a number of seconds above 0")),
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

/// Why a command did not finish.
enum Failure {
    /// Something went wrong: the message says what.
    Error(String),
    /// Standard output was closed (`| head`): a normal end.
    ClosedPipe,
    /// The command line does not make sense: reported as clap reports
    /// its own usage errors (status 2).
    Usage(clap::error::ErrorKind, String),
}

impl From<String> for Failure {
    fn from(message: String) -> Self {
        Failure::Error(message)
    }
}

/// How a run ended.
enum Ended {
    /// Every step ran.
    Finished,
    /// A signal stopped it.
    Stopped(Signal),
}

/// The command line with XScreenSaver's one-dash spellings (`-root`,
/// `-window-id ID`), which it hands display modes configured with them,
/// read as their two-dash forms.
fn with_xscreensaver_spellings(
    args: impl Iterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    args.map(|a| match a.to_str() {
        Some("-root") => "--root".into(),
        Some("-window-id") => "--window-id".into(),
        _ => a,
    })
    .collect()
}

fn main() -> ExitCode {
    let cli = Cli::parse_from(with_xscreensaver_spellings(std::env::args_os()));
    if let Err(e) = screensaver::stop::install() {
        eprintln!("screensaver: warning: cannot catch SIGINT and SIGTERM: {e}");
    }
    let outcome = match &cli.command {
        Some(Command::Gen(args)) => gen(args).map(|()| Ended::Finished),
        None => run(&cli),
    };
    match outcome {
        Ok(Ended::Finished) | Err(Failure::ClosedPipe) => ExitCode::SUCCESS,
        Ok(Ended::Stopped(signal)) => ExitCode::from(signal.exit_status()),
        Err(Failure::Error(message)) => {
            eprintln!("screensaver: error: {message}");
            ExitCode::FAILURE
        }
        Err(Failure::Usage(kind, message)) => {
            use clap::CommandFactory;
            Cli::command().error(kind, message).exit()
        }
    }
}

/// `screensaver gen`: streams the scene out, so that even huge scenes are
/// never held in memory.
fn gen(args: &GenArgs) -> Result<(), Failure> {
    let lines = generate_iter(args.kind, args.lines, args.seed);
    match &args.output {
        Some(path) => output::write_with(path, |mut out| {
            screensaver::scene::write_scene(&mut out, args.lines, lines)
        })
        .map_err(|e| Failure::Error(e.to_string())),
        None => screensaver::scene::write_scene(&mut std::io::stdout().lock(), args.lines, lines)
            .map_err(|e| stdout_failure(e, "the scene")),
    }
}

/// A failed write to standard output: a closed pipe ends quietly.
fn stdout_failure(e: std::io::Error, what: &str) -> Failure {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        Failure::ClosedPipe
    } else {
        Failure::Error(format!("cannot write {what}: {e}"))
    }
}

/// The frames `--render` pictures: every K-th with `--render-every`.
fn frames_of(cli: &Cli) -> Frames {
    match cli.render_every {
        Some(_) => Frames::Every,
        None => Frames::Last,
    }
}

/// Seconds each generated scene of an endless run is shown, unless
/// `--cycle` says.
const DEFAULT_CYCLE: f64 = 60.0;

/// Most frames a GIF gets unless `--render-every` says otherwise.
const GIF_FRAMES: u64 = 300;

/// Where a live run shows itself.
enum Display {
    /// Our own window (`-g`), filling the screen if asked.
    Window { fullscreen: bool },
    /// A window another program owns (`--root`, `--window-id`,
    /// `XSCREENSAVER_WINDOW`).
    Embedded(embedded::Target),
}

/// The display a run asked for, if any: `--window-id` before `--root`
/// before XScreenSaver's variable before `-g` and `--fullscreen`.
fn display(cli: &Cli) -> Result<Option<Display>, String> {
    if let Some(id) = cli.window_id {
        return Ok(Some(Display::Embedded(embedded::Target::Id(id))));
    }
    if cli.root {
        return Ok(Some(Display::Embedded(embedded::Target::Root)));
    }
    if !cli.graphics && !cli.fullscreen {
        if let Some(id) = embedded::screensaver_window() {
            if cli.render.is_some() || cli.verify {
                return Err(
                    "XSCREENSAVER_WINDOW is set, so the run draws in that window; \
                     --render and --verify are for runs off screen (unset it for them)"
                        .into(),
                );
            }
            return Ok(Some(Display::Embedded(embedded::Target::Id(id?))));
        }
    }
    Ok((cli.graphics || cli.fullscreen).then_some(Display::Window {
        fullscreen: cli.fullscreen,
    }))
}

/// FRAMES and INPUT as given: FRAMES may be left out of a live run, and
/// then a lone positional argument that is not a number is the input.
fn positionals(cli: &Cli, live: bool) -> Result<(Option<u64>, Option<PathBuf>), Failure> {
    use clap::error::ErrorKind;
    match (&cli.frames, &cli.input) {
        (None, _) if live => Ok((None, None)),
        (None, _) => Err(Failure::Usage(
            ErrorKind::MissingRequiredArgument,
            "FRAMES is required (it may be left out only with -g, --fullscreen, \
             --root, --window-id or under XScreenSaver)"
                .into(),
        )),
        (Some(first), None) if live && first.parse::<u64>().is_err() => {
            Ok((None, Some(PathBuf::from(first))))
        }
        (Some(first), input) => {
            let frames = parse_frames(first)
                .map_err(|e| Failure::Usage(ErrorKind::ValueValidation, format!("FRAMES: {e}")))?;
            Ok((Some(frames), input.clone()))
        }
    }
}

/// The arrangement of the `k`-th generated scene (from 0): `--kind`, or
/// each kind in turn.
fn scene_kind(chosen: Option<SceneKind>, k: u64) -> SceneKind {
    chosen.unwrap_or(SceneKind::ALL[k as usize % SceneKind::ALL.len()])
}

/// The seed of the first generated scene: `--seed`, or the clock's for an
/// endless run (so that each run shows other scenes), or the built-in
/// scene's.
fn first_seed(cli: &Cli, endless: bool) -> u64 {
    match cli.seed {
        Some(seed) => seed,
        None if endless => std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(DEFAULT_SEED, |d| d.as_secs()),
        None => DEFAULT_SEED,
    }
}

/// Scenes from this size shown live run on every core all the same: their
/// pictures come seldom enough that the team gains more than the drawing
/// takes (two cores, `--fullscreen`: 300,000 clustered lines 10 frames
/// 0.72 s on two threads against 0.89 s on one; 100,000 lines 0.19 s
/// against 0.16 s; 10,000 lines 0.159 s against 0.097 s).
const LIVE_ALL_CORES_FROM: usize = 200_000;

/// Threads to run on unless `--threads` says: every core, less one for
/// the drawing where a scene of `lines` lines is shown live and smaller
/// than [`LIVE_ALL_CORES_FROM`] (the drawing takes a core a good part of
/// the time, and a member of the team switched out for it mid-piece holds
/// up the step: `-g 5000 koch.in` on two cores took 0.41 s on one thread
/// and 0.51 s on two).
fn default_threads(live: bool, lines: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if live && lines < LIVE_ALL_CORES_FROM {
        (cores - 1).max(1)
    } else {
        cores
    }
}

fn run(cli: &Cli) -> Result<Ended, Failure> {
    let display = display(cli)?;
    if display.is_some() {
        window::check_display()?;
    } else if cli.speed.is_some() {
        return Err(Failure::Usage(
            clap::error::ErrorKind::ArgumentConflict,
            "--speed sets the pace of a run on screen (-g, --fullscreen, --root, \
             --window-id, XScreenSaver); a run without one always goes as fast as it can"
                .into(),
        ));
    }
    let pace = cli.speed.unwrap_or(Pace::PerFrame);
    if let Some(extra) = cli.extra.first() {
        return Err(Failure::Usage(
            clap::error::ErrorKind::UnknownArgument,
            format!("unexpected argument `{extra}`: give FRAMES and at most one INPUT"),
        ));
    }
    let (frames, input) = positionals(cli, display.is_some())?;
    let endless = frames.is_none();
    if cli.cycle.is_some() && !(endless && input.is_none()) {
        return Err(Failure::Usage(
            clap::error::ErrorKind::ArgumentConflict,
            "--cycle sets how long each generated scene of an endless run on screen \
             is shown (no FRAMES, no INPUT); this run shows one scene"
                .into(),
        ));
    }
    if endless && (cli.state_out.is_some() || cli.checkpoint.is_some() || cli.resume.is_some()) {
        return Err(Failure::Usage(
            clap::error::ErrorKind::ArgumentConflict,
            "--state-out, --checkpoint and --resume need FRAMES: an endless run has no end to write"
                .into(),
        ));
    }
    let lines = cli.lines.unwrap_or(DEFAULT_LINES);
    let seed = first_seed(cli, endless);
    let kind_of = |k: u64| scene_kind(cli.kind, k);
    let generated_name = |k: u64| report::generated_input(kind_of(k), lines, seed.wrapping_add(k));
    let (scene, input_name) = match &input {
        Some(path) => {
            if cli.lines.is_some() || cli.kind.is_some() || cli.seed.is_some() {
                return Err(Failure::Usage(
                    clap::error::ErrorKind::ArgumentConflict,
                    "--lines, --kind and --seed choose a generated scene; they cannot go with INPUT"
                        .into(),
                ));
            }
            (
                Scene::load(path).map_err(|e| e.to_string())?,
                path.display().to_string(),
            )
        }
        None => (
            generate(kind_of(0), lines, seed),
            if cli.lines.is_none() && cli.kind.is_none() && cli.seed.is_none() && !endless {
                report::built_in_input()
            } else {
                generated_name(0)
            },
        ),
    };
    let digest = checkpoint::scene_digest(&scene);
    let config = DetectorConfig {
        leaf_size: cli.leaf_size,
        max_depth: cli.max_depth,
        threads: (cli.threads)
            .unwrap_or_else(|| default_threads(display.is_some(), scene.lines.len())),
        grain: cli.grain,
    };
    // An endless run has no last step.
    let steps = frames.map_or(u64::MAX, |f| f.saturating_add(1));
    let threads_error = |e: screensaver::ThreadsError| e.to_string();
    let mut world = match &cli.resume {
        Some(path) => {
            let saved = Checkpoint::load(path).map_err(|e| e.to_string())?;
            saved
                .continues(&path.display().to_string(), &scene, digest, steps)
                .map_err(|e| e.to_string())?;
            World::resume(saved, cli.detector, &config).map_err(threads_error)?
        }
        None => World::with_config(&scene, cli.detector, &config).map_err(threads_error)?,
    };
    // The world holds its own copy; a huge scene's text form can go.
    drop(scene);
    world.set_timing(cli.stats);
    check_outputs(cli)?;

    let recorder = match &cli.render {
        Some(path) => {
            let target = Target::for_path(path, frames_of(cli)).map_err(|e| e.to_string())?;
            let every = match (cli.render_every, &target) {
                (Some(every), _) => every,
                // A GIF of every step of a long run is slow to write and
                // huge (2,000 frames at full size: 101 MB).
                (None, Target::Gif(_)) if steps > GIF_FRAMES => {
                    let every = steps.div_ceil(GIF_FRAMES);
                    eprintln!(
                        "screensaver: --render: a GIF frame every {every} steps (about {} frames); \
                         --render-every 1 for every step",
                        steps / every + 1
                    );
                    every
                }
                (None, _) => 1,
            };
            Some(Recorder::new(target, cli.size, every, cli.fps).map_err(|e| e.to_string())?)
        }
        None => None,
    };
    let mut stdout = std::io::stdout().lock();
    let header = |name: &str| report::header(frames, name);
    // Generated scenes shown one after another: the results are the last
    // scene's, so the header names it once the run has ended.
    let cycling = display.is_some() && endless && input.is_none();
    if !cli.json && !cycling {
        write_out(&mut stdout, &header(&input_name))?;
    }

    let checkpoints = cli.checkpoint.as_deref().map(|path| Checkpoints {
        path,
        every: cli.checkpoint_every,
        digest,
    });
    let first_step = world.steps();
    let to_run = steps.saturating_sub(first_step);
    let drawn;
    let elapsed = match display {
        Some(display) => {
            let scenes = if endless && input.is_none() {
                let (detector, kind, timing, config) = (cli.detector, cli.kind, cli.stats, config);
                let make = move |k: u64| {
                    let scene = generate(scene_kind(kind, k), lines, seed.wrapping_add(k));
                    let mut world = World::with_config(&scene, detector, &config)
                        .expect("threads started once start again");
                    world.set_timing(timing);
                    world
                };
                Scenes::Generated {
                    first: Box::new(world),
                    next: Box::new(make),
                    cycle: Duration::from_secs_f64(cli.cycle.unwrap_or(DEFAULT_CYCLE)),
                }
            } else {
                Scenes::One {
                    world: Box::new(world),
                    steps: frames.map(|_| to_run),
                }
            };
            let (outcome, stats) = match display {
                Display::Window { fullscreen } => window::run(
                    scenes,
                    window::Options {
                        fps: cli.fps,
                        hold: cli.hold,
                        fullscreen,
                        hud: cli.hud,
                        pace,
                    },
                ),
                Display::Embedded(target) => embedded::run(
                    target,
                    scenes,
                    embedded::Options {
                        fps: cli.fps,
                        hud: cli.hud,
                        pace,
                    },
                ),
            }?;
            if outcome.scenes > 1 {
                eprintln!(
                    "screensaver: showed {} scenes (seeds {} to {}); the results are the last one's",
                    outcome.scenes,
                    seed,
                    seed.wrapping_add(outcome.scenes - 1)
                );
            }
            if cycling && !cli.json {
                write_out(&mut stdout, &header(&generated_name(outcome.scenes - 1)))?;
            }
            world = outcome.world;
            drawn = Some(stats);
            outcome.scene_elapsed
        }
        None => {
            let ran = batch(&mut world, to_run, cli.verify, recorder, checkpoints)?;
            drawn = ran.pictures;
            ran.elapsed
        }
    };
    let stopped = screensaver::stop::requested();
    let counts = world.counters();

    if let Some(checkpoints) = &checkpoints {
        checkpoints.save(&world).map_err(|e| e.to_string())?;
    }
    if let Some(path) = &cli.state_out {
        output::write_with(path, |out| world.write_state(out)).map_err(|e| e.to_string())?;
    }
    if let Some(signal) = stopped {
        let of = if endless {
            String::new()
        } else {
            format!(" of {steps}")
        };
        eprintln!(
            "screensaver: stopped by {} after step {}{of}",
            signal.name(),
            world.steps(),
        );
    }
    if cli.verify && world.mismatch().is_none() {
        let verified = world.steps() - first_step;
        match world.slivers() {
            (0, _) => eprintln!(
                "screensaver: verified: {verified} steps, every event as the all-pairs detector found it"
            ),
            (count, first) => eprintln!(
                "screensaver: verified: {verified} steps, every event as the all-pairs detector \
                 found it but {count} sliver event{}, the documented exception (a line sliding \
                 along its own supporting line past a segment on it; see the README, \
                 Conformance){}",
                if count == 1 { "" } else { "s" },
                first.map_or(String::new(), |(step, e)| format!(
                    ": the first at step {step}, lines {} and {}",
                    e.first, e.second
                ))
            ),
        }
    }

    let report = if cli.json {
        let mut value = serde_json::json!({
            "frames": frames,
            "steps": frames.map(|_| steps),
            "steps_run": world.steps(),
            "interrupted": stopped.is_some(),
            "input": cli.input.as_ref().map(|p| p.display().to_string()),
            "lines": world.lines().len(),
            "detector": cli.detector.name(),
            "threads": config.threads,
            "elapsed_seconds": elapsed.as_secs_f64(),
            "line_wall_collisions": counts.wall,
            "line_line_collisions": counts.line,
        });
        if cli.verify {
            value["verified_steps"] = serde_json::json!(world.steps() - first_step);
            value["sliver_events"] = serde_json::json!(world.slivers().0);
        }
        if cli.stats {
            let stats = Stats::of(&world, cli.detector, &config, drawn).json();
            value["stats"] = serde_json::from_str(&stats).expect("the statistics are JSON");
        }
        format!("{value}\n")
    } else {
        let mut text = report::results(elapsed.as_secs_f64(), counts);
        if cli.stats {
            text.push_str(&Stats::of(&world, cli.detector, &config, drawn).text());
        }
        text
    };
    write_out(&mut stdout, &report)?;
    Ok(stopped.map_or(Ended::Finished, Ended::Stopped))
}

/// Checks, before any step runs, that every file the run will write can be
/// written, so that a long run never ends in an error it could have
/// reported at once.
fn check_outputs(cli: &Cli) -> Result<(), String> {
    let mut paths: Vec<PathBuf> = Vec::new();
    paths.extend(cli.state_out.iter().cloned());
    paths.extend(cli.checkpoint.iter().cloned());
    if let Some(path) = &cli.render {
        Target::for_path(path, frames_of(cli)).map_err(|e| e.to_string())?;
        paths.push(path.clone());
    }
    for path in paths {
        output::check_writable(&path).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Runs `steps` steps of a batch run, checked against all pairs with
/// `verify`, writing pictures and checkpoints if asked, until a signal
/// stops it; with a progress bar on stderr once the run has taken a
/// second, if stderr is a terminal.
fn batch(
    world: &mut World,
    steps: u64,
    verify: bool,
    recorder: Option<Recorder>,
    checkpoints: Option<Checkpoints>,
) -> Result<Ran, String> {
    let show_progress = std::io::stderr().is_terminal();
    let mut bar: Option<ProgressBar> = None;
    let mut progress = |done: u64, elapsed: Duration| {
        if !show_progress {
            return;
        }
        match &bar {
            Some(bar) => bar.set_position(done),
            None if elapsed > Duration::from_secs(1) => {
                bar = Some(progress_bar(steps, done, Instant::now() - elapsed))
            }
            None => {}
        }
    };
    let stop = || screensaver::stop::requested().is_some();
    let run = Run {
        verify,
        recorder,
        checkpoints,
        progress: Some(&mut progress),
        stop: Some(&stop),
    };
    let ran = run.run(world, steps);
    if let Some(bar) = bar {
        if ran.as_ref().is_ok_and(|r| !r.stopped) {
            bar.finish_and_clear();
        } else {
            bar.abandon();
        }
    }
    ran.map_err(|e| e.to_string())
}

/// A progress bar for a run of `steps` steps that started at `start` and
/// has run `done`. Its rate and time left are the run's own, steps over
/// the time since `start`: indicatif's estimate counts the `done` steps
/// set at once as one burst (it showed 1,309,816 steps a second for a run
/// going at 384).
fn progress_bar(steps: u64, done: u64, start: Instant) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {run_rate}")
            .expect("valid progress template")
            .with_key(
                "run_rate",
                move |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", progress_text(state.pos(), steps, start.elapsed()));
                },
            ),
    );
    bar.set_position(done);
    bar
}

/// The rate and time left of a run that has done `done` of `steps` steps
/// in `elapsed`: `384 steps/s  eta 3s`.
fn progress_text(done: u64, steps: u64, elapsed: Duration) -> String {
    let seconds = elapsed.as_secs_f64();
    if done == 0 || seconds <= 0.0 {
        return "eta -".to_string();
    }
    let rate = done as f64 / seconds;
    let left = steps.saturating_sub(done) as f64 / rate;
    format!(
        "{rate:.0} steps/s  eta {}",
        indicatif::HumanDuration(Duration::from_secs_f64(left.min(1e9)))
    )
}

fn write_out(out: &mut impl Write, text: &str) -> Result<(), Failure> {
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| stdout_failure(e, "the results"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_counts_the_run_since_it_started() {
        // 213 of 1501 steps in 0.555 s: 384 a second, 3 s to go.
        let text = progress_text(213, 1501, Duration::from_secs_f64(213.0 / 384.0));
        assert_eq!(text, "384 steps/s  eta 3 seconds");
        assert_eq!(progress_text(0, 10, Duration::from_secs(1)), "eta -");
    }

    #[test]
    fn xscreensavers_one_dash_spellings_are_read() {
        let args = ["screensaver", "-root", "-window-id", "0x12", "-g", "-1"];
        let read = with_xscreensaver_spellings(args.iter().map(std::ffi::OsString::from));
        assert_eq!(
            read,
            ["screensaver", "--root", "--window-id", "0x12", "-g", "-1"]
        );
    }
}
