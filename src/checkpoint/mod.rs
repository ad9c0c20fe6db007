//! The state of a run as text: the reference's state rows, and checkpoints
//! that a run can be resumed from.
//!
//! A state is one row per line in id order, `id p1.x p1.y p2.x p2.y v.x v.y`
//! in box coordinates, each value the shortest decimal that reads back to
//! the same `f64`, written as the reference wrote them (`1e-05`, `1e+16`,
//! `NaN`), so a state written here matches the reference's files byte for
//! byte.
//!
//! A checkpoint is a state with a header and each line's colour code
//! after its row:
//!
//! ```text
//! # screensaver checkpoint v2
//! # scene: 3 lines, digest 6c1f0e3b9a2d4c55
//! # steps: 1200
//! # line-wall collisions: 17
//! # line-line collisions: 240
//! 0 0.6264977220338983 0.6865993543749994 0.64514178983 0.71409935437 -0.00011 -0.00016 1
//! ...
//! # checksum: 9d2c5680f1a3e47b
//! ```
//!
//! The digest identifies the scene the run started from (its values, not
//! its spelling), so that a checkpoint is never resumed on another scene.
//! The checksum (64-bit FNV-1a of every byte before its line) makes any
//! edit or damage a located error rather than another run.

pub(crate) mod pieces;

use crate::counters::Counters;
use crate::fnv::Fnv;
use crate::line::{Color, Line};
use crate::plural;
use crate::rows::{push_row, write_rows};
use crate::scene::Scene;
use crate::schedule::Schedule;
use crate::scoped::Run;
use crate::Vec2;
use crate::World;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The first line of every checkpoint.
const MAGIC: &str = "# screensaver checkpoint v2";

/// The first line of the checkpoints of earlier versions, which had no
/// checksum.
const MAGIC_V1: &str = "# screensaver checkpoint v1";

/// The start of a checkpoint's last line.
const CHECKSUM: &str = "# checksum: ";

/// A run's whole state: enough to continue it bit for bit.
///
/// ```
/// use screensaver::checkpoint::Checkpoint;
/// use screensaver::{DetectorConfig, DetectorKind, Scene, World};
///
/// let scene = Scene::built_in();
/// let mut world = World::with_detector(&scene, DetectorKind::Sweep);
/// world.run(40);
/// let mut text = Vec::new();
/// Checkpoint::write(&world, scene.digest(), &mut text).unwrap();
///
/// // Later: read it back, check it continues this scene, and go on.
/// let saved = Checkpoint::parse(&text, "run.ckpt").unwrap();
/// saved.continues("run.ckpt", &scene, scene.digest(), 101).unwrap();
/// let mut resumed = saved.resume(DetectorKind::Sweep, &DetectorConfig::default()).unwrap();
/// resumed.run(61);
/// world.run(61);
/// assert_eq!(resumed.counters(), world.counters());
/// assert_eq!(resumed.lines(), world.lines());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// The [`Scene::digest`] of the scene the run started from.
    pub scene_digest: u64,
    /// Steps run.
    pub steps: u64,
    /// The counters after those steps.
    pub counters: Counters,
    /// Every line, by id, in box coordinates.
    pub lines: Vec<Line>,
    /// Every line's colour, by id.
    pub colors: Vec<Color>,
}

/// What is wrong with a checkpoint text, and where.
#[derive(Debug, thiserror::Error)]
#[error("{origin}:{line}: {problem}")]
pub struct ParseError {
    /// The file (or other name) the text came from.
    pub origin: String,
    /// The line, counting from 1.
    pub line: usize,
    /// What is wrong there.
    pub problem: String,
}

/// A checkpoint file that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The text is not a checkpoint.
    #[error(transparent)]
    Parse(#[from] ParseError),
}

/// A writer that hashes what it passes on.
struct Hashing<'a> {
    out: &'a mut dyn std::io::Write,
    hash: Fnv,
}

