//! The compact scene (issue #19): 4-wide nodes with child boxes quantised to 8 bits (64 bytes
//! per node, [`QNode`]); leaves that name their primitives by id; balls and sticks tested
//! straight from 16-byte points (x, y, z, radius) and bond index pairs, the sticks without a
//! unit axis ([`crate::intersect::ray_bond`]), so no 32-byte record per primitive is stored.
//! Built by collapsing a binary [`Bvh`], which stays the reference the tests compare against.
//! Not yet used by the renderer.
//!
//! Measured (`cargo run --release -p bvh --example build_time -- N 5`, AVX2 Zen 3, 2 threads,
//! camera rays 1024²): 740K atoms 55 B/atom against 122 for the binary tree and its records,
//! far 148 ms against 139-141, zoomed 95 against 87-89, inside 158-160 against 141-143.
//!
//! The box test is the fused form `lo·(1/d) − o·(1/d)` (Embree's), not the binary
//! traversal's exact `(lo − o)·(1/d)`: at 4.8 M atoms 259 against 314 ms far. Its rounding
//! can only matter for a ray grazing a box face within `ε·|o|`; the tests (rays from
//! surfaces included) find the same hits as brute force.

mod collapse;
mod qnode;

use rayon::prelude::*;
use spmd::{Isa, Kernel, Simd, V3};

use crate::geometry::{trimmed_stick, Aabb, Geometry, Prim};
use crate::intersect::{intersect_ball, intersect_bond};
use crate::traverse::{load_packet, PacketHit, Ray, RayPacket, BOX_GROW};
use crate::tree::Bvh;
/// Which binary nodes become one 4-wide node (for tests that rebuild the tree another way).
pub use qnode::cut;
pub use qnode::{QNode, EMPTY, LEAF, MAX_SLOTS};

/// Why a compact tree could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CompactError {
    /// More leaf slots than a child reference addresses.
    #[error("{0} primitives: the compact tree addresses at most 2^28")]
    TooManyPrims(usize),
    /// The tree was built over other geometry.
    #[error("the BVH has {bvh} primitives, the geometry {geometry}")]
    Mismatch {
        /// Primitives of the tree.
        bvh: usize,
        /// Primitives of the geometry.
        geometry: usize,
    },
}

/// The compact tree and the geometry it tests, self-contained.
#[derive(Clone, Debug, Default)]
pub struct CompactBvh {
    /// Nodes; the root is [`CompactBvh::root`].
    pub nodes: Vec<QNode>,
    /// Primitive id of every leaf slot (see [`Geometry::prim`]).
    pub prim_ids: Vec<u32>,
    /// Atom centres then extra stick ends (Å), with the ball radius (Å; 0 for extra ends).
    pub points: Vec<[f32; 4]>,
    /// Stick endpoints, indices into `points`.
    pub bonds: Vec<[u32; 2]>,
    /// Primitive ids below this are balls (ball `i` is point `i`), the rest sticks.
    pub n_balls: u32,
    /// Stick radius (Å).
    pub stick_radius: f32,
    /// Sticks are capsules.
    pub capped: bool,
    /// Bounds of everything (Å).
    pub bounds: Aabb,
    /// Root reference: node 0, a leaf reference for a one-leaf tree, [`EMPTY`] for no
    /// primitives.
    pub root: u32,
    /// Depth of the deepest node (root = 0).
    pub depth: usize,
}

impl CompactBvh {
    /// Collapses `bvh` (built over `g`) into 4-wide quantised nodes and copies `g`'s points and
    /// bonds; O(nodes).
    pub fn new(g: &Geometry, bvh: &Bvh) -> Result<CompactBvh, CompactError> {
        let n = g.prim_count();
        if bvh.prim_ids.len() != n {
            return Err(CompactError::Mismatch {
                bvh: bvh.prim_ids.len(),
                geometry: n,
            });
        }
        if n >= MAX_SLOTS {
            return Err(CompactError::TooManyPrims(n));
        }
        let b = &g.balls;
        let mut points: Vec<[f32; 4]> = (0..b.len())
            .into_par_iter()
            .map(|i| [b.x[i], b.y[i], b.z[i], b.radius[i]])
            .collect();
        points.extend(g.sticks.ends.iter().map(|e| [e[0], e[1], e[2], 0.0]));
        let mut c = CompactBvh {
            nodes: Vec::new(),
            prim_ids: bvh.prim_ids.clone(),
            points,
            bonds: g
                .sticks
                .a
                .iter()
                .zip(&g.sticks.b)
                .map(|(&a, &b)| [a, b])
                .collect(),
            n_balls: g.n_ball_prims() as u32,
            stick_radius: g.sticks.radius,
            capped: g.capped,
            bounds: bvh.bounds,
            root: EMPTY,
            depth: 0,
        };
        let top = bvh.nodes[0];
        c.root = if n == 0 {
            EMPTY
        } else if top.is_leaf() {
            qnode::leaf_ref(&top)
        } else {
            (c.nodes, c.depth) = collapse::collapse(bvh, 0);
            0
        };
        Ok(c)
    }

