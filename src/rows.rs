//! The rows of a state or a checkpoint as text, a block of rows at a time,
//! formatted on several threads while this one writes.
//!
//! A million lines are six million shortest decimals, about 0.3 s of
//! formatting on one thread, and a checkpoint's checksum reads every byte
//! in turn. So each of `threads` formatters (scoped threads) takes every
//! `threads`-th block and hands it over a channel of its own, two blocks
//! deep, and the calling thread writes the blocks in order, hashing them
//! if it is a checkpoint, while the next are formatted. The bytes are the
//! ones one thread writes: blocks are cut by row and joined in order.

use crate::decimal::push_decimal;
use crate::line::{Color, Line};
use std::fmt::Write as _;
use std::sync::mpsc::{sync_channel, Receiver};

/// Rows a block holds: about 500 KB of text.
const BLOCK: usize = 4096;

/// Rows from which they are formatted on threads.
const SHARED_FROM: usize = 4 * BLOCK;

/// Appends the state row of line `id`: `id p1.x p1.y p2.x p2.y v.x v.y`.
pub(crate) fn push_row(out: &mut String, id: usize, line: &Line) {
    write!(out, "{id}").expect("writing to a String");
    for v in [
        line.p1.x, line.p1.y, line.p2.x, line.p2.y, line.v.x, line.v.y,
    ] {
        out.push(' ');
        push_decimal(out, v);
    }
}

/// Writes the rows of `lines` (each followed by its colour code where
/// `colors` are given) to `out`, formatted on up to `threads` threads.
pub(crate) fn write_rows(
    out: &mut dyn std::io::Write,
    lines: &[Line],
    colors: Option<&[Color]>,
    threads: usize,
) -> std::io::Result<()> {
    let blocks = lines.len().div_ceil(BLOCK);
    let format = |block: usize| {
        let rows = block * BLOCK..((block + 1) * BLOCK).min(lines.len());
        let mut text = String::with_capacity(rows.len() * 128);
        for id in rows {
            push_row(&mut text, id, &lines[id]);
            if let Some(colors) = colors {
                write!(text, " {}", colors[id].code()).expect("writing to a String");
            }
            text.push('\n');
        }
        text
    };
    if threads <= 1 || lines.len() < SHARED_FROM {
        return (0..blocks).try_for_each(|block| out.write_all(format(block).as_bytes()));
    }
    std::thread::scope(|scope| {
        // Each formatter's blocks come over its channel; a formatter that
        // could not be started leaves its blocks to this thread.
        let formatters: Vec<Option<Receiver<String>>> = (0..threads)
            .map(|first| {
                let (send, receive) = sync_channel(2);
                let format = &format;
                let formatter = move || {
                    for block in (first..blocks).step_by(threads) {
                        // The writer has stopped (an error): so do we.
                        if send.send(format(block)).is_err() {
                            return;
                        }
                    }
                };
                let started = std::thread::Builder::new().spawn_scoped(scope, formatter);
                started.ok().map(|_| receive)
            })
            .collect();
        for block in 0..blocks {
            let text = match &formatters[block % threads] {
                Some(formatter) => formatter.recv().expect("a formatter hands every block"),
                None => format(block),
            };
            out.write_all(text.as_bytes())?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec2;

    fn lines(n: usize) -> (Vec<Line>, Vec<Color>) {
        let line = |k: usize| {
            let x = k as f64 / 7.0;
            Line {
                p1: Vec2::new(x, -x),
                p2: Vec2::new(1e-5 * x, 1e20 * x),
                v: Vec2::new(if k % 5 == 0 { f64::NAN } else { -x / 3.0 }, 0.5),
            }
        };
        let colors = (0..n).map(|k| if k % 2 == 0 { Color::Red } else { Color::Gray });
        ((0..n).map(line).collect(), colors.collect())
    }

    fn written(lines: &[Line], colors: Option<&[Color]>, threads: usize) -> Vec<u8> {
        let mut out = Vec::new();
        write_rows(&mut out, lines, colors, threads).unwrap();
        out
    }

    #[test]
    fn threads_write_the_bytes_one_thread_writes() {
        for n in [
            0,
            1,
            BLOCK - 1,
            BLOCK,
            SHARED_FROM,
            SHARED_FROM + 1,
            9 * BLOCK + 17,
        ] {
            let (lines, colors) = lines(n);
            let one = written(&lines, Some(&colors), 1);
            assert_eq!(one.iter().filter(|&&b| b == b'\n').count(), n);
            for threads in [2, 3, 8] {
                assert!(
                    written(&lines, Some(&colors), threads) == one,
                    "{n} rows, {threads} threads"
                );
                assert!(written(&lines, None, threads) == written(&lines, None, 1));
            }
        }
        let (lines, _) = lines(2);
        let text = String::from_utf8(written(&lines, None, 1)).unwrap();
        assert_eq!(text, "0 0.0 -0.0 0.0 0.0 NaN 0.5\n1 0.14285714285714285 -0.14285714285714285 1.4285714285714286e-06 1.4285714285714285e+19 -0.047619047619047616 0.5\n");
    }

    /// A writer that fails after `left` bytes.
    struct Failing {
        left: usize,
    }

    impl std::io::Write for Failing {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if buf.len() > self.left {
                return Err(std::io::Error::other("disk full"));
            }
            self.left -= buf.len();
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn an_error_stops_the_formatters_and_is_returned() {
        let (lines, colors) = lines(40 * BLOCK);
        for threads in [1, 2, 4] {
            let mut out = Failing { left: 1 << 20 };
            let e = write_rows(&mut out, &lines, Some(&colors), threads).unwrap_err();
            assert_eq!(e.to_string(), "disk full");
        }
    }
}