impl std::io::Write for Hashing<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.out.write(buf)?;
        self.hash.bytes(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// Writes the whole state of `world` to `out` in the reference's state
/// format: one row per line, `id p1.x p1.y p2.x p2.y v.x v.y`, each value
/// the shortest decimal that reads back to the same `f64`; a block of rows
/// at a time, formatted on the world's threads.
pub fn write_state(world: &World, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    write_rows(out, &world.lines(), None, world.threads())
}

/// Writes the state of `world` to the file `path`, whole or not at all.
pub fn save_state(world: &World, path: &Path) -> Result<(), crate::OutputError> {
    crate::output::write_with(path, |out| write_state(world, out))
}

/// Writes the checkpoint of a run of the scene with digest `scene_digest`
/// after `steps` steps, holding `lines` and `colors`, to `out`, its rows
/// formatted on up to `threads` threads.
pub(crate) fn write_checkpoint(
    out: &mut dyn std::io::Write,
    scene_digest: u64,
    steps: u64,
    counters: Counters,
    (lines, colors): (&[Line], &[Color]),
    threads: usize,
) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut hashed = Hashing {
        out,
        hash: Fnv::default(),
    };
    writeln!(hashed, "{MAGIC}")?;
    writeln!(
        hashed,
        "# scene: {}, digest {scene_digest:016x}",
        plural(lines.len() as u64, "line")
    )?;
    writeln!(hashed, "# steps: {steps}")?;
    writeln!(hashed, "# line-wall collisions: {}", counters.wall)?;
    writeln!(hashed, "# line-line collisions: {}", counters.line)?;
    write_rows(&mut hashed, lines, Some(colors), threads)?;
    let sum = hashed.hash.0;
    writeln!(out, "{CHECKSUM}{sum:016x}")
}

/// Why a checkpoint cannot continue a run (named by the checkpoint's name
/// and the line that says so).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ResumeError {
    /// The checkpoint is of another scene.
    #[error(
        "{name}:2: the checkpoint is of another scene ({lines} lines, digest {digest:016x}; \
         this scene has {scene_lines} lines, digest {scene_digest:016x})"
    )]
    OtherScene {
        /// The checkpoint's name.
        name: String,
        /// Its lines.
        lines: usize,
        /// Its scene's digest.
        digest: u64,
        /// The scene's lines.
        scene_lines: usize,
        /// The scene's digest.
        scene_digest: u64,
    },
    /// A counter larger than any run of the checkpoint's lines and steps
    /// reaches (a line hits the walls at most once a step, a pair meets at
    /// most once): a run carrying it on could wrap past 2^64.
    #[error(
        "{name}:{line}: {value} {kind} collisions are more than {} can have in {steps} steps \
         (at most {most})",
        crate::plural(*lines as u64, "line")
    )]
    Counter {
        /// The checkpoint's name.
        name: String,
        /// The counter's line.
        line: usize,
        /// `line-wall` or `line-line`.
        kind: &'static str,
        /// The counter.
        value: u64,
        /// Its lines.
        lines: usize,
        /// Its step.
        steps: u64,
        /// The most such a run counts.
        most: u64,
    },
    /// The checkpoint is past the run's last step.
    #[error("{name}:3: the checkpoint is at step {step}, past this run's {steps} steps")]
    PastTheEnd {
        /// The checkpoint's name.
        name: String,
        /// Its step.
        step: u64,
        /// The steps the run is to take.
        steps: u64,
    },
}

impl Checkpoint {
    /// Writes a checkpoint of `world`'s run so far to `out`;
    /// `scene_digest` is the [`Scene::digest`] of the scene the run started
    /// from.
    pub fn write(
        world: &World,
        scene_digest: u64,
        out: &mut dyn std::io::Write,
    ) -> std::io::Result<()> {
        let lines = world.lines();
        let counters = world.counters();
        let rows = (&lines[..], world.colors());
        write_checkpoint(
            out,
            scene_digest,
            world.steps(),
            counters,
            rows,
            world.threads(),
        )
    }

