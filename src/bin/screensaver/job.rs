//! A job: what the command line asks of one run, from choosing the scene to
//! printing its results. The command line parses its arguments into a
//! [`Job`] and [`Job::run`] does the rest: it loads or generates the scene,
//! builds (or resumes) the world, runs it off screen with a [`Run`] or on
//! screen with [`Screen::show`] (our window, the desktop or a window
//! another program owns), writes the files asked for and prints the
//! original program's text (or JSON). Only the library's public calls are
//! used: the job is what any program could make of them.

use crate::words::plural;
use screensaver::checkpoint::{self, Checkpoint};
use screensaver::generate::{generate, SceneKind};
use screensaver::render::{Pace, Recorder, Scenes, Screen, ScreenError, ShowOptions, Size};
use screensaver::report::{self, DrawStats, Stats};
use screensaver::run::{Checkpoints, Run, RunError};
use screensaver::{check_writable, FileIdentity};
use screensaver::{DetectorConfig, DetectorKind, Scene, Signal, World};
use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// One run of the command: the scene, how long it runs, where it is shown
/// and which files it writes. [`Job::default`] is the built-in scene run
/// off screen, which needs `frames`.
#[derive(Clone, Debug)]
pub struct Job {
    /// Frames to run (FRAMES + 1 steps); `None` runs until stopped, which
    /// only a run on screen may.
    pub frames: Option<u64>,
    /// The scene file; without it a generated scene.
    pub input: Option<PathBuf>,
    /// Generated scenes: lines (default [`Scene::BUILT_IN_LINES`]).
    pub lines: Option<usize>,
    /// Generated scenes: the arrangement (endless runs: each in turn).
    pub kind: Option<SceneKind>,
    /// Generated scenes: the first seed (endless runs: from the clock).
    pub seed: Option<u64>,
    /// Endless runs of generated scenes: how long each is shown.
    pub cycle: Option<Duration>,
    /// The collision detector.
    pub detector: DetectorKind,
    /// The detector's settings; `threads` 0 chooses for the run.
    pub config: DetectorConfig,
    /// Checks every step against all pairs (off screen only).
    pub verify: bool,
    /// Reports the detector's work and the phases' times.
    pub stats: bool,
    /// Prints the results as JSON.
    pub json: bool,
    /// Where the run is shown; `None` runs off screen.
    pub screen: Option<Screen>,
    /// On screen: most frames a second; GIFs: frames shown a second.
    pub fps: u32,
    /// In the window: keep the last picture until closed.
    pub hold: bool,
    /// On screen: show the heads-up display from the start.
    pub hud: bool,
    /// On screen: how fast the run goes (default one step a picture).
    pub pace: Option<Pace>,
    /// Pictures to write (`.png`, `.gif`, `.svg`).
    pub render: Option<PathBuf>,
    /// A picture every K steps.
    pub render_every: Option<u64>,
    /// The pictures' size.
    pub size: Size,
    /// Where to write the final state.
    pub state_out: Option<PathBuf>,
    /// Where to write checkpoints.
    pub checkpoint: Option<PathBuf>,
    /// Steps between checkpoints (besides the one at the end).
    pub checkpoint_every: Option<u64>,
    /// The checkpoint to continue from.
    pub resume: Option<PathBuf>,
}

impl Default for Job {
    fn default() -> Job {
        Job {
            frames: None,
            input: None,
            lines: None,
            kind: None,
            seed: None,
            cycle: None,
            detector: DetectorKind::DEFAULT,
            config: DetectorConfig {
                threads: 0,
                ..DetectorConfig::default()
            },
            verify: false,
            stats: false,
            json: false,
            screen: None,
            fps: 60,
            hold: false,
            hud: false,
            pace: None,
            render: None,
            render_every: None,
            size: Size::WINDOW,
            state_out: None,
            checkpoint: None,
            checkpoint_every: None,
            resume: None,
        }
    }
}

