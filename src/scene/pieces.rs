//! A large scene text read on several threads.
//!
//! The text is cut into pieces where rows start (a `(` first on a text
//! line), each piece is parsed on a thread of its own, and the rows are
//! joined in order. The lexer's tokens do not depend on what came before
//! them, so a piece that begins where a row begins reads the rows the one
//! thread would. Whenever that cannot be known, [`parse`] gives up and the
//! caller reads the text on one thread: a row that runs across a cut (a
//! piece's last row ending past where the next piece starts), any error
//! (so that every error, and the line it names, is the one thread's), a
//! count of rows other than the declared one, or a thread that could not
//! be started.

use super::{strip_bom, Lexer, Parser, Scene, SceneLine, Token};
use crate::scoped::Run;

/// The scene `text` holds, its rows read in up to `pieces` pieces as
/// `run` says, or `None` where it must be read on one thread (see the
/// module's doc).
pub(crate) fn parse(text: &[u8], pieces: usize, run: Run) -> Option<Scene> {
    let text = strip_bom(text);
    let mut lexer = Lexer::new(text);
    let Some((Token::Word(word), _)) = lexer.next() else {
        return None;
    };
    let declared: u64 = std::str::from_utf8(word).ok()?.parse().ok()?;
    let cuts = cuts(text, lexer.pos, pieces);
    let read = run.each(cuts.len() - 1, |k| rows(text, cuts[k], cuts[k + 1]));
    let mut read = read?.into_iter();
    let mut lines = read.next()?;
    let rest: Vec<Vec<SceneLine>> = read.collect();
    let count = lines.len() + rest.iter().map(Vec::len).sum::<usize>();
    if count as u64 != declared {
        return None;
    }
    lines.reserve_exact(count - lines.len());
    rest.into_iter().for_each(|piece| lines.extend(piece));
    Some(Scene { lines })
}

/// Where the pieces of the rows from `body` on begin, then the text's end:
/// the first row start (a `(` first on its text line) after each even
/// cut of the text, where there is one.
fn cuts(text: &[u8], body: usize, pieces: usize) -> Vec<usize> {
    let mut cuts = vec![body];
    for k in 1..pieces {
        let even = body + (text.len() - body) * k / pieces;
        let Some(newline) = text[even..].iter().position(|&b| b == b'\n') else {
            break;
        };
        let first = (text[even + newline..].iter())
            .position(|b| !b.is_ascii_whitespace())
            .map(|blank| even + newline + blank);
        match first {
            Some(at) if text[at] == b'(' && at > cuts[cuts.len() - 1] => cuts.push(at),
            _ => {}
        }
    }
    cuts.push(text.len());
    cuts
}

