//! The screen saver on Windows: a full-screen winit window (`/s`), or the
//! preview window Windows hands (`/p`), that softbuffer fills with the
//! lines, drawn as the main program draws them on screen.

use crate::args::Mode;
use screensaver::generate::{generate, SceneKind};
use screensaver::render::{Canvas, Size, View};
use screensaver::Scene;
use screensaver::{DetectorConfig, DetectorKind, World};
use std::num::{NonZeroIsize, NonZeroU32};
use std::rc::Rc;
use std::time::{Duration, Instant, SystemTime};
use windows_sys::Win32::Foundation::{HWND, POINT, RECT};
use windows_sys::Win32::UI::WindowsAndMessaging::{
    GetClientRect, GetCursorPos, IsWindow, MessageBoxW, MB_ICONERROR, MB_ICONINFORMATION, MB_OK,
};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::raw_window_handle::{
    DisplayHandle, HandleError, HasDisplayHandle, HasWindowHandle, RawWindowHandle,
    Win32WindowHandle, WindowHandle,
};
use winit::window::{Fullscreen, Window, WindowId, WindowLevel};

/// How long each scene is shown, as `screensaver --fullscreen` shows them.
const CYCLE: Duration = Duration::from_secs(60);

/// Frames a second: one step each, the original's pace.
const FPS: u32 = 60;

/// How far the mouse may move, in pixels, before the screen saver ends:
/// Windows sends a move when the window appears, and a desk's tremor
/// should not end it either.
const MOUSE_SLACK: i32 = 4;

/// Runs the mode until it ends: input (`/s`), the preview window closing
/// (`/p`), the message closed (`/c`).
pub fn run(mode: Mode) -> Result<(), String> {
    match mode {
        Mode::Configure(owner) => {
            message_box(
                owner,
                "Screensaver: line segments bouncing in a box, as MIT 6.172's \
                 screensaver computed them.\n\nIt has no settings: it shows generated \
                 scenes of 1000 lines, each kind in turn, a new one every minute.\n\n\
                 For other scenes, sizes and speeds, run screensaver.exe from a \
                 command prompt (screensaver --help).",
                MB_ICONINFORMATION,
            );
            Ok(())
        }
        Mode::Preview(hwnd) => preview(hwnd),
        Mode::Saver => {
            let event_loop = EventLoop::new().map_err(|e| format!("cannot start: {e}"))?;
            let mut app = Saver {
                window: None,
                surface: None,
                frame: Vec::new(),
                scenes: Scenes::new(),
                mouse_at: None,
                next_frame: Instant::now(),
                failure: None,
            };
            event_loop
                .run_app(&mut app)
                .map_err(|e| format!("cannot run: {e}"))?;
            app.failure.map_or(Ok(()), Err)
        }
    }
}

/// Whether `hwnd` names a window.
fn is_window(hwnd: usize) -> bool {
    // SAFETY: IsWindow takes any value and says whether it names a window.
    unsafe { IsWindow(hwnd as HWND) != 0 }
}

/// The preview window Windows hands, drawn into as it is. The usual way,
/// a child window of our own inside it, showed nothing under Wine, which
/// does not draw a child window inside another process's window.
struct Preview(NonZeroIsize);

impl HasWindowHandle for Preview {
    fn window_handle(&self) -> Result<WindowHandle<'_>, HandleError> {
        let raw = RawWindowHandle::Win32(Win32WindowHandle::new(self.0));
        // SAFETY: the handle names a window (checked before every frame);
        // drawing into one that has gone since fails, which ends the
        // preview.
        Ok(unsafe { WindowHandle::borrow_raw(raw) })
    }
}

impl HasDisplayHandle for Preview {
    fn display_handle(&self) -> Result<DisplayHandle<'_>, HandleError> {
        Ok(DisplayHandle::windows())
    }
}

