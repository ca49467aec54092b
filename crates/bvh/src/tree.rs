//! The BVH: flat node array, primitive index array, build statistics and validation.

use std::time::Duration;

use rayon::prelude::*;

use crate::geometry::{Aabb, Geometry, PrimRecord, PrimRef};

/// Largest number of primitives in a leaf.
pub const LEAF_MAX: usize = 4;

/// Flag in [`Node::meta`] marking an inner node; the low two bits then hold the split axis.
pub const INNER: u32 = 0x8000_0000;

/// One BVH node, 32 bytes. Children of an inner node are adjacent: `first` and `first + 1`.
///
/// (Tried: padding so every sibling pair fills one aligned 64-byte line. No measurable change,
/// 8.8-9.1 vs 8.8-8.9 Mrays/s single-thread AVX-512 at 1024² on 1M primitives; not kept.)
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(32))]
pub struct Node {
    /// Lower corner of the bounds (Å).
    pub min: [f32; 3],
    /// Inner: index of the left child. Leaf: first slot in [`Bvh::prim_ids`] / [`Bvh::records`].
    pub first: u32,
    /// Upper corner of the bounds (Å).
    pub max: [f32; 3],
    /// Leaf: number of primitives (1..=[`LEAF_MAX`]; 0 only for the root of an empty tree).
    /// Inner: [`INNER`] | split axis.
    pub meta: u32,
}

impl Node {
    /// True for a leaf.
    #[inline(always)]
    pub fn is_leaf(&self) -> bool {
        self.meta & INNER == 0
    }
    /// Number of primitives of a leaf (0 for inner nodes).
    #[inline(always)]
    pub fn count(&self) -> usize {
        if self.is_leaf() {
            self.meta as usize
        } else {
            0
        }
    }
    /// Split axis of an inner node (0 = x, 1 = y, 2 = z).
    #[inline(always)]
    pub fn axis(&self) -> usize {
        (self.meta & 3) as usize
    }
    /// An inner node's children as (near, far) for rays whose direction is negative along
    /// the axes `neg` says: the child on the rays' side of the split first.
    #[inline(always)]
    pub fn near_far(&self, neg: &[bool; 3]) -> (usize, usize) {
        let c = self.first as usize;
        if neg[self.axis()] {
            (c + 1, c)
        } else {
            (c, c + 1)
        }
    }
    /// The node's box.
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }
    pub(crate) fn set_aabb(&mut self, b: &Aabb) {
        self.min = b.min;
        self.max = b.max;
    }
}

/// Which builder made a BVH.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builder {
    /// Binned SAH, parallel over subtrees ([`Bvh::build`]).
    Binned,
    /// Full-sweep SAH over presorted lists, the paper's builder (§4.1, [`Bvh::build_full_sweep`]).
    FullSweep,
}

/// Figures describing a build.
#[derive(Clone, Copy, Debug)]
pub struct BuildStats {
    /// The builder used.
    pub builder: Builder,
    /// Wall time of the whole build (bounds pass, tree, records).
    pub build_time: Duration,
    /// Number of primitives.
    pub prims: usize,
    /// Number of atoms of the geometry (for bytes per atom).
    pub atoms: usize,
    /// Number of nodes (inner + leaves).
    pub nodes: usize,
    /// Number of leaves.
    pub leaves: usize,
    /// Depth of the deepest leaf (root = 0).
    pub max_depth: usize,
    /// SAH cost with traversal and intersection cost 1: Σ_inner A(n)/A(root) + Σ_leaf
    /// A(l)/A(root)·count(l).
    pub sah_cost: f64,
    /// Bytes of nodes + primitive ids + primitive records.
    pub bytes: usize,
    /// Bytes of the primitive records alone (the kernels' copy of the geometry, 32 B each).
    pub record_bytes: usize,
}

impl BuildStats {
    /// Primitives per second of wall time.
    pub fn prims_per_second(&self) -> f64 {
        self.prims as f64 / self.build_time.as_secs_f64().max(1e-12)
    }
    /// Bytes of BVH + kernel geometry per atom.
    pub fn bytes_per_atom(&self) -> f64 {
        self.bytes as f64 / self.atoms.max(1) as f64
    }
    /// Bytes per atom of the primitive records (the kernels' copy of the geometry).
    pub fn record_bytes_per_atom(&self) -> f64 {
        self.record_bytes as f64 / self.atoms.max(1) as f64
    }
    /// Bytes per atom of the tree itself (nodes and primitive ids).
    pub fn node_bytes_per_atom(&self) -> f64 {
        (self.bytes - self.record_bytes) as f64 / self.atoms.max(1) as f64
    }
}

/// Bounding volume hierarchy over a [`Geometry`]: flat node array (root at 0), the primitive
/// id of every leaf slot, and the intersection records in the same (leaf) order.
#[derive(Clone, Debug)]
pub struct Bvh {
    /// Nodes; root at index 0.
    pub nodes: Vec<Node>,
    /// Primitive id per slot (see [`Geometry::prim`]).
    pub prim_ids: Vec<u32>,
    /// Kernel record per slot.
    pub records: Vec<PrimRecord>,
    /// Sticks have round caps (capsules).
    pub capped: bool,
    /// Bounds of everything (Å).
    pub bounds: Aabb,
    /// Build figures.
    pub stats: BuildStats,
}

