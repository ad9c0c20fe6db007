//! Scene files (`.in`): reading them with errors that say exactly where and
//! what is wrong, and writing them so that they read back unchanged.
//!
//! ```text
//! <number of lines>
//! (<x1>, <y1>), (<x2>, <y2>), <vx>, <vy>, <color>
//! ```
//!
//! Values are window coordinates and window velocity units. Whitespace
//! between tokens is free, as it was for the reference's `scanf`; a row may
//! even span several text lines. Errors name the text line where the
//! offending token (or the end of the file) is.

pub(crate) mod pieces;

use crate::geometry::Vec2;
use crate::line::Color;
use crate::schedule::Schedule;
use crate::scoped::Run;
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One line of a scene, in window coordinates, as written in the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneLine {
    /// First endpoint.
    pub p1: Vec2,
    /// Second endpoint.
    pub p2: Vec2,
    /// Velocity in window units per unit of time.
    pub v: Vec2,
    /// Drawing colour.
    pub color: Color,
}

/// A whole scene: its lines in id order.
///
/// ```
/// use screensaver::{DetectorKind, Scene, World};
///
/// // The `.in` format: the count, then a row a line, in window units.
/// let text = "2\n\
///     (300.0, 400.0), (320.0, 420.0), 0.5, 0.0, 0\n\
///     (900.0, 400.0), (920.0, 430.0), -0.5, 0.0, 1\n";
/// let scene = Scene::parse(text.as_bytes(), "two.in").expect("a scene");
/// assert_eq!(scene.lines.len(), 2);
/// let mut world = World::with_detector(&scene, DetectorKind::Sweep);
/// world.run(10);
///
/// // Errors name the text, the line and the problem.
/// let error = Scene::parse(b"3\n", "short.in").unwrap_err();
/// assert!(error.to_string().starts_with("short.in:"), "{error}");
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The lines; a line's id is its position here.
    pub lines: Vec<SceneLine>,
}

/// What is wrong with a scene text.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParseErrorKind {
    /// The text holds nothing at all.
    #[error("the file is empty; expected the number of lines first")]
    Empty,
    /// The text holds nothing but blank lines (spaces, tabs, newlines).
    #[error("the file has only blank lines; expected the number of lines first")]
    Blank,
    /// A row goes on after its colour.
    #[error("row {row}: an extra field after the colour, `{found}` (a row is `(x1, y1), (x2, y2), vx, vy, colour`)")]
    ExtraField {
        /// 1-based row number.
        row: u64,
        /// What follows the colour on its text line: `, ` and the next
        /// token, or `,` alone.
        found: String,
    },
    /// The first token is not a non-negative integer.
    #[error("expected the number of lines (a non-negative integer), found `{found}`")]
    BadCount {
        /// The token found.
        found: String,
    },
    /// The first token is a whole number too large to count lines by.
    #[error("the number of lines `{found}` is too large (at most {})", u64::MAX)]
    CountTooLarge {
        /// The token found.
        found: String,
    },
    /// The file ends before the declared number of rows.
    #[error("the file declares {} but ends after {found}", crate::plural(*declared, "line"))]
    TooFewRows {
        /// The declared count.
        declared: u64,
        /// Complete rows read.
        found: u64,
    },
    /// Something follows the last declared row.
    #[error("the file declares {} but has more rows (or trailing text `{found}`)", crate::plural(*declared, "line"))]
    TooManyRows {
        /// The declared count.
        declared: u64,
        /// The first token past the last row.
        found: String,
    },
    /// A token is not what the row syntax expects at this point.
    #[error("row {row}: expected {expected}, found {found}")]
    Unexpected {
        /// 1-based row number (the header is not a row).
        row: u64,
        /// What the grammar wanted.
        expected: &'static str,
        /// The token found, quoted, or "the end of the file".
        found: String,
    },
    /// A number parsed as infinite or NaN.
    #[error("row {row}: {field} must be a finite number, found `{found}`")]
    NotFinite {
        /// 1-based row number.
        row: u64,
        /// Which value (`x1`, `vy`, ...).
        field: &'static str,
        /// The token found.
        found: String,
    },
    /// The colour is not 0 or 1.
    #[error("row {row}: colour must be 0 (red) or 1 (gray), found `{found}`")]
    BadColor {
        /// 1-based row number.
        row: u64,
        /// The token found.
        found: String,
    },
}