    /// Checks that this checkpoint (named `name` in errors) continues a run
    /// of `scene` (whose digest, [`Scene::digest`], is `digest`) that is to
    /// take `steps` steps in all.
    pub fn continues(
        &self,
        name: &str,
        scene: &Scene,
        digest: u64,
        steps: u64,
    ) -> Result<(), ResumeError> {
        if self.lines.len() != scene.lines.len() || self.scene_digest != digest {
            return Err(ResumeError::OtherScene {
                name: name.to_string(),
                lines: self.lines.len(),
                digest: self.scene_digest,
                scene_lines: scene.lines.len(),
                scene_digest: digest,
            });
        }
        if self.steps > steps {
            return Err(ResumeError::PastTheEnd {
                name: name.to_string(),
                step: self.steps,
                steps,
            });
        }
        let n = self.lines.len() as u64;
        let pairs = n.saturating_mul(n.saturating_sub(1)) / 2;
        for (line, kind, value, most) in [
            (
                4,
                "line-wall",
                self.counters.wall,
                self.steps.saturating_mul(n),
            ),
            (
                5,
                "line-line",
                self.counters.line,
                self.steps.saturating_mul(pairs),
            ),
        ] {
            if value > most {
                return Err(ResumeError::Counter {
                    name: name.to_string(),
                    line,
                    kind,
                    value,
                    lines: self.lines.len(),
                    steps: self.steps,
                    most,
                });
            }
        }
        Ok(())
    }

    /// A world continuing the run this checkpoint recorded (its lines,
    /// colours, step count and counters), with a detector chosen by kind
    /// and tuned by `config`. Detectors keep nothing from step to step that
    /// changes results, so the run goes on exactly as it would have.
    pub fn resume(
        self,
        kind: crate::DetectorKind,
        config: &crate::DetectorConfig,
    ) -> Result<World, crate::ThreadsError> {
        let (lines, colors, at) = (self.lines, self.colors, (self.steps, self.counters));
        World::continuing(lines, colors, at, kind, config)
    }

    /// The checkpoint as text ([`Checkpoint::parse`] reads it back).
    pub fn to_text(&self) -> String {
        let mut out = Vec::new();
        write_checkpoint(
            &mut out,
            self.scene_digest,
            self.steps,
            self.counters,
            (&self.lines, &self.colors),
            1,
        )
        .expect("writing to memory");
        String::from_utf8(out).expect("checkpoints are ASCII")
    }

    /// Reads a checkpoint file.
    pub fn load(path: &Path) -> Result<Checkpoint, LoadError> {
        Self::load_on(path, 1)
    }

    /// Reads a checkpoint file and parses it on up to `threads` threads
    /// (see [`Checkpoint::parse_on`]).
    pub fn load_on(path: &Path, threads: usize) -> Result<Checkpoint, LoadError> {
        let text = std::fs::read(path).map_err(|source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self::parse_on(&text, &path.display().to_string(), threads)?)
    }

    /// [`Checkpoint::parse`] on up to `threads` threads: a text of a
    /// megabyte or more has its rows read in pieces, cut at newlines, while
    /// another thread sums it. The checkpoint, or the error, is the one
    /// [`Checkpoint::parse`] gives: on any problem the text is read again
    /// on one thread, which names it.
    pub fn parse_on(text: &[u8], origin: &str, threads: usize) -> Result<Checkpoint, ParseError> {
        if threads > 1 && text.len() >= Schedule::PARSE_SHARED_FROM {
            if let Some(checkpoint) = pieces::parse(text, threads, Run::Threads) {
                return Ok(checkpoint);
            }
        }
        Self::parse(text, origin)
    }