/// Why a job did not finish.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The job's options do not go together.
    #[error(transparent)]
    Conflict(#[from] Conflict),
    /// The scene file could not be loaded.
    #[error(transparent)]
    Scene(#[from] screensaver::scene::LoadError),
    /// The checkpoint to resume from could not be loaded.
    #[error(transparent)]
    Checkpoint(#[from] checkpoint::LoadError),
    /// The checkpoint does not continue this run.
    #[error(transparent)]
    Resume(#[from] checkpoint::ResumeError),
    /// The threads asked for could not be started.
    #[error(transparent)]
    Threads(#[from] screensaver::ThreadsError),
    /// The run cannot be shown: no display, or no such window.
    #[error(transparent)]
    Screen(#[from] ScreenError),
    /// The pictures asked for cannot be made.
    #[error(transparent)]
    Pictures(#[from] screensaver::render::RenderError),
    /// An output file cannot be written.
    #[error(transparent)]
    Output(#[from] screensaver::OutputError),
    /// The run could not go on (a check against all pairs that failed, a
    /// picture or a checkpoint that could not be written).
    #[error(transparent)]
    Run(#[from] RunError),
    /// Files the run wrote as it ended could not be written; the results
    /// were printed all the same.
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("; "))]
    Files(Vec<JobError>),
    /// The run needs more memory than this process may have.
    #[error(
        "a scene of {} needs about {} MB of memory, more than this process can have \
         (the memory free, or a limit such as `ulimit -v`)",
        plural(*lines, "line"),
        bytes.div_ceil(1_000_000)
    )]
    Memory {
        /// The scene's lines (at most, for a scene file not read yet).
        lines: u64,
        /// The bytes asked for.
        bytes: u64,
    },
    /// Writing the results failed.
    #[error("cannot write the results: {0}")]
    Results(#[source] std::io::Error),
    /// The final state was not written: the run ended early, on an error,
    /// and no file may claim to be the end of a run that did not end.
    #[error("{}: not written: the run ended early, after step {step} of {of}", path.display())]
    StateNotWritten {
        /// The state file asked for.
        path: PathBuf,
        /// The step the run ended after.
        step: u64,
        /// The steps it was to run.
        of: u64,
    },
}

/// Options of a job that do not go together.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Conflict {
    /// A run off screen without a number of frames, which would not end.
    #[error("a run off screen needs a number of frames")]
    NoEnd,
    /// A pace for a run off screen, which always goes as fast as it can.
    #[error("a pace is for runs on screen")]
    PaceOffScreen,
    /// Pictures or the check against all pairs for a run on screen.
    #[error("pictures and the check against all pairs are for runs off screen")]
    OffScreenOnly,
    /// A time to show each scene, for a run of one scene.
    #[error("a time to show each scene is for endless runs of generated scenes")]
    CycleOfOneScene,
    /// Files to write at the end, or a checkpoint to resume up to an end,
    /// for a run without one.
    #[error("an endless run has no end to write files at or resume up to")]
    EndlessFiles,
    /// A generated scene's settings beside a scene file.
    #[error("a generated scene's settings cannot go with a scene file")]
    GeneratedAndFile,
    /// A file the job writes is one it reads, or one it writes already.
    #[error("the {written} file `{}` is the {other} file `{}`", written_path.display(), other_path.display())]
    SameFile {
        /// The file written.
        written: FileRole,
        /// Its name as given.
        written_path: PathBuf,
        /// The other part the same file plays.
        other: FileRole,
        /// Its name there, as given.
        other_path: PathBuf,
    },
}

/// The part a file plays in a job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileRole {
    /// The scene read (`input`).
    Scene,
    /// The checkpoint resumed from.
    Resume,
    /// The final state written.
    State,
    /// The checkpoint written.
    Checkpoint,
    /// The pictures written.
    Pictures,
    /// Standard output, where the results are printed, when it is a file.
    Results,
}

impl std::fmt::Display for FileRole {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FileRole::Scene => "scene",
            FileRole::Resume => "resumed checkpoint",
            FileRole::State => "state",
            FileRole::Checkpoint => "checkpoint",
            FileRole::Pictures => "pictures'",
            FileRole::Results => "results'",
        })
    }
}

/// What a job has to say beside its results, for the program running it to
/// put in its own words.
#[derive(Clone, Debug, PartialEq)]
pub enum Note {
    /// A GIF of a long run gets a frame every `every` steps, about
    /// `frames` in all (said before the run).
    GifFrames {
        /// Steps between frames.
        every: u64,
        /// Frames, about.
        frames: u64,
    },
    /// Generated scenes were shown one after another; the results are the
    /// last one's.
    Scenes {
        /// Scenes shown.
        shown: u64,
        /// The first one's seed.
        first_seed: u64,
        /// The last one's seed.
        last_seed: u64,
    },
    /// A signal stopped the run.
    Stopped {
        /// Which.
        signal: Signal,
        /// The step the run stopped after.
        step: u64,
        /// The steps it was to run, if it had an end.
        of: Option<u64>,
    },
    /// The run went on from a checkpoint.
    Resumed {
        /// The checkpoint.
        path: PathBuf,
        /// Its step.
        step: u64,
    },
    /// Every step's events were those the all-pairs detector finds, but
    /// for `slivers` sliver events (the documented exception).
    Verified {
        /// Steps checked.
        steps: u64,
        /// Sliver events met.
        slivers: u64,
        /// The step and event of the first.
        first_sliver: Option<(u64, screensaver::Event)>,
    },
}

