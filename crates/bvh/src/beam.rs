//! Camera rays by blocks: one walk of the tree for a group of up to `LANES` pixel blocks of
//! `LANES` rays each, nodes tested against every block's frustum and depth bound at once (SIMD
//! over blocks) instead of against every ray of every packet (the packet traversal of paper
//! §4.3 amortised over a whole tile, as in Reshetov et al.'s multi-level ray tracing).
//!
//! A node is entered for block `b` when it meets `b`'s frustum (four planes bounding all of
//! its rays) and may hold a hit nearer than the farthest current hit of `b`'s rays; at a leaf
//! each such block runs the packet leaf test (per-ray box test, then every primitive). Where
//! only a few blocks are left at an inner node, each finishes that subtree as a packet (per-ray
//! box tests, paper §4.3). So every ray meets every primitive it can hit and gets the packet
//! traversal's nearest hit.

use spmd::{Simd, V3};

use crate::intersect::intersect_record;
use crate::traverse::{box_test, PacketHit, RayPacket, BOX_GROW};
use crate::tree::Bvh;

/// Relative slack of the frustum and depth tests, far above f32 rounding (≈ 6·10⁻⁸ per
/// operation), so rounding never culls a node a ray reaches.
const SLACK: f32 = 1e-5;

/// Most blocks still in the walk at an inner node for which each of them finishes the node's
/// subtree as a packet instead ([`Bvh::walk_packets`]): a quarter of the group. Frusta cull
/// well near the root, where many blocks share a node; below, where atoms are smaller than a
/// block or rays pass between them, a frustum meets boxes that none of its rays do, and the
/// rays' own box tests cull better.
///
/// (Measured on AMD EPYC Zen 4, AVX-512, `bench --scenes S --modes bs`, median ms far /
/// close: ns740k 512² 39-41 / 13 with no hand-off, 34-37 / 13-14 with 2 or 4 blocks; 1024²
/// 86-92 / 44-45 against 81-84 / 44-45; sio2 1024² 190-193 / 111-112 against 148-166 /
/// 101-105. Same hits.)
#[inline(always)]
fn handoff_blocks<S: Simd>() -> usize {
    S::LANES / 4
}

/// Rays of one block: the lines through its four corners, in order around the block (Å;
/// directions need not be unit).
#[derive(Clone, Copy, Debug)]
pub struct Corners {
    /// Origins of the corner rays.
    pub o: [[f64; 3]; 4],
    /// Directions of the corner rays.
    pub d: [[f64; 3]; 4],
}

/// Where a group's rays start, for the lower bound of a hit distance inside a box.
#[derive(Clone, Copy, Debug)]
pub enum Origin {
    /// All rays leave one point (perspective camera; Å).
    Point([f32; 3]),
    /// Rays leave the plane through `org` perpendicular to the unit direction `forward` they
    /// all share (orthographic camera; Å).
    Plane {
        /// A point of the plane (Å).
        org: [f32; 3],
        /// The rays' common unit direction.
        forward: [f32; 3],
    },
}

impl Origin {
    /// A lower bound of `t` where any of the group's rays meets the box `[lo, hi]` (Å).
    #[inline(always)]
    fn lower_t(&self, lo: [f32; 3], hi: [f32; 3]) -> f32 {
        match *self {
            Origin::Point(e) => {
                let mut d2 = 0.0;
                for a in 0..3 {
                    let g = (lo[a] - e[a]).max(e[a] - hi[a]).max(0.0);
                    d2 += g * g;
                }
                d2.sqrt()
            }
            Origin::Plane { org, forward } => {
                let mut t = 0.0;
                for a in 0..3 {
                    let near = if forward[a] >= 0.0 { lo[a] } else { hi[a] };
                    t += forward[a] * (near - org[a]);
                }
                t.max(0.0)
            }
        }
    }
}

/// The frusta of a group of blocks, block `b` in lane `b`: inside is `n·p + w ≥ 0` for all
/// four planes.
#[derive(Clone, Copy, Debug)]
pub struct Frusta<S: Simd> {
    n: [V3<S>; 4],
    abs_n: [V3<S>; 4],
    w: [S::F32; 4],
    /// Blocks present (lanes with at least one active ray).
    active: S::M,
    origin: Origin,
    /// Near-child order: the sign of the group's central direction per axis.
    neg: [bool; 3],
}