    /// Parses a checkpoint text; `origin` names it in errors.
    pub fn parse(text: &[u8], origin: &str) -> Result<Checkpoint, ParseError> {
        let (header, body) = Header::parse(text, origin)?;
        let Header {
            scene_digest,
            count,
            steps,
            counters,
        } = header;
        let mut rows = text[body..]
            .split(|&b| b == b'\n')
            .enumerate()
            .map(|(k, row)| {
                let row = row.strip_suffix(b"\r").unwrap_or(row);
                (k + 6, row)
            });
        let fail = |line: usize, problem: String| ParseError {
            origin: origin.to_string(),
            line,
            problem,
        };
        // Never trust the declared count for the allocation: a row takes
        // at least 16 bytes.
        let capacity = count.min(text.len() / 16 + 1);
        let mut lines = Vec::with_capacity(capacity);
        let mut colors = Vec::with_capacity(capacity);
        let mut summed = false;
        for (line, row) in rows.by_ref() {
            if let Some(sum) = row.strip_prefix(CHECKSUM.as_bytes()) {
                let at = row.as_ptr() as usize - text.as_ptr() as usize;
                let mut hash = Fnv::default();
                hash.bytes(&text[..at]);
                // The line exactly as written: 16 lower-case hex digits and
                // a newline that ends the file.
                let spelled = sum.get(..16).and_then(hex16);
                let raw = &text[at + CHECKSUM.len()..];
                let written = match (spelled, raw.get(16)) {
                    (Some(w), Some(b'\n')) => w,
                    _ => {
                        return Err(fail(
                            line,
                            format!(
                                "expected `{CHECKSUM}` and 16 hex digits (lower-case), then a \
                                 newline, found `{}`",
                                show(&String::from_utf8_lossy(row))
                            ),
                        ))
                    }
                };
                if written != hash.0 {
                    return Err(changed(text, origin, line, written, hash.0));
                }
                if raw.len() > 17 {
                    let later = rows.find(|(_, r)| !r.is_empty()).map(|(k, _)| k);
                    return Err(fail(
                        later.unwrap_or(line + 1),
                        "text after the checksum, which ends the file".to_string(),
                    ));
                }
                summed = true;
                break;
            }
            if row.is_empty() {
                // Only the end of the file may follow a blank line.
                if let Some((later, _)) = rows.find(|(_, r)| !r.is_empty()) {
                    return Err(fail(later, "text after a blank line".to_string()));
                }
                break;
            }
            let id = lines.len();
            if id == count {
                return Err(fail(
                    line,
                    format!(
                        "the checkpoint declares {} but has more rows",
                        plural(count as u64, "line")
                    ),
                ));
            }
            let (l, color) = parse_row(row, id).map_err(|problem| fail(line, problem))?;
            lines.push(l);
            colors.push(color);
        }
        // The line where the next row (or the checksum) should be: the
        // text's last line, if it ends without one.
        let next_line =
            || (5 + lines.len() + 1).min(text.iter().filter(|&&b| b == b'\n').count() + 1);
        if lines.len() < count {
            return Err(fail(
                next_line(),
                format!(
                    "the checkpoint declares {} but ends after {}",
                    plural(count as u64, "line"),
                    lines.len()
                ),
            ));
        }
        if !summed {
            return Err(fail(
                next_line(),
                format!("the checkpoint ends without its `{CHECKSUM}` line: cut short?"),
            ));
        }
        Ok(Checkpoint {
            scene_digest,
            steps,
            counters,
            lines,
            colors,
        })
    }
}

/// What a checkpoint's five header lines say.
struct Header {
    scene_digest: u64,
    /// The lines declared.
    count: usize,
    steps: u64,
    counters: Counters,
}