/// Told how a job goes: after each step of a run off screen, once when it
/// ends (before the results are printed), and what the job has to say
/// beside its results.
pub trait Progress: Send {
    /// `done` of `steps` steps run, `elapsed` since the run started.
    fn step(&mut self, done: u64, steps: u64, elapsed: Duration);
    /// The run ended: all its steps run (`finished`) or not.
    fn end(&mut self, finished: bool);
    /// Something to say beside the results; by default nothing is said.
    fn note(&mut self, _note: Note) {}
}

/// No progress to show, nothing said.
struct Quiet;

impl Progress for Quiet {
    fn step(&mut self, _: u64, _: u64, _: Duration) {}
    fn end(&mut self, _: bool) {}
}

/// Seconds each generated scene of an endless run is shown by default.
const DEFAULT_CYCLE: Duration = Duration::from_secs(60);

/// Most frames a GIF gets unless `render_every` says otherwise.
const GIF_FRAMES: u64 = 300;

/// The most memory a run takes a line: a million generated lines peak at
/// 249 MB on one thread and 261 MB on two (50 frames, `/usr/bin/time`),
/// and a margin for the lines' order and the thread team.
const BYTES_PER_LINE: u64 = 300;

/// Fails, saying how much memory the run needs, where this process cannot
/// have it: the memory for `lines` lines and `text` bytes of scene file is
/// asked for, and given back at once, before the scene is read or made,
/// so that a scene too large for the machine or its limits ends with a
/// message rather than an abort part way.
fn check_memory(lines: u64, text: u64) -> Result<(), JobError> {
    let bytes = lines.saturating_mul(BYTES_PER_LINE).saturating_add(text);
    let mut probe = Vec::<u8>::new();
    match usize::try_from(bytes).map(|b| probe.try_reserve_exact(b)) {
        Ok(Ok(())) => Ok(()),
        _ => Err(JobError::Memory { lines, bytes }),
    }
}

/// The world a job runs and what it knows of it before the first step.
struct Started {
    world: World,
    /// The input's name in the header.
    input_name: String,
    /// The scene's digest, for the checkpoints, when there are any: a
    /// million lines take 50 ms to digest.
    digest: Option<u64>,
    /// Steps the run ends after (`u64::MAX`: endless).
    steps: u64,
    /// The first generated scene's seed.
    seed: u64,
}

/// What the results say of the run beside its world.
struct Ran {
    /// A signal stopped it.
    stopped: bool,
    /// The step it started from (a checkpoint's, when resumed).
    first_step: u64,
    /// Steps checked against all pairs.
    verified: u64,
    /// The first generated scene's seed.
    seed: u64,
}

/// How the steps went, on screen or off.
struct Finished {
    /// Scenes shown (1 unless generated scenes were cycled).
    scenes: u64,
    world: World,
    elapsed: Duration,
    drawn: Option<DrawStats>,
    /// The input's name when it changed during the run (cycled scenes).
    input_name: Option<String>,
    /// Why a picture or a checkpoint could not be written, when that
    /// ended the run early.
    failure: Option<RunError>,
    /// Checked against all pairs: the sliver events met, and the first.
    slivers: Option<(u64, Option<(u64, screensaver::Event)>)>,
}