/// A scene text that could not be read, with where the problem is.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{origin}:{line}: {kind}")]
pub struct ParseError {
    /// The file name (or another description of where the text came from).
    pub origin: String,
    /// 1-based text line of the problem.
    pub line: usize,
    /// The problem.
    pub kind: ParseErrorKind,
}

/// A scene file that could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read at all.
    #[error("{}: cannot read the file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file was read but is not a valid scene.
    #[error(transparent)]
    Parse(#[from] ParseError),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Token<'a> {
    Open,
    Close,
    Comma,
    Word(&'a [u8]),
}

impl fmt::Display for Token<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Token::Open => f.write_str("`(`"),
            Token::Close => f.write_str("`)`"),
            Token::Comma => f.write_str("`,`"),
            Token::Word(w) => write!(f, "`{}`", show(w)),
        }
    }
}

/// A token's bytes for an error message, shortened if long.
fn show(word: &[u8]) -> String {
    const MAX: usize = 40;
    // Bytes that are not printable ASCII are shown as `\xNN`, so that a
    // binary file's bytes never reach the terminal as they are.
    let mut shown: String = word
        .iter()
        .take(MAX)
        .flat_map(|&b| std::ascii::escape_default(b))
        .map(char::from)
        .collect();
    if word.len() > MAX {
        shown.push_str("...");
    }
    shown
}

struct Lexer<'a> {
    text: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a [u8]) -> Self {
        Self {
            text,
            pos: 0,
            line: 1,
        }
    }

    /// The text line the end of the file is reported on: the last line
    /// that has any character other than its newline.
    fn eof_line(&self) -> usize {
        let trailing_newline = self.text.last() == Some(&b'\n');
        (self.line - usize::from(trailing_newline)).max(1)
    }

    /// Whether `b` ends a word: a blank or punctuation.
    fn ends_word(b: u8) -> bool {
        b.is_ascii_whitespace() || matches!(b, b'(' | b')' | b',')
    }

    /// Passes the blanks (spaces, tabs, newlines) before the next token.
    fn skip_blanks(&mut self) {
        while let Some(&b) = self.text.get(self.pos) {
            if b == b'\n' {
                self.line += 1;
            } else if !b.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
    }

    /// The next token and the text line it starts on, or `None` at the end.
    fn next(&mut self) -> Option<(Token<'a>, usize)> {
        self.skip_blanks();
        let start = self.pos;
        let token = match *self.text.get(start)? {
            b'(' => Token::Open,
            b')' => Token::Close,
            b',' => Token::Comma,
            _ => {
                let len = self.text[start..]
                    .iter()
                    .position(|&b| Lexer::ends_word(b))
                    .unwrap_or(self.text.len() - start);
                self.pos += len;
                return Some((Token::Word(&self.text[start..start + len]), self.line));
            }
        };
        self.pos += 1;
        Some((token, self.line))
    }
}

struct Parser<'a> {
    lexer: Lexer<'a>,
    origin: &'a str,
    row: u64,
}

impl<'a> Parser<'a> {
    fn error(&self, line: usize, kind: ParseErrorKind) -> ParseError {
        ParseError {
            origin: self.origin.to_string(),
            line,
            kind,
        }
    }

