//! A small team of threads for the phases of a step: each phase is handed
//! to every member at once, and the hand-off costs well under a
//! microsecond while the members are awake.
//!
//! A step of a course scene takes about a hundred microseconds in a few
//! phases; waking a pooled worker through the operating system for each
//! phase costs a good part of what sharing the phase saves. The members
//! here wait for work by spinning on an atomic counter for a while, so a
//! phase handed to them soon after the last one starts at once; a member
//! that has waited longer than `SPIN` (200 us) parks, and then uses no CPU until
//! it is woken (between runs, while a window is paused, after the run).
//!
//! This is the one module with `unsafe` code: a member runs a job that
//! borrows from the caller's stack frame, which the type system cannot see
//! outlive the call. [`Team::run`] does not return before every member has
//! finished with the job, which is what makes the borrow sound.

use crate::affinity::{self, Tied};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Grains of work up to which the step shares a phase among its team rather
/// than on rayon's pool: 4,194,304 boxes or lines at the default grain.
/// The team's fixed shares and spinning hand-offs did as well as the
/// pool's or better at every size measured (two threads, medians of
/// interleaved rounds, and the median of each round's ratio): 100,000
/// lines 100 frames 0.344 s against 0.420 (1.08x), 300,000 lines 1.231
/// against 1.266 (1.01x), a million 50 frames 3.09 against 3.08 (1.08x by
/// rounds), two million 20 frames 2.49 against 2.61 (1.04x). With a grain
/// of a few lines (as in tests) every phase goes to the pool.
pub const TEAM_GRAINS: usize = 256;

/// Whether `work` boxes or lines of a phase go to the team: from `least`
/// (below, one thread does better) up to [`TEAM_GRAINS`] grains of
/// `grain` (from there, rayon's pool).
pub(crate) fn takes(work: usize, least: usize, grain: usize) -> bool {
    (least..TEAM_GRAINS.saturating_mul(grain)).contains(&work)
}

/// How long an idle member spins before it parks.
const SPIN: Duration = Duration::from_micros(200);

/// A member that starts its part of a job later than this after the job
/// is handed out counts as late ([`HandOffs::late`]).
const LATE: Duration = Duration::from_micros(10);

/// What a team's hand-offs cost, summed over the jobs timed
/// ([`Team::set_timing`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HandOffs {
    /// Jobs timed.
    pub jobs: u64,
    /// From each job's hand-out until its last member started its part.
    pub start: Duration,
    /// Jobs whose last member started more than 10 us after the hand-out.
    pub late: u64,
    /// The caller's wait, its own part done, for the members to finish.
    pub wait: Duration,
    /// The caller's own parts of the jobs.
    pub caller_parts: Duration,
    /// Of each job, the longest part a member took.
    pub longest_member_parts: Duration,
}

/// A job: called once with each member's number, `0..threads`.
type Job<'a> = dyn Fn(usize) + Sync + 'a;

/// What the caller and the members share.
struct Shared {
    /// Bumped once for every job; a member runs a job when it sees the
    /// counter move.
    epoch: AtomicU64,
    /// The current job: a pointer to a `&Job` on the stack of the caller
    /// of [`Team::run`], valid from the bump of `epoch` until `done`
    /// reaches the number of members.
    job: AtomicUsize,
    /// Members finished with the current job.
    done: AtomicUsize,
    /// Members parked (or about to park), who must be woken.
    parked: AtomicUsize,
    /// Bumped by [`Team::wake`]: a member woken sees it move, and spins
    /// for a while before it parks again.
    wakes: AtomicU64,
    /// Set when the team is dropped.
    quit: AtomicBool,
    /// Set when a member's part of the current job panicked.
    panicked: AtomicBool,
    /// The members' threads, to wake them.
    threads: Mutex<Vec<std::thread::Thread>>,
    /// Set while a job runs: jobs never overlap.
    busy: AtomicBool,
    /// Whether jobs are timed ([`Team::set_timing`]).
    timing: AtomicBool,
    /// When the team was made: the members' start times count from it.
    born: Instant,
    /// While jobs are timed, when each member started its part of the
    /// current job, in nanoseconds from `born` (member `k` at `k - 1`).
    started: Vec<AtomicU64>,
    /// How long each thread's part of the last timed job took, in
    /// nanoseconds (the caller's at 0): written before the thread counts
    /// itself done.
    parts: Vec<AtomicU64>,
    /// Whether the current job's parts are timed (set before its epoch is
    /// bumped): by [`Team::run_timed`], or for every job while the
    /// hand-offs are timed.
    time_parts: AtomicBool,
}

