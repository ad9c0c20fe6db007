//! Stopping a run cleanly on SIGINT or SIGTERM: the first signal asks the
//! run to stop at the end of the current step (so that its results are
//! printed and its files written whole); a second one ends the process at
//! once, removing the temporary files of outputs being written.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// The signals that stop a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Ctrl-C.
    Interrupt,
    /// What `kill` and screen-saver daemons send.
    Terminate,
}

impl Signal {
    /// The signal's name.
    pub fn name(self) -> &'static str {
        match self {
            Signal::Interrupt => "SIGINT",
            Signal::Terminate => "SIGTERM",
        }
    }

    /// The exit status of a process that stopped on this signal (128 plus
    /// the signal's number, as shells report it).
    pub fn exit_status(self) -> u8 {
        128 + self.number() as u8
    }

    fn number(self) -> i32 {
        match self {
            Signal::Interrupt => signal_hook::consts::SIGINT,
            Signal::Terminate => signal_hook::consts::SIGTERM,
        }
    }
}

/// The number of the first signal received (0 for none).
static RECEIVED: AtomicUsize = AtomicUsize::new(0);

/// Whether the handlers are installed.
static INSTALLED: OnceLock<()> = OnceLock::new();

/// Installs the handlers (once; later calls do nothing). Until it is
/// called, signals end the process as they do by default.
///
/// The signals are taken by a thread of their own, not in a handler, so
/// that a second one can remove the temporary files of outputs being
/// written ([`crate::output::remove_temporaries`]) before the process
/// ends with the usual status.
pub fn install() -> std::io::Result<()> {
    if INSTALLED.get().is_some() {
        return Ok(());
    }
    let numbers = [Signal::Interrupt, Signal::Terminate].map(Signal::number);
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
                    std::process::exit(128 + number);
                }
            }
        })?;
    let _ = INSTALLED.set(());
    Ok(())
}

/// The signal that asked the run to stop, if one has.
pub fn requested() -> Option<Signal> {
    match RECEIVED.load(Ordering::Relaxed) as i32 {
        0 => None,
        n if n == signal_hook::consts::SIGTERM => Some(Signal::Terminate),
        _ => Some(Signal::Interrupt),
    }
}
