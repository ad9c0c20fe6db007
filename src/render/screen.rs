//! Runs shown on screen: in a window of our own, on the root window, or in
//! a window another program owns (XScreenSaver's). [`Screen::show`] runs
//! [`Scenes`] there until they end, the window goes or a signal stops the
//! run; [`Screen::check`] says beforehand whether it can.

use super::live::{Outcome, Pace, Scenes};
use super::{embedded, window};

/// Where a run is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Screen {
    /// A window of our own, filling the screen if asked.
    Window {
        /// Fill the screen, the box stretched over it.
        fullscreen: bool,
    },
    /// The root window (the desktop).
    Root,
    /// A window another program owns, by its X id (XScreenSaver names
    /// its window in `XSCREENSAVER_WINDOW`).
    WindowId(u32),
}

/// How a run on screen goes.
#[derive(Clone, Copy, Debug)]
pub struct ShowOptions {
    /// Most frames drawn a second.
    pub fps: u32,
    /// Our own window: keep the last picture until the window is closed.
    pub hold: bool,
    /// Show the heads-up display from the start.
    pub hud: bool,
    /// How fast the run goes (`+` and `-` change it in our own window).
    pub pace: Pace,
}

impl Default for ShowOptions {
    /// Sixty frames a second, a step a frame, no display of figures.
    fn default() -> ShowOptions {
        ShowOptions {
            fps: 60,
            hold: false,
            hud: false,
            pace: Pace::PerFrame,
        }
    }
}

/// Why a run cannot be shown, or stopped being shown.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ScreenError {
    /// No display is named (`DISPLAY` is not set).
    #[error(
        "cannot open a window: no display (DISPLAY is not set); \
         run under xvfb-run for a virtual one"
    )]
    NoDisplay,
    /// The display named does not answer.
    #[error(
        "cannot open a window: cannot connect to the X display `{display}` \
         (is an X server running there, and may this user connect to it?)"
    )]
    Unreachable {
        /// The display's name (`DISPLAY`).
        display: String,
    },
    /// No window has this id.
    #[error("there is no window 0x{0:x} on this display")]
    NoWindow(u32),
    /// The window's pixels are not 24-bit true colour.
    #[error("window 0x{window:x}: cannot draw in a window of depth {depth} that is not 24-bit true colour")]
    NotTrueColour {
        /// The window.
        window: u32,
        /// Its depth.
        depth: u8,
    },
    /// Text that is not a window id.
    #[error(
        "{}`{text}` is not a window id (write it as 0x1a00003 or as a decimal number)",
        variable.map(|v| format!("{v}: ")).unwrap_or_default()
    )]
    BadWindowId {
        /// The text.
        text: String,
        /// The environment variable it came from, if any.
        variable: Option<&'static str>,
    },
    /// The display or the window failed while the run was shown (in the
    /// words of the windowing system).
    #[error("{0}")]
    Failed(String),
    /// The simulation's thread panicked.
    #[error("the simulation thread panicked")]
    Panicked,
}

impl Screen {
    /// The window XScreenSaver names in `XSCREENSAVER_WINDOW`, if it is
    /// set.
    pub fn from_environment() -> Option<Result<Screen, ScreenError>> {
        embedded::screensaver_window().map(|id| id.map(Screen::WindowId))
    }

    /// Reads a window id written as XScreenSaver and `xwininfo` write
    /// them: hexadecimal after `0x`, else decimal.
    ///
    /// ```
    /// use screensaver::render::Screen;
    ///
    /// assert_eq!(Screen::parse_window_id("0x1a00003"), Ok(0x1a0_0003));
    /// assert_eq!(Screen::parse_window_id("42"), Ok(42));
    /// assert!(Screen::parse_window_id("root").is_err());
    /// ```
    pub fn parse_window_id(s: &str) -> Result<u32, ScreenError> {
        embedded::parse_window_id(s)
    }

    /// Fails, saying why, when a run cannot be shown here: no display, a
    /// display that does not answer, no such window, or one whose pixels
    /// are not 24-bit true colour. The connection it made stays open, so
    /// that a virtual display with no other client does not reset before
    /// the run connects.
    pub fn check(self) -> Result<(), ScreenError> {
        match self {
            Screen::Window { .. } => window::check_display(),
            Screen::Root => embedded::check(embedded::Target::Root),
            Screen::WindowId(id) => embedded::check(embedded::Target::Id(id)),
        }
    }

    /// Shows `scenes` here until they end, the window goes (or is closed)
    /// or a signal stops the run; the outcome holds the world on show
    /// then.
    pub fn show(self, scenes: Scenes, options: ShowOptions) -> Result<Outcome, ScreenError> {
        match self {
            Screen::Window { fullscreen } => window::run(scenes, options, fullscreen),
            Screen::Root => embedded::run(embedded::Target::Root, scenes, options),
            Screen::WindowId(id) => embedded::run(embedded::Target::Id(id), scenes, options),
        }
    }
}