/// A team of `threads` threads: the caller of [`Team::run`] and
/// `threads - 1` members of its own, alive as long as the team.
pub struct Team {
    shared: Arc<Shared>,
    members: Vec<JoinHandle<()>>,
    /// The hand-offs timed so far ([`Team::set_timing`]).
    hand_offs: Mutex<HandOffs>,
    /// The core the caller is tied to while [`Team::tie_caller`]'s guard
    /// lives, when the team has every core the process may use: member
    /// `k` is tied to the `k`-th of those cores, the caller to the first
    /// (see [`crate::affinity`]).
    caller_core: Option<usize>,
}

impl std::fmt::Debug for Team {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Team({} threads)", self.threads())
    }
}

impl Team {
    /// A team of `threads` threads in all (at least 1; with 1, jobs run on
    /// the caller alone).
    pub fn new(threads: usize) -> std::io::Result<Team> {
        let shared = Arc::new(Shared {
            epoch: AtomicU64::new(0),
            job: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            parked: AtomicUsize::new(0),
            wakes: AtomicU64::new(0),
            quit: AtomicBool::new(false),
            panicked: AtomicBool::new(false),
            threads: Mutex::new(Vec::new()),
            busy: AtomicBool::new(false),
            timing: AtomicBool::new(false),
            born: Instant::now(),
            started: (1..threads.max(1)).map(|_| AtomicU64::new(0)).collect(),
            parts: (0..threads.max(1)).map(|_| AtomicU64::new(0)).collect(),
            time_parts: AtomicBool::new(false),
        });
        // A core for each thread where the team has them all.
        let cores = affinity::allowed().filter(|cores| threads > 1 && cores.len() == threads);
        let mut members = Vec::new();
        for k in 1..threads.max(1) {
            let mine = Arc::clone(&shared);
            let core = cores.as_ref().map(|cores| cores[k]);
            let handle = std::thread::Builder::new()
                .name(format!("screensaver-team-{k}"))
                .spawn(move || {
                    if let Some(core) = core {
                        affinity::tie(core);
                    }
                    member(&mine, k)
                })?;
            shared
                .threads
                .lock()
                .expect("team lock")
                .push(handle.thread().clone());
            members.push(handle);
        }
        Ok(Team {
            shared,
            members,
            hand_offs: Mutex::default(),
            caller_core: cores.map(|cores| cores[0]),
        })
    }

    /// Ties the calling thread to a core of its own, away from the
    /// members', until the result is dropped, when the thread gets back
    /// the cores it had; `None` (nothing tied) where the team's threads
    /// are not tied (see [`crate::affinity`]). For a run of many steps:
    /// tying and untying take two system calls.
    pub(crate) fn tie_caller(&self) -> Option<Tied> {
        Tied::to(self.caller_core?)
    }

    /// Wakes the parked members, so that the first job of a run finds them
    /// spinning: a member woken by a job started on `koch` 100 us after
    /// the caller, a member already awake within a microsecond.
    pub fn wake(&self) {
        self.shared.wakes.fetch_add(1, Ordering::Relaxed);
        if self.shared.parked.load(Ordering::SeqCst) > 0 {
            for t in self.shared.threads.lock().expect("team lock").iter() {
                t.unpark();
            }
        }
    }

    /// Threads in the team, the caller's included.
    pub fn threads(&self) -> usize {
        self.members.len() + 1
    }