impl<S: Simd> Frusta<S> {
    /// Frusta of the blocks whose corner rays are `corners` (`corners.len() ≤ LANES`; lane `b`
    /// for `corners[b]`), `present` saying which blocks hold active rays. `centre` is a
    /// direction near the group's rays (front-to-back order); `origin` where they start.
    #[inline(always)]
    pub fn new(s: S, corners: &[Corners], present: u32, origin: Origin, centre: [f32; 3]) -> Self {
        let mut n = [[[0.0f32; spmd::MAX_LANES]; 3]; 4];
        let mut w = [[0.0f32; spmd::MAX_LANES]; 4];
        let mut bits = 0u32;
        for (b, c) in corners.iter().enumerate().take(S::LANES) {
            if present >> b & 1 == 0 {
                continue;
            }
            // A point inside the block's bundle of rays, to orient the planes.
            let mut q = [0.0f64; 3];
            for i in 0..4 {
                q = add(q, add(c.o[i], c.d[i]));
            }
            let q = q.map(|v| 0.25 * v);
            let mut ok = true;
            for p in 0..4 {
                let (i, j) = (p, (p + 1) % 4);
                // The plane holding corner rays i and j: through o_i, o_i + d_i and o_j + d_j.
                let u = c.d[i];
                let v = sub(add(c.o[j], c.d[j]), c.o[i]);
                let mut nn = cross(u, v);
                let mut ww = -dot(nn, c.o[i]);
                if dot(nn, q) + ww < 0.0 {
                    nn = [-nn[0], -nn[1], -nn[2]];
                    ww = -ww;
                }
                ok &= nn.iter().chain([ww].iter()).all(|x| x.is_finite()) && dot(nn, nn) > 0.0;
                for a in 0..3 {
                    n[p][a][b] = nn[a] as f32;
                }
                // Moved outwards by the slack, so the f32 test below stays conservative.
                let scale = (dot(nn, nn).sqrt() * norm_inf(c.o[i]).max(1.0) + ww.abs()) as f32;
                w[p][b] = ww as f32 + SLACK * scale;
            }
            if ok {
                bits |= 1 << b;
            } else {
                // A degenerate block (zero-size or non-finite corners): no plane culls it.
                for (np, wp) in n.iter_mut().zip(w.iter_mut()) {
                    for na in np.iter_mut() {
                        na[b] = 0.0;
                    }
                    wp[b] = 1.0;
                }
                bits |= 1 << b;
            }
        }
        // (Loops, not closures: closures may not inherit the entry point's target features.)
        let mut nv = [V3::splat(s, [0.0; 3]); 4];
        let mut abs_n = nv;
        let mut wv = [s.splat(0.0); 4];
        for p in 0..4 {
            nv[p] = V3::new(s.load(&n[p][0]), s.load(&n[p][1]), s.load(&n[p][2]));
            abs_n[p] = V3::new(s.abs(nv[p].x), s.abs(nv[p].y), s.abs(nv[p].z));
            wv[p] = s.load(&w[p]);
        }
        Frusta {
            n: nv,
            abs_n,
            w: wv,
            active: s.mask_from_bits(bits),
            origin,
            neg: [centre[0] < 0.0, centre[1] < 0.0, centre[2] < 0.0],
        }
    }

    // Blocks whose frustum meets the box [lo, hi] (grown by the slack): for every plane the
    // box's farthest corner along the normal, n·c + |n|·e + w, is not below zero.
    #[inline(always)]
    fn meets(&self, s: S, lo: [f32; 3], hi: [f32; 3]) -> S::M {
        let mut c = [0.0f32; 3];
        let mut e = [0.0f32; 3];
        for a in 0..3 {
            c[a] = 0.5 * (lo[a] + hi[a]);
            e[a] = 0.5 * (hi[a] - lo[a]) + SLACK * (c[a].abs() + (hi[a] - lo[a]).abs());
        }
        let (c, e) = (V3::splat(s, c), V3::splat(s, e));
        let mut m = self.active;
        for p in 0..4 {
            let reach = self.n[p].dot(c) + self.abs_n[p].dot(e) + self.w[p];
            m = m & s.ge(reach, s.splat(0.0));
        }
        m
    }
}

