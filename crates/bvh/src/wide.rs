//! An 8-wide BVH for single incoherent rays (secondary rays: shadow, AO, path bounces).
//!
//! Packet traversal (§4.3) pays for the union of the nodes its rays need; rays that leave
//! diffuse or blurred-metal hits share few nodes. Here one ray visits only its own nodes and
//! tests a node's eight child boxes in one SIMD op (two on SSE4.1, eight on scalar), as
//! Embree's BVH8 single-ray kernels. The tree is the binary BVH collapsed: each wide node
//! takes a binary inner node and a cut of its subtree of at most eight nodes as children,
//! the cuts chosen by a dynamic program for the least SAH cost (`wide/plan.rs`); leaves (and their
//! primitive records) are the binary BVH's own.
//!
//! (Before: greedy, open the largest-area inner child until eight. Nodes per primitive
//! varied 0.085-0.148 with the scene, half-empty nodes at the bottom; see BENCHMARKS.md,
//! "Wide BVH: SAH collapse".)

mod plan;
mod spans;

use spmd::{Scalar, Simd, V3};

use crate::geometry::{Aabb, Geometry};
use crate::intersect::intersect_record;
use crate::traverse::{slab_test, PacketHit, Ray, RayPacket, BOX_GROW};
use crate::tree::Bvh;
use plan::{children, count_wide, plan};

/// Children per wide node.
pub const WIDTH: usize = 8;

/// One wide node: up to [`WIDTH`] children, boxes in SoA order so one load reads the same
/// coordinate of every child. Children are packed at the front (`n` of them). 256 bytes,
/// four cache lines, the header first (the traversal reads it first).
///
/// (Measured: with `n` and `count` after the boxes, 260 bytes padded to 320 (five lines),
/// ns90k path tracing, far view, 1024², AVX2 took 2.37 s per sample; this layout 2.04 s.)
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct WideNode {
    /// Number of children in use.
    pub n: u32,
    /// 0 for an inner child, else the leaf's primitive count (1..=[`crate::LEAF_MAX`]).
    pub count: [u8; WIDTH],
    _pad: [u32; 5],
    /// Lower corners per axis (Å): `min[axis][child]`.
    pub min: [[f32; WIDTH]; 3],
    /// Upper corners per axis (Å).
    pub max: [[f32; WIDTH]; 3],
    /// Inner child: index of its wide node. Leaf child: first slot in [`Bvh::records`].
    pub child: [u32; WIDTH],
}

impl WideNode {
    /// Lower and upper corners of children `c .. c + S::LANES` (zeros past the last), for
    /// one SIMD box test.
    #[inline(always)]
    pub fn boxes<S: Simd>(&self, s: S, c: usize) -> (V3<S>, V3<S>) {
        (corners(s, &self.min, c), corners(s, &self.max, c))
    }

    const EMPTY: WideNode = WideNode {
        n: 0,
        count: [0; WIDTH],
        _pad: [0; 5],
        min: [[0.0; WIDTH]; 3],
        max: [[0.0; WIDTH]; 3],
        child: [0; WIDTH],
    };
}

/// Corners `c ..` of one side of a node's boxes (a function, not a closure: closures may not
/// inherit the backend's target features).
#[inline(always)]
fn corners<S: Simd>(s: S, b: &[[f32; WIDTH]; 3], c: usize) -> V3<S> {
    V3::new(
        s.load_partial(&b[0][c..], 0.0),
        s.load_partial(&b[1][c..], 0.0),
        s.load_partial(&b[2][c..], 0.0),
    )
}

/// A stack entry of the wide traversal: a child reference and the distance where the ray
/// enters its box (Å).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WideEntry {
    child: u32,
    count: u32,
    t: f32,
}

/// The 8-wide BVH collapsed from a binary [`Bvh`]; it shares that tree's records, so every
/// query takes the `Bvh` it was built from.
#[derive(Clone, Debug, Default)]
pub struct WideBvh {
    /// Nodes, root at 0 (empty for an empty tree).
    pub nodes: Vec<WideNode>,
    /// Depth of the deepest wide node (root = 0).
    pub depth: usize,
    /// Number of records of the binary tree it was built from (checked by queries).
    records: usize,
}

impl WideBvh {
    /// Collapses `bvh` into 8-wide nodes with the fewest node visits by the SAH (`wide/plan.rs`),
    /// O(binary nodes); allocates the exact node count.
    pub fn new(bvh: &Bvh) -> WideBvh {
        let mut w = WideBvh {
            nodes: Vec::new(),
            depth: 0,
            records: bvh.records.len(),
        };
        if bvh.nodes.is_empty() || bvh.records.is_empty() {
            return w;
        }
        let plan = plan(bvh);
        w.nodes.reserve_exact(count_wide(bvh, &plan));
        w.collapse(bvh, &plan, 0, 0);
        w
    }