    fn unexpected(&self, expected: &'static str, got: Option<(Token<'a>, usize)>) -> ParseError {
        let (found, line) = match got {
            Some((token, line)) => (token.to_string(), line),
            None => ("the end of the file".to_string(), self.lexer.eof_line()),
        };
        let kind = ParseErrorKind::Unexpected {
            row: self.row,
            expected,
            found,
        };
        self.error(line, kind)
    }

    /// The punctuation `want` next, or the error saying `expected`. The
    /// common case (the byte itself) is inlined and the rest is not, so
    /// that reading a row costs no more than its bytes.
    #[inline]
    fn punct(&mut self, want: Token<'static>, expected: &'static str) -> Result<(), ParseError> {
        self.lexer.skip_blanks();
        let byte = match want {
            Token::Open => b'(',
            Token::Close => b')',
            _ => b',',
        };
        if self.lexer.text.get(self.lexer.pos) == Some(&byte) {
            self.lexer.pos += 1;
            return Ok(());
        }
        self.punct_otherwise(want, expected)
    }

    #[cold]
    #[inline(never)]
    fn punct_otherwise(
        &mut self,
        want: Token<'static>,
        expected: &'static str,
    ) -> Result<(), ParseError> {
        match self.lexer.next() {
            Some((token, _)) if token == want => Ok(()),
            other => Err(self.unexpected(expected, other)),
        }
    }

    /// The number next, named `field`, or the error saying `expected`: a
    /// plain decimal (nearly every number of a scene file) is read where
    /// it stands, in one pass, if its word ends where it does
    /// ([`crate::decimal::read_plain`]); any other spelling goes the
    /// general way, not inlined.
    #[inline]
    fn number(&mut self, field: &'static str, expected: &'static str) -> Result<f64, ParseError> {
        self.lexer.skip_blanks();
        let rest = &self.lexer.text[self.lexer.pos..];
        if let Some((value, len)) = crate::decimal::read_plain(rest) {
            if rest.get(len).is_none_or(|&b| Lexer::ends_word(b)) {
                self.lexer.pos += len;
                return Ok(value);
            }
        }
        self.number_otherwise(field, expected)
    }

    #[cold]
    #[inline(never)]
    fn number_otherwise(
        &mut self,
        field: &'static str,
        expected: &'static str,
    ) -> Result<f64, ParseError> {
        let got = self.lexer.next();
        let Some((Token::Word(word), line)) = got else {
            return Err(self.unexpected(expected, got));
        };
        // Not a plain decimal where it stands (`number` looked): any
        // other spelling, by Rust's reader.
        let value = crate::decimal::read_any(word).ok_or_else(|| self.unexpected(expected, got))?;
        if !value.is_finite() {
            let kind = ParseErrorKind::NotFinite {
                row: self.row,
                field,
                found: show(word),
            };
            return Err(self.error(line, kind));
        }
        Ok(value)
    }

    fn point(
        &mut self,
        name: &'static str,
        x: &'static str,
        y: &'static str,
    ) -> Result<Vec2, ParseError> {
        self.punct(Token::Open, name)?;
        let px = self.number(x, x)?;
        self.punct(Token::Comma, "`,` between the coordinates")?;
        let py = self.number(y, y)?;
        self.punct(Token::Close, "`)` after the point")?;
        Ok(Vec2::new(px, py))
    }

    /// Refuses a field after a row's colour: a `,` after it on the same
    /// text line.
    fn row_end(&mut self) -> Result<(), ParseError> {
        let save = (self.lexer.pos, self.lexer.line);
        match self.lexer.next() {
            Some((Token::Comma, line)) if line == save.1 => {
                let found = match self.lexer.next() {
                    Some((token, next)) if next == line => {
                        format!(", {}", token.to_string().trim_matches('`'))
                    }
                    _ => ",".to_string(),
                };
                let kind = ParseErrorKind::ExtraField {
                    row: self.row,
                    found,
                };
                Err(self.error(line, kind))
            }
            _ => {
                (self.lexer.pos, self.lexer.line) = save;
                Ok(())
            }
        }
    }

    fn row(&mut self) -> Result<SceneLine, ParseError> {
        let p1 = self.point("`(` opening the first point", "x1", "y1")?;
        self.punct(Token::Comma, "`,` after the first point")?;
        let p2 = self.point("`(` opening the second point", "x2", "y2")?;
        self.punct(Token::Comma, "`,` after the second point")?;
        let vx = self.number("vx", "the velocity vx")?;
        self.punct(Token::Comma, "`,` after vx")?;
        let vy = self.number("vy", "the velocity vy")?;
        self.punct(Token::Comma, "`,` after vy")?;
        let color = self.color()?;
        self.row_end()?;
        Ok(SceneLine {
            p1,
            p2,
            v: Vec2::new(vx, vy),
            color,
        })
    }

    fn color(&mut self) -> Result<Color, ParseError> {
        let got = self.lexer.next();
        let Some((Token::Word(word), line)) = got else {
            return Err(self.unexpected("the colour (0 or 1)", got));
        };
        std::str::from_utf8(word)
            .ok()
            .and_then(|s| s.parse::<i64>().ok())
            .and_then(Color::from_code)
            .ok_or_else(|| {
                let kind = ParseErrorKind::BadColor {
                    row: self.row,
                    found: show(word),
                };
                self.error(line, kind)
            })
    }
}