impl Job {
    /// Runs the job, writing the original program's text (or JSON) to
    /// `out` and telling `progress` how a run off screen goes. Returns the
    /// signal that stopped the run early, if one did.
    pub fn run(
        mut self,
        out: &mut dyn Write,
        progress: Option<&mut dyn Progress>,
    ) -> Result<Option<Signal>, JobError> {
        let mut quiet = Quiet;
        let progress = progress.unwrap_or(&mut quiet);
        self.check()?;
        // The display and the window are checked before anything is
        // printed, so that a run that cannot be shown prints only why.
        if let Some(screen) = self.screen {
            screen.check()?;
        }
        let mut started = self.start()?;
        let first_step = started.world.steps();
        if let Some(path) = &self.resume {
            let (path, step) = (path.clone(), first_step);
            progress.note(Note::Resumed { path, step });
        }
        started.world.set_timing(self.stats);
        self.check_outputs()?;
        let cycling = self.cycles();
        if !self.json && !cycling {
            let header = report::header(self.frames, &started.input_name);
            (out.write_all(header.as_bytes()))
                .and_then(|()| out.flush())
                .map_err(JobError::Results)?;
        }
        let mut finished = match self.screen {
            Some(screen) => self.on_screen(screen, started.world, started.seed, progress)?,
            None => self.off_screen(started.world, started.steps, started.digest, progress)?,
        };
        if cycling && !self.json {
            let name = finished
                .input_name
                .as_deref()
                .unwrap_or(&started.input_name);
            (out.write_all(report::header(self.frames, name).as_bytes()))
                .map_err(JobError::Results)?;
        }
        let stopped = Signal::requested();
        // The results are printed whatever the files did: a file that could
        // not be written is reported after them, and the counts are kept.
        let failure = finished.failure.take();
        // Ended before its last step (a picture that failed after it, the
        // run's end all the same, is no reason to call it short).
        let short = failure.is_some() && finished.world.steps() < started.steps;
        let ended_early = short.then_some(started.steps);
        let written = self.write_files(&finished.world, started.digest, failure, ended_early);
        if let Some(signal) = stopped {
            progress.note(Note::Stopped {
                signal,
                step: finished.world.steps(),
                of: self.frames.map(|_| started.steps),
            });
        }
        let verified = finished.world.steps() - first_step;
        if let Some((slivers, first_sliver)) = finished.slivers {
            progress.note(Note::Verified {
                steps: verified,
                slivers,
                first_sliver,
            });
        }
        let ran = Ran {
            stopped: stopped.is_some() || short,
            first_step,
            verified,
            seed: started.seed,
        };
        let text = self.results(&finished, &ran);
        (out.write_all(text.as_bytes()))
            .and_then(|()| out.flush())
            .map_err(JobError::Results)?;
        written?;
        Ok(stopped)
    }

    /// Whether the run shows one generated scene after another.
    fn cycles(&self) -> bool {
        self.screen.is_some() && self.frames.is_none() && self.input.is_none()
    }

    /// Refuses options that do not go together.
    fn check(&self) -> Result<(), JobError> {
        let endless = self.frames.is_none();
        let on_screen = self.screen.is_some();
        let generated = self.lines.is_some() || self.kind.is_some() || self.seed.is_some();
        let files = self.state_out.is_some() || self.checkpoint.is_some();
        let conflict = if !on_screen && endless {
            Some(Conflict::NoEnd)
        } else if !on_screen && self.pace.is_some() {
            Some(Conflict::PaceOffScreen)
        } else if on_screen && (self.render.is_some() || self.verify) {
            Some(Conflict::OffScreenOnly)
        } else if self.cycle.is_some() && !self.cycles() {
            Some(Conflict::CycleOfOneScene)
        } else if endless && (files || self.resume.is_some()) {
            Some(Conflict::EndlessFiles)
        } else if self.input.is_some() && generated {
            Some(Conflict::GeneratedAndFile)
        } else {
            None
        };
        if let Some(conflict) = conflict {
            return Err(conflict.into());
        }
        // A picture's name the program cannot write, before anything is
        // read or made.
        if let Some(path) = &self.render {
            Recorder::check_name(path, self.render_every.is_some())?;
        }
        self.check_clashes()
    }

    /// Refuses a file written over a file the run reads, or written twice:
    /// each output is compared by identity with INPUT, `--resume` and the
    /// other outputs (a checkpoint written over the one it resumes from is
    /// meant: the run carries it on).
    fn check_clashes(&self) -> Result<(), JobError> {
        let outputs = named(&[
            (FileRole::State, &self.state_out),
            (FileRole::Checkpoint, &self.checkpoint),
            (FileRole::Pictures, &self.render),
        ]);
        let mut inputs = named(&[
            (FileRole::Scene, &self.input),
            (FileRole::Resume, &self.resume),
        ]);
        // Replacing standard output's file would lose the results.
        let stdout = FileIdentity::of_stdout();
        if let Some(identity) = &stdout {
            if let Some(output) = outputs.iter().find(|o| &o.identity == identity) {
                let path = output.path;
                let role = FileRole::Results;
                let identity = identity.clone();
                inputs.push(NamedFile {
                    role,
                    path,
                    identity,
                });
            }
        }
        if let Some(clash) = self.frame_clash(&outputs, &inputs, stdout) {
            return Err(clash);
        }
        for (k, output) in outputs.iter().enumerate() {
            for input in &inputs {
                let resumed = output.role == FileRole::Checkpoint && input.role == FileRole::Resume;
                if output.identity == input.identity && !resumed {
                    return Err(output.clash(input));
                }
            }
            for other in &outputs[k + 1..] {
                if output.identity == other.identity {
                    return Err(other.clash(output));
                }
            }
        }
        Ok(())
    }

