//! The two names a line goes by. A line's *id* is its place in the scene
//! as read: ids order the events the contract resolves and name the lines
//! in every output. A *slot* is where the world stores the line this step
//! (see [`crate::storage`]): the same as its id until a detector has the
//! lines stored in its own order. Each is its own type, so that one is
//! never taken for the other; a detector's places in its own arrays are
//! plain indices.

use std::fmt;

/// A line's id: its place in the scene as read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct LineId(pub u32);

/// Where the world stores a line this step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct Slot(pub u32);

/// A name of a line that indexes an array of lines stored by that name.
pub trait Index: Copy + Ord + fmt::Debug {
    /// The index into lines stored by this name.
    fn at(self) -> usize;
}

impl Index for LineId {
    #[inline(always)]
    fn at(self) -> usize {
        self.0 as usize
    }
}

impl Index for Slot {
    #[inline(always)]
    fn at(self) -> usize {
        self.0 as usize
    }
}

impl Slot {
    /// The id of the line in this slot while the lines are stored by id.
    #[inline(always)]
    pub(crate) fn as_id(self) -> LineId {
        LineId(self.0)
    }
}

impl fmt::Display for LineId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}