    /// Runs `job(k)` for every `k` in `0..threads()` at once, `k = 0` on
    /// the calling thread, and returns when all have finished. A panic in
    /// any part is raised here once all have finished.
    pub fn run(&self, job: &Job<'_>) {
        self.run_job(job, false);
    }

    /// [`Team::run`], each thread timing its part for
    /// [`Team::last_parts`] (two clock reads a thread: the other jobs of a
    /// step skip them).
    pub fn run_timed(&self, job: &Job<'_>) {
        self.run_job(job, true);
    }

    fn run_job(&self, job: &Job<'_>, time_parts: bool) {
        let members = self.members.len();
        if members == 0 {
            job(0);
            return;
        }
        let s = &*self.shared;
        let timing = s.timing.load(Ordering::Relaxed);
        let handed_out = timing.then(Instant::now);
        let time_parts = time_parts || timing;
        let was_busy = s.busy.swap(true, Ordering::Acquire);
        assert!(!was_busy, "a team runs one job at a time");
        s.done.store(0, Ordering::Relaxed);
        s.panicked.store(false, Ordering::Relaxed);
        let erased: &Job<'_> = job;
        s.job
            .store(&erased as *const &Job<'_> as usize, Ordering::Relaxed);
        s.time_parts.store(time_parts, Ordering::Relaxed);
        // A member that sees the new epoch sees the job too (the store
        // above comes before this bump). SeqCst, with the load of `parked`
        // below and a member's announcement and second look at the epoch,
        // ensures that either the member sees this epoch or this thread
        // sees the member parked (and wakes it).
        s.epoch.fetch_add(1, Ordering::SeqCst);
        if s.parked.load(Ordering::SeqCst) > 0 {
            for t in s.threads.lock().expect("team lock").iter() {
                t.unpark();
            }
        }
        let mine = timed(time_parts.then_some(&s.parts[0]), || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(0)))
        });
        let mine_done = handed_out.map(|_| Instant::now());
        // The job (and `erased`, which points to it) must outlive every
        // member's use of it: wait for all of them before returning.
        let mut spins = 0u32;
        while s.done.load(Ordering::Acquire) < members {
            spins = spins.wrapping_add(1);
            if spins % 64 == 0 {
                // A member may be waiting for this very core.
                std::thread::yield_now();
            } else {
                std::hint::spin_loop();
            }
        }
        if let (Some(handed_out), Some(mine_done)) = (handed_out, mine_done) {
            self.note_hand_off(handed_out, mine_done);
        }
        s.busy.store(false, Ordering::Release);
        if let Err(panic) = mine {
            std::panic::resume_unwind(panic);
        }
        if s.panicked.load(Ordering::Relaxed) {
            panic!("a team member's part of a job panicked");
        }
    }
}

/// Runs `part`, storing how long it took in `took` (nanoseconds), if
/// given.
fn timed<R>(took: Option<&AtomicU64>, part: impl FnOnce() -> R) -> R {
    let Some(took) = took else {
        return part();
    };
    let start = Instant::now();
    let outcome = part();
    let nanos = start.elapsed().as_nanos().try_into().unwrap_or(u64::MAX);
    took.store(nanos, Ordering::Relaxed);
    outcome
}