    /// Makes the wide node for binary node `b` (its children: `b` itself when `b` is a leaf,
    /// so a one-leaf tree still has a root; else the cut `plan` chose) and returns its index.
    fn collapse(&mut self, bvh: &Bvh, plan: &[u32], b: usize, depth: usize) -> u32 {
        self.depth = self.depth.max(depth);
        let at = self.nodes.len();
        self.nodes.push(WideNode::EMPTY);
        let (kids, n) = children(bvh, plan, b);
        let mut node = WideNode::EMPTY;
        node.n = n as u32;
        for (i, &k) in kids[..n].iter().enumerate() {
            let bn = bvh.nodes[k as usize];
            for a in 0..3 {
                node.min[a][i] = bn.min[a];
                node.max[a][i] = bn.max[a];
            }
            if bn.is_leaf() {
                node.child[i] = bn.first;
                node.count[i] = bn.count() as u8;
            } else {
                node.child[i] = self.collapse(bvh, plan, k as usize, depth + 1);
            }
        }
        self.nodes[at] = node;
        at as u32
    }

    /// Stack entries a query needs (each popped node pushes at most [`WIDTH`]).
    pub fn stack_size(&self) -> usize {
        (WIDTH - 1) * (self.depth + 1) + 2
    }

    /// Stack entries [`WideBvh::sphere_spans`] needs (a leaf's entry takes two words, so a
    /// popped node pushes at most 2·[`WIDTH`]).
    pub fn spans_stack_size(&self) -> usize {
        (2 * WIDTH - 1) * (self.depth + 1) + 2
    }

