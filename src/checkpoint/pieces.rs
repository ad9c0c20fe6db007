//! A large checkpoint read on several threads.
//!
//! A checkpoint has one row a text line, so its rows are cut at newlines
//! into pieces, each read on a thread of its own, while another thread
//! sums the text before the checksum's line. Whenever the result might
//! differ from one thread's (any row that does not read, a blank line
//! among the rows, ids out of turn, a count other than the declared one,
//! a checksum that does not match, or a thread that could not be
//! started), [`parse`] gives up and the caller reads the text on one
//! thread, which names the first problem and its line.

use super::{hex16, parse_row, Checkpoint, Header, CHECKSUM};
use crate::fnv::Fnv;
use crate::line::{Color, Line};
use crate::scoped::Run;

/// What one thread read: the sum of the text before the checksum's line,
/// or a piece of rows (the id of the first, the lines and their colours).
enum Part {
    Sum(u64),
    Rows(usize, Vec<Line>, Vec<Color>),
}

/// The checkpoint `text` holds, its rows read in up to `pieces` pieces as
/// `run` says, or `None` where it must be read on one thread (see the
/// module's doc).
pub(crate) fn parse(text: &[u8], pieces: usize, run: Run) -> Option<Checkpoint> {
    let (header, body) = Header::parse(text, "").ok()?;
    let (sum_at, written) = checksum(text)?;
    let rows = text.get(body..sum_at)?;
    let cuts = cuts(rows, pieces);
    let parts = run.each(cuts.len(), |k| match k {
        0 => {
            let mut hash = Fnv::default();
            hash.bytes(&text[..sum_at]);
            Some(Part::Sum(hash.0))
        }
        k => read(&rows[cuts[k - 1]..cuts[k]]),
    })?;
    let mut parts = parts.into_iter();
    match parts.next() {
        Some(Part::Sum(sum)) if sum == written => {}
        _ => return None,
    }
    let mut rows: Vec<(usize, Vec<Line>, Vec<Color>)> = Vec::new();
    for part in parts {
        let Part::Rows(first, lines, colors) = part else {
            return None;
        };
        rows.push((first, lines, colors));
    }
    // The declared count is checked before anything is made of it.
    if rows.iter().map(|r| r.1.len()).sum::<usize>() != header.count {
        return None;
    }
    let (mut lines, mut colors) = (Vec::with_capacity(header.count), Vec::new());
    colors.reserve_exact(header.count);
    for (first, piece_lines, piece_colors) in rows {
        if first != lines.len() {
            return None;
        }
        lines.extend(piece_lines);
        colors.extend(piece_colors);
    }
    (lines.len() == header.count).then_some(Checkpoint {
        scene_digest: header.scene_digest,
        steps: header.steps,
        counters: header.counters,
        lines,
        colors,
    })
}

/// Where the checksum's line starts (the last line) and the sum it gives,
/// if it is spelled exactly as written.
fn checksum(text: &[u8]) -> Option<(usize, u64)> {
    let body = text.strip_suffix(b"\n")?;
    let start = body.iter().rposition(|&b| b == b'\n').map_or(0, |k| k + 1);
    let digits = body[start..].strip_prefix(CHECKSUM.as_bytes())?;
    Some((start, hex16(digits)?))
}

/// The ends of up to `pieces` pieces of `rows` (one after each cut), each
/// just after a newline.
fn cuts(rows: &[u8], pieces: usize) -> Vec<usize> {
    let mut cuts = vec![0];
    for k in 1..pieces {
        let even = rows.len() * k / pieces;
        match rows[even..].iter().position(|&b| b == b'\n') {
            Some(newline) if even + newline + 1 > cuts[cuts.len() - 1] => {
                cuts.push(even + newline + 1)
            }
            _ => {}
        }
    }
    if cuts[cuts.len() - 1] < rows.len() {
        cuts.push(rows.len());
    }
    cuts
}

