//! A small team of threads for the phases of a step. A phase is cut into
//! pieces; the stepping thread and the members claim the pieces one at a
//! time, so a thread that is not running (its core taken by another
//! program, or by this program's own drawing) holds up at most the one
//! piece it has claimed, and a member that has not started holds up
//! nothing: the stepping thread takes its pieces.
//!
//! A step of a course scene takes a few tens of microseconds in a few
//! phases; waking a pooled worker through the operating system for each
//! phase costs a good part of what sharing the phase saves. The members
//! here wait for work by spinning on an atomic word for a while, so a
//! phase handed out soon after the last one starts at once; a member that
//! has waited longer than `SPIN` parks, and then uses no CPU until it is
//! woken. The stepping thread, its pieces done, spins for at most
//! `CALLER_SPIN` for the pieces still running elsewhere, then parks until
//! the last of them ends, so that a member switched out mid-piece can have
//! the core back.
//!
//! Which thread runs a piece changes nothing in the results: piece `k`
//! reads and writes what piece `k` owns, and the callers merge the pieces'
//! findings in piece order.
//!
//! This is the one module with `unsafe` code: a member runs a job that
//! borrows from the caller's stack frame, which the type system cannot see
//! outlive the call. [`Team::run`] does not return before every piece has
//! finished, and a member reads the job only while a piece it claimed is
//! unfinished, which is what makes the borrow sound.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long an idle member spins before it parks.
const SPIN: Duration = Duration::from_micros(200);

/// How long the stepping thread, its own pieces done, spins for the others
/// before it parks: a piece of a running member ends within a few tens of
/// microseconds; one whose member was switched out ends only when the
/// member has a core again, which the stepping thread's parking may give.
const CALLER_SPIN: Duration = Duration::from_micros(50);

/// The most pieces a job may have (the width of the claim counter).
pub const MAX_PIECES: usize = (1 << PIECE_BITS) - 1;

/// Bits of the job word for the piece count, and as many for the next
/// piece to claim; the rest number the jobs.
const PIECE_BITS: u32 = 12;
const PIECE_MASK: u64 = (1 << PIECE_BITS) - 1;

/// The job word: the job's number, its piece count and the next piece to
/// claim, in one atomic so that a claim is checked against all three at
/// once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Word {
    job: u64,
    pieces: usize,
    next: usize,
}

impl Word {
    fn pack(self) -> u64 {
        debug_assert!(self.pieces <= MAX_PIECES && self.next <= self.pieces);
        (self.job << (2 * PIECE_BITS)) | ((self.pieces as u64) << PIECE_BITS) | self.next as u64
    }

    fn unpack(w: u64) -> Word {
        Word {
            job: w >> (2 * PIECE_BITS),
            pieces: ((w >> PIECE_BITS) & PIECE_MASK) as usize,
            next: (w & PIECE_MASK) as usize,
        }
    }
}

/// What a thread team's hand-offs cost, summed over the jobs timed (while
/// the world is timed: [`World::set_timing`](crate::World::set_timing)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HandOffs {
    /// Jobs timed.
    pub jobs: u64,
    /// Pieces of those jobs, in all.
    pub pieces: u64,
    /// Pieces the members ran (the stepping thread ran the rest).
    pub member_pieces: u64,
    /// Jobs whose every piece the stepping thread ran itself, no member
    /// having come for one in time.
    pub alone: u64,
    /// The stepping thread's wait, no piece left to claim, for the pieces
    /// still running elsewhere.
    pub wait: Duration,
    /// Of those waits, the ones long enough that it parked.
    pub parked: u64,
}

/// A job: called once with each piece's number, `0..pieces`.
type Job<'a> = dyn Fn(usize) + Sync + 'a;