/// The rows from `start` to `end` of `text`, if they parse and the last
/// ends at `end` (up to blanks).
fn rows(text: &[u8], start: usize, end: usize) -> Option<Vec<SceneLine>> {
    // The row and line numbers are only for errors, which are given up on.
    let mut parser = Parser {
        lexer: Lexer {
            text,
            pos: start,
            line: 1,
        },
        origin: "",
        row: 0,
    };
    // A row written by this program takes 60 to 120 bytes.
    let mut lines = Vec::with_capacity((end - start) / 64);
    loop {
        parser.lexer.skip_blanks();
        if parser.lexer.pos >= end {
            break;
        }
        lines.push(parser.row().ok()?);
    }
    (parser.lexer.pos == end).then_some(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Color, Vec2};
    use proptest::prelude::*;

    fn serial(text: &[u8]) -> Option<Scene> {
        Scene::parse(text, "t.in").ok()
    }

    fn scene(n: usize) -> Scene {
        let lines = (0..n)
            .map(|k| SceneLine {
                p1: Vec2::new(k as f64 * 0.37, -(k as f64) / 3.0),
                p2: Vec2::new(1e-300 * k as f64, 12345.678 + k as f64),
                v: Vec2::new(-0.0, k as f64 * 1e10),
                color: if k % 3 == 0 { Color::Gray } else { Color::Red },
            })
            .collect();
        Scene { lines }
    }

    #[test]
    fn pieces_read_the_rows_one_thread_reads() {
        let text = scene(1000).to_text();
        for pieces in [1, 2, 3, 4, 7, 64] {
            let read = parse(text.as_bytes(), pieces, Run::Threads)
                .expect("one row a text line cuts anywhere");
            assert_eq!(Some(read), serial(text.as_bytes()), "{pieces} pieces");
        }
        let cut = cuts(text.as_bytes(), 5, 4);
        assert_eq!(cut.len(), 5, "{cut:?}");
    }

    #[test]
    fn a_byte_order_mark_and_blank_lines_are_read_as_one_thread_reads_them() {
        let text = format!(
            "\u{feff}{}\n\n\n",
            scene(50).to_text().replace('\n', "\n\r\n  ")
        );
        assert_eq!(
            parse(text.as_bytes(), 5, Run::Threads),
            serial(text.as_bytes())
        );
        assert!(parse(text.as_bytes(), 5, Run::Threads).is_some());
    }

    #[test]
    fn a_row_across_a_cut_gives_up() {
        // Every row spans two text lines, the second starting with `(`, so
        // that a cut may fall between a row's two points.
        let text = scene(200).to_text().replace("), (", "),\n(");
        let text = text.as_bytes();
        let body = text.iter().position(|&b| b == b'\n').unwrap() + 1;
        let second_point = body + text[body..].windows(2).position(|w| w == b"\n(").unwrap() + 1;
        let next_row = second_point
            + text[second_point..]
                .windows(2)
                .position(|w| w == b"\n(")
                .unwrap()
            + 1;
        assert_eq!(
            rows(text, body, second_point),
            None,
            "the row runs past the cut"
        );
        assert_eq!(
            rows(text, second_point, text.len()),
            None,
            "no row starts here"
        );
        assert_eq!(rows(text, body, next_row).map(|r| r.len()), Some(1));
        // Wherever the cuts fall, pieces read what one thread reads, or
        // give up.
        for pieces in 2..12 {
            if let Some(read) = parse(text, pieces, Run::Threads) {
                assert_eq!(Some(read), serial(text), "{pieces} pieces");
            }
        }
    }

    #[test]
    fn errors_and_wrong_counts_give_up() {
        let text = scene(300).to_text();
        let more = text.replacen("300", "299", 1);
        let fewer = text.replacen("300", "301", 1);
        // A row late in the text, in the last piece, broken.
        let mut rows: Vec<String> = text.lines().map(str::to_string).collect();
        rows[250] = rows[250].replace("), (", ") (");
        let broken = rows.join("\n");
        for bad in [more, fewer, broken, format!("{text}x")] {
            assert_eq!(parse(bad.as_bytes(), 3, Run::Threads), None);
            assert_eq!(serial(bad.as_bytes()), None);
        }
        assert_eq!(parse(b"", 2, Run::Threads), None);
        assert_eq!(parse(b"0\n", 2, Run::Threads), serial(b"0\n"));
    }

    proptest! {
        /// Whatever the text, read in pieces it is what one thread reads,
        /// or given up on.
        #[test]
        fn pieces_agree_with_one_thread(
            n in 0usize..60,
            at in any::<prop::sample::Index>(),
            edit in 0u8..4,
            byte in prop_oneof![Just(b'('), Just(b')'), Just(b','), Just(b'\n'), Just(b' '),
                                Just(b'-'), Just(b'.'), Just(b'e'), Just(b'9'), any::<u8>()],
            pieces in 2usize..6,
        ) {
            let mut text = scene(n).to_text().into_bytes();
            let i = at.index(text.len());
            match edit {
                0 => { text.remove(i); }
                1 => text.insert(i, byte),
                2 => text[i] = byte,
                _ => {}
            }
            prop_assert_eq!(parse(&text, pieces, Run::Threads), parse(&text, pieces, Run::Here));
            if let Some(read) = parse(&text, pieces, Run::Threads) {
                prop_assert_eq!(Some(read), serial(&text));
            } else if edit == 3 {
                prop_assert!(false, "an unedited scene is read in pieces");
            }
        }
    }
}
