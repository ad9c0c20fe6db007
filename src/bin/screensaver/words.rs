//! What the command says in its own words: the job's conflicts named by
//! the flags that made them, and what a run has to say beside its results.

use crate::job::{Conflict, FileRole, Note};

/// `n` things, in the singular for one.
pub(crate) fn plural(n: u64, thing: &str) -> String {
    match n {
        1 => format!("1 {thing}"),
        n => format!("{n} {thing}s"),
    }
}

/// The flag (or argument) that names a file in this part.
fn flag(role: FileRole) -> &'static str {
    match role {
        FileRole::Scene => "INPUT",
        FileRole::Resume => "--resume",
        FileRole::State => "--state-out",
        FileRole::Checkpoint => "--checkpoint",
        FileRole::Pictures => "--render",
        FileRole::Results => "standard output (`>`)",
    }
}

/// The usage error for a conflict, by the flags that made it.
pub(crate) fn conflict(conflict: &Conflict) -> String {
    const SCREENS: &str = "-g, --fullscreen, --root, --window-id or under XScreenSaver";
    match conflict {
        Conflict::NoEnd => {
            format!("FRAMES is required (it may be left out only with {SCREENS})")
        }
        Conflict::PaceOffScreen => format!(
            "--speed sets the pace of a run on screen ({SCREENS}); a run without one always \
             goes as fast as it can"
        ),
        Conflict::OffScreenOnly => format!(
            "a run on screen ({SCREENS}, XSCREENSAVER_WINDOW) cannot take --render or --verify; \
             they are for runs off screen"
        ),
        Conflict::CycleOfOneScene => "--cycle sets how long each generated scene of an endless \
             run on screen is shown (no FRAMES, no INPUT); this run shows one scene"
            .into(),
        Conflict::EndlessFiles => "--state-out, --checkpoint and --resume need FRAMES: an \
             endless run has no end to write"
            .into(),
        Conflict::GeneratedAndFile => {
            "--lines, --kind and --seed choose a generated scene; they cannot go with INPUT".into()
        }
        Conflict::SameFile {
            written,
            written_path,
            other,
            other_path,
        } => {
            let (a, b) = (written_path.display(), other_path.display());
            let same = match written_path == other_path {
                true => format!("`{a}`"),
                false => format!("`{a}` and `{b}`"),
            };
            let (written, other) = (flag(*written), flag(*other));
            format!(
                "{written} and {other} name the same file ({same}): the run would write over \
                 it; give {written} another file"
            )
        }
    }
}

/// What a run says on stderr beside its results.
pub(crate) fn note(note: &Note) -> String {
    match note {
        Note::GifFrames { every, frames } => format!(
            "--render: a GIF frame every {every} steps (about {frames} frames); \
             --render-every 1 for every step"
        ),
        Note::Scenes {
            shown,
            first_seed,
            last_seed,
        } => format!(
            "showed {shown} scenes (seeds {first_seed} to {last_seed}); the results are the last one's"
        ),
        Note::Stopped { signal, step, of } => {
            let of = of.map_or(String::new(), |n| format!(" of {n}"));
            format!("stopped by {} after step {step}{of}", signal.name())
        }
        Note::Resumed { path, step } => {
            format!("resumed from {} at step {step}", path.display())
        }
        Note::Verified {
            steps,
            slivers,
            first_sliver,
        } => {
            let agreed =
                format!("verified: {steps} steps, every event as the all-pairs detector found it");
            if *slivers == 0 {
                return agreed;
            }
            let first = first_sliver.map_or(String::new(), |(step, e)| {
                format!(": the first at step {step}, lines {} and {}", e.first, e.second)
            });
            format!(
                "{agreed} but {}, the documented exception (a line sliding along its own \
                 supporting line past a segment on it; see the README, Conformance){first}",
                plural(*slivers, "sliver event")
            )
        }
    }
}