impl Team {
    /// How long each thread's part of the last timed job took (the
    /// caller's first, then member `k`'s at `k`; see [`Team::run_timed`]):
    /// for evening out the next job's shares where the threads run at
    /// different speeds.
    pub fn last_parts(&self) -> impl ExactSizeIterator<Item = Duration> + '_ {
        // Each member stored its time before counting itself done, which
        // `run` waited for (Acquire).
        (self.shared.parts.iter()).map(|t| Duration::from_nanos(t.load(Ordering::Relaxed)))
    }

    /// Turns the timing of the hand-offs on or off (off at first; it costs
    /// a few clock reads a job): see [`Team::hand_offs`].
    pub fn set_timing(&self, on: bool) {
        self.shared.timing.store(on, Ordering::Relaxed);
    }

    /// The hand-offs timed so far.
    pub fn hand_offs(&self) -> HandOffs {
        *self.hand_offs.lock().expect("the team's timing")
    }

    /// Adds one timed job: handed out at `handed_out`, the caller's part
    /// done at `mine_done`, every member's part done now (each member's
    /// start read after its `done`, which orders it).
    fn note_hand_off(&self, handed_out: Instant, mine_done: Instant) {
        let s = &*self.shared;
        let last_start = s
            .started
            .iter()
            .map(|t| s.born + Duration::from_nanos(t.load(Ordering::Relaxed)))
            .max()
            .map_or(Duration::ZERO, |t| t.saturating_duration_since(handed_out));
        let mut parts = self.last_parts();
        let caller = parts.next().unwrap_or_default();
        let longest = parts.max().unwrap_or_default();
        let mut h = self.hand_offs.lock().expect("the team's timing");
        h.jobs += 1;
        h.start += last_start;
        h.late += u64::from(last_start > LATE);
        h.wait += mine_done.elapsed();
        h.caller_parts += caller;
        h.longest_member_parts += longest;
    }

    /// [`Team::run`] of a job whose parts each count something: returns
    /// the sum of the counts (the same in any order).
    pub fn run_sum(&self, job: &(dyn Fn(usize) -> u64 + Sync)) -> u64 {
        let sum = AtomicU64::new(0);
        self.run(&|k| {
            sum.fetch_add(job(k), Ordering::Relaxed);
        });
        sum.into_inner()
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        self.shared.quit.store(true, Ordering::SeqCst);
        for t in self.shared.threads.lock().expect("team lock").iter() {
            t.unpark();
        }
        for m in self.members.drain(..) {
            let _ = m.join();
        }
    }
}

/// A member's life: wait for a job, run its part, say so; until the team
/// is dropped.
fn member(s: &Shared, k: usize) {
    let mut seen = 0;
    let mut woken = 0;
    loop {
        let mut started = Instant::now();
        let mut spins = 0u32;
        let epoch = loop {
            let epoch = s.epoch.load(Ordering::Acquire);
            if epoch != seen {
                break epoch;
            }
            if s.quit.load(Ordering::SeqCst) {
                return;
            }
            spins += 1;
            if spins % 64 != 0 {
                std::hint::spin_loop();
                continue;
            }
            if started.elapsed() < SPIN {
                // Let whatever else wants this core run (the caller, on a
                // busy machine), then look again.
                std::thread::yield_now();
                continue;
            }
            // Park, announcing it first so that the next job wakes us; the
            // epoch is read again after the announcement, so a job handed
            // out in between is not missed (SeqCst orders the two).
            s.parked.fetch_add(1, Ordering::SeqCst);
            if s.epoch.load(Ordering::SeqCst) == seen && !s.quit.load(Ordering::SeqCst) {
                std::thread::park_timeout(Duration::from_millis(100));
            }
            s.parked.fetch_sub(1, Ordering::SeqCst);
            let wakes = s.wakes.load(Ordering::Relaxed);
            if wakes != woken {
                // Woken for a run about to start: spin for it.
                (woken, started) = (wakes, Instant::now());
            }
        };
        // The proof below rests on jobs coming one at a time, each waited
        // for by `run`: a member never skips one.
        debug_assert_eq!(epoch, seen + 1, "member {k} missed a job");
        seen = epoch;
        let at = s.job.load(Ordering::Relaxed) as *const &Job<'static>;
        debug_assert!(!at.is_null());
        debug_assert!(s.busy.load(Ordering::Relaxed), "a job outside `run`");
        // SAFETY: `at` was stored by `Team::run` before it bumped `epoch`
        // (Release), and this thread read the bumped epoch (Acquire), so it
        // sees that store. It points to `erased`, a `&Job` on the stack of
        // that call of `run`, which does not return (so `erased` and the
        // job it refers to stay alive and unmoved) until `done` counts
        // every member, and this member adds itself to `done` only after
        // its last use of the job below. `run` calls never overlap (`busy`),
        // so `job` is not replaced meanwhile. The job is `Sync`, so calling
        // it from this thread while others call it is allowed. The lifetime
        // written here (`'static`) is never relied on: the reference does
        // not escape this iteration.
        let job: &Job<'static> = unsafe { *at };
        if s.timing.load(Ordering::Relaxed) {
            let since = s.born.elapsed().as_nanos().try_into().unwrap_or(u64::MAX);
            s.started[k - 1].store(since, Ordering::Relaxed);
        }
        // Stored before the epoch's bump, as the job was.
        let time_parts = s.time_parts.load(Ordering::Relaxed).then_some(&s.parts[k]);
        let part = timed(time_parts, || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(k)))
        });
        if part.is_err() {
            s.panicked.store(true, Ordering::Relaxed);
        }
        s.done.fetch_add(1, Ordering::Release);
    }
}