/// The preview: one step a frame into the window until it closes.
fn preview(hwnd: usize) -> Result<(), String> {
    if !is_window(hwnd) {
        return Err(format!("{hwnd} is not a window"));
    }
    let target = Rc::new(Preview(
        NonZeroIsize::new(hwnd as isize).ok_or("no preview window")?,
    ));
    let context = softbuffer::Context::new(Rc::clone(&target))
        .map_err(|e| format!("cannot draw in the preview window: {e}"))?;
    let mut surface = softbuffer::Surface::new(&context, Rc::clone(&target))
        .map_err(|e| format!("cannot draw in the preview window: {e}"))?;
    let mut scenes = Scenes::new();
    let mut frame = Vec::new();
    let period = Duration::from_secs_f64(1.0 / f64::from(FPS));
    let mut next = Instant::now();
    while is_window(hwnd) {
        let Some(size) = client_size(hwnd) else {
            break;
        };
        if show(&mut surface, &mut frame, &scenes.world, size).is_err() {
            // The window went between the check and the drawing.
            break;
        }
        scenes.advance();
        next += period;
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    Ok(())
}

/// Draws the world into the surface, `size` pixels, by way of `frame`.
fn show<D: HasDisplayHandle, W: HasWindowHandle>(
    surface: &mut softbuffer::Surface<D, W>,
    frame: &mut Vec<u32>,
    world: &World,
    size: PhysicalSize<u32>,
) -> Result<(), String> {
    let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) else {
        return Ok(());
    };
    surface
        .resize(w, h)
        .map_err(|e| format!("cannot draw: {e}"))?;
    let (width, height) = (w.get() as usize, h.get() as usize);
    frame.clear();
    frame.resize(width * height, 0);
    let mut canvas = Canvas::new(frame, width, height);
    // The box fills the screen, as `screensaver --fullscreen` has it.
    let view = View::filling(Size {
        width: w.get(),
        height: h.get(),
    });
    for (line, color) in world.lines_as_stored() {
        let a = view.point(line.p1.x, line.p1.y);
        let b = view.point(line.p2.x, line.p2.y);
        canvas.draw_segment(a, b, color.rgb());
    }
    let mut buffer = surface
        .buffer_mut()
        .map_err(|e| format!("cannot draw: {e}"))?;
    buffer.copy_from_slice(frame);
    buffer.present().map_err(|e| format!("cannot draw: {e}"))
}

/// Says what went wrong where a screen saver's user can see it.
pub fn show_error(message: &str) {
    message_box(None, &format!("Screensaver: {message}"), MB_ICONERROR);
}

fn message_box(owner: Option<usize>, text: &str, icon: u32) {
    let wide = |s: &str| s.encode_utf16().chain([0]).collect::<Vec<u16>>();
    let (text, caption) = (wide(text), wide("Screensaver"));
    // SAFETY: both strings are NUL-terminated UTF-16 that outlive the
    // call; an owner that is not a window is taken as none.
    unsafe {
        MessageBoxW(
            owner.map_or(std::ptr::null_mut(), |h| h as HWND),
            text.as_ptr(),
            caption.as_ptr(),
            MB_OK | icon,
        );
    }
}

/// The size of the preview window's client area.
fn client_size(hwnd: usize) -> Option<PhysicalSize<u32>> {
    let mut rect = RECT {
        left: 0,
        top: 0,
        right: 0,
        bottom: 0,
    };
    // SAFETY: `rect` is a RECT to write; a handle that is no window fails.
    if unsafe { GetClientRect(hwnd as HWND, &mut rect) } == 0 {
        return None;
    }
    let width = u32::try_from(rect.right - rect.left).ok()?;
    let height = u32::try_from(rect.bottom - rect.top).ok()?;
    Some(PhysicalSize::new(width, height))
}

fn is_modifier(key: &Key) -> bool {
    matches!(
        key,
        Key::Named(
            NamedKey::Alt
                | NamedKey::AltGraph
                | NamedKey::Control
                | NamedKey::Shift
                | NamedKey::Super
                | NamedKey::Meta
        )
    )
}

/// Where the mouse is on the screen.
fn cursor() -> Option<(i32, i32)> {
    let mut point = POINT { x: 0, y: 0 };
    // SAFETY: `point` is a POINT to write.
    (unsafe { GetCursorPos(&mut point) } != 0).then_some((point.x, point.y))
}

/// The generated scenes, one after another.
struct Scenes {
    world: World,
    shown: u64,
    started: Instant,
    seed: u64,
}

impl Scenes {
    fn new() -> Scenes {
        // A different show each time, as `screensaver --fullscreen` gives.
        let seed = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        Scenes {
            world: Self::scene(0, seed),
            shown: 0,
            started: Instant::now(),
            seed,
        }
    }