    /// Stack entries a query needs (a node pushes at most three).
    pub fn stack_size(&self) -> usize {
        3 * (self.depth + 1) + 1
    }

    /// Bytes of nodes, slot ids, points and bonds.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.nodes.len() * size_of::<QNode>()
            + self.prim_ids.len() * 4
            + self.points.len() * 16
            + self.bonds.len() * 8
    }

    /// Checks the structure against `g`: every primitive inside the boxes of all its
    /// ancestors (quantised boxes round outwards on their own, so a child's box may stick out
    /// of its parent's; what must hold is that no ancestor culls a primitive), every slot
    /// reached once, every id a primitive of `g` once, points and bonds equal to `g`'s.
    pub fn validate(&self, g: &Geometry) -> Result<(), String> {
        let n = g.prim_count();
        if self.prim_ids.len() != n {
            return Err(format!("{} slots for {n} primitives", self.prim_ids.len()));
        }
        let mut seen = vec![0u8; n];
        match self.root {
            EMPTY if n == 0 => {}
            EMPTY => return Err("no root".into()),
            r if r & LEAF != 0 => self.check_leaf(g, r, &self.bounds, &mut seen)?,
            r => self.check(g, r as usize, &self.bounds, 0, &mut seen)?,
        }
        if let Some(i) = seen.iter().position(|&c| c != 1) {
            return Err(format!("slot {i} reached {} times", seen[i]));
        }
        let mut seen_ids = vec![false; n];
        for &id in &self.prim_ids {
            let k = id as usize;
            if k >= n || std::mem::replace(&mut seen_ids[k], true) {
                return Err(format!("primitive id {id} out of range or twice"));
            }
        }
        let b = &g.balls;
        let same_points = self.points.len() == b.len() + g.sticks.ends.len()
            && (0..b.len()).all(|i| self.points[i] == [b.x[i], b.y[i], b.z[i], b.radius[i]]);
        let same_bonds = self.bonds.len() == g.sticks.len()
            && (0..g.sticks.len()).all(|j| self.bonds[j] == [g.sticks.a[j], g.sticks.b[j]]);
        if !same_points || !same_bonds {
            return Err("points or bonds differ from the geometry".into());
        }
        Ok(())
    }

    /// Checks node `at` at depth `depth`, `clip` the intersection of its ancestors' boxes.
    fn check(
        &self,
        g: &Geometry,
        at: usize,
        clip: &Aabb,
        depth: usize,
        seen: &mut [u8],
    ) -> Result<(), String> {
        if depth > self.depth {
            return Err(format!("node {at} deeper than {}", self.depth));
        }
        let q = self
            .nodes
            .get(at)
            .ok_or(format!("node {at} out of range"))?;
        if q.child[0] == EMPTY {
            return Err(format!("node {at} has no children"));
        }
        for c in 0..4 {
            let r = q.child[c];
            if r == EMPTY {
                if q.child[c..].iter().any(|&r| r != EMPTY) {
                    return Err(format!("node {at}: a child after an empty slot"));
                }
                break;
            }
            let b = q.child_box(c);
            let clip = Aabb {
                min: std::array::from_fn(|a| b.min[a].max(clip.min[a])),
                max: std::array::from_fn(|a| b.max[a].min(clip.max[a])),
            };
            if r & LEAF != 0 {
                self.check_leaf(g, r, &clip, seen)?;
            } else {
                self.check(g, r as usize, &clip, depth + 1, seen)?;
            }
        }
        Ok(())
    }

    fn check_leaf(&self, g: &Geometry, r: u32, b: &Aabb, seen: &mut [u8]) -> Result<(), String> {
        let (first, count) = leaf_range(r);
        if count == 0 || first + count > self.prim_ids.len() {
            return Err(format!("leaf {first}+{count} out of range"));
        }
        for (slot, (&id, seen)) in self.prim_ids[first..first + count]
            .iter()
            .zip(&mut seen[first..first + count])
            .enumerate()
        {
            let slot = first + slot;
            if id as usize >= g.prim_count() {
                return Err(format!("slot {slot}: id {id} out of range"));
            }
            if !b.contains(&g.prim_bounds(id)) {
                return Err(format!(
                    "slot {slot}: primitive {id} outside its ancestors' boxes"
                ));
            }
            *seen = seen.saturating_add(1);
        }
        Ok(())
    }

    /// Nearest hits of a packet: `t` and leaf slot per lane (−1 for a miss). `stack` must hold
    /// [`CompactBvh::stack_size`] entries.
    #[inline(always)]
    pub fn closest_packet<S: Simd>(
        &self,
        s: S,
        ray: &RayPacket<S>,
        stack: &mut [(u32, u32)],
    ) -> PacketHit<S> {
        self.query::<S, false>(s, ray, stack)
    }

    /// Lanes of a packet that hit anything in `(tmin, tmax)`.
    #[inline(always)]
    pub fn occluded_packet<S: Simd>(
        &self,
        s: S,
        ray: &RayPacket<S>,
        stack: &mut [(u32, u32)],
    ) -> S::M {
        let h = self.query::<S, true>(s, ray, stack);
        s.gt_i(h.slot, s.splat_i(-1))
    }

    // §4.3 packet traversal over 4-wide nodes: each child's dequantised box against the
    // packet, the children hit pushed farthest first with the lanes that hit them; one loop
    // for closest hit and any hit (`ANY`: a lane's first hit ends it, as Embree's epilogs).
    #[inline(always)]
    fn query<S: Simd, const ANY: bool>(
        &self,
        s: S,
        ray: &RayPacket<S>,
        stack: &mut [(u32, u32)],
    ) -> PacketHit<S> {
        let ninf = s.splat(f32::NEG_INFINITY);
        let mut hit = PacketHit {
            t: s.select(ray.active, ray.tmax, ninf),
            slot: s.splat_i(-1),
        };
        let bits0 = s.bitmask(ray.active);
        if bits0 == 0 || self.root == EMPTY {
            return hit;
        }
        const BITS: [i32; 16] = [
            1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192, 16384, 32768,
        ];
        let lanebits = s.load_i(&BITS[..S::LANES]);
        let inv = V3::<S>::new(s.rcp(ray.d.x), s.rcp(ray.d.y), s.rcp(ray.d.z));
        let grow = s.splat(BOX_GROW);
        let noi = V3::<S>::new(-(ray.o.x * inv.x), -(ray.o.y * inv.y), -(ray.o.z * inv.z));
        let lane = bits0.trailing_zeros() as usize;
        let d0 = [
            s.extract(ray.d.x, lane),
            s.extract(ray.d.y, lane),
            s.extract(ray.d.z, lane),
        ];
        let mut sp = 0usize;
        let (mut r, mut bits) = (self.root, bits0);
        loop {
            let m = !s.eq_i(s.splat_i(bits as i32) & lanebits, s.splat_i(0));
            if r & LEAF != 0 {
                let (first, count) = leaf_range(r);
                for slot in first..first + count {
                    let mut h = PacketHit {
                        t: hit.t,
                        slot: if ANY { s.splat_i(-1) } else { hit.slot },
                    };
                    self.intersect_prim(s, ray, m, slot, &mut h);
                    if ANY {
                        let hm = s.gt_i(h.slot, s.splat_i(-1));
                        hit.slot = s.select_i(hm, h.slot, hit.slot);
                        hit.t = s.select(hm, ninf, hit.t);
                    } else {
                        hit = h;
                    }
                }
                if ANY && s.none(ray.active & !s.gt_i(hit.slot, s.splat_i(-1))) {
                    return hit;
                }
            } else {
                let q = &self.nodes[r as usize];
                // Children hit, nearest (by the first lane's direction) last.
                let mut kids = [(0.0f32, 0u32, 0u32); 4];
                let mut nk = 0;
                let (lo, hi) = q.boxes();
                let key =
                    (lo[0] + hi[0]) * d0[0] + (lo[1] + hi[1]) * d0[1] + (lo[2] + hi[2]) * d0[2];
                for c in 0..4 {
                    if q.child[c] == EMPTY {
                        break;
                    }
                    let tx0 = s.fma(s.splat(lo[0][c]), inv.x, noi.x);
                    let tx1 = s.fma(s.splat(hi[0][c]), inv.x, noi.x);
                    let ty0 = s.fma(s.splat(lo[1][c]), inv.y, noi.y);
                    let ty1 = s.fma(s.splat(hi[1][c]), inv.y, noi.y);
                    let tz0 = s.fma(s.splat(lo[2][c]), inv.z, noi.z);
                    let tz1 = s.fma(s.splat(hi[2][c]), inv.z, noi.z);
                    let entry = s.max(
                        s.min(tx0, tx1),
                        s.max(s.min(ty0, ty1), s.max(s.min(tz0, tz1), ray.tmin)),
                    );
                    let exit = s.min(
                        s.max(tx0, tx1),
                        s.min(s.max(ty0, ty1), s.min(s.max(tz0, tz1), hit.t)),
                    );
                    let mc = s.le(entry, exit * grow);
                    let cb = s.bitmask(mc & m);
                    if cb != 0 {
                        let key = key[c];
                        let mut j = nk;
                        while j > 0 && kids[j - 1].0 < key {
                            kids[j] = kids[j - 1];
                            j -= 1;
                        }
                        kids[j] = (key, q.child[c], cb);
                        nk += 1;
                    }
                }
                if nk > 0 {
                    for &(_, kr, kb) in &kids[..nk - 1] {
                        stack[sp] = (kr, kb);
                        sp += 1;
                    }
                    (r, bits) = (kids[nk - 1].1, kids[nk - 1].2);
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            (r, bits) = stack[sp];
        }
        hit
    }

    /// Endpoints (Å) of stick `j` as drawn: trimmed at both ends as the geometry's records
    /// are when balls are drawn (the part inside both end balls is never seen from outside
    /// them).
    pub fn stick_ends(&self, j: usize) -> ([f32; 3], [f32; 3]) {
        let [a, b] = self.bonds[j];
        self.drawn_stick(self.points[a as usize], self.points[b as usize])
    }

    /// [`CompactBvh::stick_ends`] of the stick between points `p` and `q`.
    #[inline(always)]
    fn drawn_stick(&self, p: [f32; 4], q: [f32; 4]) -> ([f32; 3], [f32; 3]) {
        let (p3, q3) = ([p[0], p[1], p[2]], [q[0], q[1], q[2]]);
        let trim = self.n_balls > 0 && !self.capped;
        if !trim {
            return (p3, q3);
        }
        let (start, axis, len) = trimmed_stick(p3, q3, [p[3], q[3]], self.stick_radius, trim);
        let end = std::array::from_fn(|k| (start[k] as f64 + axis[k] * len) as f32);
        (start, end)
    }

    /// The leaf test of slot `slot`'s primitive for lanes `m`.
    #[inline(always)]
    fn intersect_prim<S: Simd>(
        &self,
        s: S,
        ray: &RayPacket<S>,
        m: S::M,
        slot: usize,
        hit: &mut PacketHit<S>,
    ) {
        let id = self.prim_ids[slot];
        if id < self.n_balls {
            let p = self.points[id as usize];
            intersect_ball(s, ray, m, [p[0], p[1], p[2]], p[3], slot as i32, hit);
        } else {
            let [a, b] = self.bonds[(id - self.n_balls) as usize];
            let (p, q) = (self.points[a as usize], self.points[b as usize]);
            let (p, q) = self.drawn_stick(p, q);
            intersect_bond(
                s,
                ray,
                m,
                p,
                q,
                self.stick_radius,
                self.capped,
                slot as i32,
                hit,
            );
        }
    }

    /// Nearest hit of each ray as `(t, primitive id)`, in packets of the backend's width;
    /// rayon over chunks of rays.
    pub fn intersect_rays(&self, isa: Isa, rays: &[Ray]) -> Vec<Option<(f32, Prim)>> {
        rays.par_chunks(1024)
            .flat_map_iter(|chunk| {
                isa.dispatch(Batch {
                    c: self,
                    rays: chunk,
                })
            })
            .collect()
    }
}

/// First slot and count of a leaf reference.
#[inline(always)]
fn leaf_range(r: u32) -> (usize, usize) {
    (
        (r & (MAX_SLOTS as u32 - 1)) as usize,
        ((r >> 28) & 7) as usize,
    )
}

struct Batch<'a> {
    c: &'a CompactBvh,
    rays: &'a [Ray],
}

impl Kernel for Batch<'_> {
    type Output = Vec<Option<(f32, Prim)>>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Self::Output {
        let mut out = Vec::with_capacity(self.rays.len());
        let mut stack = vec![(0u32, 0u32); self.c.stack_size()];
        let mut t = vec![0.0f32; S::LANES];
        let mut slot = vec![0i32; S::LANES];
        for chunk in self.rays.chunks(S::LANES) {
            let p = load_packet(s, chunk);
            let h = self.c.closest_packet(s, &p, &mut stack);
            s.store(h.t, &mut t);
            s.store_i(h.slot, &mut slot);
            out.extend((0..chunk.len()).map(|i| {
                (slot[i] >= 0).then(|| {
                    let id = self.c.prim_ids[slot[i] as usize];
                    let prim = if id < self.c.n_balls {
                        Prim::Ball(id)
                    } else {
                        Prim::Stick(id - self.c.n_balls)
                    };
                    (t[i], prim)
                })
            }));
        }
        out
    }
}