impl Scene {
    /// A digest of the scene's values (FNV-1a over every coordinate's bits
    /// and colour code): a checkpoint names the digest of its scene, and
    /// resumes only a run of that scene.
    pub fn digest(&self) -> u64 {
        let mut hash = crate::fnv::Fnv::default();
        hash.add(self.lines.len() as u64);
        for l in &self.lines {
            for v in [l.p1.x, l.p1.y, l.p2.x, l.p2.y, l.v.x, l.v.y] {
                hash.add(v.to_bits());
            }
            hash.add(u64::from(l.color.code()));
        }
        hash.0
    }

    /// Parses a scene text. `origin` names the text in error messages
    /// (usually the file's path).
    pub fn parse(text: &[u8], origin: &str) -> Result<Self, ParseError> {
        let text = strip_bom(text);
        let mut parser = Parser {
            lexer: Lexer::new(text),
            origin,
            row: 0,
        };
        let declared = match parser.lexer.next() {
            None if text.is_empty() => return Err(parser.error(1, ParseErrorKind::Empty)),
            None => return Err(parser.error(1, ParseErrorKind::Blank)),
            Some((Token::Word(word), line)) => std::str::from_utf8(word)
                .ok()
                .and_then(|s| s.parse::<u64>().ok())
                .ok_or_else(|| {
                    let found = show(word);
                    let digits = !word.is_empty() && word.iter().all(u8::is_ascii_digit);
                    match digits {
                        true => parser.error(line, ParseErrorKind::CountTooLarge { found }),
                        false => parser.error(line, ParseErrorKind::BadCount { found }),
                    }
                })?,
            Some((token, line)) => {
                let found = match token {
                    Token::Open => "(",
                    Token::Close => ")",
                    _ => ",",
                };
                let kind = ParseErrorKind::BadCount {
                    found: found.to_string(),
                };
                return Err(parser.error(line, kind));
            }
        };

        // Never trust the declared count for the allocation.
        let capacity = rows_at_most(declared, text.len() as u64);
        let mut lines = Vec::with_capacity(capacity as usize);
        for row in 1..=declared {
            parser.row = row;
            // A clean end of file between rows is "too few rows".
            let save = (parser.lexer.pos, parser.lexer.line);
            if parser.lexer.next().is_none() {
                let kind = ParseErrorKind::TooFewRows {
                    declared,
                    found: row - 1,
                };
                return Err(parser.error(parser.lexer.eof_line(), kind));
            }
            (parser.lexer.pos, parser.lexer.line) = save;
            lines.push(parser.row()?);
        }
        if let Some((token, line)) = parser.lexer.next() {
            let found = match token {
                Token::Word(w) => show(w),
                other => other.to_string().trim_matches('`').to_string(),
            };
            return Err(parser.error(line, ParseErrorKind::TooManyRows { declared, found }));
        }
        Ok(Scene { lines })
    }

    /// [`Scene::parse`] on up to `threads` threads: a text of a megabyte
    /// or more is cut where rows start and read a piece a thread. The
    /// scene, or the error, is the one [`Scene::parse`] gives: where that
    /// cannot be known (a row across a cut, any error), the text is read
    /// again on one thread.
    pub fn parse_on(text: &[u8], origin: &str, threads: usize) -> Result<Self, ParseError> {
        if threads > 1 && text.len() >= Schedule::PARSE_SHARED_FROM {
            if let Some(scene) = pieces::parse(text, threads, Run::Threads) {
                return Ok(scene);
            }
        }
        Self::parse(text, origin)
    }

    /// Reads and parses a scene file on one thread.
    pub fn load(path: &Path) -> Result<Self, LoadError> {
        Self::load_on(path, 1)
    }

    /// Reads a scene file and parses it on up to `threads` threads (see
    /// [`Scene::parse_on`]).
    pub fn load_on(path: &Path, threads: usize) -> Result<Self, LoadError> {
        let text = std::fs::read(path).map_err(|source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self::parse_on(&text, &path.display().to_string(), threads)?)
    }