impl Header {
    /// Reads the header of `text` (`origin` names it in errors); returns
    /// it and where the sixth line, the first row, begins (the text's end
    /// if there is none).
    fn parse(text: &[u8], origin: &str) -> Result<(Header, usize), ParseError> {
        let mut rows = text.split(|&b| b == b'\n').enumerate().map(|(k, row)| {
            let row = row.strip_suffix(b"\r").unwrap_or(row);
            (k + 1, row)
        });
        let fail = |line: usize, problem: String| ParseError {
            origin: origin.to_string(),
            line,
            problem,
        };
        let mut header = |what: &str| -> Result<(usize, String), ParseError> {
            match rows.next() {
                Some((line, row)) => match std::str::from_utf8(row) {
                    Ok(row) => Ok((line, row.to_string())),
                    Err(_) => Err(fail(
                        line,
                        format!("expected {what}, found bytes that are not text"),
                    )),
                },
                None => Err(fail(1, format!("the file ends before {what}"))),
            }
        };
        let (line, magic) = header("the checkpoint header")?;
        if magic == MAGIC_V1 {
            return Err(fail(
                line,
                "a checkpoint of an earlier version, without a checksum to check it by: \
                 run again from the scene"
                    .to_string(),
            ));
        }
        if magic != MAGIC {
            return Err(fail(
                line,
                format!(
                    "not a screensaver checkpoint: expected `{MAGIC}`, found `{}`",
                    show(&magic)
                ),
            ));
        }
        let (line, scene) = header("the scene line")?;
        let (count, scene_digest) = parse_scene_line(&scene).ok_or_else(|| {
            fail(
                line,
                format!(
                    "expected `# scene: N lines, digest HEX`, found `{}`",
                    show(&scene)
                ),
            )
        })?;
        let mut number = |key: &str| -> Result<u64, ParseError> {
            let (line, row) = header(&format!("`# {key}: N`"))?;
            row.strip_prefix(&format!("# {key}: "))
                .and_then(decimal)
                .ok_or_else(|| {
                    fail(
                        line,
                        format!("expected `# {key}: N`, found `{}`", show(&row)),
                    )
                })
        };
        let steps = number("steps")?;
        let wall = number("line-wall collisions")?;
        let line_count = number("line-line collisions")?;
        let body = (text.iter().enumerate())
            .filter(|&(_, &b)| b == b'\n')
            .nth(4)
            .map_or(text.len(), |(k, _)| k + 1);
        let header = Header {
            scene_digest,
            count,
            steps,
            counters: Counters {
                wall,
                line: line_count,
            },
        };
        Ok((header, body))
    }
}

/// The error for a checkpoint whose content does not match the checksum
/// `written` on line `sum_line` (`found` is the content's): located at the
/// first row that is not spelt as the program writes rows (such a row was
/// edited), else at the checksum, saying that where the change is cannot
/// be told.
fn changed(text: &[u8], origin: &str, sum_line: usize, written: u64, found: u64) -> ParseError {
    let intro = "the file was changed after it was written";
    let sums = format!("the checksum on line {sum_line} ({written:016x}) does not match the content ({found:016x})");
    // Rows from line 6, each read back and spelt anew.
    let rows = text.split(|&b| b == b'\n').enumerate().skip(5);
    let unusual = rows
        .take_while(|(k, _)| k + 1 < sum_line)
        .enumerate()
        .find_map(|(id, (k, row))| {
            let row = row.strip_suffix(b"\r").unwrap_or(row);
            let (line, color) = parse_row(row, id).ok()?;
            let mut spelt = String::new();
            push_row(&mut spelt, id, &line);
            write!(spelt, " {}", color.code()).expect("writing to a String");
            (spelt.as_bytes() != row).then_some(k + 1)
        });
    let (line, problem) = match unusual {
        Some(line) => (
            line,
            format!("{intro}: this row is not as the program writes it, and {sums}"),
        ),
        None => (
            sum_line,
            format!(
                "{intro}: {sums}; the checksum covers every line above it, and the change \
                 keeps the program's own spelling, so where it is cannot be told"
            ),
        ),
    };
    ParseError {
        origin: origin.to_string(),
        line,
        problem,
    }
}

/// A text for an error message: at most 40 characters, control characters
/// escaped.
fn show(text: &str) -> String {
    let cut: String = text.chars().take(40).collect();
    let mut shown: String = cut.chars().flat_map(char::escape_debug).collect();
    if text.chars().count() > 40 {
        shown.push_str("...");
    }
    shown
}

/// `# scene: N lines, digest HEX` (or `1 line`).
fn parse_scene_line(row: &str) -> Option<(usize, u64)> {
    let rest = row.strip_prefix("# scene: ")?;
    let (count, rest) = rest.split_once(' ')?;
    let count = usize::try_from(decimal(count)?).ok()?;
    let rest = rest
        .strip_prefix(if count == 1 { "line" } else { "lines" })?
        .strip_prefix(", digest ")?;
    Some((count, hex16(rest.as_bytes())?))
}