impl Bvh {
    /// Assembles the tree from builder output: `order[slot]` is the primitive in that slot;
    /// its record is written into `records[slot]` (an array of the same length whose old
    /// contents are no longer needed, e.g. the builder's references).
    pub(crate) fn finish(
        g: &Geometry,
        nodes: Vec<Node>,
        order: Vec<u32>,
        mut records: Vec<PrimRecord>,
        builder: Builder,
        start: std::time::Instant,
    ) -> Bvh {
        assert_eq!(records.len(), order.len(), "one record per slot");
        records
            .par_iter_mut()
            .zip(order.par_iter())
            .with_min_len(4096)
            .for_each(|(r, &id)| *r = g.record(id));
        let bounds = nodes.first().map(|n| n.aabb()).unwrap_or(Aabb::EMPTY);
        let build_time = start.elapsed();
        let (leaves, max_depth, sah_cost) = tree_figures(&nodes);
        let record_bytes = records.len() * size_of::<PrimRecord>();
        let bytes = nodes.len() * size_of::<Node>() + order.len() * size_of::<u32>() + record_bytes;
        let stats = BuildStats {
            builder,
            build_time,
            prims: order.len(),
            atoms: g.balls.len(),
            nodes: nodes.len(),
            leaves,
            max_depth,
            sah_cost,
            bytes,
            record_bytes,
        };
        Bvh {
            nodes,
            prim_ids: order,
            records,
            capped: g.capped,
            bounds,
            stats,
        }
    }

    /// Checks the structure: every child box inside its parent's box, every primitive's bounds
    /// inside its leaf's box, leaves of 1..=[`LEAF_MAX`] primitives, every node reached once and
    /// every primitive of `g` in exactly one leaf slot, records matching the primitives.
    pub fn validate(&self, g: &Geometry) -> Result<(), String> {
        let n = g.prim_count();
        if self.prim_ids.len() != n || self.records.len() != n {
            return Err(format!(
                "{} prim ids / {} records for {} primitives",
                self.prim_ids.len(),
                self.records.len(),
                n
            ));
        }
        if n == 0 {
            return if self.nodes.len() == 1 && self.nodes[0].is_leaf() {
                Ok(())
            } else {
                Err("empty geometry needs one empty leaf".into())
            };
        }
        let mut seen_slot = vec![false; n];
        let mut seen_node = vec![false; self.nodes.len()];
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            if seen_node[i] {
                return Err(format!("node {i} reached twice"));
            }
            seen_node[i] = true;
            let node = &self.nodes[i];
            let b = node.aabb();
            if node.is_leaf() {
                let (f, c) = (node.first as usize, node.count());
                if c == 0 || c > LEAF_MAX || f + c > n {
                    return Err(format!("leaf {i}: bad range {f}+{c}"));
                }
                #[allow(clippy::needless_range_loop)] // indexes three arrays by slot
                for s in f..f + c {
                    if seen_slot[s] {
                        return Err(format!("slot {s} in two leaves"));
                    }
                    seen_slot[s] = true;
                    let pb = g.prim_bounds(self.prim_ids[s]);
                    if !b.contains(&pb) {
                        return Err(format!(
                            "leaf {i}: primitive {} sticks out",
                            self.prim_ids[s]
                        ));
                    }
                    if !same_bits(&self.records[s], &g.record(self.prim_ids[s])) {
                        return Err(format!("slot {s}: record does not match its primitive"));
                    }
                }
            } else {
                let c = node.first as usize;
                if c + 1 >= self.nodes.len() || c == 0 {
                    return Err(format!("node {i}: child index {c} out of range"));
                }
                for ch in [c, c + 1] {
                    if !b.contains(&self.nodes[ch].aabb()) {
                        return Err(format!("node {i}: child {ch} not inside"));
                    }
                    stack.push(ch);
                }
            }
        }
        if let Some(i) = seen_node.iter().position(|s| !s) {
            return Err(format!("node {i} unreachable"));
        }
        let mut seen_id = vec![false; n];
        for &id in &self.prim_ids {
            let id = id as usize;
            if id >= n || seen_id[id] {
                return Err(format!("primitive {id} missing or twice"));
            }
            seen_id[id] = true;
        }
        Ok(())
    }
}

/// Leaves, maximum depth and SAH cost of a node array.
fn tree_figures(nodes: &[Node]) -> (usize, usize, f64) {
    if nodes.is_empty() {
        return (0, 0, 0.0);
    }
    let root_area = nodes[0].aabb().area() as f64;
    let mut leaves = 0;
    let mut max_depth = 0;
    let mut cost = 0.0f64;
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, d)) = stack.pop() {
        let node = &nodes[i];
        let a = if root_area > 0.0 {
            node.aabb().area() as f64 / root_area
        } else {
            0.0
        };
        max_depth = max_depth.max(d);
        if node.is_leaf() {
            leaves += 1;
            cost += a * node.count() as f64;
        } else {
            cost += a;
            stack.push((node.first as usize, d + 1));
            stack.push((node.first as usize + 1, d + 1));
        }
    }
    (leaves, max_depth, cost)
}

/// Bounds of a run of primitive refs.
pub(crate) fn refs_bounds(refs: &[PrimRef]) -> Aabb {
    refs.iter().fold(Aabb::EMPTY, |b, r| b.union(r.aabb()))
}

fn same_bits(a: &PrimRecord, b: &PrimRecord) -> bool {
    let fa = [
        a.p0[0], a.p0[1], a.p0[2], a.r, a.axis[0], a.axis[1], a.axis[2], a.len,
    ];
    let fb = [
        b.p0[0], b.p0[1], b.p0[2], b.r, b.axis[0], b.axis[1], b.axis[2], b.len,
    ];
    fa.iter()
        .zip(fb.iter())
        .all(|(x, y)| x.to_bits() == y.to_bits())
}