    /// The lines the scene file at `path` can hold at most, by its first
    /// number and its size (without reading the rest), and its size: what
    /// a run must plan memory for before it reads the file. `None` where
    /// the file cannot be read or does not start with a count.
    pub fn peek_lines(path: &Path) -> Option<(u64, u64)> {
        use std::io::Read;
        let mut file = std::fs::File::open(path).ok()?;
        // A pipe (`/dev/stdin`, `<(...)`) is read once, by the loading
        // itself, and says no size.
        let size = Some(file.metadata().ok()?).filter(|m| m.is_file())?.len();
        let mut head = Vec::with_capacity(64);
        Read::by_ref(&mut file)
            .take(64)
            .read_to_end(&mut head)
            .ok()?;
        let head = strip_bom(&head);
        let start = head.iter().position(|c| !c.is_ascii_whitespace())?;
        let digits = head[start..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        let declared = std::str::from_utf8(&head[start..start + digits]).ok()?;
        Some((rows_at_most(declared.parse().ok()?, size), size))
    }

    /// The scene as text that [`Scene::parse`] reads back to an identical
    /// scene (every value printed as the shortest decimal that round-trips).
    pub fn to_text(&self) -> String {
        let mut out = Vec::with_capacity(16 + self.lines.len() * 64);
        write_scene(&mut out, self.lines.len(), self.lines.iter().copied())
            .expect("writing to memory");
        String::from_utf8(out).expect("scene text is ASCII")
    }
}

/// The rows a text of `len` bytes that declares `declared` can hold: a row
/// takes at least 15 bytes, which bounds how many the text can hold.
fn rows_at_most(declared: u64, len: u64) -> u64 {
    declared.min(len / 15 + 1)
}

/// `text` without a UTF-8 byte-order mark, which some editors put first
/// and which says only how the text is encoded.
fn strip_bom(text: &[u8]) -> &[u8] {
    text.strip_prefix(b"\xef\xbb\xbf").unwrap_or(text)
}

/// Writes a scene of `count` lines, given one at a time, in the format
/// [`Scene::parse`] reads: huge generated scenes never need to be held in
/// memory. Returns an error if writing fails or if `lines` does not yield
/// exactly `count` lines (the header would lie).
pub(crate) fn write_scene(
    out: &mut (impl Write + ?Sized),
    count: usize,
    lines: impl IntoIterator<Item = SceneLine>,
) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    writeln!(out, "{count}")?;
    let mut written = 0;
    for l in lines {
        // Streams of millions of lines stop on a signal (where signals are
        // caught), so that an interrupted file is removed, not finished.
        #[cfg(feature = "signals")]
        if written % 4096 == 0 {
            if let Some(signal) = crate::stop::requested() {
                return Err(std::io::Error::other(format!(
                    "stopped by {}",
                    signal.name()
                )));
            }
        }
        writeln!(
            out,
            "({}, {}), ({}, {}), {}, {}, {}",
            l.p1.x,
            l.p1.y,
            l.p2.x,
            l.p2.y,
            l.v.x,
            l.v.y,
            l.color.code()
        )?;
        written += 1;
    }
    if written != count {
        return Err(std::io::Error::other(format!(
            "declared {count} lines but wrote {written}"
        )));
    }
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every spelling of a number reads as Rust's reader reads it: the
    /// plain decimals by the fast path, the rest by Rust's.
    #[test]
    fn numbers_read_as_rust_reads_them_however_spelt() {
        use proptest::prelude::*;
        use proptest::test_runner::TestRunner;
        let spellings = prop::sample::select(vec![0usize, 1, 2, 3, 4, 5, 6]);
        let mut runner = TestRunner::default();
        let strategy = (any::<u64>(), spellings, -40i32..40);
        runner
            .run(&strategy, |(bits, spelling, scale)| {
                let x = f64::from_bits(bits);
                prop_assume!(x.is_finite());
                let x = x.abs().min(1e300) * 10f64.powi(scale) % 1e6;
                let word = match spelling {
                    0 => format!("{x:.6}"),
                    1 => format!("{x}"),
                    2 => format!("{x:e}"),
                    3 => format!("+{x:.3}"),
                    4 => format!("-{x:.20}"),
                    5 => format!("{:.0}.", x.trunc()),
                    _ => format!("-00{x:.9}"),
                };
                let text = format!("1\n({word}, 0.6), (0.7, 0.8), {word}, 0.0, 1\n");
                let scene = Scene::parse(text.as_bytes(), "t.in");
                let expected = word.parse::<f64>().ok().filter(|v| v.is_finite());
                match (scene, expected) {
                    (Ok(scene), Some(v)) => {
                        let line = &scene.lines[0];
                        prop_assert_eq!(line.p1.x.to_bits(), v.to_bits(), "{}", word);
                        prop_assert_eq!(line.v.x.to_bits(), v.to_bits(), "{}", word);
                    }
                    (Err(_), None) => {}
                    (got, expected) => prop_assert!(false, "{word}: {got:?} against {expected:?}"),
                }
                Ok(())
            })
            .unwrap();
    }

