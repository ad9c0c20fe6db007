//! The Windows screen saver's arguments (`src/bin/screensaver-scr/args.rs`),
//! tested on every system: the screen saver itself builds only for Windows
//! (`scripts/cross.sh windows`), where its behaviour is tested under Wine.

// The module's tests use only part of what the screen saver uses.
#![allow(dead_code)]

#[path = "../src/bin/screensaver-scr/args.rs"]
mod args;