    /// A numbered picture of a PNG sequence (`seq-000005.png` of `--render
    /// seq.png`) that would be written over another file the job names.
    fn frame_clash(
        &self,
        outputs: &[NamedFile],
        inputs: &[NamedFile],
        stdout: Option<FileIdentity>,
    ) -> Option<JobError> {
        let render = self.render.as_deref()?;
        let png = render
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !(png && self.render_every.is_some()) {
            return None;
        }
        // Standard output's file, when it has a frame's name.
        let results = stdout.and_then(|identity| {
            let dir = render.parent().filter(|p| !p.as_os_str().is_empty());
            let entries = std::fs::read_dir(dir.unwrap_or(std::path::Path::new("."))).ok()?;
            let path = entries.flatten().map(|e| e.path()).find(|path| {
                frame_name(render, path).is_some()
                    && FileIdentity::of(path).as_ref() == Some(&identity)
            })?;
            Some((path, identity))
        });
        let results = results.as_ref().map(|(path, identity)| NamedFile {
            role: FileRole::Results,
            path,
            identity: identity.clone(),
        });
        let others = outputs.iter().chain(inputs).chain(results.as_ref());
        let others = others.filter(|o| o.role != FileRole::Pictures);
        others.into_iter().find_map(|other| {
            let frame = frame_name(render, other.path)?;
            let identity = FileIdentity::of(&frame)?;
            (identity == other.identity).then(|| {
                let frame = NamedFile {
                    role: FileRole::Pictures,
                    path: &frame,
                    identity,
                };
                frame.clash(other)
            })
        })
    }

    /// Lines of the generated scenes.
    fn lines(&self) -> usize {
        self.lines.unwrap_or(Scene::BUILT_IN_LINES)
    }

    /// The arrangement of the `k`-th generated scene (from 0).
    fn kind_of(&self, k: u64) -> SceneKind {
        kind_of(self.kind, k)
    }

    /// Loads or generates the scene and builds the world, resumed from the
    /// checkpoint if asked.
    fn start(&mut self) -> Result<Started, JobError> {
        let endless = self.frames.is_none();
        let lines = self.lines();
        // An endless run takes its seed from the clock, so that each run
        // shows other scenes.
        let seed = match self.seed {
            Some(seed) => seed,
            None if endless => clock_seed(),
            None => Scene::BUILT_IN_SEED,
        };
        let built_in = self.lines.is_none() && self.kind.is_none() && self.seed.is_none();
        let (scene, input_name) = match &self.input {
            Some(path) => {
                if let Some((lines, size)) = Scene::peek_lines(path) {
                    check_memory(lines, size)?;
                }
                // The scene's size is not known yet: every core, unless
                // asked otherwise.
                let threads = match self.config.threads {
                    0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
                    asked => asked,
                };
                (Scene::load_on(path, threads)?, path.display().to_string())
            }
            None => {
                check_memory(lines as u64, 0)?;
                let name = if built_in && !endless {
                    report::input_name(None)
                } else {
                    report::input_name(Some((self.kind_of(0), lines, seed)))
                };
                (generate(self.kind_of(0), lines, seed), name)
            }
        };
        if self.config.threads == 0 {
            let live = self.screen.is_some();
            self.config.threads = DetectorConfig::threads_for(scene.lines.len(), live);
        }
        let digest = (self.checkpoint.is_some() || self.resume.is_some()).then(|| scene.digest());
        // An endless run has no last step.
        let steps = self.frames.map_or(u64::MAX, |f| f.saturating_add(1));
        let world = match &self.resume {
            Some(path) => {
                let saved = Checkpoint::load_on(path, self.config.threads)?;
                let name = path.display().to_string();
                let digest = digest.unwrap_or_else(|| scene.digest());
                saved.continues(&name, &scene, digest, steps)?;
                saved.resume(self.detector, &self.config)
            }
            None => World::with_config(&scene, self.detector, &self.config),
        };
        let world = world?;
        Ok(Started {
            world,
            input_name,
            digest,
            steps,
            seed,
        })
    }