/// The rows of `piece` (whole text lines, each ending with a newline), if
/// every one reads and their ids follow from the first's.
fn read(piece: &[u8]) -> Option<Part> {
    let rows = piece.strip_suffix(b"\n")?.split(|&b| b == b'\n');
    let first = piece.split(|&b| b.is_ascii_whitespace()).next()?;
    let first: usize = std::str::from_utf8(first).ok()?.parse().ok()?;
    let (mut lines, mut colors) = (Vec::new(), Vec::new());
    for (k, row) in rows.enumerate() {
        let row = row.strip_suffix(b"\r").unwrap_or(row);
        // A blank line or a checksum among the rows: one thread says so.
        if row.is_empty() || row.starts_with(CHECKSUM.as_bytes()) {
            return None;
        }
        let (line, color) = parse_row(row, first + k).ok()?;
        lines.push(line);
        colors.push(color);
    }
    Some(Part::Rows(first, lines, colors))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::counters::Counters;
    use crate::Vec2;

    fn sample(n: usize) -> Checkpoint {
        let lines: Vec<Line> = (0..n)
            .map(|k| {
                let x = k as f64 / 3.0;
                Line {
                    p1: Vec2::new(x, 0.5),
                    p2: Vec2::new(-x, 1e-7 * x),
                    v: Vec2::new(f64::NAN, x),
                }
            })
            .collect();
        Checkpoint {
            scene_digest: 0x0123_4567_89ab_cdef,
            steps: 77,
            counters: Counters { wall: 3, line: 9 },
            colors: (0..n).map(|k| [Color::Red, Color::Gray][k % 2]).collect(),
            lines,
        }
    }

    fn bits(c: &Checkpoint) -> Vec<u64> {
        let values = c
            .lines
            .iter()
            .flat_map(|l| [l.p1.x, l.p1.y, l.p2.x, l.p2.y, l.v.x, l.v.y]);
        values.map(f64::to_bits).collect()
    }

    #[test]
    fn pieces_read_what_one_thread_reads() {
        for n in [0, 1, 2, 10, 1000] {
            let text = sample(n).to_text();
            let one = Checkpoint::parse(text.as_bytes(), "c").unwrap();
            for pieces in [1, 2, 3, 7] {
                let read =
                    parse(text.as_bytes(), pieces, Run::Threads).expect("a checkpoint as written");
                assert_eq!(bits(&read), bits(&one), "{n} rows, {pieces} pieces");
                assert_eq!(
                    (read.steps, read.counters, &read.colors),
                    (one.steps, one.counters, &one.colors)
                );
                assert_eq!(read.scene_digest, one.scene_digest);
            }
            // Blank lines after the checksum: one thread refuses them, and
            // the pieces give up.
            let blanks = format!("{text}\n\r\n");
            assert!(Checkpoint::parse(blanks.as_bytes(), "c").is_err());
            assert!(parse(blanks.as_bytes(), 3, Run::Threads).is_none());
        }
    }

    proptest::proptest! {
        /// Whatever one byte is changed, pieces read what one thread reads
        /// or give up.
        #[test]
        fn pieces_agree_with_one_thread(
            n in 0usize..40,
            at in proptest::prelude::any::<proptest::sample::Index>(),
            byte in proptest::prelude::any::<u8>(),
            pieces in 2usize..5,
        ) {
            let mut text = sample(n).to_text().into_bytes();
            let i = at.index(text.len());
            text[i] = byte;
            proptest::prop_assert_eq!(
                parse(&text, pieces, Run::Threads).map(|c| bits(&c)),
                parse(&text, pieces, Run::Here).map(|c| bits(&c))
            );
            if let Some(read) = parse(&text, pieces, Run::Threads) {
                let one = Checkpoint::parse(&text, "c").expect("one thread reads it too");
                proptest::prop_assert_eq!(bits(&read), bits(&one));
                proptest::prop_assert_eq!(read.colors, one.colors);
            }
        }
    }

    #[test]
    fn anything_one_thread_refuses_gives_up() {
        let text = sample(300).to_text();
        let row = |k: usize| text.lines().nth(5 + k).unwrap().to_string();
        let damaged = [
            // A value changed: the checksum no longer matches.
            text.replacen(&row(250), &row(250).replacen(" 0.5 ", " 0.25 ", 1), 1),
            // A row left out, a blank line among the rows, two swapped.
            text.replacen(&format!("{}\n", row(200)), "", 1),
            text.replacen(&format!("{}\n", row(200)), &format!("{}\n\n", row(200)), 1),
            text.replacen(&row(10), "X", 1)
                .replacen(&row(11), &row(10), 1)
                .replacen("X", &row(11), 1),
            // The checksum cut, text after it, a second checksum early.
            text.trim_end()
                .trim_end_matches(|c: char| c.is_ascii_hexdigit())
                .to_string(),
            format!("{text}0\n"),
            text.replacen(
                &format!("{}\n", row(100)),
                &format!("{}\n{}", row(100), text.lines().last().unwrap()),
                1,
            ),
            // Fewer rows than declared.
            text.replacen("# scene: 300 lines", "# scene: 301 lines", 1),
        ];
        for (k, bad) in damaged.iter().enumerate() {
            assert!(Checkpoint::parse(bad.as_bytes(), "c").is_err(), "case {k}");
            assert!(parse(bad.as_bytes(), 3, Run::Threads).is_none(), "case {k}");
        }
    }
}
