//! Our `hypot` and `atan2` against the system's, at scale: how many of
//! `PAIRS` argument pairs of each class give other bits. On glibc 2.36,
//! x86-64 (the reference's libm) `hypot` must differ nowhere; `atan2`
//! differs where glibc's is not correctly rounded.
//!
//! ```text
//! cargo run --release -p screensaver-bench --example libm_compare -- [PAIRS per class] [SEED] [--hypot-only]
//! ```
//!
//! Runs on every core; prints a Markdown table.

use screensaver::internals::classes::ALL;
use screensaver::maths::{atan2, hypot};
use std::time::Instant;

fn main() {
    let hypot_only = std::env::args().any(|a| a == "--hypot-only");
    let mut args = std::env::args().skip(1).filter(|a| !a.starts_with("--"));
    let pairs: u64 = args
        .next()
        .map_or(10_000_000, |a| a.parse().expect("PAIRS"));
    let seed: u64 = args.next().map_or(1, |a| a.parse().expect("SEED"));
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
    println!("{pairs} pairs a class, seed {seed}, {threads} threads\n");
    println!("| class | pairs | `hypot` differing | `atan2` differing | `atan2` rate |");
    println!("| --- | ---: | ---: | ---: | ---: |");
    let start = Instant::now();
    let (mut all_h, mut all_a, mut all) = (0u64, 0u64, 0u64);
    for class in ALL {
        let (h, a) = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|t| {
                    scope.spawn(move || {
                        let share = pairs / threads + u64::from(t < pairs % threads);
                        let (mut h, mut a) = (0u64, 0u64);
                        for (x, y) in class.pairs(share, seed.wrapping_mul(1000).wrapping_add(t)) {
                            if hypot(x, y).to_bits() != x.hypot(y).to_bits() {
                                h += 1;
                                if h <= 3 {
                                    eprintln!(
                                        "hypot({x:e}, {y:e}): ours {:e}, system {:e}",
                                        hypot(x, y),
                                        x.hypot(y)
                                    );
                                }
                            }
                            if hypot_only {
                                continue;
                            }
                            let (ours, system) = (atan2(x, y), x.atan2(y));
                            if ours.to_bits() != system.to_bits()
                                && !(ours.is_nan() && system.is_nan())
                            {
                                a += 1;
                            }
                        }
                        (h, a)
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("a thread"))
                .fold((0, 0), |(h, a), (h2, a2)| (h + h2, a + a2))
        });
        println!(
            "| {} | {pairs} | {h} | {a} | {:.4}% |",
            class.name(),
            100.0 * a as f64 / pairs as f64
        );
        (all_h, all_a, all) = (all_h + h, all_a + a, all + pairs);
    }
    println!(
        "| all | {all} | {all_h} | {all_a} | {:.4}% |",
        100.0 * all_a as f64 / all as f64
    );
    println!("\n{:.1} s", start.elapsed().as_secs_f64());
}