    /// Checks, before any step runs, that every file the run will write
    /// can be written, so that a long run never ends in an error it could
    /// have reported at once.
    fn check_outputs(&self) -> Result<(), JobError> {
        let files = [&self.state_out, &self.checkpoint, &self.render];
        for path in files.into_iter().flatten() {
            check_writable(path)?;
        }
        Ok(())
    }

    /// The pictures' writer, if pictures were asked for.
    fn recorder(
        &self,
        steps: u64,
        progress: &mut dyn Progress,
    ) -> Result<Option<Recorder>, JobError> {
        let Some(path) = &self.render else {
            return Ok(None);
        };
        let gif = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
        let every = match self.render_every {
            // A GIF of every step of a long run is slow to write and huge
            // (2,000 frames at full size: 101 MB).
            None if gif && steps > GIF_FRAMES => {
                let every = steps.div_ceil(GIF_FRAMES);
                let frames = steps / every + 1;
                progress.note(Note::GifFrames { every, frames });
                Some(every)
            }
            every => every,
        };
        Ok(Some(Recorder::new(path, self.size, every, self.fps)?))
    }

    /// Runs the steps off screen: checked, pictured and saved as asked.
    fn off_screen(
        &self,
        mut world: World,
        steps: u64,
        digest: Option<u64>,
        progress: &mut dyn Progress,
    ) -> Result<Finished, JobError> {
        let to_run = steps.saturating_sub(world.steps());
        let checkpoints = self
            .checkpoint
            .as_deref()
            .zip(digest)
            .map(|(path, digest)| Checkpoints {
                path,
                every: self.checkpoint_every,
                digest,
            });
        let recorder = self.recorder(steps, progress)?;
        let first = world.steps();
        let mut each = |world: &World, elapsed: Duration| {
            progress.step(world.steps() - first, to_run, elapsed)
        };
        let run = Run {
            verify: self.verify,
            recorder,
            checkpoints,
            progress: Some(&mut each),
            stop: None,
        };
        let started = Instant::now();
        let ran = run.run(&mut world, to_run);
        progress.end(ran.as_ref().is_ok_and(|r| !r.stopped));
        let (elapsed, drawn, failure, slivers) = match ran {
            Ok(ran) => (ran.elapsed, ran.pictures, None, ran.slivers),
            // The steps run before a file failed are counted all the same
            // (their time with the writing's).
            Err(e @ (RunError::Picture(_) | RunError::Checkpoint(_))) => {
                (started.elapsed(), None, Some(e), None)
            }
            Err(e @ RunError::Mismatch { .. }) => return Err(e.into()),
        };
        Ok(Finished {
            scenes: 1,
            world,
            elapsed,
            drawn,
            input_name: None,
            failure,
            slivers,
        })
    }

    /// Runs the steps on screen, until they end or the window closes.
    fn on_screen(
        &self,
        screen: Screen,
        world: World,
        seed: u64,
        progress: &mut dyn Progress,
    ) -> Result<Finished, JobError> {
        let scenes = if self.cycles() {
            let (detector, kinds, timing, config) =
                (self.detector, self.kind, self.stats, self.config);
            let lines = self.lines();
            let make = move |k: u64| {
                let scene = generate(kind_of(kinds, k), lines, seed.wrapping_add(k));
                let mut world = World::with_config(&scene, detector, &config)
                    .expect("threads started once start again");
                world.set_timing(timing);
                world
            };
            Scenes::Generated {
                first: Box::new(world),
                next: Box::new(make),
                cycle: self.cycle.unwrap_or(DEFAULT_CYCLE),
            }
        } else {
            // FRAMES + 1 steps from the scene's start, as off screen: a
            // resumed world has run the checkpoint's share already.
            Scenes::One {
                world: Box::new(world),
                until: self.frames.map(|f| f + 1),
            }
        };
        let options = ShowOptions {
            fps: self.fps,
            hold: self.hold,
            hud: self.hud,
            pace: self.pace.unwrap_or(Pace::PerFrame),
        };
        let outcome = screen.show(scenes, options)?;
        let last = outcome.scenes - 1;
        if outcome.scenes > 1 {
            progress.note(Note::Scenes {
                shown: outcome.scenes,
                first_seed: seed,
                last_seed: seed.wrapping_add(last),
            });
        }
        let lines = self.lines();
        let name = report::input_name(Some((self.kind_of(last), lines, seed.wrapping_add(last))));
        Ok(Finished {
            scenes: outcome.scenes,
            world: outcome.world,
            elapsed: outcome.scene_elapsed,
            drawn: Some(outcome.drawn),
            input_name: self.cycles().then_some(name),
            failure: None,
            slivers: None,
        })
    }

