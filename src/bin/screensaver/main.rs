//! The `screensaver` command: runs a scene for a number of frames and prints
//! the collision counts, compatible with the original program's output.
//! It reads its arguments into a [`Job`] and runs it over the library's
//! calls; what is here is the command line, its conflicts and words, its
//! exit codes and the progress bar.

/// `eprintln!` that never panics: after a hangup the terminal is gone,
/// and a message that cannot be shown must not change how the run ends.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod args;
mod job;
mod progress;
mod stats;
mod words;

use args::{parse_frames, Cli, Command, GenArgs};
use clap::error::ErrorKind;
use clap::parser::ValueSource;
use clap::{ArgMatches, CommandFactory, FromArgMatches};
use job::{Job, JobError};
use screensaver::render::{RenderError, Screen, ScreenError};
use screensaver::run::RunError;
use screensaver::{DetectorConfig, DetectorKind, Signal};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// Why a command did not finish.
enum Failure {
    /// Something went wrong: the message says what.
    Error(String),
    /// Several things went wrong, each message on its own line.
    Errors(Vec<String>),
    /// Standard output was closed (`| head`): a normal end.
    ClosedPipe,
    /// The command line does not make sense: reported as clap reports
    /// its own usage errors (status 2).
    Usage(ErrorKind, String),
}

impl From<JobError> for Failure {
    fn from(e: JobError) -> Self {
        match e {
            JobError::Conflict(c) => {
                Failure::Usage(ErrorKind::ArgumentConflict, words::conflict(&c))
            }
            JobError::Results(e) => stdout_failure(e, "the results"),
            // A picture's name the program cannot write is a bad argument,
            // like any other.
            JobError::Pictures(RenderError::OneFrameOnly(path)) => Failure::Usage(
                ErrorKind::InvalidValue,
                format!(
                    "--render: {}: an SVG holds one picture, the last frame; leave out \
                     --render-every, or name a .png (a numbered sequence) or a .gif",
                    path.display()
                ),
            ),
            JobError::Pictures(e @ RenderError::UnknownType(_)) => {
                Failure::Usage(ErrorKind::InvalidValue, format!("--render: {e}"))
            }
            JobError::Screen(e @ ScreenError::NoDisplay) => {
                Failure::Error(format!("{e}, or use --render"))
            }
            JobError::Run(e @ RunError::Mismatch { .. }) => {
                Failure::Error(format!("--verify: {e}"))
            }
            JobError::Files(errors) => {
                Failure::Errors(errors.iter().map(ToString::to_string).collect())
            }
            e => Failure::Error(e.to_string()),
        }
    }
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
    let matches = Cli::command().get_matches_from(with_xscreensaver_spellings(std::env::args_os()));
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Err(e) = Signal::catch() {
        say!("screensaver: warning: cannot catch SIGINT, SIGTERM and SIGHUP: {e}");
    }
    let outcome = match &cli.command {
        Some(Command::Gen(args)) => gen(args),
        None => run(&cli, &matches),
    };
    match outcome {
        Ok(None) | Err(Failure::ClosedPipe) => ExitCode::SUCCESS,
        Ok(Some(signal)) => {
            use std::io::Write;
            let _ = std::io::stdout().flush();
            signal.end_process()
        }
        Err(Failure::Error(message)) => {
            say!("screensaver: error: {message}");
            ExitCode::FAILURE
        }
        Err(Failure::Errors(messages)) => {
            for message in messages {
                say!("screensaver: error: {message}");
            }
            ExitCode::FAILURE
        }
        Err(Failure::Usage(kind, message)) => Cli::command().error(kind, message).exit(),
    }
}

