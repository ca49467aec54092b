//! Where to cut the binary BVH into 8-wide nodes: a dynamic program over the binary tree, the
//! idea of Ylitie, Karras and Laine 2017 ("Efficient incoherent ray traversal on GPUs through
//! compressed wide BVHs") without their leaf merging (the binary leaves are kept as they are).
//!
//! With the leaves fixed, a leaf is tested whenever a ray hits its own box, wherever it sits,
//! so the SAH cost of a collapse is the sum over wide nodes of the area of the node's box (a
//! ray hitting that box visits the node and tests its up to [`WIDTH`] child boxes at once).
//! The greedy collapse (open the largest-area inner child until there are eight) fills the top
//! of the tree and leaves nodes of two or four children at the bottom whenever the binary depth
//! is not a multiple of three: in a balanced tree (a crystal) that is most of the nodes. The
//! bottom holds most nodes and so most of the summed area; minimizing it fills them.

use super::WIDTH;
use crate::tree::Bvh;

/// Cost of a wide node besides its visits, in visits of the root (SAH units): memory, and so
/// the count per primitive the estimate assumes. Nodes per primitive and the SAH node cost
/// (Σ area / root area) against 0 (pure SAH) and 1000 (fewest nodes), nanobowl / ns90k /
/// ns740k / sio2 at 200 K atoms: 0 → 0.067 / 0.064 / 0.064 / 0.098 nodes, SAH 16.5 / 35.0 /
/// 73.1 / 51.9; 0.001 → 0.064 / 0.059 / 0.057 / 0.068, SAH +0-4 %; 1000 → 0.061 / 0.056 /
/// 0.056 / 0.064, SAH +12-18 %.
const NODE_COST: f64 = 0.001;

/// Bits per field of a plan word (a slot count 0..=7).
const BITS: u32 = 3;

/// The plan: one word per binary node (0 for leaves). Field `k - 1` (3 bits) for an inner
/// node `n` given `k` child slots (2 ≤ k ≤ 8): 0 = `n` is one child (a wide node of its
/// own), else the slots of its left child `a` (the right child gets `k - a`). Field 0: the
/// split `a` of the eight slots of the wide node made at `n` itself.
pub(super) fn plan(bvh: &Bvh) -> Vec<u32> {
    let mut plan = vec![0u32; bvh.nodes.len()];
    let ra = (bvh.nodes[0].aabb().area() as f64).max(f64::MIN_POSITIVE);
    solve(bvh, 0, &mut plan, (1.0 / ra, NODE_COST));
    plan
}

/// Field `i` of a plan word.
#[inline]
fn field(word: u32, i: usize) -> usize {
    ((word >> (BITS * i as u32)) & ((1 << BITS) - 1)) as usize
}

/// Fills the plan of the subtree at `n` and returns its costs: entry `k - 1` is the least
/// cost of the wide nodes needed to hang the subtree below at most `k` child slots, a node
/// costing `w.0` per Å² of its box plus `w.1` (1 / root area and [`NODE_COST`]: SAH units).
fn solve(bvh: &Bvh, n: usize, plan: &mut [u32], w: (f64, f64)) -> [f64; WIDTH] {
    let node = bvh.nodes[n];
    if node.is_leaf() {
        return [0.0; WIDTH];
    }
    let l = node.first as usize;
    let fl = solve(bvh, l, plan, w);
    let fr = solve(bvh, l + 1, plan, w);
    // split[k - 1]: the least cost of giving a slots to the left and k - a to the right.
    let mut split = [(f64::INFINITY, 0usize); WIDTH];
    for k in 2..=WIDTH {
        for a in 1..k {
            let c = fl[a - 1] + fr[k - a - 1];
            if c < split[k - 1].0 {
                split[k - 1] = (c, a);
            }
        }
    }
    let own = node.aabb().area() as f64 * w.0 + w.1 + split[WIDTH - 1].0;
    let mut word = split[WIDTH - 1].1 as u32;
    let mut cost = [own; WIDTH];
    for k in 2..=WIDTH {
        // Ties split: with zero-area boxes that keeps the nodes full.
        if split[k - 1].0 <= own {
            cost[k - 1] = split[k - 1].0;
            word |= (split[k - 1].1 as u32) << (BITS * (k as u32 - 1));
        }
    }
    plan[n] = word;
    cost
}

/// The children of the wide node made at binary node `b` (`b` itself for a leaf): binary
/// node indices, in binary-tree order, and their number.
pub(super) fn children(bvh: &Bvh, plan: &[u32], b: usize) -> ([u32; WIDTH], usize) {
    let mut kids = ([0u32; WIDTH], 0usize);
    let node = bvh.nodes[b];
    if node.is_leaf() {
        kids.0[0] = b as u32;
        kids.1 = 1;
        return kids;
    }
    let l = node.first as usize;
    let a = field(plan[b], 0);
    gather(bvh, plan, l, a, &mut kids);
    gather(bvh, plan, l + 1, WIDTH - a, &mut kids);
    kids
}

/// Appends the (at most `k`) children the plan hangs binary node `x`'s subtree below.
fn gather(bvh: &Bvh, plan: &[u32], x: usize, k: usize, kids: &mut ([u32; WIDTH], usize)) {
    let node = bvh.nodes[x];
    let a = if node.is_leaf() || k == 1 {
        0
    } else {
        field(plan[x], k - 1)
    };
    if a == 0 {
        kids.0[kids.1] = x as u32;
        kids.1 += 1;
        return;
    }
    let l = node.first as usize;
    gather(bvh, plan, l, a, kids);
    gather(bvh, plan, l + 1, k - a, kids);
}

/// Number of wide nodes the plan makes (to allocate them exactly).
pub(super) fn count_wide(bvh: &Bvh, plan: &[u32]) -> usize {
    let mut stack = vec![0usize];
    let mut count = 0;
    while let Some(b) = stack.pop() {
        count += 1;
        let (kids, n) = children(bvh, plan, b);
        for &k in &kids[..n] {
            if !bvh.nodes[k as usize].is_leaf() {
                stack.push(k as usize);
            }
        }
    }
    count
}