    /// Writes the last checkpoint and the final state, if asked: each one
    /// whatever became of the other. The errors, one a line, after
    /// `failure` (what went wrong, if anything did); `ended_early` is the
    /// steps the run was to take, where the failure ended it before them.
    fn write_files(
        &self,
        world: &World,
        digest: Option<u64>,
        failure: Option<RunError>,
        ended_early: Option<u64>,
    ) -> Result<(), JobError> {
        let mut errors: Vec<JobError> = failure.into_iter().map(JobError::from).collect();
        if let (Some(path), Some(digest)) = (&self.checkpoint, digest) {
            let checkpoints = Checkpoints {
                path,
                every: None,
                digest,
            };
            errors.extend(checkpoints.save(world).err().map(JobError::from));
        }
        // A checkpoint says its step; a state does not, so the state of a
        // run that an error ended early is not written.
        match (&self.state_out, ended_early) {
            (Some(path), Some(of)) => errors.push(JobError::StateNotWritten {
                path: path.clone(),
                step: world.steps(),
                of,
            }),
            (Some(path), None) => {
                let written = checkpoint::save_state(world, path);
                errors.extend(written.err().map(JobError::from));
            }
            (None, _) => {}
        }
        match errors.is_empty() {
            true => Ok(()),
            false => Err(JobError::Files(errors)),
        }
    }

    /// The results: the original program's block (and the statistics), or
    /// one JSON object.
    fn results(&self, finished: &Finished, ran: &Ran) -> String {
        let (stopped, verified) = (ran.stopped, ran.verified);
        let world = &finished.world;
        let stats = || Stats::of(world, self.detector, &self.config, finished.drawn);
        let counts = world.counters();
        if !self.json {
            let mut text = report::results(finished.elapsed.as_secs_f64(), counts);
            if self.stats {
                text.push_str(&crate::stats::text(&stats()));
            }
            return text;
        }
        let mut value = serde_json::json!({
            "frames": self.frames,
            "steps": self.frames.map(|f| f.saturating_add(1)),
            "steps_run": world.steps(),
            "interrupted": stopped,
            "input": self.input.as_ref().map(|p| p.display().to_string()),
            "lines": world.lines().len(),
            "detector": self.detector.name(),
            "threads": world.threads_run(),
            "elapsed_seconds": finished.elapsed.as_secs_f64(),
            "line_wall_collisions": counts.wall,
            "line_line_collisions": counts.line,
        });
        // The scene shown last, so that it can be run again: a generated
        // one by kind, lines and seed (an endless run's seeds come from
        // the clock); and the checkpoint a resumed run went on from.
        value["generated"] = match self.input {
            Some(_) => serde_json::Value::Null,
            None => {
                let last = finished.scenes - 1;
                serde_json::json!({
                    "kind": self.kind_of(last).name(),
                    "lines": self.lines(),
                    "seed": ran.seed.wrapping_add(last),
                })
            }
        };
        value["resumed_from"] = match &self.resume {
            Some(path) => serde_json::json!({
                "checkpoint": path.display().to_string(),
                "step": ran.first_step,
            }),
            None => serde_json::Value::Null,
        };
        if self.verify {
            value["verified_steps"] = serde_json::json!(verified);
            value["sliver_events"] = serde_json::json!(finished.slivers.map_or(0, |s| s.0));
        }
        if self.stats {
            value["stats"] = crate::stats::json(&stats());
        }
        format!("{value}\n")
    }
}

/// A file a run reads or writes, by the part it plays.
struct NamedFile<'a> {
    role: FileRole,
    path: &'a std::path::Path,
    identity: FileIdentity,
}

impl NamedFile<'_> {
    /// The error for this output written over `other`.
    fn clash(&self, other: &NamedFile) -> JobError {
        JobError::Conflict(Conflict::SameFile {
            written: self.role,
            written_path: self.path.to_path_buf(),
            other: other.role,
            other_path: other.path.to_path_buf(),
        })
    }
}