/// What the caller and the members share.
struct Shared {
    /// The current job's [`Word`]: bumped to a new job number, with piece
    /// 0 claimed, when a job is handed out; each claim adds one to `next`.
    word: AtomicU64,
    /// The current job: a pointer to a `&Job` on the stack of the caller
    /// of [`Team::run`], valid from the job's hand-out until `done`
    /// reaches its piece count.
    job: AtomicUsize,
    /// Pieces of the current job finished.
    done: AtomicUsize,
    /// Pieces the members ran (for [`HandOffs`]).
    member_pieces: AtomicUsize,
    /// Members parked (or about to park), who must be woken.
    parked: AtomicUsize,
    /// Bumped by [`Team::wake`]: a member woken sees it move, and spins
    /// for a while before it parks again.
    wakes: AtomicU64,
    /// Set when the team is dropped.
    quit: AtomicBool,
    /// Set when a piece of the current job panicked.
    panicked: AtomicBool,
    /// The members' threads, to wake them.
    threads: Mutex<Vec<std::thread::Thread>>,
    /// The stepping thread while it is parked (or about to park) waiting
    /// for the last pieces: the member that finishes the last one wakes it.
    waiting: Mutex<Option<std::thread::Thread>>,
    caller_parked: AtomicBool,
    /// Set while a job runs: jobs never overlap.
    busy: AtomicBool,
    /// Whether jobs are timed ([`Team::set_timing`]).
    timing: AtomicBool,
    /// Tests: the longest a member waits, in nanoseconds, before it claims
    /// a piece of a job it has seen (a pseudo-random time up to this), as
    /// a member switched out by the scheduler would.
    #[cfg(test)]
    delay: AtomicU64,
}

impl Shared {
    /// Claims the next piece of job `job`, if it has one left: the piece
    /// and the job's piece count.
    fn claim(&self, job: u64) -> Option<(usize, usize)> {
        let mut now = self.word.load(Ordering::Acquire);
        loop {
            let w = Word::unpack(now);
            if w.job != job || w.next >= w.pieces {
                return None;
            }
            let claimed = Word {
                next: w.next + 1,
                ..w
            }
            .pack();
            match self.word.compare_exchange_weak(
                now,
                claimed,
                Ordering::Acquire,
                Ordering::Acquire,
            ) {
                Ok(_) => return Some((w.next, w.pieces)),
                Err(seen) => now = seen,
            }
        }
    }

    /// Runs piece `k` of `job`, catching a panic (raised by the caller once
    /// every piece is done).
    fn run_piece(&self, job: &Job<'_>, k: usize) {
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(k)));
        if outcome.is_err() {
            self.panicked.store(true, Ordering::Relaxed);
        }
    }

    /// Counts `finished` pieces of a job of `pieces` done, waking the
    /// stepping thread if they were the last and it is parked. Nothing of
    /// the job may be touched after this.
    fn finish(&self, finished: usize, pieces: usize) {
        // SeqCst, with the stepping thread's `caller_parked` store and its
        // second look at `done`: either it sees every piece done, or this
        // thread sees it parked (and wakes it).
        let before = self.done.fetch_add(finished, Ordering::SeqCst);
        if before + finished == pieces && self.caller_parked.load(Ordering::SeqCst) {
            if let Some(t) = &*self.waiting.lock().expect("team lock") {
                t.unpark();
            }
        }
    }
}

/// A team of `threads` threads: the caller of [`Team::run`] and
/// `threads - 1` members of its own, alive as long as the team.
pub struct Team {
    shared: Arc<Shared>,
    members: Vec<JoinHandle<()>>,
    /// The hand-offs timed so far ([`Team::set_timing`]).
    hand_offs: Mutex<HandOffs>,
}

impl std::fmt::Debug for Team {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Team({} threads)", self.threads())
    }
}

impl Default for Team {
    /// A team of one.
    fn default() -> Team {
        Team::solo()
    }
}

impl Team {
    /// A team of one: jobs run on the caller alone.
    pub fn solo() -> Team {
        Team::new(1).expect("a team of one starts no thread")
    }

