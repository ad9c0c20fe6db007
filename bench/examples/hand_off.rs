//! What handing two equal parts of a job to two threads costs, back to
//! back, with this project's thread team and with the crates that offer
//! low-overhead parallelism: rayon's `join`, chili's `Scope::join` and
//! paralight's fixed ranges.
//!
//! ```sh
//! cargo run --release -p screensaver-bench --example hand_off -- [team|rayon|chili|paralight]
//! ```
//!
//! Each part is a chain of dependent multiplications (`work` turns of
//! it, about 2 ns each), so that the parts cost the same on either core;
//! a job is timed over 20,000 calls in a row, and "one thread" runs both
//! parts one after the other. Name one contender to time it alone (each
//! keeps threads of its own alive, which would compete with the next).

use paralight::prelude::*;
use screensaver::internals::Team;
use std::hint::black_box;
use std::time::Instant;

/// Turns of the chain in each part.
const WORKS: [u64; 3] = [0, 2000, 10000];

/// Calls timed for each amount of work.
const CALLS: u32 = 20_000;

/// One part of the job.
fn part(k: usize, turns: u64) -> u64 {
    let mut x = k as u64 + 1;
    for i in 0..turns {
        x = black_box(x.wrapping_mul(6364136223846793005).wrapping_add(i));
    }
    x
}

/// Nanoseconds a call of `job` takes, over `CALLS` calls.
fn time(mut job: impl FnMut() -> u64) -> f64 {
    let start = Instant::now();
    for _ in 0..CALLS {
        black_box(job());
    }
    start.elapsed().as_nanos() as f64 / f64::from(CALLS)
}

/// Ties the calling thread to `core` (the team ties its member to the
/// other, as `World::run_with` ties the stepping thread to this one).
fn tie(core: usize) {
    let mut set = nix::sched::CpuSet::new();
    if set.set(core).is_ok() {
        let _ = nix::sched::sched_setaffinity(nix::unistd::Pid::from_raw(0), &set);
    }
}

fn main() {
    let only = std::env::args().nth(1);
    let on = |name: &str| only.as_deref().is_none_or(|o| o == name);
    // Made while the process may use every core, so that its member is
    // tied to a core of its own; then this thread to the other.
    let team = on("team").then(|| Team::new(2).expect("a team of two"));
    if team.is_some() {
        tie(0);
    }
    for turns in WORKS {
        let mut row = format!(
            "{turns:6} turns a part: one thread {:8.0} ns",
            time(|| part(0, turns) + part(1, turns))
        );
        if let Some(team) = &team {
            row += &format!(" | team {:8.0}", time(|| team.run_sum(&|k| part(k, turns))));
        }
        if on("rayon") {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .build()
                .expect("a pool");
            let ns = pool.install(|| {
                time(|| {
                    let (a, b) = rayon::join(|| part(0, turns), || part(1, turns));
                    a + b
                })
            });
            row += &format!(" | rayon::join {ns:8.0}");
        }
        if on("chili") {
            let mut scope = chili::Scope::global();
            let ns = time(|| {
                let (a, b) = scope.join(|_| part(0, turns), |_| part(1, turns));
                a + b
            });
            row += &format!(" | chili {ns:8.0}");
        }
        if on("paralight") {
            let mut pool = ThreadPoolBuilder {
                num_threads: ThreadCount::try_from(2).expect("two threads"),
                range_strategy: RangeStrategy::Fixed,
                cpu_pinning: CpuPinningPolicy::IfSupported,
            }
            .build();
            let ns = time(|| {
                (0..2usize)
                    .into_par_iter()
                    .with_thread_pool(&mut pool)
                    .map(|k| part(k, turns))
                    .sum::<u64>()
            });
            row += &format!(" | paralight {ns:8.0}");
        }
        println!("{row}");
    }
}
