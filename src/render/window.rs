//! The live window (`-g`): the simulation runs on its own thread as fast as
//! it may, and the window shows its latest state at the display's pace.
//!
//! Keys: Space pauses and resumes, Right arrow takes one step while paused,
//! `+` and `-` speed up and slow down, Q or Esc quits. The title shows the
//! step, both counters and the steps per second.

use super::{draw, Size};
use crate::line::{Color, Line};
use crate::World;
use std::num::NonZeroU32;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tiny_skia::Pixmap;
use winit::application::ApplicationHandler;
use winit::dpi::LogicalSize;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// What a key does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Pause, or resume.
    TogglePause,
    /// One step (while paused).
    Step,
    /// Run twice as fast (up to no limit).
    Faster,
    /// Run half as fast.
    Slower,
    /// Close the window and end the run.
    Quit,
}

/// The action bound to a key, if any.
pub fn action_for(key: &Key) -> Option<Action> {
    match key {
        Key::Named(NamedKey::Space) => Some(Action::TogglePause),
        Key::Named(NamedKey::ArrowRight) => Some(Action::Step),
        Key::Named(NamedKey::Escape) => Some(Action::Quit),
        Key::Character(c) => match c.as_str() {
            "+" | "=" => Some(Action::Faster),
            "-" | "_" => Some(Action::Slower),
            "q" | "Q" => Some(Action::Quit),
            _ => None,
        },
        _ => None,
    }
}

/// How the window was asked to behave.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Steps to run.
    pub steps: u64,
    /// Most frames drawn per second.
    pub fps: u32,
    /// Keep the window open after the last step, until it is closed.
    pub hold: bool,
}

/// The simulation's speed limit: unlimited, or a number of steps per second.
/// `Faster` from the fastest limit lifts it; `Slower` from no limit starts
/// at the rate last measured.
fn change_rate(limit: u64, measured: f64, action: Action) -> u64 {
    match (action, limit) {
        (Action::Faster, 0) => 0,
        (Action::Faster, l) if l >= 1 << 20 => 0,
        (Action::Faster, l) => l * 2,
        (Action::Slower, 0) => ((measured / 2.0) as u64).max(1),
        (Action::Slower, l) => (l / 2).max(1),
        (_, l) => l,
    }
}

/// What the two threads share.
struct Shared {
    paused: AtomicBool,
    steps_requested: AtomicU64,
    /// Steps per second allowed; 0 for no limit.
    limit: AtomicU64,
    quit: AtomicBool,
    finished: AtomicBool,
    /// The latest state, for the window to take.
    latest: Mutex<Option<Snapshot>>,
    /// Whether the window has taken the latest state (so a new one is wanted).
    taken: AtomicBool,
}

struct Snapshot {
    lines: Vec<Line>,
    step: u64,
    wall: u64,
    line: u64,
    rate: f64,
}

/// The outcome of a windowed run: the world after the steps it ran, and how
/// long the simulation loop took.
pub struct Outcome {
    /// The world, back from the simulation thread.
    pub world: World,
    /// The time the simulation loop ran (pauses included).
    pub elapsed: Duration,
}

/// Fails, with a message that says what to do, when there is plainly no
/// display to open a window on.
pub fn check_display() -> Result<(), String> {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") || set("WAYLAND_DISPLAY") || set("WAYLAND_SOCKET") {
        Ok(())
    } else {
        Err("cannot open a window: no display (DISPLAY is not set); \
             run under xvfb-run for a virtual one, or use --render"
            .into())
    }
}

/// Opens the window and runs the world in it. Fails with a message when no
/// window can be opened (no display).
pub fn run(world: World, options: Options) -> Result<Outcome, String> {
    check_display()?;
    let event_loop = EventLoop::new().map_err(|e| format!("cannot open a window: {e}"))?;
    let colors = world.colors().to_vec();
    let shared = Arc::new(Shared {
        paused: AtomicBool::new(false),
        steps_requested: AtomicU64::new(0),
        limit: AtomicU64::new(0),
        quit: AtomicBool::new(false),
        finished: AtomicBool::new(false),
        latest: Mutex::new(None),
        taken: AtomicBool::new(true),
    });
    let simulation = {
        let shared = Arc::clone(&shared);
        std::thread::spawn(move || simulate(world, options.steps, &shared))
    };
    let mut app = App {
        shared: Arc::clone(&shared),
        colors,
        options,
        window: None,
        surface: None,
        pixmap: None,
        lines: Vec::new(),
        title: String::new(),
        next_frame: Instant::now(),
        rate: 0.0,
        error: None,
    };
    let looped = event_loop.run_app(&mut app);
    shared.quit.store(true, Ordering::Relaxed);
    let outcome = simulation
        .join()
        .map_err(|_| "the simulation thread panicked".to_string())?;
    looped.map_err(|e| format!("the window failed: {e}"))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(outcome),
    }
}

