//! `screensaver.scr`: the Windows screen saver. Windows starts a screen
//! saver with `/s` (full screen until input), `/p HWND` (the preview in
//! the control panel's little screen) or `/c` (settings); see `args.rs`.
//! It shows generated scenes of the default size, each kind in turn, a new
//! one every minute or as soon as one has died out, one step a frame: the
//! original's pace, as `screensaver --fullscreen` shows them.
//!
//! Built for Windows by `scripts/cross.sh windows` (feature `scr`), which
//! renames it `screensaver.scr`. The arguments are read the same way on
//! every system (and tested on every system, by `tests/scr_args.rs`); the
//! screen saver itself exists only on Windows.

// A screen saver has no console window of its own (one would flash up
// behind it); Wine and a console that starts it still get its stderr.
#![windows_subsystem = "windows"]

mod args;
#[cfg(windows)]
mod saver;

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = match args::parse(&args) {
        Ok(mode) => mode,
        Err(message) => {
            eprintln!("screensaver.scr: {message}");
            return ExitCode::from(2);
        }
    };
    run(mode)
}

#[cfg(windows)]
fn run(mode: args::Mode) -> ExitCode {
    match saver::run(mode) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("screensaver.scr: {message}");
            // Windows starts a screen saver without a console: full
            // screen, the user is there to be told. A preview that fails
            // (its window gone) has no one to tell, and a message box
            // would keep it from ending.
            if mode == args::Mode::Saver {
                saver::show_error(&message);
            }
            ExitCode::FAILURE
        }
    }
}

/// Elsewhere the screen saver is the main program's own screen modes.
#[cfg(not(windows))]
fn run(_: args::Mode) -> ExitCode {
    eprintln!(
        "screensaver.scr is the Windows screen saver; here, run `screensaver --fullscreen`, \
         or `screensaver` under XScreenSaver"
    );
    ExitCode::from(2)
}
