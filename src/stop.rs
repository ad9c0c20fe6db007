//! Stopping a run cleanly on SIGINT or SIGTERM: the first signal asks the
//! run to stop at the end of the current step (so that its results are
//! printed and its files written whole); a second one ends the process at
//! once.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

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

/// The flags the handlers set.
struct Flags {
    /// Set by the first signal: a second one ends the process.
    stopping: Arc<AtomicBool>,
    /// The number of the first signal received (0 for none).
    received: Arc<AtomicUsize>,
}

static FLAGS: OnceLock<Flags> = OnceLock::new();

/// Installs the handlers (once; later calls do nothing). Until it is
/// called, signals end the process as they do by default.
pub fn install() -> std::io::Result<()> {
    if FLAGS.get().is_some() {
        return Ok(());
    }
    let flags = Flags {
        stopping: Arc::new(AtomicBool::new(false)),
        received: Arc::new(AtomicUsize::new(0)),
    };
    for signal in [Signal::Interrupt, Signal::Terminate] {
        let number = signal.number();
        // Registered first, so it sees the flag as the previous signal
        // left it: a second signal exits with the usual status.
        signal_hook::flag::register_conditional_shutdown(
            number,
            i32::from(signal.exit_status()),
            Arc::clone(&flags.stopping),
        )?;
        signal_hook::flag::register(number, Arc::clone(&flags.stopping))?;
        // A second signal ends the process, so the number kept is the
        // first one's.
        signal_hook::flag::register_usize(number, Arc::clone(&flags.received), number as usize)?;
    }
    let _ = FLAGS.set(flags);
    Ok(())
}

/// The signal that asked the run to stop, if one has.
pub fn requested() -> Option<Signal> {
    let flags = FLAGS.get()?;
    match flags.received.load(Ordering::Relaxed) as i32 {
        0 => None,
        n if n == signal_hook::consts::SIGTERM => Some(Signal::Terminate),
        _ => Some(Signal::Interrupt),
    }
}