    /// Bytes of the wide nodes.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<WideNode>()
    }

    /// Checks the tree against `bvh`: every child box contains the boxes below it, every
    /// record slot is reached exactly once, child indices are in range.
    pub fn validate(&self, bvh: &Bvh, g: &Geometry) -> Result<(), String> {
        if self.records != bvh.records.len() {
            return Err(format!(
                "built for {} records, the BVH has {}",
                self.records,
                bvh.records.len()
            ));
        }
        let mut seen = vec![0u8; bvh.records.len()];
        if !self.nodes.is_empty() {
            self.check(bvh, g, 0, None, &mut seen)?;
        }
        if let Some(i) = seen.iter().position(|&c| c != 1) {
            return Err(format!("record slot {i} reached {} times", seen[i]));
        }
        Ok(())
    }

    fn check(
        &self,
        bvh: &Bvh,
        g: &Geometry,
        at: usize,
        parent: Option<Aabb>,
        seen: &mut [u8],
    ) -> Result<(), String> {
        let node = self
            .nodes
            .get(at)
            .ok_or(format!("node {at} out of range"))?;
        if node.n == 0 || node.n as usize > WIDTH {
            return Err(format!("node {at} has {} children", node.n));
        }
        for i in 0..node.n as usize {
            let b = Aabb {
                min: [node.min[0][i], node.min[1][i], node.min[2][i]],
                max: [node.max[0][i], node.max[1][i], node.max[2][i]],
            };
            if let Some(p) = parent {
                if !p.contains(&b) {
                    return Err(format!("node {at} child {i}: box not inside its parent's"));
                }
            }
            if node.count[i] == 0 {
                self.check(bvh, g, node.child[i] as usize, Some(b), seen)?;
                continue;
            }
            let first = node.child[i] as usize;
            #[allow(clippy::needless_range_loop)] // indexes prim_ids and seen by slot
            for slot in first..first + node.count[i] as usize {
                let id = *bvh
                    .prim_ids
                    .get(slot)
                    .ok_or(format!("slot {slot} out of range"))?;
                let pb = g.prim_bounds(id);
                if !b.contains(&pb) {
                    return Err(format!(
                        "node {at} child {i}: record {slot} outside the box"
                    ));
                }
                seen[slot] = seen[slot].saturating_add(1);
            }
        }
        Ok(())
    }

    /// Nearest hit of one ray: `(t, slot)`, slot −1 (and `t = ray.tmax`) for a miss.
    /// Children are visited nearest box first; popped entries beyond the current hit are
    /// skipped. `stack` must hold [`WideBvh::stack_size`] entries.
    #[inline(always)]
    pub fn closest<S: Simd>(
        &self,
        s: S,
        bvh: &Bvh,
        ray: &Ray,
        stack: &mut [WideEntry],
    ) -> (f32, i32) {
        self.query::<S, false>(s, bvh, ray, stack)
    }

    /// Whether one ray hits anything in `(tmin, tmax)` (any hit ends the search).
    #[inline(always)]
    pub fn occluded<S: Simd>(&self, s: S, bvh: &Bvh, ray: &Ray, stack: &mut [WideEntry]) -> bool {
        self.query::<S, true>(s, bvh, ray, stack).1 >= 0
    }

    #[inline(always)]
    fn query<S: Simd, const ANY: bool>(
        &self,
        s: S,
        bvh: &Bvh,
        ray: &Ray,
        stack: &mut [WideEntry],
    ) -> (f32, i32) {
        assert_eq!(self.records, bvh.records.len(), "wide BVH of another tree");
        if self.nodes.is_empty() || ray.tmax.is_nan() {
            return (ray.tmax, -1);
        }
        let records = &bvh.records[..];
        // The leaf tests take the ray as a one-lane packet.
        let ray1 = RayPacket::<Scalar> {
            o: V3::new(ray.o[0], ray.o[1], ray.o[2]),
            d: V3::new(ray.d[0], ray.d[1], ray.d[2]),
            tmin: ray.tmin,
            tmax: ray.tmax,
            active: true,
        };
        let mut hit = PacketHit::<Scalar> {
            t: ray.tmax,
            slot: std::num::Wrapping(-1),
        };
        // The packet traversal's slab test, the ray uniform and the boxes varying.
        let o: V3<S> = V3::splat(s, ray.o);
        let inv: V3<S> = V3::new(
            s.rcp(s.splat(ray.d[0])),
            s.rcp(s.splat(ray.d[1])),
            s.rcp(s.splat(ray.d[2])),
        );
        let tmin = s.splat(ray.tmin);
        let grow = s.splat(BOX_GROW);
        let mut entry_buf = [0.0f32; spmd::MAX_LANES];
        let mut found = [WideEntry::default(); WIDTH];
        stack[0] = WideEntry {
            child: 0,
            count: 0,
            t: f32::NEG_INFINITY,
        };
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let e = stack[sp];
            if e.t > hit.t {
                continue;
            }
            if e.count > 0 {
                let first = e.child as usize;
                for (k, rec) in records[first..first + e.count as usize].iter().enumerate() {
                    let slot = (first + k) as i32;
                    intersect_record(Scalar, &ray1, true, rec, bvh.capped, slot, &mut hit);
                    if ANY && hit.slot.0 >= 0 {
                        return (hit.t, hit.slot.0);
                    }
                }
                continue;
            }
            let node = &self.nodes[e.child as usize];
            let n = node.n as usize;
            let tv = s.splat(hit.t);
            let mut nf = 0usize;
            let mut c = 0usize;
            while c < n {
                let (lo, hi) = node.boxes(s, c);
                let (m, entry) = slab_test(s, lo, hi, o, inv, tmin, tv, grow);
                let m = m & s.first_n(n - c);
                let mut bits = s.bitmask(m);
                if bits != 0 {
                    s.store(entry, &mut entry_buf);
                }
                while bits != 0 {
                    let i = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    found[nf] = WideEntry {
                        child: node.child[c + i],
                        count: node.count[c + i] as u32,
                        t: entry_buf[i],
                    };
                    nf += 1;
                }
                c += S::LANES;
            }
            // Push farthest first so the nearest box is popped next (insertion sort, ≤ 8).
            for i in 1..nf {
                let x = found[i];
                let mut j = i;
                while j > 0 && found[j - 1].t < x.t {
                    found[j] = found[j - 1];
                    j -= 1;
                }
                found[j] = x;
            }
            stack[sp..sp + nf].copy_from_slice(&found[..nf]);
            sp += nf;
        }
        (hit.t, hit.slot.0)
    }

    /// Nearest hits of many rays, one at a time on `isa` (for tests and tools).
    pub fn intersect_rays(&self, isa: spmd::Isa, bvh: &Bvh, rays: &[Ray]) -> Vec<(f32, i32)> {
        isa.dispatch(WideBatch {
            wide: self,
            bvh,
            rays,
            any: false,
        })
    }

    /// Occlusion of many rays, one at a time on `isa` (1 = hit; for tests and tools).
    pub fn occluded_rays(&self, isa: spmd::Isa, bvh: &Bvh, rays: &[Ray]) -> Vec<(f32, i32)> {
        isa.dispatch(WideBatch {
            wide: self,
            bvh,
            rays,
            any: true,
        })
    }
}

struct WideBatch<'a> {
    wide: &'a WideBvh,
    bvh: &'a Bvh,
    rays: &'a [Ray],
    any: bool,
}

impl spmd::Kernel for WideBatch<'_> {
    type Output = Vec<(f32, i32)>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Vec<(f32, i32)> {
        let mut stack = vec![WideEntry::default(); self.wide.stack_size()];
        let mut out = Vec::with_capacity(self.rays.len());
        // (A loop, not `map`: closures do not inherit the entry point's target features.)
        for r in self.rays {
            out.push(if self.any {
                let o = self.wide.occluded(s, self.bvh, r, &mut stack);
                (if o { 1.0 } else { 0.0 }, o as i32)
            } else {
                self.wide.closest(s, self.bvh, r, &mut stack)
            });
        }
        out
    }
}

const _: () = assert!(std::mem::size_of::<WideNode>() == 256);
