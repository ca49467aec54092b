//! The compact tree's node: four children whose boxes are quantised to 8 bits per
//! coordinate in the node's own box (64 bytes, one cache line), collapsed from the binary
//! tree by opening the child of largest surface area until four.

use glam::Vec4;

use crate::geometry::Aabb;
use crate::tree::{Bvh, Node};

/// Unused child slot.
pub const EMPTY: u32 = u32::MAX;
/// Leaf flag of a child reference; bits 28-30 hold the primitive count, bits 0-27 the first
/// slot in [`super::CompactBvh::prim_ids`].
pub const LEAF: u32 = 1 << 31;
/// Most leaf slots a child reference can address.
pub const MAX_SLOTS: usize = 1 << 28;

/// Four children: box corners `origin + q·scale` (Å) with `q` in 0..=255, rounded outwards;
/// `child[c]` is a node index, a leaf reference ([`LEAF`]) or [`EMPTY`] (after the last).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub struct QNode {
    /// Lower corner of the node's box (Å).
    pub origin: [f32; 3],
    /// Å per quantisation step, per axis.
    pub scale: [f32; 3],
    /// Children's lower corners in steps: `lo[axis][child]`.
    pub lo: [[u8; 4]; 3],
    /// Children's upper corners in steps.
    pub hi: [[u8; 4]; 3],
    /// Child references.
    pub child: [u32; 4],
}

impl QNode {
    /// Dequantised box of child `c` (the same arithmetic as the traversal's).
    #[inline(always)]
    pub fn child_box(&self, c: usize) -> Aabb {
        let mut b = Aabb::EMPTY;
        for a in 0..3 {
            b.min[a] = self.origin[a] + self.lo[a][c] as f32 * self.scale[a];
            b.max[a] = self.origin[a] + self.hi[a][c] as f32 * self.scale[a];
        }
        b
    }

    /// Dequantised corners of all four children at once: `(lo, hi)`, one `Vec4` per axis
    /// holding the four children (the same arithmetic as [`QNode::child_box`]).
    #[inline(always)]
    pub fn boxes(&self) -> ([Vec4; 3], [Vec4; 3]) {
        let deq = |q: &[u8; 4], a: usize| {
            let v = Vec4::new(q[0] as f32, q[1] as f32, q[2] as f32, q[3] as f32);
            Vec4::splat(self.origin[a]) + v * self.scale[a]
        };
        (
            [
                deq(&self.lo[0], 0),
                deq(&self.lo[1], 1),
                deq(&self.lo[2], 2),
            ],
            [
                deq(&self.hi[0], 0),
                deq(&self.hi[1], 1),
                deq(&self.hi[2], 2),
            ],
        )
    }

    /// Node over the binary nodes `kids` (at most four): their boxes quantised outwards, leaf
    /// children referenced, inner ones left [`EMPTY`] for the caller.
    pub fn over(nodes: &[Node], kids: &[usize]) -> QNode {
        let b = kids
            .iter()
            .fold(Aabb::EMPTY, |b, &k| b.union(nodes[k].aabb()));
        let mut q = QNode {
            origin: b.min,
            child: [EMPTY; 4],
            ..QNode::default()
        };
        for a in 0..3 {
            // A little over 1/255 of the extent, so 255 steps reach past the upper corner.
            q.scale[a] = ((b.max[a] - b.min[a]) / 255.0 * (1.0 + 1e-5)).max(f32::MIN_POSITIVE);
        }
        for (c, &k) in kids.iter().enumerate() {
            let n = &nodes[k];
            for a in 0..3 {
                let (o, h) = (q.origin[a], q.scale[a]);
                let mut lo = ((n.min[a] - o) / h).floor().clamp(0.0, 255.0) as u8;
                while lo > 0 && o + lo as f32 * h > n.min[a] {
                    lo -= 1;
                }
                let mut hi = ((n.max[a] - o) / h).ceil().clamp(0.0, 255.0) as u8;
                while hi < 255 && o + hi as f32 * h < n.max[a] {
                    hi += 1;
                }
                q.lo[a][c] = lo;
                q.hi[a][c] = hi;
            }
            if n.is_leaf() {
                q.child[c] = leaf_ref(n);
            }
        }
        q
    }
}

/// The reference of binary leaf `n`.
pub fn leaf_ref(n: &Node) -> u32 {
    LEAF | (n.count() as u32) << 28 | n.first
}

/// The binary nodes under inner node `i` that become one 4-wide node: its two children, then
/// the inner child of largest area opened until there are four.
pub fn cut(b: &Bvh, i: usize) -> ([usize; 4], usize) {
    let first = b.nodes[i].first as usize;
    let mut kids = [first, first + 1, 0, 0];
    let mut n = 2;
    while n < 4 {
        let open = (0..n)
            .filter(|&c| !b.nodes[kids[c]].is_leaf())
            .max_by(|&x, &y| {
                let area = |c: usize| b.nodes[kids[c]].aabb().area();
                area(x).total_cmp(&area(y))
            });
        let Some(c) = open else { break };
        let f = b.nodes[kids[c]].first as usize;
        kids[c] = f;
        kids[n] = f + 1;
        n += 1;
    }
    (kids, n)
}
