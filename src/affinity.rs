//! Keeping each thread of a team on a core of its own, where the team has
//! every core the process may use.
//!
//! Left to the scheduler, the two threads of a two-thread team on a
//! two-core machine sometimes share one core for a while (in 0 to 10% of
//! `koch`'s hand-offs, run to run), and each hand-off then waits for the
//! other thread to be switched in. Tied to cores of their own, they ran
//! `koch` 1.047x faster on two threads (see `docs/DESIGN.md`, "The thread
//! team"). A team with fewer threads than the process has cores is not
//! tied: other work (another world, another program) may want the rest,
//! and the scheduler knows about it where this module does not.
//!
//! Only on Linux; elsewhere nothing is tied.

/// The cores the calling thread may run on, in increasing order; `None`
/// where that cannot be told.
pub(crate) fn allowed() -> Option<Vec<usize>> {
    imp::allowed()
}

/// Ties the calling thread to core `core`; whether that took.
pub(crate) fn tie(core: usize) -> bool {
    imp::tie(core)
}

/// The calling thread tied to one core until this is dropped, when it
/// gets back the cores it had.
#[must_use = "the thread is untied when this is dropped"]
pub(crate) struct Tied {
    before: imp::Set,
}

impl Tied {
    /// Ties the calling thread to `core` for the life of the result;
    /// `None` (and nothing changed) where that cannot be done.
    pub(crate) fn to(core: usize) -> Option<Tied> {
        let before = imp::current()?;
        imp::tie(core).then_some(Tied { before })
    }
}

impl Drop for Tied {
    fn drop(&mut self) {
        imp::set(&self.before);
    }
}

#[cfg(target_os = "linux")]
mod imp {
    use nix::sched::{sched_getaffinity, sched_setaffinity, CpuSet};
    use nix::unistd::Pid;

    pub(super) type Set = CpuSet;

    /// The calling thread (pid 0 names it).
    fn me() -> Pid {
        Pid::from_raw(0)
    }

    pub(super) fn current() -> Option<Set> {
        sched_getaffinity(me()).ok()
    }

    pub(super) fn allowed() -> Option<Vec<usize>> {
        let set = current()?;
        Some(
            (0..CpuSet::count())
                .filter(|&k| set.is_set(k).unwrap_or(false))
                .collect(),
        )
    }

    pub(super) fn tie(core: usize) -> bool {
        let mut set = CpuSet::new();
        set.set(core).is_ok() && sched_setaffinity(me(), &set).is_ok()
    }

    pub(super) fn set(set: &Set) {
        // Nothing to be done if it fails: the thread keeps the one core.
        let _ = sched_setaffinity(me(), set);
    }
}

#[cfg(not(target_os = "linux"))]
mod imp {
    pub(super) type Set = ();

    pub(super) fn current() -> Option<Set> {
        None
    }

    pub(super) fn allowed() -> Option<Vec<usize>> {
        None
    }

    pub(super) fn tie(_core: usize) -> bool {
        false
    }

    pub(super) fn set(_set: &Set) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thread_tied_for_a_while_gets_its_cores_back() {
        std::thread::spawn(|| {
            let Some(cores) = allowed() else {
                return;
            };
            assert!(!cores.is_empty());
            let last = *cores.last().expect("a core");
            {
                let _tied = Tied::to(last).expect("a core this thread may use");
                assert_eq!(allowed(), Some(vec![last]));
            }
            assert_eq!(allowed(), Some(cores));
        })
        .join()
        .expect("the thread");
    }
}