/// Splits `items` into `parts` contiguous shares of nearly equal length
/// (share `k` as [`share`] gives it), each behind its own lock so that a
/// job (`Fn`, shared by the members) can write its own: each lock is taken
/// once, by one member, and never waited for.
pub fn shares_mut<T>(items: &mut [T], parts: usize) -> Vec<Mutex<&mut [T]>> {
    let n = items.len();
    let mut rest = items;
    (0..parts.max(1))
        .map(|k| {
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(share(n, parts, k).len());
            rest = tail;
            Mutex::new(head)
        })
        .collect()
}

/// Splits `0..n` into `parts` contiguous ranges of nearly equal length;
/// part `k`'s range.
pub fn share(n: usize, parts: usize, k: usize) -> std::ops::Range<usize> {
    let parts = parts.max(1);
    (n * k / parts)..(n * (k + 1) / parts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summed_jobs_add_every_members_count() {
        for threads in [1, 2, 3, 8] {
            let team = Team::new(threads).unwrap();
            for round in 0..200u64 {
                let sum = team.run_sum(&|k| round * 10 + k as u64);
                let t = threads as u64;
                assert_eq!(sum, round * 10 * t + t * (t - 1) / 2);
            }
        }
    }

    #[test]
    fn every_member_runs_its_part_of_every_job() {
        for threads in [1, 2, 3, 8] {
            let team = Team::new(threads).unwrap();
            assert_eq!(team.threads(), threads);
            for round in 0..2000u64 {
                let seen: Vec<AtomicU64> = (0..threads).map(|_| AtomicU64::new(0)).collect();
                team.run(&|k| {
                    seen[k].fetch_add(round + 1, Ordering::Relaxed);
                });
                for s in &seen {
                    assert_eq!(s.load(Ordering::Relaxed), round + 1);
                }
                if round % 500 == 0 {
                    // Long enough for the members to park.
                    std::thread::sleep(Duration::from_millis(2));
                }
            }
        }
    }

    #[test]
    fn parts_write_disjoint_shares_of_a_borrowed_buffer() {
        let team = Team::new(3).unwrap();
        let mut data = vec![0u64; 10_007];
        for round in 1..200u64 {
            let n = data.len();
            let parts: Vec<Mutex<&mut [u64]>> = {
                let mut rest: &mut [u64] = &mut data;
                (0..3)
                    .map(|k| {
                        let r = share(n, 3, k);
                        let (head, tail) = std::mem::take(&mut rest).split_at_mut(r.len());
                        rest = tail;
                        Mutex::new(head)
                    })
                    .collect()
            };
            team.run(&|k| {
                for x in parts[k].lock().unwrap().iter_mut() {
                    *x += round;
                }
            });
        }
        assert!(data.iter().all(|&x| x == (1..200).sum::<u64>()));
    }

    #[test]
    fn only_timed_jobs_time_their_parts() {
        let team = Team::new(2).unwrap();
        let slow = Duration::from_millis(2);
        team.run_timed(&|k| {
            if k == 1 {
                std::thread::sleep(slow);
            }
        });
        let parts: Vec<Duration> = team.last_parts().collect();
        assert!(parts[1] >= slow && parts[0] < parts[1], "{parts:?}");
        // An untimed job leaves the last timed one's parts.
        team.run(&|_| std::thread::sleep(2 * slow));
        assert_eq!(team.last_parts().collect::<Vec<_>>(), parts);
    }

    #[test]
    fn woken_members_still_run_every_job_once() {
        for threads in [2, 3] {
            let team = Team::new(threads).unwrap();
            let count = AtomicUsize::new(0);
            for round in 0..300 {
                match round % 3 {
                    // Parked, woken, then handed a job while spinning.
                    0 => {
                        std::thread::sleep(Duration::from_micros(300));
                        team.wake();
                    }
                    // Woken twice while awake.
                    1 => {
                        team.wake();
                        team.wake();
                    }
                    // Woken and left to park again before the job.
                    _ => {
                        team.wake();
                        std::thread::sleep(Duration::from_micros(400));
                    }
                }
                team.run(&|_| {
                    count.fetch_add(1, Ordering::Relaxed);
                });
            }
            assert_eq!(count.load(Ordering::Relaxed), 300 * threads);
        }
    }

    #[test]
    fn a_panicking_part_is_raised_once_all_are_done() {
        let team = Team::new(2).unwrap();
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            team.run(&|k| assert!(k != 1, "member 1 fails"));
        }));
        assert!(outcome.is_err());
        // The team still works.
        let count = AtomicUsize::new(0);
        team.run(&|_| {
            count.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(count.load(Ordering::Relaxed), 2);
    }

    #[test]
    fn a_team_with_every_core_ties_each_thread_to_its_own() {
        let Some(cores) = affinity::allowed() else {
            return;
        };
        let seen: Vec<Mutex<Option<Vec<usize>>>> = cores.iter().map(|_| Mutex::default()).collect();
        let team = Team::new(cores.len()).unwrap();
        std::thread::scope(|scope| {
            scope.spawn(|| {
                let tied = team.tie_caller();
                assert_eq!(tied.is_some(), cores.len() > 1);
                team.run(&|k| *seen[k].lock().unwrap() = affinity::allowed());
            });
        });
        if cores.len() > 1 {
            for (k, seen) in seen.iter().enumerate() {
                assert_eq!(*seen.lock().unwrap(), Some(vec![cores[k]]), "thread {k}");
            }
        }
        // A team with fewer threads than cores is left to the scheduler.
        if cores.len() > 2 {
            assert!(Team::new(2).unwrap().tie_caller().is_none());
        }
    }

    #[test]
    fn timed_hand_offs_count_the_callers_wait_for_a_slow_member() {
        let team = Team::new(2).unwrap();
        // Not timed: nothing counted.
        team.run(&|_| {});
        assert_eq!(team.hand_offs(), HandOffs::default());
        team.set_timing(true);
        let slow = Duration::from_millis(2);
        for _ in 0..5 {
            team.run(&|k| {
                if k == 1 {
                    std::thread::sleep(slow);
                }
            });
        }
        let h = team.hand_offs();
        assert_eq!(h.jobs, 5);
        assert!(h.wait >= 5 * slow, "{h:?}");
        // The member's parts are the slow ones.
        assert!(h.longest_member_parts >= 5 * slow, "{h:?}");
        assert!(h.caller_parts < h.longest_member_parts, "{h:?}");
        assert!(h.late <= h.jobs);
        // A member that starts its part is counted from the hand-out: it
        // cannot start before it.
        assert!(h.start <= h.wait, "{h:?}");
        team.set_timing(false);
        team.run(&|_| {});
        assert_eq!(team.hand_offs().jobs, 5);
    }

    #[test]
    fn shares_cover_the_range_once() {
        for n in [0, 1, 7, 100] {
            for parts in 1..5 {
                let all: Vec<usize> = (0..parts).flat_map(|k| share(n, parts, k)).collect();
                assert_eq!(all, (0..n).collect::<Vec<_>>());
            }
        }
    }
}