    fn parse(text: &str) -> Result<Scene, ParseError> {
        Scene::parse(text.as_bytes(), "test.in")
    }

    fn err(text: &str) -> (usize, String) {
        let e = parse(text).unwrap_err();
        assert!(
            e.to_string().starts_with(&format!("test.in:{}: ", e.line)),
            "{e}"
        );
        (e.line, e.kind.to_string())
    }

    #[test]
    fn reads_the_course_formats() {
        let s = parse(
            "3\n(276, 206), (293, 219), -0.19221, -0.055276, 0\n\
             (291.000000, 540.000000), (291.469136, 540.000000), -00.208073, 000.454649, 1\n\
             (1,1),(1,1),+5,-0,0\n",
        )
        .unwrap();
        assert_eq!(s.lines.len(), 3);
        assert_eq!(s.lines[0].p1, Vec2::new(276.0, 206.0));
        assert_eq!(s.lines[0].v, Vec2::new(-0.19221, -0.055276));
        assert_eq!(s.lines[1].v, Vec2::new(-0.208073, 0.454649));
        assert_eq!(s.lines[1].color, Color::Gray);
        // Zero-length lines are valid.
        assert_eq!(s.lines[2].p1, s.lines[2].p2);
        assert_eq!(s.lines[2].v.x, 5.0);
    }

    #[test]
    fn whitespace_is_free_and_rows_may_span_lines() {
        let s =
            parse("  2 \r\n\n( 1 ,2 ) ,\t(3,4),5,6,\n0\n\n(1e2, 2.5E-1), (0, 0), 0, 0, 1").unwrap();
        assert_eq!(s.lines[0].p2, Vec2::new(3.0, 4.0));
        assert_eq!(s.lines[0].color, Color::Red);
        assert_eq!(s.lines[1].p1, Vec2::new(100.0, 0.25));
    }

    #[test]
    fn an_empty_scene_is_valid() {
        assert_eq!(parse("0\n").unwrap().lines.len(), 0);
    }

    #[test]
    fn empty_file() {
        assert_eq!(
            err(""),
            (
                1,
                "the file is empty; expected the number of lines first".into()
            )
        );
        assert_eq!(
            err("\n\n  \n"),
            (
                1,
                "the file has only blank lines; expected the number of lines first".into()
            )
        );
    }

    #[test]
    fn a_field_after_the_colour_is_named() {
        let (line, msg) = err("1\n(1, 2), (3, 4), 0.1, 0.2, 0, 7\n");
        assert_eq!(line, 2);
        assert!(
            msg.starts_with("row 1: an extra field after the colour, `, 7`"),
            "{msg}"
        );
        let (line, msg) = err("2\n(1, 2), (3, 4), 0, 0, 0,\n(1, 2), (3, 4), 0, 0, 0\n");
        assert_eq!(line, 2);
        assert!(
            msg.starts_with("row 1: an extra field after the colour, `,`"),
            "{msg}"
        );
    }

    #[test]
    fn a_byte_order_mark_is_passed_over() {
        let scene = Scene::parse(b"\xef\xbb\xbf1\n(1, 2), (3, 4), 0, 0, 1\n", "bom.in").unwrap();
        assert_eq!(scene.lines.len(), 1);
        assert_eq!(scene, parse("1\n(1, 2), (3, 4), 0, 0, 1\n").unwrap());
    }

    #[test]
    fn bad_count() {
        let (line, msg) = err("two\n");
        assert_eq!(line, 1);
        assert!(
            msg.contains("number of lines") && msg.contains("`two`"),
            "{msg}"
        );
        assert!(err("-1\n").1.contains("`-1`"));
        assert!(err("1.5\n").1.contains("`1.5`"));
        assert!(err("(1, 2), (3, 4), 0, 0, 0\n").1.contains("found `(`"));
    }