/// The simulation thread: steps until done or told to quit, obeying pause,
/// single steps and the speed limit, and leaves a snapshot whenever the
/// window has taken the last one.
fn simulate(mut world: World, steps: u64, shared: &Shared) -> Outcome {
    let start = Instant::now();
    let (mut window_start, mut window_steps) = (Instant::now(), 0u64);
    let mut rate = 0.0;
    let publish = |world: &World, rate: f64, force: bool| {
        if force || shared.taken.swap(false, Ordering::AcqRel) {
            let c = world.counters();
            let snapshot = Snapshot {
                lines: world.lines().to_vec(),
                step: world.steps(),
                wall: c.wall,
                line: c.line,
                rate,
            };
            *shared
                .latest
                .lock()
                .expect("no panics while holding the lock") = Some(snapshot);
        }
    };
    publish(&world, 0.0, true);
    while world.steps() < steps && !shared.quit.load(Ordering::Relaxed) {
        let paused = shared.paused.load(Ordering::Relaxed);
        if paused && shared.steps_requested.load(Ordering::Relaxed) == 0 {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        if paused {
            shared.steps_requested.fetch_sub(1, Ordering::Relaxed);
        }
        let step_start = Instant::now();
        world.step();
        window_steps += 1;
        if window_start.elapsed() >= Duration::from_millis(250) {
            rate = window_steps as f64 / window_start.elapsed().as_secs_f64();
            (window_start, window_steps) = (Instant::now(), 0);
        }
        publish(&world, rate, paused);
        let limit = shared.limit.load(Ordering::Relaxed);
        if limit > 0 {
            let budget = Duration::from_secs_f64(1.0 / limit as f64);
            if let Some(rest) = budget.checked_sub(step_start.elapsed()) {
                std::thread::sleep(rest);
            }
        }
    }
    let elapsed = start.elapsed();
    publish(&world, rate, true);
    shared.finished.store(true, Ordering::Release);
    Outcome { world, elapsed }
}

struct App {
    shared: Arc<Shared>,
    colors: Vec<Color>,
    options: Options,
    window: Option<Arc<Window>>,
    surface: Option<softbuffer::Surface<Arc<Window>, Arc<Window>>>,
    pixmap: Option<Pixmap>,
    lines: Vec<Line>,
    title: String,
    next_frame: Instant,
    rate: f64,
    error: Option<String>,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, message: String) {
        self.error = Some(message);
        event_loop.exit();
    }

    /// Takes the latest snapshot, if there is a new one.
    fn take_snapshot(&mut self) {
        let snapshot = self
            .shared
            .latest
            .lock()
            .expect("no panics while holding the lock")
            .take();
        if let Some(s) = snapshot {
            self.lines = s.lines;
            self.rate = s.rate;
            let paused = if self.shared.paused.load(Ordering::Relaxed) {
                "  [paused]"
            } else {
                ""
            };
            self.title = format!(
                "screensaver - step {} - {} line-wall, {} line-line - {:.0} steps/s{paused}",
                s.step, s.wall, s.line, s.rate
            );
            self.shared.taken.store(true, Ordering::Release);
        }
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        self.take_snapshot();
        let (Some(window), Some(surface)) = (&self.window, &mut self.surface) else {
            return;
        };
        window.set_title(&self.title);
        let size = window.inner_size();
        let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) else {
            return;
        };
        if let Err(e) = surface.resize(w, h) {
            let message = format!("cannot draw: {e}");
            return self.fail(event_loop, message);
        }
        let fits = self
            .pixmap
            .as_ref()
            .is_some_and(|p| p.width() == w.get() && p.height() == h.get());
        if !fits {
            self.pixmap = Pixmap::new(w.get(), h.get());
        }
        let Some(pixmap) = &mut self.pixmap else {
            return;
        };
        draw(&self.lines, &self.colors, pixmap);
        let mut buffer = match surface.buffer_mut() {
            Ok(buffer) => buffer,
            Err(e) => {
                let message = format!("cannot draw: {e}");
                return self.fail(event_loop, message);
            }
        };
        for (out, p) in buffer.iter_mut().zip(pixmap.pixels()) {
            *out = (u32::from(p.red()) << 16) | (u32::from(p.green()) << 8) | u32::from(p.blue());
        }
        if let Err(e) = buffer.present() {
            let message = format!("cannot draw: {e}");
            self.fail(event_loop, message);
        }
    }

    fn act(&mut self, action: Action, event_loop: &ActiveEventLoop) {
        let shared = &self.shared;
        match action {
            Action::TogglePause => {
                shared.paused.fetch_xor(true, Ordering::Relaxed);
                shared.taken.store(true, Ordering::Release);
            }
            Action::Step => {
                if shared.paused.load(Ordering::Relaxed) {
                    shared.steps_requested.fetch_add(1, Ordering::Relaxed);
                }
            }
            Action::Faster | Action::Slower => {
                let limit = change_rate(shared.limit.load(Ordering::Relaxed), self.rate, action);
                shared.limit.store(limit, Ordering::Relaxed);
            }
            Action::Quit => event_loop.exit(),
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes()
            .with_title("screensaver")
            .with_inner_size(LogicalSize::new(Size::WINDOW.width, Size::WINDOW.height))
            .with_resizable(true);
        let window = match event_loop.create_window(attributes) {
            Ok(window) => Arc::new(window),
            Err(e) => return self.fail(event_loop, format!("cannot open a window: {e}")),
        };
        let surface = softbuffer::Context::new(Arc::clone(&window))
            .and_then(|context| softbuffer::Surface::new(&context, Arc::clone(&window)));
        match surface {
            Ok(surface) => self.surface = Some(surface),
            Err(e) => return self.fail(event_loop, format!("cannot draw in the window: {e}")),
        }
        self.window = Some(window);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if let Some(action) = action_for(&event.logical_key) {
                    self.act(action, event_loop);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if crate::stop::requested().is_some() {
            event_loop.exit();
            return;
        }
        let finished = self.shared.finished.load(Ordering::Acquire);
        if finished && !self.options.hold && self.shared.latest.lock().map_or(true, |l| l.is_none())
        {
            // The last state has been drawn.
            event_loop.exit();
            return;
        }
        let now = Instant::now();
        if now >= self.next_frame {
            if let Some(window) = &self.window {
                window.request_redraw();
            }
            self.next_frame =
                now + Duration::from_secs_f64(1.0 / f64::from(self.options.fps.max(1)));
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(self.next_frame));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_map_to_actions() {
        assert_eq!(
            action_for(&Key::Named(NamedKey::Space)),
            Some(Action::TogglePause)
        );
        assert_eq!(
            action_for(&Key::Named(NamedKey::ArrowRight)),
            Some(Action::Step)
        );
        assert_eq!(
            action_for(&Key::Named(NamedKey::Escape)),
            Some(Action::Quit)
        );
        assert_eq!(action_for(&Key::Character("q".into())), Some(Action::Quit));
        assert_eq!(action_for(&Key::Character("Q".into())), Some(Action::Quit));
        assert_eq!(
            action_for(&Key::Character("+".into())),
            Some(Action::Faster)
        );
        assert_eq!(
            action_for(&Key::Character("=".into())),
            Some(Action::Faster)
        );
        assert_eq!(
            action_for(&Key::Character("-".into())),
            Some(Action::Slower)
        );
        assert_eq!(action_for(&Key::Character("x".into())), None);
        assert_eq!(action_for(&Key::Named(NamedKey::ArrowLeft)), None);
    }

    #[test]
    fn speed_changes_halve_and_double_the_limit() {
        assert_eq!(change_rate(0, 1000.0, Action::Slower), 500);
        assert_eq!(change_rate(500, 1000.0, Action::Slower), 250);
        assert_eq!(change_rate(1, 1000.0, Action::Slower), 1);
        assert_eq!(change_rate(250, 1000.0, Action::Faster), 500);
        assert_eq!(change_rate(0, 1000.0, Action::Faster), 0);
        assert_eq!(change_rate(1 << 20, 1000.0, Action::Faster), 0);
        assert_eq!(change_rate(0, 0.5, Action::Slower), 1);
    }
}