/// A number as the program writes it: decimal digits, without a sign or a
/// leading zero.
fn decimal(text: &str) -> Option<u64> {
    let digits = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
    let spelled = digits && (text == "0" || !text.starts_with('0'));
    spelled.then(|| text.parse().ok()).flatten()
}

/// Sixteen lower-case hex digits, as the program writes a digest or a
/// checksum.
fn hex16(text: &[u8]) -> Option<u64> {
    let spelled = text.len() == 16 && text.iter().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'));
    let text = std::str::from_utf8(text).ok().filter(|_| spelled)?;
    u64::from_str_radix(text, 16).ok()
}

/// One row: `id p1.x p1.y p2.x p2.y v.x v.y color`, for line `id`.
fn parse_row(row: &[u8], id: usize) -> Result<(Line, Color), String> {
    let row = std::str::from_utf8(row).map_err(|_| {
        format!(
            "row {id}: bytes that are not text: `{}`",
            show(&String::from_utf8_lossy(row))
        )
    })?;
    let mut fields = [""; 8];
    let mut found = 0;
    for field in row.split_ascii_whitespace() {
        if let Some(slot) = fields.get_mut(found) {
            *slot = field;
        }
        found += 1;
    }
    if found != 8 {
        return Err(format!(
            "row {id}: expected 8 fields (id, six values, colour), found {found}: `{}`",
            show(row)
        ));
    }
    if fields[0].parse::<usize>().ok() != Some(id) {
        return Err(format!(
            "expected the row of line {id}, found id `{}`",
            show(fields[0])
        ));
    }
    let mut v = [0.0; 6];
    for (k, field) in fields[1..7].iter().enumerate() {
        v[k] = crate::decimal::read_decimal(field.as_bytes())
            .ok_or_else(|| format!("row {id}: `{}` is not a number", show(field)))?;
    }
    let color = fields[7]
        .parse::<i64>()
        .ok()
        .and_then(Color::from_code)
        .ok_or_else(|| format!("row {id}: colour `{}` is not 0 or 1", show(fields[7])))?;
    let line = Line {
        p1: Vec2::new(v[0], v[1]),
        p2: Vec2::new(v[2], v[3]),
        v: Vec2::new(v[4], v[5]),
    };
    Ok((line, color))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decimal::push_decimal;

    fn sample() -> Checkpoint {
        let l = |x: f64| Line {
            p1: Vec2::new(x, 0.6),
            p2: Vec2::new(0.7, f64::NAN),
            v: Vec2::new(-1e-5, 3e16),
        };
        Checkpoint {
            scene_digest: 0x0123_4567_89ab_cdef,
            steps: 1200,
            counters: Counters {
                wall: 17,
                line: 240,
            },
            lines: vec![l(0.55), l(-0.0)],
            colors: vec![Color::Gray, Color::Red],
        }
    }

    #[test]
    fn decimals_are_spelled_as_the_reference_spells_them() {
        let spell = |x: f64| {
            let mut s = String::new();
            push_decimal(&mut s, x);
            s
        };
        assert_eq!(spell(1e-5), "1e-05");
        assert_eq!(spell(-0.00011289491525423729), "-0.00011289491525423729");
        assert_eq!(spell(1.5e-20), "1.5e-20");
        assert_eq!(spell(1e16), "1e+16");
        assert_eq!(spell(2.5e300), "2.5e+300");
        assert_eq!(spell(0.6264977220338983), "0.6264977220338983");
        assert_eq!(spell(f64::NAN), "NaN");
        assert_eq!(spell(-f64::NAN), "-NaN");
        assert_eq!(
            "-NaN".parse::<f64>().unwrap().to_bits(),
            (-f64::NAN).to_bits()
        );
        // What x86 arithmetic makes of an invalid operation.
        let made = f64::INFINITY - f64::INFINITY;
        assert_eq!(
            spell(made).parse::<f64>().unwrap().to_bits(),
            made.to_bits()
        );
        assert_eq!(spell(-0.0), "-0.0");
        for x in [1e-5, 1.5e-20, 1e16, 2.5e300, 5e-324, f64::MAX] {
            assert_eq!(spell(x).parse::<f64>().unwrap().to_bits(), x.to_bits());
        }
    }

    #[test]
    fn a_checkpoint_reads_back_to_the_same_bits() {
        let c = sample();
        let text = c.to_text();
        assert!(text.starts_with("# screensaver checkpoint v2\n# scene: 2 lines, digest 0123456789abcdef\n# steps: 1200\n"));
        let back = Checkpoint::parse(text.as_bytes(), "c").unwrap();
        assert_eq!(back.to_text(), text);
        assert_eq!(back.lines[1].p1.x.to_bits(), (-0.0f64).to_bits());
        assert!(back.lines[0].p2.y.is_nan());
        assert_eq!(
            (back.steps, back.counters, back.colors.clone()),
            (c.steps, c.counters, c.colors.clone())
        );
    }

    #[test]
    fn damage_is_reported_with_its_line() {
        let text = sample().to_text();
        let sum = text.rsplit_once("# checksum: ").unwrap().1.trim_end();
        assert!(sum.bytes().any(|b| b.is_ascii_alphabetic()), "{sum}");
        let cases: Vec<(String, &str)> = vec![
            (String::new(), "c:1: not a screensaver checkpoint"),
            (
                text.replace("v2", "v3"),
                "c:1: not a screensaver checkpoint",
            ),
            (
                text.replace("v2", "v1"),
                "c:1: a checkpoint of an earlier version",
            ),
            (
                text.replace("# steps: 1200", "# steps: many"),
                "c:3: expected `# steps: N`",
            ),
            (
                text.replace("digest 0123", "digest 0z23"),
                "c:2: expected `# scene",
            ),
            (
                text.replace(" 0.55 ", " 0.5.5 "),
                "c:6: row 0: `0.5.5` is not a number",
            ),
            (
                text.replace("NaN -1e-05 3e+16 0", "NaN -1e-05 3e+16 7"),
                "c:7: row 1: colour `7` is not 0 or 1",
            ),
            (
                text.replace("\n1 ", "\n2 "),
                "c:7: expected the row of line 1, found id `2`",
            ),
            (
                text.replace("2 lines", "3 lines"),
                "c:8: the file was changed after it was written",
            ),
            (
                text.replace("2 lines", "1 line"),
                "c:7: the checkpoint declares 1 line but has more rows",
            ),
            (format!("{text}\n5"), "c:10: text after the checksum"),
            (
                text[..text.find("# checksum").unwrap()].to_string(),
                "c:8: the checkpoint ends without its `# checksum: ` line",
            ),
            (
                text.replace("# checksum: ", "# checksum: 0"),
                "c:8: expected `# checksum: ` and 16 hex digits",
            ),
            (
                text.replace("\n1 ", "\n1 \u{1b}"),
                "c:7: row 1: `\\u{1b}-0.0` is not a number",
            ),
            // Only the spelling the program writes: lower-case hex, one
            // newline that ends the file, numbers without sign or zeros.
            (
                text.replace(sum, &sum.to_uppercase()),
                "c:8: expected `# checksum: ` and 16 hex digits",
            ),
            (
                text.replace(&format!("{sum}\n"), &format!("{sum}\r\n")),
                "c:8: expected `# checksum: ` and 16 hex digits",
            ),
            (
                format!("{text}\n\n"),
                "c:9: text after the checksum, which ends the file",
            ),
            (
                text.replace("# steps: 1200", "# steps: +1200"),
                "c:3: expected `# steps: N`",
            ),
            (
                text.replace("# steps: 1200", "# steps: 01200"),
                "c:3: expected `# steps: N`",
            ),
            (
                text.replace("2 lines", "02 lines"),
                "c:2: expected `# scene",
            ),
        ];
        for (bad, expected) in cases {
            let err = Checkpoint::parse(bad.as_bytes(), "c")
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with(expected),
                "{err:?} should start with {expected:?}"
            );
        }
        // Edits that keep the syntax: the steps, a counter, one bit of a
        // coordinate, a colour. Each is refused at the checksum's line, as
        // a change whose place cannot be told.
        let edits = [
            text.replace("# steps: 1200", "# steps: 1201"),
            text.replace("collisions: 17", "collisions: 18"),
            text.replace(" 0.55 ", " 0.5500000000000002 "),
            text.replace("3e+16 0", "3e+16 1"),
        ];
        for edited in edits {
            assert_ne!(edited, text);
            let err = Checkpoint::parse(edited.as_bytes(), "c")
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("c:8: the file was changed after it was written: the checksum")
                    && err.contains("cannot be told"),
                "{err}"
            );
        }
        // A row spelt otherwise than the program spells it is named.
        for (edited, line) in [
            (text.replace(" 0.55 ", " 0.550 "), 6),
            (text.replace("3e+16 0", "3e16 0"), 7),
        ] {
            let err = Checkpoint::parse(edited.as_bytes(), "c")
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with(&format!(
                    "c:{line}: the file was changed after it was written: this row"
                )),
                "{err}"
            );
        }
        let err = Checkpoint::parse(b"\xff\xfe", "c").unwrap_err().to_string();
        assert!(
            err.starts_with("c:1: expected the checkpoint header"),
            "{err}"
        );
    }

    #[test]
    fn the_digest_tells_scenes_apart() {
        let a = crate::Scene::built_in();
        let mut b = a.clone();
        b.lines[5].v.x = f64::from_bits(b.lines[5].v.x.to_bits() ^ 1);
        assert_eq!(a.digest(), a.clone().digest());
        assert_ne!(a.digest(), b.digest());
    }

    #[test]
    fn a_checkpoint_continues_only_its_own_scene_within_the_run() {
        let scene = crate::generate::generate(crate::generate::SceneKind::Grid, 2, 3);
        let digest = scene.digest();
        let saved = Checkpoint {
            scene_digest: digest,
            ..sample()
        };
        assert_eq!(saved.continues("a.ckpt", &scene, digest, 1200), Ok(()));
        let past = saved.continues("a.ckpt", &scene, digest, 1199).unwrap_err();
        assert_eq!(
            past.to_string(),
            "a.ckpt:3: the checkpoint is at step 1200, past this run's 1199 steps"
        );
        let other = crate::Scene::built_in();
        let wrong = saved
            .continues("a.ckpt", &other, other.digest(), 5000)
            .unwrap_err();
        assert!(wrong
            .to_string()
            .starts_with("a.ckpt:2: the checkpoint is of another scene (2 lines, digest "));
        // Counters no run of 2 lines reaches in 1,200 steps.
        let mut high = saved.clone();
        high.counters.wall = 2401;
        assert_eq!(
            high.continues("a.ckpt", &scene, digest, 5000)
                .unwrap_err()
                .to_string(),
            "a.ckpt:4: 2401 line-wall collisions are more than 2 lines can have in 1200 steps \
             (at most 2400)"
        );
        high.counters.wall = 2400;
        assert_eq!(high.continues("a.ckpt", &scene, digest, 5000), Ok(()));
        high.counters.line = u64::MAX;
        let err = high.continues("a.ckpt", &scene, digest, 5000).unwrap_err();
        assert!(err
            .to_string()
            .starts_with("a.ckpt:5: 18446744073709551615 line-line"));
    }

    /// Numbers and hex digits only as the program writes them.
    #[test]
    fn numbers_are_read_only_as_written() {
        assert_eq!(decimal("1200"), Some(1200));
        assert_eq!(decimal("0"), Some(0));
        for bad in ["+5", "05", "", "-1", "1 ", "18446744073709551616"] {
            assert_eq!(decimal(bad), None, "{bad}");
        }
        assert_eq!(hex16(b"0123456789abcdef"), Some(0x0123_4567_89ab_cdef));
        for bad in [
            &b"0123456789ABCDEF"[..],
            b"+123456789abcdef",
            b"0123456789abcde",
        ] {
            assert_eq!(hex16(bad), None);
        }
    }
}
