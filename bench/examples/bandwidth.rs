//! What one thread of this machine does with the memory a million lines
//! take, without any arithmetic: the floor under a large scene's step
//! (docs/PERFORMANCE.md, "Instructions a line costs each step").
//!
//! ```sh
//! cargo run --release -p screensaver-bench --example bandwidth -- [--megabytes M] [--rounds R]
//! ```
//!
//! Times, on buffers of `M` megabytes (48 by default, the lines of a
//! million-line scene), the fastest of `R` rounds (15 by default) of: a
//! copy into another buffer (as a layout copied from step to step), an
//! update in place (as the move), and a read (as the sweep reads its
//! boxes, with enough sums at once that the additions never wait on each
//! other).

use std::hint::black_box;
use std::time::Instant;

/// Sums to keep at once in the read, so that it waits on memory alone.
const SUMS: usize = 16;

/// Seconds of the fastest of `rounds` runs of `f`.
fn fastest(rounds: usize, mut f: impl FnMut()) -> f64 {
    (0..rounds)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let mut megabytes = 48usize;
    let mut rounds = 15usize;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| -> usize {
            let v = args
                .next()
                .unwrap_or_else(|| panic!("{name} needs a number"));
            v.parse()
                .unwrap_or_else(|_| panic!("{name}: not a number: {v}"))
        };
        match arg.as_str() {
            "--megabytes" => megabytes = value("--megabytes").max(1),
            "--rounds" => rounds = value("--rounds").max(1),
            other => panic!("unknown argument {other}"),
        }
    }
    let n = megabytes * 1024 * 1024 / 8;
    let from: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let mut to = vec![0.0f64; n];
    let mut lines = from.clone();
    let copy = fastest(rounds, || to.copy_from_slice(black_box(&from)));
    let update = fastest(rounds, || {
        for x in black_box(&mut lines).iter_mut() {
            *x += 1.0;
        }
    });
    let read = fastest(rounds, || {
        let mut sums = [0.0f64; SUMS];
        for chunk in black_box(&from).chunks_exact(SUMS) {
            for (sum, x) in sums.iter_mut().zip(chunk) {
                *sum += x;
            }
        }
        black_box(sums);
    });
    black_box((&to, &lines));
    let gb = megabytes as f64 / 1024.0;
    println!("{megabytes} MB, fastest of {rounds} rounds, one thread:");
    println!(
        "  copy       {:6.2} ms ({:.1} GB/s read and as much written)",
        copy * 1e3,
        gb / copy
    );
    println!(
        "  in place   {:6.2} ms ({:.1} GB/s read and as much written)",
        update * 1e3,
        gb / update
    );
    println!("  read       {:6.2} ms ({:.1} GB/s)", read * 1e3, gb / read);
}