impl Bvh {
    /// Nearest hits of the blocks' rays, `rays[b]` the packet of block `b` of `fr` (at most
    /// `LANES` blocks; `hits.len() == rays.len()`): one walk of the tree for all of them. The
    /// same nearest hits as [`Bvh::traverse_packet`] on each packet (up to ties in `t`).
    ///
    /// `stack` must hold at least [`Bvh::stack_size`] entries.
    #[inline(always)]
    pub fn traverse_blocks<S: Simd>(
        &self,
        s: S,
        fr: &Frusta<S>,
        rays: &[RayPacket<S>],
        hits: &mut [PacketHit<S>],
        stack: &mut [u32],
    ) {
        assert!(rays.len() <= S::LANES && hits.len() == rays.len());
        let nodes = &self.nodes[..];
        let records = &self.records[..];
        let capped = self.capped;
        let grow = s.splat(BOX_GROW);
        let mut inv = [V3::splat(s, [0.0; 3]); spmd::MAX_LANES];
        // Farthest current hit per block (+∞ while a ray has none).
        let mut far_t = [f32::NEG_INFINITY; spmd::MAX_LANES];
        for (b, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
            inv[b] = V3::new(s.rcp(ray.d.x), s.rcp(ray.d.y), s.rcp(ray.d.z));
            hit.t = s.select(ray.active, ray.tmax, s.splat(f32::NEG_INFINITY));
            hit.slot = s.splat_i(-1);
            far_t[b] = s.reduce_max(hit.t);
        }
        let live = fr.active & s.mask_from_bits(((1u64 << rays.len()) - 1) as u32);
        if nodes.is_empty() || s.none(live) {
            return;
        }
        let mut sp = 0usize;
        let mut idx = 0usize;
        loop {
            let node = &nodes[idx];
            // Blocks whose frustum meets the box and whose farthest hit lies beyond its near side.
            let near_t = fr.origin.lower_t(node.min, node.max) * (1.0 - SLACK);
            let m = live & fr.meets(s, node.min, node.max) & s.le(s.splat(near_t), s.load(&far_t));
            if s.any(m) {
                if node.is_leaf() {
                    let first = node.first as usize;
                    let mut bits = s.bitmask(m);
                    while bits != 0 {
                        let b = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let lanes = box_test(s, node, &rays[b], &inv[b], hits[b].t, grow);
                        if s.none(lanes) {
                            continue;
                        }
                        for (k, rec) in records[first..first + node.count()].iter().enumerate() {
                            let slot = (first + k) as i32;
                            intersect_record(s, &rays[b], lanes, rec, capped, slot, &mut hits[b]);
                        }
                        far_t[b] = s.reduce_max(hits[b].t);
                    }
                } else if s.bitmask(m).count_ones() as usize <= handoff_blocks::<S>() {
                    // Few blocks left: each finishes the subtree as a packet, its rays' own
                    // box tests culling what its frustum cannot (sub-pixel atoms, gaps).
                    let mut bits = s.bitmask(m);
                    while bits != 0 {
                        let b = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let ray = std::array::from_ref(&rays[b]);
                        let iv = std::array::from_ref(&inv[b]);
                        let h = std::array::from_mut(&mut hits[b]);
                        let rest = &mut stack[sp..];
                        self.walk_packets::<S, 1, false>(s, ray, iv, h, idx, &fr.neg, rest);
                        far_t[b] = s.reduce_max(hits[b].t);
                    }
                } else {
                    let (near, far) = node.near_far(&fr.neg);
                    stack[sp] = far as u32;
                    sp += 1;
                    idx = near;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            idx = stack[sp] as usize;
        }
    }
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm_inf(a: [f64; 3]) -> f64 {
    a[0].abs().max(a[1].abs()).max(a[2].abs())
}