    #[test]
    fn too_few_rows() {
        let (line, msg) = err("3\n(1, 2), (3, 4), 0, 0, 0\n(1, 2), (3, 4), 0, 0, 0\n");
        assert_eq!(line, 3);
        assert_eq!(msg, "the file declares 3 lines but ends after 2");
    }

    #[test]
    fn too_many_rows() {
        let (line, msg) = err("1\n(1, 2), (3, 4), 0, 0, 0\n(5, 6), (7, 8), 0, 0, 0\n");
        assert_eq!(line, 3);
        assert!(msg.contains("declares 1 line but has more rows"), "{msg}");
        assert_eq!(err("1\n(1, 2), (3, 4), 0, 0, 0 junk\n").0, 2);
    }

    #[test]
    fn malformed_rows_say_what_was_expected() {
        let (line, msg) = err("1\n(1, 2) (3, 4), 0, 0, 0\n");
        assert_eq!(line, 2);
        assert_eq!(msg, "row 1: expected `,` after the first point, found `(`");
        let (_, msg) = err("1\n(1, 2), (3, 4), 0, 0\n");
        assert_eq!(
            msg,
            "row 1: expected `,` after vy, found the end of the file"
        );
        let (_, msg) = err("1\n(1, x), (3, 4), 0, 0, 0\n");
        assert_eq!(msg, "row 1: expected y1, found `x`");
        let (_, msg) = err("2\n(1, 2), (3, 4), 0, 0, 0\n1, 2), (3, 4), 0, 0, 0\n");
        assert_eq!(
            msg,
            "row 2: expected `(` opening the first point, found `1`"
        );
        let (line, msg) = err("1\n(1, 2), (3, 4),\n 0, 0.0.0, 0\n");
        assert_eq!(line, 3);
        assert_eq!(msg, "row 1: expected the velocity vy, found `0.0.0`");
    }

    #[test]
    fn non_finite_values_are_refused() {
        let (line, msg) = err("1\n(1, 2), (inf, 4), 0, 0, 0\n");
        assert_eq!(line, 2);
        assert_eq!(msg, "row 1: x2 must be a finite number, found `inf`");
        assert!(err("1\n(1, 2), (3, 4), NaN, 0, 0\n")
            .1
            .contains("vx must be a finite"));
        assert!(err("1\n(1, 1e999), (3, 4), 0, 0, 0\n")
            .1
            .contains("y1 must be a finite"));
    }

    #[test]
    fn bad_colours_are_refused() {
        let (_, msg) = err("1\n(1, 2), (3, 4), 0, 0, 2\n");
        assert_eq!(msg, "row 1: colour must be 0 (red) or 1 (gray), found `2`");
        assert!(err("1\n(1, 2), (3, 4), 0, 0, 0.5\n")
            .1
            .contains("found `0.5`"));
        assert!(err("1\n(1, 2), (3, 4), 0, 0, red\n")
            .1
            .contains("found `red`"));
    }

    #[test]
    fn binary_garbage_is_an_error_not_a_panic() {
        let e = Scene::parse(&[0xff, 0xfe, b'\n', 0x00], "bin.in").unwrap_err();
        assert_eq!(e.line, 1);
        assert!(matches!(e.kind, ParseErrorKind::BadCount { .. }));
    }

    #[test]
    fn huge_declared_counts_do_not_allocate_up_front() {
        let (_, msg) = err("18446744073709551615\n(1, 2), (3, 4), 0, 0, 0\n");
        assert!(msg.contains("ends after 1"), "{msg}");
    }

    #[test]
    fn long_tokens_are_shortened_in_messages() {
        let long = "9".repeat(100) + "x";
        let (_, msg) = err(&format!("{long}\n"));
        assert!(msg.contains("...") && msg.len() < 150, "{msg}");
    }

    #[test]
    fn written_scenes_read_back_identically() {
        let text = "2\n(0.1, 1e-7), (1179.999999999, 800), -0.19221, 0.1, 1\n\
                    (3, 3), (3, 3), 123456.75, -0.000001, 0\n";
        let scene = parse(text).unwrap();
        let again = parse(&scene.to_text()).unwrap();
        assert_eq!(scene, again);
    }

    #[test]
    fn missing_files_name_the_path() {
        let e = Scene::load(Path::new("/nonexistent/dir/x.in")).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with("/nonexistent/dir/x.in: cannot read the file"),
            "{msg}"
        );
    }
}
