//! The live window (`-g`, or `--fullscreen`): the simulation runs on its
//! own thread (see [`super::live`]) as fast as it may, and the window shows
//! its latest state at the display's pace, redrawing only when there is a
//! new state, a new size or an exposure.
//!
//! Keys: Space pauses and resumes, Right arrow takes one step while paused,
//! `+` and `-` speed up and slow down, H shows or hides the heads-up
//! display, Q or Esc quits. The title shows the step, both counters and
//! the steps per second.

use super::live::{FrameClock, Outcome, Scenes, Simulation, Snapshot};
use super::raster::{Canvas, Painter};
use super::screen::{ScreenError, ShowOptions};
use super::{hud, Size, View};
use std::num::NonZeroU32;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::{LogicalSize, PhysicalPosition};
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::raw_window_handle::{HasWindowHandle, RawWindowHandle};
use winit::window::{Fullscreen, Window, WindowId};
use x11rb::protocol::xproto::ConnectionExt as _;

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
    /// Show or hide the heads-up display.
    ToggleHud,
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
            "h" | "H" => Some(Action::ToggleHud),
            _ => None,
        },
        _ => None,
    }
}

/// The window's title for a state of the run: the step, both counters and
/// the rate, or that the run is paused.
fn title(s: &Snapshot) -> String {
    let rate = match s.paused {
        true => "paused".to_string(),
        false => format!("{:.0} steps/s", s.rate),
    };
    format!(
        "screensaver - step {} - {} line-wall, {} line-line - {rate}",
        s.step, s.wall, s.line
    )
}

/// Fails, with a message that says what to do, when there is no display
/// to open a window on or it does not answer: a connection is made, so
/// that a run reports it before it prints anything, and kept
/// ([`keep_open`]).
pub(super) fn check_display() -> Result<(), ScreenError> {
    display_named()?;
    match std::env::var_os("DISPLAY").is_some_and(|v| !v.is_empty()) {
        true => x11rb::connect(None)
            .map(|(conn, _)| keep_open(conn))
            .map_err(|_| unreachable_display()),
        false => Ok(()),
    }
}

/// The connection a check made, open until the process ends.
static CHECKED: std::sync::Mutex<Option<x11rb::rust_connection::RustConnection>> =
    std::sync::Mutex::new(None);

/// Keeps the connection `conn` open until the process ends. An X server
/// with no other client resets when its last client leaves (as Xvfb does
/// under `xvfb-run`), and the run's own connection, made a moment later,
/// would meet the server mid-reset and be cut.
pub(super) fn keep_open(conn: x11rb::rust_connection::RustConnection) {
    *CHECKED.lock().unwrap_or_else(|e| e.into_inner()) = Some(conn);
}

/// Fails, with a message that says what to do, when no display is named
/// at all; the caller connects next and reports a display that does not
/// answer.
pub(super) fn display_named() -> Result<(), ScreenError> {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") || set("WAYLAND_DISPLAY") || set("WAYLAND_SOCKET") {
        Ok(())
    } else {
        Err(ScreenError::NoDisplay)
    }
}

/// The message for a display that cannot be reached: the display's name
/// and what to check, not the windowing library's own words.
fn unreachable_display() -> ScreenError {
    let display = std::env::var("DISPLAY").unwrap_or_default();
    ScreenError::Unreachable { display }
}

/// Opens the window and runs the scenes in it until the run ends, the
/// window is closed or a signal stops it. Fails with a message when no
/// window can be opened.
pub(super) fn run(
    scenes: Scenes,
    options: ShowOptions,
    fullscreen: bool,
) -> Result<Outcome, ScreenError> {
    display_named()?;
    let event_loop = EventLoop::new().map_err(|_| unreachable_display())?;
    let run = Simulation::start(scenes, options.pace);
    let mut app = App {
        run: &run,
        options,
        fullscreen,
        window: None,
        surface: None,
        painter: Painter::new(),
        frame: Vec::new(),
        state: None,
        title: String::new(),
        hud: options.hud,
        clock: FrameClock::default(),
        next_frame: Instant::now(),
        error: None,
        x11: None,
    };
    let looped = event_loop.run_app(&mut app);
    let (error, stats) = (app.error.take(), app.clock.stats());
    let outcome = run.finish()?;
    looped.map_err(|e| ScreenError::Failed(format!("the window failed: {e}")))?;
    match error {
        Some(e) => Err(ScreenError::Failed(e)),
        None => Ok(Outcome {
            drawn: stats,
            ..outcome
        }),
    }
}