/// The regular files among `files` (role and path, if given).
fn named<'a>(files: &[(FileRole, &'a Option<PathBuf>)]) -> Vec<NamedFile<'a>> {
    (files.iter())
        .filter_map(|&(role, path)| {
            let path = path.as_deref()?;
            let identity = FileIdentity::of(path)?;
            Some(NamedFile {
                role,
                path,
                identity,
            })
        })
        .collect()
}

/// A seed from the clock, in nanoseconds, so that two endless runs started
/// in one second show other scenes.
fn clock_seed() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(Scene::BUILT_IN_SEED, |d| d.as_nanos() as u64)
}

/// The name of the numbered picture of the sequence `render` that `other`'s
/// file name would be, if it is of that form.
fn frame_name(render: &std::path::Path, other: &std::path::Path) -> Option<PathBuf> {
    let name = other.file_name()?.to_str()?;
    let stem = render.file_stem()?.to_str()?;
    let digits = name.strip_prefix(stem)?.strip_prefix('-')?;
    let (digits, ext) = digits.split_once('.')?;
    let index = digits.parse::<u64>().ok()?;
    let frame = Recorder::sequence_name(render, index);
    let same = frame.file_name()?.to_str()? == name && ext.eq_ignore_ascii_case("png");
    same.then_some(frame)
}

/// The arrangement of the `k`-th generated scene (from 0): `kind`, or each
/// kind in turn.
fn kind_of(kind: Option<SceneKind>, k: u64) -> SceneKind {
    kind.unwrap_or(SceneKind::ALL[k as usize % SceneKind::ALL.len()])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A job of the built-in scene off screen, its text written to a
    /// buffer.
    fn text_of(job: Job) -> Result<String, JobError> {
        let mut out = Vec::new();
        job.run(&mut out, None)?;
        Ok(String::from_utf8(out).unwrap())
    }

    #[test]
    fn the_built_in_scene_prints_the_original_text() {
        let job = Job {
            frames: Some(10),
            detector: DetectorKind::Brute,
            ..Job::default()
        };
        let text = text_of(job).unwrap();
        assert!(text.starts_with("Number of frames = 10\nInput file path is: (none: built-in"));
        let mut world = World::with_detector(&screensaver::Scene::built_in(), DetectorKind::Brute);
        world.run(11);
        let c = world.counters();
        let counts = format!(
            "{} Line-Wall Collisions\n{} Line-Line Collisions\n",
            c.wall, c.line
        );
        assert!(text.contains(&counts), "{text}");
    }

    #[test]
    fn options_that_do_not_go_together_are_refused() {
        let refused = |job: Job| matches!(text_of(job), Err(JobError::Conflict(_)));
        assert!(refused(Job::default()), "no FRAMES off screen");
        let frames = Some(3);
        assert!(refused(Job {
            frames,
            pace: Some(Pace::Max),
            ..Job::default()
        }));
        assert!(refused(Job {
            frames,
            input: Some("x.in".into()),
            lines: Some(5),
            ..Job::default()
        }));
        assert!(refused(Job {
            frames,
            cycle: Some(Duration::from_secs(1)),
            ..Job::default()
        }));
    }

    #[test]
    fn endless_runs_started_together_get_other_seeds() {
        let first = clock_seed();
        std::thread::sleep(Duration::from_millis(2));
        assert_ne!(first, clock_seed());
    }

    /// A small scene runs on one thread whatever the team, and says so.
    #[test]
    fn json_results_report_the_threads_that_ran() {
        let threads = |lines: usize| {
            let job = Job {
                frames: Some(3),
                json: true,
                lines: Some(lines),
                config: DetectorConfig {
                    threads: 2,
                    ..DetectorConfig::default()
                },
                ..Job::default()
            };
            let value: serde_json::Value = serde_json::from_str(&text_of(job).unwrap()).unwrap();
            value["threads"].as_u64().unwrap()
        };
        assert_eq!(threads(20), 1);
        assert_eq!(threads(20_000), 2);
    }

    #[test]
    fn json_results_name_the_run() {
        let job = Job {
            frames: Some(4),
            json: true,
            verify: true,
            lines: Some(50),
            ..Job::default()
        };
        let value: serde_json::Value = serde_json::from_str(&text_of(job).unwrap()).unwrap();
        assert_eq!(value["steps_run"], 5);
        assert_eq!(value["verified_steps"], 5);
        assert_eq!(value["lines"], 50);
    }
}
