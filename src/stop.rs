//! Stopping a run cleanly on SIGINT, SIGTERM or SIGHUP (the terminal
//! closed): the first signal asks the
//! run to stop at the end of the current step (so that its results are
//! printed and its files written whole); a second one ends the process at
//! once, removing the temporary files of outputs being written.
//!
//! On Windows the same holds for the console's events: Ctrl-C and
//! Ctrl-Break are [`Signal::Interrupt`], the console closing (and logoff
//! and shutdown) [`Signal::Terminate`] (the `windows` module below).

use std::sync::atomic::{AtomicUsize, Ordering};
#[cfg(unix)]
use std::sync::Mutex;

/// The signals that stop a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Ctrl-C.
    Interrupt,
    /// What `kill` and screen-saver daemons send.
    Terminate,
    /// The terminal the run was started from closed.
    Hangup,
}

impl Signal {
    /// The signal's name.
    pub fn name(self) -> &'static str {
        match self {
            Signal::Interrupt => "SIGINT",
            Signal::Terminate => "SIGTERM",
            Signal::Hangup => "SIGHUP",
        }
    }

    /// The exit status of a process that stopped on this signal (128 plus
    /// the signal's number, as shells report it).
    #[cfg(unix)]
    pub fn exit_status(self) -> u8 {
        128 + self.number() as u8
    }

    /// The signal that has asked the program to stop, if one has (since
    /// [`Signal::catch`]).
    pub fn requested() -> Option<Signal> {
        requested()
    }

    /// Ends the process by this signal itself, its default action
    /// restored: a parent (a shell, a screen-saver daemon) sees a death by
    /// the signal, as if it had never been caught, and a shell reports
    /// [`Signal::exit_status`]. For the end of a run the signal stopped,
    /// once its results are out.
    #[cfg(unix)]
    pub fn end_process(self) -> ! {
        // Failing that, the status a shell would report.
        let _ = signal_hook::low_level::emulate_default_handler(self.number());
        std::process::exit(i32::from(self.exit_status()))
    }

    #[cfg(unix)]
    fn number(self) -> i32 {
        match self {
            Signal::Interrupt => signal_hook::consts::SIGINT,
            Signal::Terminate => signal_hook::consts::SIGTERM,
            Signal::Hangup => signal_hook::consts::SIGHUP,
        }
    }

    /// The signal of this number (SIGTERM's, SIGHUP's, or else SIGINT:
    /// the only three the handlers take).
    #[cfg(unix)]
    fn from_number(number: i32) -> Signal {
        match number {
            signal_hook::consts::SIGTERM => Signal::Terminate,
            signal_hook::consts::SIGHUP => Signal::Hangup,
            _ => Signal::Interrupt,
        }
    }
}

/// The number of the first signal received (0 for none; on Windows,
/// 1 + the [`Signal`]'s index).
static RECEIVED: AtomicUsize = AtomicUsize::new(0);

/// Whether the handlers are installed.
#[cfg(unix)]
static INSTALLED: Mutex<bool> = Mutex::new(false);

impl Signal {
    /// Catches SIGINT, SIGTERM and SIGHUP from now on (later calls do nothing):
    /// a run stops cleanly after the step under way, and a second signal
    /// ends the process at once, removing the temporary files of outputs
    /// being written. Until it is called, signals end the process as they
    /// do by default.
    pub fn catch() -> std::io::Result<()> {
        install()
    }
}

/// Installs the handlers (once; later calls do nothing).
///
/// The signals are taken by a thread of their own, not in a handler, so
/// that a second one can remove the temporary files of outputs being
/// written ([`crate::output::remove_temporaries`]) before the process
/// ends with the usual status.
#[cfg(unix)]
fn install() -> std::io::Result<()> {
    let mut installed = INSTALLED.lock().unwrap_or_else(|e| e.into_inner());
    if *installed {
        return Ok(());
    }
    // A signal the program was started ignoring stays ignored: `nohup`
    // ignores SIGHUP, a shell script's background jobs SIGINT, and a run
    // started so must go on when the terminal closes.
    let ignored = ignored_at_start();
    let numbers = [Signal::Interrupt, Signal::Terminate, Signal::Hangup]
        .map(Signal::number)
        .into_iter()
        .filter(|&n| !ignored(n));
    let mut signals = signal_hook::iterator::Signals::new(numbers)?;
    std::thread::Builder::new()
        .name("signals".to_string())
        .spawn(move || {
            for number in signals.forever() {
                // A second signal ends the process, so the number kept is
                // the first one's.
                if RECEIVED
                    .compare_exchange(0, number as usize, Ordering::Relaxed, Ordering::Relaxed)
                    .is_err()
                {
                    crate::output::remove_temporaries();
                    Signal::from_number(number).end_process();
                }
            }
        })?;
    *installed = true;
    Ok(())
}