struct App<'a> {
    run: &'a Simulation,
    options: ShowOptions,
    /// Fill the screen, the box stretched over it.
    fullscreen: bool,
    window: Option<Arc<Window>>,
    surface: Option<softbuffer::Surface<Arc<Window>, Arc<Window>>>,
    painter: Painter,
    /// The frame drawn, before it goes to the window.
    frame: Vec<u32>,
    /// The state on show.
    state: Option<Snapshot>,
    title: String,
    /// Whether the heads-up display is on.
    hud: bool,
    clock: FrameClock,
    next_frame: Instant,
    error: Option<String>,
    /// The window on the X server, asked for its size over a connection of
    /// our own: the windowing library's own question panics once another
    /// client has destroyed the window, where this one answers that it is
    /// gone.
    x11: Option<(x11rb::rust_connection::RustConnection, u32)>,
}

impl App<'_> {
    /// Ends the run with an error, unless the window is gone: then it
    /// ends as a closed window does.
    fn fail(&mut self, event_loop: &ActiveEventLoop, message: String) {
        if self.size().is_some() {
            self.error = Some(message);
        }
        self.closed(event_loop);
    }

    /// Ends the run as when the window is closed: the results of the
    /// steps run so far.
    fn closed(&mut self, event_loop: &ActiveEventLoop) {
        self.surface = None;
        self.window = None;
        event_loop.exit();
    }

    /// The window's size in pixels, or `None` once it is gone.
    fn size(&self) -> Option<winit::dpi::PhysicalSize<u32>> {
        let window = self.window.as_ref()?;
        match &self.x11 {
            Some((conn, id)) => {
                let geometry = conn.get_geometry(*id).ok()?.reply().ok()?;
                Some((u32::from(geometry.width), u32::from(geometry.height)).into())
            }
            None => Some(window.inner_size()),
        }
    }

    /// Takes the latest state, if there is a new one.
    fn take_snapshot(&mut self) {
        if let Some(s) = self.run.shared.take() {
            self.title = title(&s);
            if let Some(old) = self.state.replace(s) {
                self.run.shared.recycle(old);
            }
        }
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let started = Instant::now();
        self.take_snapshot();
        let Some(window) = &self.window else {
            return;
        };
        window.set_title(&self.title);
        let Some(size) = self.size() else {
            return self.closed(event_loop);
        };
        let (Some(surface), Some(state)) = (&mut self.surface, &self.state) else {
            return;
        };
        let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) else {
            return;
        };
        if let Err(e) = surface.resize(w, h) {
            let message = format!("cannot draw: {e}");
            return self.fail(event_loop, message);
        }
        let mut buffer = match surface.buffer_mut() {
            Ok(buffer) => buffer,
            Err(e) => {
                let message = format!("cannot draw: {e}");
                return self.fail(event_loop, message);
            }
        };
        let frame = Size {
            width: w.get(),
            height: h.get(),
        };
        let view = if self.fullscreen {
            View::filling(frame)
        } else {
            View::new(frame)
        };
        // Drawn in a frame of our own, then copied: drawing straight into
        // the window's shared buffer costs more than the one copy
        // (docs/PERFORMANCE.md, "Drawing live").
        let (w, h) = (w.get() as usize, h.get() as usize);
        self.frame.resize(w * h, 0);
        let mut canvas = Canvas::new(&mut self.frame, w, h);
        self.painter
            .paint(&state.lines, &state.colors, &view, &mut canvas);
        if self.hud {
            let text = hud::lines(state, self.clock.recent_fps(), self.run.shared.pace());
            hud::draw(&mut canvas, &text);
        }
        buffer.copy_from_slice(&self.frame);
        if let Err(e) = buffer.present() {
            let message = format!("cannot draw: {e}");
            return self.fail(event_loop, message);
        }
        self.clock.drawn(started);
    }

    fn act(&mut self, action: Action, event_loop: &ActiveEventLoop) {
        let shared = &self.run.shared;
        match action {
            Action::TogglePause => {
                shared.paused.fetch_xor(true, Ordering::Relaxed);
                shared.want_news();
            }
            Action::Step => {
                if shared.paused.load(Ordering::Relaxed) {
                    shared.steps_requested.fetch_add(1, Ordering::Relaxed);
                }
            }
            Action::Faster | Action::Slower => {
                let rate = self.state.as_ref().map_or(0.0, |s| s.rate);
                let pace = shared.pace().changed(action == Action::Faster, rate);
                shared.set_pace(pace);
            }
            Action::ToggleHud => {
                self.hud = !self.hud;
                if let Some(window) = &self.window {
                    window.request_redraw();
                }
            }
            Action::Quit => event_loop.exit(),
        }
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let mut attributes = Window::default_attributes()
            .with_title("screensaver")
            .with_inner_size(LogicalSize::new(Size::WINDOW.width, Size::WINDOW.height))
            .with_resizable(true);
        if self.fullscreen {
            // Fullscreen asks the window manager; the size and place are
            // set as well, for displays without one.
            let monitor = event_loop
                .primary_monitor()
                .or_else(|| event_loop.available_monitors().next());
            if let Some(monitor) = &monitor {
                attributes = attributes
                    .with_inner_size(monitor.size())
                    .with_position(PhysicalPosition::new(0, 0))
                    .with_decorations(false);
            }
            attributes = attributes.with_fullscreen(Some(Fullscreen::Borderless(monitor)));
        }
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
        // Where the window is an X window, its size is asked over a
        // connection of our own (see `App::x11`).
        let id = match window.window_handle().map(|h| h.as_raw()) {
            Ok(RawWindowHandle::Xlib(h)) => u32::try_from(h.window).ok(),
            Ok(RawWindowHandle::Xcb(h)) => Some(h.window.get()),
            _ => None,
        };
        self.x11 = id.and_then(|id| Some((x11rb::connect(None).ok()?.0, id)));
        self.window = Some(window);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => self.closed(event_loop),
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
        let shared = &self.run.shared;
        let news = shared.has_news();
        if shared.finished.load(Ordering::Acquire) && !self.options.hold && !news {
            // The last state has been drawn.
            event_loop.exit();
            return;
        }
        let now = Instant::now();
        if now >= self.next_frame {
            if news {
                if let Some(window) = &self.window {
                    window.request_redraw();
                }
            }
            // With nothing running (paused, or held after the end) the
            // window wakes only a few times a second, to see whether a
            // signal or a single step came.
            let idle =
                shared.finished.load(Ordering::Acquire) || shared.paused.load(Ordering::Relaxed);
            let period = if idle {
                Duration::from_millis(100)
            } else {
                Duration::from_secs_f64(1.0 / f64::from(self.options.fps.max(1)))
            };
            self.next_frame = now + period;
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(self.next_frame));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The title shows the rate while the run steps, and that it is
    /// paused when it is not.
    #[test]
    fn a_paused_runs_title_shows_no_rate() {
        let snapshot = Snapshot {
            lines: Vec::new(),
            colors: Vec::new(),
            step: 12,
            wall: 3,
            line: 4,
            rate: 950.2,
            paused: false,
            scene: 0,
        };
        assert_eq!(
            title(&snapshot),
            "screensaver - step 12 - 3 line-wall, 4 line-line - 950 steps/s"
        );
        let paused = Snapshot {
            paused: true,
            ..snapshot
        };
        assert_eq!(
            title(&paused),
            "screensaver - step 12 - 3 line-wall, 4 line-line - paused"
        );
    }

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
        assert_eq!(
            action_for(&Key::Character("h".into())),
            Some(Action::ToggleHud)
        );
        assert_eq!(action_for(&Key::Character("x".into())), None);
        assert_eq!(action_for(&Key::Named(NamedKey::ArrowLeft)), None);
    }
}