/// `screensaver gen`: streams the scene out, so that even huge scenes are
/// never held in memory. A signal stops it at once, leaving no file.
fn gen(args: &GenArgs) -> Result<Option<Signal>, Failure> {
    let (kind, lines, seed) = (args.kind, args.lines, args.seed);
    let written = match &args.output {
        Some(path) => (kind.save(lines, seed, path)).map_err(|e| Failure::Error(e.to_string())),
        None => (kind.write(lines, seed, &mut std::io::stdout().lock()))
            .map_err(|e| stdout_failure(e, "the scene")),
    };
    match Signal::requested() {
        Some(signal) => {
            let what = args.output.as_ref().map_or("the scene".into(), |p| {
                format!("{}: nothing written", p.display())
            });
            say!("screensaver: gen stopped by {}: {what}", signal.name());
            Ok(Some(signal))
        }
        None => written.map(|()| None),
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

/// The screen a run asked for, if any: `--window-id` before `--root`
/// before XScreenSaver's variable before `-g` and `--fullscreen`. The
/// variable is read only by a run without FRAMES, as XScreenSaver starts
/// its display modes: a run of so many frames goes off screen as asked,
/// whatever the environment it inherited.
fn screen(cli: &Cli) -> Result<Option<Screen>, Failure> {
    if let Some(id) = cli.window_id {
        return Ok(Some(Screen::WindowId(id)));
    }
    if cli.root {
        return Ok(Some(Screen::Root));
    }
    let frames_given = cli
        .frames
        .as_deref()
        .is_some_and(|f| parse_frames(f).is_ok());
    if !cli.graphics && !cli.fullscreen && !frames_given {
        if let Some(screen) = Screen::from_environment() {
            if cli.render.is_some() || cli.verify {
                return Err(Failure::Error(
                    "XSCREENSAVER_WINDOW is set, so the run draws in that window; \
                     --render and --verify are for runs off screen (unset it for them)"
                        .into(),
                ));
            }
            return Ok(Some(screen.map_err(|e| Failure::Error(e.to_string()))?));
        }
    }
    Ok((cli.graphics || cli.fullscreen).then_some(Screen::Window {
        fullscreen: cli.fullscreen,
    }))
}

/// FRAMES and INPUT as given: in a live run, a lone positional argument
/// that is not a number is the input.
fn positionals(cli: &Cli, live: bool) -> Result<(Option<u64>, Option<PathBuf>), Failure> {
    if let Some(extra) = cli.extra.first() {
        return Err(Failure::Usage(
            ErrorKind::UnknownArgument,
            format!("unexpected argument `{extra}`: give FRAMES and at most one INPUT"),
        ));
    }
    match (&cli.frames, &cli.input) {
        // Without FRAMES (refused by the job off screen), no INPUT either.
        (None, _) => Ok((None, None)),
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

/// Refuses a flag given for something this run does not have: a flag
/// that cannot apply is a mistake worth saying, not one to pass over.
fn check_flags_apply(
    cli: &Cli,
    matches: &ArgMatches,
    screen: Option<Screen>,
) -> Result<(), Failure> {
    let given = |id: &str| matches.value_source(id) == Some(ValueSource::CommandLine);
    let refuse = |message: &str| Err(Failure::Usage(ErrorKind::ArgumentConflict, message.into()));
    if screen.is_none() && given("hud") {
        return refuse(
            "--hud shows the heads-up display on screen (-g, --fullscreen, --root, \
             --window-id, XScreenSaver); this run has no screen",
        );
    }
    let gif = (cli.render.as_ref())
        .and_then(|p| p.extension())
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
    if screen.is_none() && !gif && given("fps") {
        return refuse(
            "--fps sets the frames a second of a run on screen and of a GIF \
             (--render FILE.gif); this run has neither",
        );
    }
    if cli.detector != DetectorKind::Quadtree && (given("leaf_size") || given("max_depth")) {
        return refuse(&format!(
            "--leaf-size and --max-depth tune the quadtree; this run uses the {} detector \
             (add --detector quadtree)",
            cli.detector
        ));
    }
    if cli.detector != DetectorKind::Sweep && given("keep_pairs") {
        return refuse(&format!(
            "--keep-pairs tunes the sweep; this run uses the {} detector \
             (add --detector sweep)",
            cli.detector
        ));
    }
    Ok(())
}

/// Runs the scene the command line names; returns the signal that
/// stopped it early, if one did.
fn run(cli: &Cli, matches: &ArgMatches) -> Result<Option<Signal>, Failure> {
    let screen = screen(cli)?;
    check_flags_apply(cli, matches, screen)?;
    let (frames, input) = positionals(cli, screen.is_some())?;
    let job = Job {
        frames,
        input,
        lines: cli.lines,
        kind: cli.kind,
        seed: cli.seed,
        cycle: cli.cycle.map(Duration::from_secs_f64),
        detector: cli.detector,
        config: DetectorConfig {
            leaf_size: cli.leaf_size,
            max_depth: cli.max_depth,
            threads: cli.threads.unwrap_or(0),
            grain: cli.grain,
            keep_pairs: cli.keep_pairs,
        },
        verify: cli.verify,
        stats: cli.stats,
        json: cli.json,
        screen,
        fps: cli.fps,
        hold: cli.hold,
        hud: cli.hud,
        pace: cli.speed,
        render: cli.render.clone(),
        render_every: cli.render_every,
        size: cli.size,
        state_out: cli.state_out.clone(),
        checkpoint: cli.checkpoint.clone(),
        checkpoint_every: cli.checkpoint_every,
        resume: cli.resume.clone(),
    };
    let mut bar = progress::Bar::new(std::io::stderr().is_terminal());
    Ok(job.run(&mut std::io::stdout().lock(), Some(&mut bar))?)
}

#[cfg(test)]
mod tests {
    use super::*;

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