    /// The `k`-th scene: each kind in turn, seeds counting up.
    fn scene(k: u64, seed: u64) -> World {
        let kind = SceneKind::ALL[(k % SceneKind::ALL.len() as u64) as usize];
        let scene = generate(kind, Scene::BUILT_IN_LINES, seed.wrapping_add(k));
        // One thread: a thousand lines step in well under a frame.
        let config = DetectorConfig {
            threads: 1,
            ..DetectorConfig::default()
        };
        World::with_config(&scene, DetectorKind::Sweep, &config)
            .unwrap_or_else(|_| World::with_detector(&scene, DetectorKind::Sweep))
    }

    /// One step, or the next scene when this one has had its time or has
    /// died out.
    fn advance(&mut self) {
        let dead = self.world.steps() % 60 == 0 && self.world.died_out();
        if dead || self.started.elapsed() >= CYCLE {
            self.shown += 1;
            self.world = Self::scene(self.shown, self.seed);
            self.started = Instant::now();
        } else {
            self.world.step();
        }
    }
}

/// Full screen (`/s`).
struct Saver {
    window: Option<Rc<Window>>,
    surface: Option<softbuffer::Surface<Rc<Window>, Rc<Window>>>,
    /// The picture, drawn here and copied to the window.
    frame: Vec<u32>,
    scenes: Scenes,
    /// Where the mouse was on the screen when the screen saver started.
    mouse_at: Option<(i32, i32)>,
    next_frame: Instant,
    failure: Option<String>,
}

impl Saver {
    fn fail(&mut self, event_loop: &ActiveEventLoop, message: String) {
        self.failure = Some(message);
        event_loop.exit();
    }

    fn attributes(event_loop: &ActiveEventLoop) -> winit::window::WindowAttributes {
        let monitor = event_loop
            .primary_monitor()
            .or_else(|| event_loop.available_monitors().next());
        let mut attributes = Window::default_attributes()
            .with_title("screensaver")
            .with_decorations(false)
            .with_resizable(false)
            .with_window_level(WindowLevel::AlwaysOnTop)
            .with_fullscreen(Some(Fullscreen::Borderless(monitor.clone())));
        if let Some(monitor) = &monitor {
            attributes = attributes
                .with_inner_size(monitor.size())
                .with_position(monitor.position());
        }
        attributes
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let (Some(window), Some(surface)) = (&self.window, &mut self.surface) else {
            return;
        };
        let size = window.inner_size();
        if let Err(message) = show(surface, &mut self.frame, &self.scenes.world, size) {
            self.fail(event_loop, message);
        }
    }
}

impl ApplicationHandler for Saver {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let window = match event_loop.create_window(Self::attributes(event_loop)) {
            Ok(window) => Rc::new(window),
            Err(e) => return self.fail(event_loop, format!("cannot open a window: {e}")),
        };
        window.set_cursor_visible(false);
        self.mouse_at = cursor();
        let surface = softbuffer::Context::new(Rc::clone(&window))
            .and_then(|context| softbuffer::Surface::new(&context, Rc::clone(&window)));
        match surface {
            Ok(surface) => self.surface = Some(surface),
            Err(e) => return self.fail(event_loop, format!("cannot draw in the window: {e}")),
        }
        self.window = Some(window);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => event_loop.exit(),
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            // Any key but a modifier alone: Wine presses Alt as the window
            // goes full screen, and a modifier is how a window switch
            // starts, not someone wanting the screen back.
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed && !is_modifier(&event.logical_key) =>
            {
                event_loop.exit()
            }
            WindowEvent::MouseInput {
                state: ElementState::Pressed,
                ..
            }
            | WindowEvent::MouseWheel { .. } => event_loop.exit(),
            // Compared on the screen, not in the window: the window's
            // own move to full screen moves the cursor within it.
            WindowEvent::CursorMoved { .. } => match (self.mouse_at, cursor()) {
                (Some((x0, y0)), Some((x, y)))
                    if (x - x0).abs() > MOUSE_SLACK || (y - y0).abs() > MOUSE_SLACK =>
                {
                    event_loop.exit()
                }
                _ => {}
            },
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let now = Instant::now();
        if now >= self.next_frame {
            self.scenes.advance();
            if let Some(window) = &self.window {
                window.request_redraw();
            }
            self.next_frame = now + Duration::from_secs_f64(1.0 / f64::from(FPS));
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(self.next_frame));
    }
}
