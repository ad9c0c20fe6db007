//! Stopping a run cleanly on SIGINT or SIGTERM: the first signal asks the
//! run to stop at the end of the current step (so that its results are
//! printed and its files written whole); a second one ends the process at
//! once, removing the temporary files of outputs being written.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

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
    pub fn end_process(self) -> ! {
        // Failing that, the status a shell would report.
        let _ = signal_hook::low_level::emulate_default_handler(self.number());
        std::process::exit(i32::from(self.exit_status()))
    }

    fn number(self) -> i32 {
        match self {
            Signal::Interrupt => signal_hook::consts::SIGINT,
            Signal::Terminate => signal_hook::consts::SIGTERM,
        }
    }

    /// The signal of this number (SIGTERM's, or else SIGINT: the only two
    /// the handlers take).
    fn from_number(number: i32) -> Signal {
        if number == signal_hook::consts::SIGTERM {
            Signal::Terminate
        } else {
            Signal::Interrupt
        }
    }
}

/// The number of the first signal received (0 for none).
static RECEIVED: AtomicUsize = AtomicUsize::new(0);

/// Whether the handlers are installed.
static INSTALLED: Mutex<bool> = Mutex::new(false);

impl Signal {
    /// Catches SIGINT and SIGTERM from now on (later calls do nothing):
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
fn install() -> std::io::Result<()> {
    let mut installed = INSTALLED.lock().unwrap_or_else(|e| e.into_inner());
    if *installed {
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
                    Signal::from_number(number).end_process();
                }
            }
        })?;
    *installed = true;
    Ok(())
}

/// The signal that asked the run to stop, if one has.
pub fn requested() -> Option<Signal> {
    match RECEIVED.load(Ordering::Relaxed) as i32 {
        0 => None,
        n => Some(Signal::from_number(n)),
    }
}
