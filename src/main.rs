//! The `screensaver` command: runs a scene for a number of frames and prints
//! the collision counts, compatible with the original program's output.

use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use screensaver::generate::{default_scene, DEFAULT_LINES, DEFAULT_SEED};
use screensaver::{DetectorKind, Scene, World};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Line segments bouncing in a box, with exact collision counts.
///
/// Runs FRAMES frames of the scene in INPUT (or of a built-in scene) and
/// prints the line-wall and line-line collision counts. Like the original
/// program, N frames run N + 1 simulation steps.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Cli {
    /// Number of frames to run (the simulation runs FRAMES + 1 steps).
    frames: u64,

    /// Scene file to run; without it, a built-in scene of 1000 lines.
    input: Option<PathBuf>,

    /// Collision detector to use.
    #[arg(long, default_value = "brute", value_parser = parse_detector)]
    detector: DetectorKind,

    /// Print the results as one JSON object instead of the text block.
    #[arg(long)]
    json: bool,

    /// Write the final state to FILE, in the reference checkpoint format.
    #[arg(long, value_name = "FILE")]
    state_out: Option<PathBuf>,
}

fn parse_detector(s: &str) -> Result<DetectorKind, String> {
    s.parse()
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("screensaver: error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: &Cli) -> Result<(), String> {
    let (scene, input_name) = match &cli.input {
        Some(path) => (
            Scene::load(path).map_err(|e| e.to_string())?,
            path.display().to_string(),
        ),
        None => (
            default_scene(),
            format!("(none: built-in scene, {DEFAULT_LINES} lines, seed {DEFAULT_SEED})"),
        ),
    };
    let mut world = World::with_detector(&scene, cli.detector);
    let steps = cli.frames.saturating_add(1);

    let mut stdout = std::io::stdout().lock();
    if !cli.json {
        let header = format!(
            "Number of frames = {}\nInput file path is: {}\n",
            cli.frames, input_name
        );
        write_out(&mut stdout, &header)?;
    }

    let elapsed = simulate(&mut world, steps);
    let counts = world.counters();

    if let Some(path) = &cli.state_out {
        std::fs::write(path, world.state_text())
            .map_err(|e| format!("{}: cannot write the state: {e}", path.display()))?;
    }

    let report = if cli.json {
        let value = serde_json::json!({
            "frames": cli.frames,
            "steps": steps,
            "input": cli.input.as_ref().map(|p| p.display().to_string()),
            "lines": world.lines().len(),
            "detector": cli.detector.name(),
            "elapsed_seconds": elapsed.as_secs_f64(),
            "line_wall_collisions": counts.wall,
            "line_line_collisions": counts.line,
        });
        format!("{value}\n")
    } else {
        format!(
            "---- RESULTS ----\nElapsed execution time: {:.6}s\n{} Line-Wall Collisions\n{} Line-Line Collisions\n---- END RESULTS ----\n",
            elapsed.as_secs_f64(),
            counts.wall,
            counts.line
        )
    };
    write_out(&mut stdout, &report)
}

/// Runs `steps` steps and returns the time the loop took. A progress bar
/// appears on stderr once a run has taken a second, if stderr is a terminal.
fn simulate(world: &mut World, steps: u64) -> Duration {
    let show_progress = std::io::stderr().is_terminal();
    let start = Instant::now();
    let mut bar: Option<ProgressBar> = None;
    for done in 0..steps {
        world.step();
        if show_progress {
            match &bar {
                Some(bar) => bar.set_position(done + 1),
                None if start.elapsed() > Duration::from_secs(1) => {
                    let new =
                        ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
                    new.set_style(
                        ProgressStyle::with_template(
                            "{bar:40} {pos}/{len} steps  {per_sec}  eta {eta}",
                        )
                        .expect("valid progress template"),
                    );
                    new.set_position(done + 1);
                    bar = Some(new);
                }
                None => {}
            }
        }
    }
    let elapsed = start.elapsed();
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    elapsed
}

fn write_out(out: &mut impl Write, text: &str) -> Result<(), String> {
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| format!("cannot write the results: {e}"))
}
