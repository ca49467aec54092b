//! The collapse of a binary tree into 4-wide nodes over all threads: a first pass counts the
//! 4-wide nodes under every binary node that becomes one, a second writes each subtree into
//! its own slice of the node array. The order is one thread's depth-first recursion's: a node,
//! then the subtree of each inner child in child order.

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

use rayon::prelude::*;

use super::qnode::{cut, QNode};
use crate::tree::Bvh;

/// Levels of 4-wide nodes split over threads; below them a subtree is one thread's (4⁶ tasks
/// at most, enough to balance two to a few dozen threads).
const PAR_LEVELS: usize = 6;

/// The 4-wide nodes over binary inner node `root` of `bvh` (the root first) and the depth of
/// the deepest (root = 0).
pub fn collapse(bvh: &Bvh, root: usize) -> (Vec<QNode>, usize) {
    let counts: Vec<AtomicU32> = (0..bvh.nodes.len()).map(|_| AtomicU32::new(0)).collect();
    let n = count(bvh, root, 0, &counts);
    let mut nodes = vec![QNode::default(); n as usize];
    let depth = write(bvh, root, 0, 0, &counts, &mut nodes);
    (nodes, depth)
}

/// The binary inner children among `cut(bvh, i)`'s nodes, with their child positions.
fn inner_kids(bvh: &Bvh, kids: &[usize]) -> [Option<(usize, usize)>; 4] {
    let mut out = [None; 4];
    for (c, &k) in kids.iter().enumerate() {
        if !bvh.nodes[k].is_leaf() {
            out[c] = Some((c, k));
        }
    }
    out
}

/// Counts the 4-wide nodes of the subtree whose root is binary inner node `i` at `level`,
/// stores the count at `counts[i]` and returns it.
fn count(bvh: &Bvh, i: usize, level: usize, counts: &[AtomicU32]) -> u32 {
    let (kids, n) = cut(bvh, i);
    let inner = inner_kids(bvh, &kids[..n]);
    let below = |(_, k): (usize, usize)| count(bvh, k, level + 1, counts);
    let below: u32 = if level < PAR_LEVELS {
        inner.into_par_iter().flatten().map(below).sum()
    } else {
        inner.into_iter().flatten().map(below).sum()
    };
    counts[i].store(1 + below, Relaxed);
    1 + below
}

/// Writes the subtree of binary inner node `i` (at `level`) into `out`, whose first node has
/// index `base` in the whole array; returns the deepest level written.
fn write(
    bvh: &Bvh,
    i: usize,
    base: u32,
    level: usize,
    counts: &[AtomicU32],
    out: &mut [QNode],
) -> usize {
    let (kids, n) = cut(bvh, i);
    let (head, mut rest) = out
        .split_first_mut()
        .expect("the count pass sized every subtree");
    *head = QNode::over(&bvh.nodes, &kids[..n]);
    let mut jobs: [Option<(usize, u32, &mut [QNode])>; 4] = [None, None, None, None];
    let mut next = base + 1;
    for (c, k) in inner_kids(bvh, &kids[..n]).into_iter().flatten() {
        let m = counts[k].load(Relaxed);
        let (mine, tail) = std::mem::take(&mut rest).split_at_mut(m as usize);
        rest = tail;
        head.child[c] = next;
        jobs[c] = Some((k, next, mine));
        next += m;
    }
    let deeper = |(k, b, s): (usize, u32, &mut [QNode])| write(bvh, k, b, level + 1, counts, s);
    let deepest = if level < PAR_LEVELS {
        jobs.into_par_iter().flatten().map(deeper).max()
    } else {
        jobs.into_iter().flatten().map(deeper).max()
    };
    deepest.unwrap_or(level)
}