    /// A team of `threads` threads in all (at least 1; with 1, jobs run on
    /// the caller alone).
    pub fn new(threads: usize) -> std::io::Result<Team> {
        let threads = threads.max(1);
        let shared = Arc::new(Shared {
            word: AtomicU64::new(0),
            job: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            member_pieces: AtomicUsize::new(0),
            parked: AtomicUsize::new(0),
            wakes: AtomicU64::new(0),
            quit: AtomicBool::new(false),
            panicked: AtomicBool::new(false),
            threads: Mutex::new(Vec::new()),
            waiting: Mutex::new(None),
            caller_parked: AtomicBool::new(false),
            busy: AtomicBool::new(false),
            timing: AtomicBool::new(false),
            #[cfg(test)]
            delay: AtomicU64::new(0),
        });
        let mut members = Vec::new();
        for k in 1..threads {
            let mine = Arc::clone(&shared);
            let handle = std::thread::Builder::new()
                .name(format!("screensaver-team-{k}"))
                .spawn(move || member(&mine))?;
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
        })
    }

    /// Wakes the parked members, so that the first job of a run finds them
    /// spinning.
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

    /// Whether a job has been handed out to the members yet (a team of
    /// one, and a job of one piece, run on the calling thread alone).
    pub fn has_shared(&self) -> bool {
        Word::unpack(self.shared.word.load(Ordering::Relaxed)).job > 0
    }

    /// Runs `job(k)` once for every piece `k` in `0..threads()`, on
    /// whichever threads claim them (the calling thread starts with piece
    /// 0 and takes every piece no member has claimed), and returns when
    /// all have finished. A panic in any piece is raised here once all
    /// have finished.
    pub fn run(&self, job: &Job<'_>) {
        self.run_pieces(self.threads(), job);
    }

    /// [`Team::run`] of a job whose pieces each count something: returns
    /// the sum of the counts (the same in any order).
    pub fn run_sum(&self, job: &(dyn Fn(usize) -> u64 + Sync)) -> u64 {
        self.run_pieces_sum(self.threads(), job)
    }

    /// [`Team::run_pieces`] of a job whose pieces each count something:
    /// returns the sum of the counts (the same in any order).
    pub fn run_pieces_sum(&self, pieces: usize, job: &(dyn Fn(usize) -> u64 + Sync)) -> u64 {
        let sum = AtomicU64::new(0);
        self.run_pieces(pieces, &|k| {
            sum.fetch_add(job(k), Ordering::Relaxed);
        });
        sum.into_inner()
    }

    /// Runs `job(k)` once for every `k` in `0..pieces` (at most
    /// [`MAX_PIECES`]), as [`Team::run`] does.
    pub fn run_pieces(&self, pieces: usize, job: &Job<'_>) {
        assert!(pieces <= MAX_PIECES, "at most {MAX_PIECES} pieces a job");
        let s = &*self.shared;
        if self.members.is_empty() || pieces <= 1 {
            (0..pieces).for_each(|k| s.run_piece(job, k));
            if s.panicked.swap(false, Ordering::Relaxed) {
                panic!("a piece of a team's job panicked");
            }
            return;
        }
        let timing = s.timing.load(Ordering::Relaxed);
        let was_busy = s.busy.swap(true, Ordering::Acquire);
        assert!(!was_busy, "a team runs one job at a time");
        s.done.store(0, Ordering::Relaxed);
        s.member_pieces.store(0, Ordering::Relaxed);
        s.panicked.store(false, Ordering::Relaxed);
        let erased: &Job<'_> = job;
        s.job
            .store(&erased as *const &Job<'_> as usize, Ordering::Relaxed);
        // The job handed out with its piece 0 claimed by this thread. A
        // member that claims a piece sees the job too (the stores above
        // come before this one). SeqCst, with the load of `parked` below
        // and a member's announcement and second look at the word, ensures
        // that either the member sees this job or this thread sees the
        // member parked (and wakes it).
        let number = Word::unpack(s.word.load(Ordering::Relaxed)).job + 1;
        let word = Word {
            job: number,
            pieces,
            next: 1,
        };
        s.word.store(word.pack(), Ordering::SeqCst);
        if s.parked.load(Ordering::SeqCst) > 0 {
            for t in s.threads.lock().expect("team lock").iter() {
                t.unpark();
            }
        }
        s.run_piece(job, 0);
        let mut mine = 1;
        while let Some((k, _)) = s.claim(number) {
            s.run_piece(job, k);
            mine += 1;
        }
        s.finish(mine, pieces);
        // The job (and `erased`, which points to it) must outlive every
        // member's use of it: wait for every piece before returning.
        let waited = timing.then(Instant::now);
        let parked = self.wait_for(pieces);
        if let Some(waited) = waited {
            let mut h = self.hand_offs.lock().expect("the team's timing");
            h.jobs += 1;
            h.pieces += pieces as u64;
            h.member_pieces += s.member_pieces.load(Ordering::Relaxed) as u64;
            h.alone += u64::from(mine == pieces);
            h.wait += waited.elapsed();
            h.parked += u64::from(parked);
        }
        s.busy.store(false, Ordering::Release);
        if s.panicked.load(Ordering::Relaxed) {
            panic!("a piece of a team's job panicked");
        }
    }

    /// Waits until `pieces` pieces of the current job are done: spinning
    /// for up to [`CALLER_SPIN`], then parked. Whether it parked.
    fn wait_for(&self, pieces: usize) -> bool {
        let s = &*self.shared;
        let mut spins = 0u32;
        let mut since = None;
        while s.done.load(Ordering::Acquire) < pieces {
            spins = spins.wrapping_add(1);
            if spins % 64 != 0 {
                std::hint::spin_loop();
                continue;
            }
            if since.get_or_insert_with(Instant::now).elapsed() < CALLER_SPIN {
                continue;
            }
            // Park, announcing it first so that the member finishing the
            // last piece wakes this thread; `done` is read again after the
            // announcement (SeqCst orders the two, see `Shared::finish`).
            *s.waiting.lock().expect("team lock") = Some(std::thread::current());
            s.caller_parked.store(true, Ordering::SeqCst);
            while s.done.load(Ordering::SeqCst) < pieces {
                std::thread::park_timeout(Duration::from_millis(10));
            }
            s.caller_parked.store(false, Ordering::SeqCst);
            return true;
        }
        false
    }

    /// Turns the timing of the hand-offs on or off (off at first; it costs
    /// a clock read or two a job): see [`Team::hand_offs`].
    pub fn set_timing(&self, on: bool) {
        self.shared.timing.store(on, Ordering::Relaxed);
    }

    /// The hand-offs timed so far.
    pub fn hand_offs(&self) -> HandOffs {
        *self.hand_offs.lock().expect("the team's timing")
    }

    /// Tests: members wait up to `most` before claiming a piece of each
    /// job they see, as members switched out by the scheduler would.
    #[cfg(test)]
    pub(crate) fn delay_members(&self, most: Duration) {
        let nanos = most.as_nanos().try_into().unwrap_or(u64::MAX);
        self.shared.delay.store(nanos, Ordering::Relaxed);
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

/// A member's life: wait for a job, claim and run its pieces while any are
/// left; until the team is dropped.
fn member(s: &Shared) {
    let mut seen = 0;
    let mut woken = 0;
    loop {
        let mut started = Instant::now();
        let mut spins = 0u32;
        let number = loop {
            let word = Word::unpack(s.word.load(Ordering::Acquire));
            if word.job != seen {
                break word.job;
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
                // Let whatever else wants this core run (the stepping
                // thread, on a busy machine), then look again.
                std::thread::yield_now();
                continue;
            }
            // Park, announcing it first so that the next job wakes us; the
            // word is read again after the announcement, so a job handed
            // out in between is not missed (SeqCst orders the two).
            s.parked.fetch_add(1, Ordering::SeqCst);
            if Word::unpack(s.word.load(Ordering::SeqCst)).job == seen
                && !s.quit.load(Ordering::SeqCst)
            {
                std::thread::park_timeout(Duration::from_millis(100));
            }
            s.parked.fetch_sub(1, Ordering::SeqCst);
            let wakes = s.wakes.load(Ordering::Relaxed);
            if wakes != woken {
                // Woken for a run about to start: spin for it.
                (woken, started) = (wakes, Instant::now());
            }
        };
        seen = number;
        #[cfg(test)]
        delay(s, number);
        while let Some((k, pieces)) = s.claim(number) {
            debug_assert!(s.busy.load(Ordering::Relaxed), "a job outside `run`");
            let at = s.job.load(Ordering::Relaxed) as *const &Job<'static>;
            debug_assert!(!at.is_null());
            // SAFETY: this thread claimed piece `k` of job `number` (the
            // successful compare-exchange in `claim`, Acquire, which reads
            // the word `Team::run_pieces` stored with `number`, or a later
            // claim of the same job, in that store's release sequence), so
            // it sees `job` as stored before that word. `job` points to
            // `erased`, a `&Job` on the stack of that call of
            // `run_pieces`, which does not return (so `erased` and the job
            // it refers to stay alive and unmoved) until `done` counts
            // every piece, and piece `k` is counted only by
            // `Shared::finish` below, after this thread's last use of the
            // job. `run_pieces` calls never overlap (`busy`), and the
            // next job is handed out only once every piece of this one is
            // done, so `job` is not replaced while piece `k` is unfinished.
            // The job is `Sync`, so calling it from this thread while
            // others call it is allowed. The lifetime written here
            // (`'static`) is never relied on: the reference does not
            // escape this iteration.
            let job: &Job<'static> = unsafe { *at };
            s.run_piece(job, k);
            s.member_pieces.fetch_add(1, Ordering::Relaxed);
            s.finish(1, pieces);
        }
    }
}

/// Tests: waits a pseudo-random time up to the team's delay (job by job,
/// thread by thread), spinning or sleeping, as a member switched out would.
#[cfg(test)]
fn delay(s: &Shared, number: u64) {
    let most = s.delay.load(Ordering::Relaxed);
    if most == 0 {
        return;
    }
    let id = std::thread::current().id();
    let mut h = std::hash::DefaultHasher::new();
    std::hash::Hash::hash(&(number, id), &mut h);
    let r = std::hash::Hasher::finish(&h);
    let nanos = r % most;
    if r & (1 << 63) == 0 {
        std::thread::sleep(Duration::from_nanos(nanos));
    } else {
        let until = Instant::now() + Duration::from_nanos(nanos);
        while Instant::now() < until {
            std::hint::spin_loop();
        }
    }
}

/// Parts that the pieces of a job take, each its own: piece `k` takes
/// part `k`, once. A job is one `Fn` that every thread runs, so it cannot
/// hand out `&mut` borrows by itself; this hands each piece its own part
/// (a share of a slice, a chunk's buffers), moved out to the one piece
/// that takes it, without a lock.
pub struct Parts<T> {
    cells: Vec<Part<T>>,
}

/// One part, and whether it has been taken.
struct Part<T> {
    taken: AtomicBool,
    value: std::cell::UnsafeCell<Option<T>>,
}

// SAFETY: a `&Parts<T>` shared between threads only lets each part's value
// move out to the one thread that wins its `taken` flag (`Parts::take`),
// so sharing it is sound exactly when moving a `T` between threads is.
unsafe impl<T: Send> Sync for Parts<T> {}

impl<T> Parts<T> {
    /// The parts, numbered in order.
    pub fn new(parts: impl IntoIterator<Item = T>) -> Parts<T> {
        let cells = (parts.into_iter())
            .map(|value| Part {
                taken: AtomicBool::new(false),
                value: std::cell::UnsafeCell::new(Some(value)),
            })
            .collect();
        Parts { cells }
    }

    /// Part `k`, moved out to its one taker.
    ///
    /// # Panics
    /// If part `k` does not exist or was taken already.
    pub fn take(&self, k: usize) -> T {
        let part = &self.cells[k];
        let first = !part.taken.swap(true, Ordering::AcqRel);
        assert!(first, "part {k} taken twice");
        // SAFETY: the swap above turned `taken` from false to true in this
        // call and in no other (it is atomic, and nothing sets it back), so
        // this is the only access to the cell's value there will ever be
        // through a shared `Parts`; `&mut self` methods cannot run while
        // the `&self` this call holds exists.
        let value = unsafe { (*part.value.get()).take() };
        debug_assert!(value.is_some(), "an untaken part holds its value");
        value.expect("an untaken part holds its value")
    }
}

/// Splits `items` into `parts` contiguous shares of nearly equal length
/// (share `k` as [`share`] gives it), for piece `k` of a job to take.
pub fn split_mut<T>(items: &mut [T], parts: usize) -> Parts<&mut [T]> {
    let n = items.len();
    let mut rest = items;
    Parts::new((0..parts.max(1)).map(|k| {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(share(n, parts, k).len());
        rest = tail;
        head
    }))
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

    /// Many threads at once take the parts of many jobs: each part goes to
    /// exactly one taker, whole, and a second take panics.
    #[test]
    fn parts_go_each_to_one_taker() {
        let team = Team::new(4).unwrap();
        let mut items: Vec<u64> = (0..10_000).collect();
        for round in 0..200u64 {
            let parts = split_mut(&mut items, 4);
            let taken = AtomicUsize::new(0);
            team.run(&|k| {
                let part = parts.take(k);
                assert_eq!(part.len(), share(10_000, 4, k).len());
                for x in part.iter_mut() {
                    *x += 1;
                }
                taken.fetch_add(1, Ordering::Relaxed);
            });
            assert_eq!(taken.into_inner(), 4, "round {round}");
        }
        assert!(items.iter().enumerate().all(|(k, &x)| x == k as u64 + 200));
        let parts = Parts::new([1, 2]);
        assert_eq!(parts.take(1), 2);
        let again = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parts.take(1)));
        assert!(again.is_err(), "a part taken twice");
        assert_eq!(parts.take(0), 1);
    }

    #[test]
    fn the_job_word_packs_and_unpacks() {
        for w in [
            Word {
                job: 0,
                pieces: 0,
                next: 0,
            },
            Word {
                job: 1,
                pieces: 2,
                next: 1,
            },
            Word {
                job: (1 << 40) - 1,
                pieces: MAX_PIECES,
                next: MAX_PIECES,
            },
        ] {
            assert_eq!(Word::unpack(w.pack()), w);
        }
    }

    #[test]
    fn every_piece_runs_once_for_any_threads_and_pieces() {
        for threads in [1, 2, 3, 8] {
            let team = Team::new(threads).unwrap();
            assert_eq!(team.threads(), threads);
            for round in 0..1500usize {
                let pieces = [0, 1, 2, threads, 3 * threads + 1, 64][round % 6];
                let seen: Vec<AtomicU64> = (0..pieces).map(|_| AtomicU64::new(0)).collect();
                team.run_pieces(pieces, &|k| {
                    seen[k].fetch_add(1, Ordering::Relaxed);
                });
                assert!(seen.iter().all(|s| s.load(Ordering::Relaxed) == 1));
                if round % 500 == 0 {
                    // Long enough for the members to park.
                    std::thread::sleep(Duration::from_millis(1));
                }
            }
        }
    }

    #[test]
    fn summed_jobs_add_every_pieces_count() {
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
    fn pieces_write_disjoint_shares_of_a_borrowed_buffer() {
        let team = Team::new(3).unwrap();
        team.delay_members(Duration::from_micros(30));
        let mut data = vec![0u64; 10_007];
        for round in 1..300u64 {
            let parts = split_mut(&mut data, 3);
            team.run(&|k| {
                for x in parts.take(k).iter_mut() {
                    *x += round;
                }
            });
        }
        assert!(data.iter().all(|&x| x == (1..300).sum::<u64>()));
    }

    /// Members held back (sleeping or spinning, up to 2 ms a job) do not
    /// hold up the job: the stepping thread takes their pieces, and every
    /// piece still runs once.
    #[test]
    fn late_members_leave_their_pieces_to_the_stepping_thread() {
        for threads in [2, 3, 8] {
            let team = Team::new(threads).unwrap();
            team.set_timing(true);
            team.delay_members(Duration::from_millis(2));
            let count = AtomicUsize::new(0);
            for _ in 0..300 {
                team.run_pieces(16, &|_| {
                    count.fetch_add(1, Ordering::Relaxed);
                });
            }
            assert_eq!(count.load(Ordering::Relaxed), 300 * 16);
            let h = team.hand_offs();
            assert_eq!((h.jobs, h.pieces), (300, 300 * 16), "{h:?}");
            // Most jobs end before any member comes.
            assert!(h.alone > 150, "{h:?}");
        }
    }

    #[test]
    fn a_piece_the_stepping_thread_waits_for_long_parks_it_and_wakes_it() {
        let team = Team::new(2).unwrap();
        team.set_timing(true);
        for _ in 0..20 {
            let (claimed, zero_done) = (AtomicBool::new(false), AtomicBool::new(false));
            team.run(&|k| {
                if k == 1 {
                    // Piece 1 goes on for 2 ms after piece 0 has ended,
                    // far longer than the stepping thread spins.
                    claimed.store(true, Ordering::SeqCst);
                    while !zero_done.load(Ordering::SeqCst) {
                        std::hint::spin_loop();
                    }
                    std::thread::sleep(Duration::from_millis(2));
                } else {
                    // Piece 0 (the stepping thread's) ends only once a
                    // member has claimed piece 1, so that it must wait.
                    while !claimed.load(Ordering::SeqCst) {
                        std::hint::spin_loop();
                    }
                    zero_done.store(true, Ordering::SeqCst);
                }
            });
        }
        let h = team.hand_offs();
        // Each wait outlasts the spin, unless this thread was itself
        // switched out for as long meanwhile (on a busy machine).
        assert!(h.parked > 0 && h.parked <= 20, "{h:?}");
        assert_eq!(h.member_pieces, 20, "{h:?}");
        assert!(h.wait > Duration::ZERO, "{h:?}");
    }

    #[test]
    fn woken_members_still_run_every_piece_once() {
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
    fn a_panicking_piece_is_raised_once_all_are_done() {
        for threads in [1, 2] {
            let team = Team::new(threads).unwrap();
            let ran = AtomicUsize::new(0);
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                team.run_pieces(4, &|k| {
                    ran.fetch_add(1, Ordering::Relaxed);
                    assert!(k != 1, "piece 1 fails");
                });
            }));
            assert!(outcome.is_err());
            assert_eq!(ran.load(Ordering::Relaxed), 4);
            // The team still works.
            let count = AtomicUsize::new(0);
            team.run(&|_| {
                count.fetch_add(1, Ordering::Relaxed);
            });
            assert_eq!(count.load(Ordering::Relaxed), threads);
        }
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