/// Which signals the process was started ignoring. Linux says in
/// `/proc/self/status` (`SigIgn`, a bit for each signal); elsewhere the
/// disposition cannot be read without `unsafe`, so SIGHUP is taken as
/// ignored (left to its default) and the others as not.
#[cfg(unix)]
fn ignored_at_start() -> impl Fn(i32) -> bool {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let mask = status
        .lines()
        .find_map(|l| l.strip_prefix("SigIgn:"))
        .and_then(|hex| u64::from_str_radix(hex.trim(), 16).ok());
    move |number: i32| match mask {
        Some(mask) => (1..=64).contains(&number) && mask & (1 << (number - 1)) != 0,
        None => number == signal_hook::consts::SIGHUP,
    }
}

/// The signal that asked the run to stop, if one has.
#[cfg(unix)]
pub fn requested() -> Option<Signal> {
    match RECEIVED.load(Ordering::Relaxed) as i32 {
        0 => None,
        n => Some(Signal::from_number(n)),
    }
}

/// Windows has no SIGINT or SIGTERM to catch: its console calls a handler
/// routine, on a thread of its own, for Ctrl-C, Ctrl-Break, the console
/// window closing, logoff and shutdown. `ctrlc` wraps the same routine
/// with no `unsafe` of ours, but its routine returns at once without
/// saying which event came, and for a console close Windows ends the
/// process as soon as the routine returns: the results block and the
/// files would race the end. This routine waits instead (Windows allows a
/// few seconds) until the run, stopped after its step, ends the process.
#[cfg(windows)]
mod windows {
    use super::{Ordering, Signal, RECEIVED};
    use windows_sys::core::BOOL;
    use windows_sys::Win32::Foundation::TRUE;
    use windows_sys::Win32::System::Console::{
        SetConsoleCtrlHandler, CTRL_BREAK_EVENT, CTRL_C_EVENT,
    };

    /// What a process ended by a console event reports when nothing
    /// handles the event (Windows' default routine exits with it): a
    /// parent (`cmd`, PowerShell) sees the same end as if the event had
    /// not been caught.
    const STATUS_CONTROL_C_EXIT: u32 = 0xC000_013A;

    impl Signal {
        /// Ends the process as Windows' own handling of the console event
        /// would have, with `STATUS_CONTROL_C_EXIT`. For the end of a run
        /// the event stopped, once its results are out.
        pub fn end_process(self) -> ! {
            std::process::exit(STATUS_CONTROL_C_EXIT as i32)
        }

        /// What [`RECEIVED`] holds for this signal (0 is none).
        fn code(self) -> usize {
            match self {
                Signal::Interrupt => 1,
                // No terminal sends Windows a hangup; kept for the match.
                Signal::Terminate | Signal::Hangup => 2,
            }
        }
    }

    unsafe extern "system" fn routine(event: u32) -> BOOL {
        let signal = match event {
            CTRL_C_EVENT | CTRL_BREAK_EVENT => Signal::Interrupt,
            // The console closing, logoff, shutdown.
            _ => Signal::Terminate,
        };
        if RECEIVED
            .compare_exchange(0, signal.code(), Ordering::Relaxed, Ordering::Relaxed)
            .is_err()
        {
            crate::output::remove_temporaries();
            signal.end_process();
        }
        if signal == Signal::Terminate {
            // Returning would let Windows end the process now; the run
            // ends it once its results are out (or Windows does, when its
            // grace period runs out).
            loop {
                std::thread::park();
            }
        }
        TRUE
    }

    /// Installs the routine. Registering it twice would call it twice per
    /// event, so later calls do nothing.
    pub(super) fn install() -> std::io::Result<()> {
        static INSTALLED: std::sync::Once = std::sync::Once::new();
        let mut result = Ok(());
        INSTALLED.call_once(|| {
            // SAFETY: `routine` is a handler routine as the console
            // expects it (`extern "system"`, one u32 in, a BOOL out) that
            // lives as long as the program.
            if unsafe { SetConsoleCtrlHandler(Some(routine), TRUE) } == 0 {
                result = Err(std::io::Error::last_os_error());
            }
        });
        result
    }

    /// The event that asked the run to stop, if one has.
    pub fn requested() -> Option<Signal> {
        match RECEIVED.load(Ordering::Relaxed) {
            0 => None,
            1 => Some(Signal::Interrupt),
            _ => Some(Signal::Terminate),
        }
    }
}

#[cfg(windows)]
use windows::install;
#[cfg(windows)]
pub use windows::requested;
