//! A build watched from another thread: its progress count and its cancel test (the BVH's,
//! and the density volume's, which re-exports it).

use std::sync::atomic::{AtomicU64, Ordering};

/// Who watches a build from another thread: a progress count and a cancel test.
#[derive(Clone, Copy)]
pub struct Watch<'a> {
    /// Gains the units of work finished, for a progress display. Each builder says what a
    /// unit is; for a BVH, the primitives placed in finished subtrees (up to
    /// [`crate::Geometry::prim_count`]).
    pub done: &'a AtomicU64,
    /// Asked between pieces of work (for a BVH: its stages and each subtree of at most a
    /// few thousand primitives, about a millisecond); once it returns true the build skips
    /// what is left and returns an error that says it was cancelled ([`Cancelled`] for a
    /// BVH).
    pub cancelled: &'a (dyn Fn() -> bool + Sync),
}

/// A watched build stopped because its [`Watch::cancelled`] said so.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the build was cancelled")]
pub struct Cancelled;

impl Watch<'_> {
    /// Adds `n` finished units.
    pub(crate) fn add(&self, n: usize) {
        self.done.fetch_add(n as u64, Ordering::Relaxed);
    }

    /// [`Cancelled`] once the build is no longer wanted.
    pub(crate) fn check(&self) -> Result<(), Cancelled> {
        if (self.cancelled)() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}
