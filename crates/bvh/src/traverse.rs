//! BVH traversal: coherent packets with a uniform stack (paper §4.3), a single-ray traversal,
//! brute force references and batch entry points that dispatch once per batch.

use rayon::prelude::*;
use spmd::{Isa, Kernel, Scalar, Simd, V3};

use crate::intersect::{intersect_record, surface};
use crate::tree::Bvh;

/// One ray (uniform data; Å). `d` must be a unit vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin (Å).
    pub o: [f32; 3],
    /// Unit direction.
    pub d: [f32; 3],
    /// Hits must lie beyond this distance (Å).
    pub tmin: f32,
    /// Hits must lie before this distance (Å).
    pub tmax: f32,
}

impl Ray {
    /// A ray from `o` along `d` (normalised here in f64) over `(0, ∞)`.
    pub fn new(o: [f32; 3], d: [f32; 3]) -> Ray {
        let l = ((d[0] as f64).powi(2) + (d[1] as f64).powi(2) + (d[2] as f64).powi(2)).sqrt();
        Ray {
            o,
            d: [
                (d[0] as f64 / l) as f32,
                (d[1] as f64 / l) as f32,
                (d[2] as f64 / l) as f32,
            ],
            tmin: 0.0,
            tmax: f32::INFINITY,
        }
    }
}

/// The nearest hit of one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray (Å).
    pub t: f32,
    /// Slot in [`Bvh::records`] / [`Bvh::prim_ids`].
    pub slot: u32,
    /// Primitive id (see [`crate::Geometry::prim`]).
    pub prim: u32,
    /// Unit outward normal at the hit.
    pub n: [f32; 3],
    /// On a stick, the hit is on the second atom's half.
    pub second_half: bool,
}

/// A packet of `S::LANES` rays, one register per component.
#[derive(Clone, Copy, Debug)]
pub struct RayPacket<S: Simd> {
    /// Origins (Å).
    pub o: V3<S>,
    /// Unit directions.
    pub d: V3<S>,
    /// Lower bound of `t` per lane.
    pub tmin: S::F32,
    /// Upper bound of `t` per lane.
    pub tmax: S::F32,
    /// Lanes carrying a ray.
    pub active: S::M,
}

/// Nearest hits of a packet: `t` (tmax where nothing was hit) and slot (−1: no hit).
#[derive(Clone, Copy, Debug)]
pub struct PacketHit<S: Simd> {
    /// Distance per lane (Å).
    pub t: S::F32,
    /// Record slot per lane, −1 for a miss.
    pub slot: S::I32,
}

impl<S: Simd> PacketHit<S> {
    /// Lanes that hit something.
    #[inline(always)]
    pub fn hit_mask(&self, s: S) -> S::M {
        s.gt_i(self.slot, s.splat_i(-1))
    }
}

/// Stack entries needed by [`Bvh::traverse_packet`] for this tree.
impl Bvh {
    /// Size of the traversal stack this tree needs (depth + 1).
    pub fn stack_size(&self) -> usize {
        self.stats.max_depth + 2
    }

    /// Coherent packet traversal (§4.3): one uniform stack for the packet; a node is entered
    /// when any active ray hits its box nearer than that ray's current hit (boxes are re-tested
    /// when popped, against the current hits); inner nodes push the far child and descend into
    /// the near one, near chosen by the sign of the packet's direction (its first active ray)
    /// along the split axis; leaves test each primitive against all rays that hit the leaf box.
    ///
    /// `stack` must hold at least [`Bvh::stack_size`] entries (allocate it once per task).
    #[inline(always)]
    pub fn traverse_packet<S: Simd>(
        &self,
        s: S,
        ray: &RayPacket<S>,
        stack: &mut [u32],
    ) -> PacketHit<S> {
        let [h] =
            self.traverse_packets::<S, 1>(s, std::slice::from_ref(ray).try_into().unwrap(), stack);
        h
    }

    /// [`Bvh::traverse_packet`] for a packet of `N` registers (`N × LANES` rays): a node is
    /// entered when any ray of any register hits it; at leaves each register with a ray in
    /// the leaf box is tested. Amortises the uniform traversal work over more rays.
    #[inline(always)]
    pub fn traverse_packets<S: Simd, const N: usize>(
        &self,
        s: S,
        rays: &[RayPacket<S>; N],
        stack: &mut [u32],
    ) -> [PacketHit<S>; N] {
        self.query_packets::<S, N, false>(s, rays, stack)
    }

    /// Lanes of `ray` (active ones) that hit any primitive in `(tmin, tmax)`: the packet
    /// traversal with any-hit early exit (a lane that hits anything stops taking part in box
    /// tests; the packet stops when every lane has hit). For shadow and AO rays.
    #[inline(always)]
    pub fn occluded_packet<S: Simd>(&self, s: S, ray: &RayPacket<S>, stack: &mut [u32]) -> S::M {
        let [h] = self.query_packets::<S, 1, true>(
            s,
            std::slice::from_ref(ray).try_into().unwrap(),
            stack,
        );
        h.hit_mask(s) & ray.active
    }

    /// The one packet traversal behind [`Bvh::traverse_packets`] (`ANY = false`: nearest
    /// hits) and [`Bvh::occluded_packet`] (`ANY = true`: a lane's first hit ends its search,
    /// its `t` becomes −∞ and its slot says only "occluded"; the packet ends when every
    /// active lane is occluded) — Embree's closest / any-hit epilogs over one loop.
    #[inline(always)]
    fn query_packets<S: Simd, const N: usize, const ANY: bool>(
        &self,
        s: S,
        rays: &[RayPacket<S>; N],
        stack: &mut [u32],
    ) -> [PacketHit<S>; N] {
        // (Loops, not `array::from_fn` closures: closures may not inherit target features.)
        let mut inv = [V3::splat(s, [0.0; 3]); N];
        let mut hits = [PacketHit {
            t: s.splat(0.0),
            slot: s.splat_i(-1),
        }; N];
        for j in 0..N {
            let d = rays[j].d;
            inv[j] = V3::new(s.rcp(d.x), s.rcp(d.y), s.rcp(d.z));
            // Inactive lanes get t = −∞ so no box test passes for them.
            hits[j].t = s.select(rays[j].active, rays[j].tmax, s.splat(f32::NEG_INFINITY));
        }
        let mut first = N;
        for j in (0..N).rev() {
            if s.any(rays[j].active) {
                first = j;
            }
        }
        if first == N || self.nodes.is_empty() {
            return hits;
        }
        let lane = s.bitmask(rays[first].active).trailing_zeros() as usize;
        let d0 = rays[first].d;
        let neg = [
            s.extract(d0.x, lane) < 0.0,
            s.extract(d0.y, lane) < 0.0,
            s.extract(d0.z, lane) < 0.0,
        ];
        self.walk_packets::<S, N, ANY>(s, rays, &inv, &mut hits, 0, &neg, stack);
        hits
    }

    /// The loop of [`Bvh::query_packets`] over the subtree of node `root`, from the current
    /// `hits` (`inv`: the rays' reciprocal directions; `neg`: the signs that order children).
    /// Also finishes a block of [`Bvh::traverse_blocks`] below the node where it leaves the
    /// block walk.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn walk_packets<S: Simd, const N: usize, const ANY: bool>(
        &self,
        s: S,
        rays: &[RayPacket<S>; N],
        inv: &[V3<S>; N],
        hits: &mut [PacketHit<S>; N],
        root: usize,
        neg: &[bool; 3],
        stack: &mut [u32],
    ) {
        let nodes = &self.nodes[..];
        let records = &self.records[..];
        let capped = self.capped;
        let grow = s.splat(BOX_GROW);
        let mut sp = 0usize;
        let mut idx = root;
        let mut masks = [s.splat_m(false); N];
        loop {
            let node = &nodes[idx];
            let mut any = false;
            for j in 0..N {
                masks[j] = box_test(s, node, &rays[j], &inv[j], hits[j].t, grow);
                any |= s.any(masks[j]);
            }
            if any {
                if node.is_leaf() {
                    let first = node.first as usize;
                    for (k, rec) in records[first..first + node.count()].iter().enumerate() {
                        for j in 0..N {
                            if N > 1 && s.none(masks[j]) {
                                continue;
                            }
                            // One leaf test; any-hit starts from "no hit" and its epilog
                            // ends a hit lane (t = −∞ fails every box), closest keeps the nearest.
                            let mut h = PacketHit {
                                t: hits[j].t,
                                slot: if ANY { s.splat_i(-1) } else { hits[j].slot },
                            };
                            let slot = (first + k) as i32;
                            intersect_record(s, &rays[j], masks[j], rec, capped, slot, &mut h);
                            if ANY {
                                let hit = s.gt_i(h.slot, s.splat_i(-1));
                                hits[j].slot = s.select_i(hit, h.slot, hits[j].slot);
                                hits[j].t = s.select(hit, s.splat(f32::NEG_INFINITY), hits[j].t);
                            } else {
                                hits[j] = h;
                            }
                        }
                    }
                    if ANY {
                        let mut open = false;
                        for j in 0..N {
                            open |= s.any(rays[j].active & !hits[j].hit_mask(s));
                        }
                        if !open {
                            return;
                        }
                    }
                } else {
                    let (near, far) = node.near_far(neg);
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

    /// Origin for a secondary ray leaving the hit `h` of `ray`: the hit point offset along the
    /// normal, to the side the ray came from, by `64·ε·(max|p| + t + r)` Å — more than the
    /// rounding error of the hit point and of the kernels, so a ray spawned there into that
    /// hemisphere never re-hits the same surface (the pbrt rule).
    pub fn spawn_point(&self, ray: &Ray, h: &Hit) -> [f32; 3] {
        let p = [
            ray.o[0] + ray.d[0] * h.t,
            ray.o[1] + ray.d[1] * h.t,
            ray.o[2] + ray.d[2] * h.t,
        ];
        let r = self.records[h.slot as usize].r;
        let m = p.iter().fold(0.0f32, |a, v| a.max(v.abs()));
        let off = 64.0 * f32::EPSILON * (m + h.t.abs() + r.abs());
        let side = if h.n[0] * ray.d[0] + h.n[1] * ray.d[1] + h.n[2] * ray.d[2] > 0.0 {
            -off
        } else {
            off
        };
        [
            p[0] + h.n[0] * side,
            p[1] + h.n[1] * side,
            p[2] + h.n[2] * side,
        ]
    }

    /// Nearest hits of a packet by testing every primitive (reference for tests; O(n)).
    #[inline(always)]
    pub(crate) fn brute_packet<S: Simd>(&self, s: S, ray: &RayPacket<S>) -> PacketHit<S> {
        let mut hit = PacketHit {
            t: s.select(ray.active, ray.tmax, s.splat(f32::NEG_INFINITY)),
            slot: s.splat_i(-1),
        };
        for (k, rec) in self.records.iter().enumerate() {
            intersect_record(s, ray, ray.active, rec, self.capped, k as i32, &mut hit);
        }
        hit
    }

    /// Single-ray traversal (the packet traversal on the scalar backend): for secondary or
    /// otherwise incoherent rays, one at a time.
    pub fn intersect_ray(&self, ray: &Ray) -> Option<Hit> {
        let mut stack = vec![0u32; self.stack_size()];
        let s = Scalar;
        let p = load_packet(s, std::slice::from_ref(ray));
        let h = self.traverse_packet(s, &p, &mut stack);
        unpack_hits(self, s, &p, &h).pop().flatten()
    }

    /// Nearest hits of many rays, in packets of the backend's width; rayon over chunks of rays,
    /// one dispatch per chunk.
    pub fn intersect_rays(&self, isa: Isa, rays: &[Ray]) -> Vec<Option<Hit>> {
        self.batch(isa, rays, false)
    }

    /// As [`Bvh::intersect_rays`] but testing every primitive for every ray (slow reference).
    pub fn intersect_rays_brute(&self, isa: Isa, rays: &[Ray]) -> Vec<Option<Hit>> {
        self.batch(isa, rays, true)
    }

    /// Nearest hits of `rays` on the calling thread: one dispatch, packets in order
    /// (`brute`: test every primitive instead of traversing). For benchmarks and tools.
    pub fn intersect_chunk(&self, isa: Isa, rays: &[Ray], brute: bool) -> Vec<Option<Hit>> {
        isa.dispatch(BatchKernel {
            bvh: self,
            rays,
            brute,
        })
    }

    fn batch(&self, isa: Isa, rays: &[Ray], brute: bool) -> Vec<Option<Hit>> {
        rays.par_chunks(1024)
            .flat_map_iter(|chunk| {
                isa.dispatch(BatchKernel {
                    bvh: self,
                    rays: chunk,
                    brute,
                })
            })
            .collect()
    }
}

struct BatchKernel<'a> {
    bvh: &'a Bvh,
    rays: &'a [Ray],
    brute: bool,
}

impl Kernel for BatchKernel<'_> {
    type Output = Vec<Option<Hit>>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Vec<Option<Hit>> {
        let mut out = Vec::with_capacity(self.rays.len());
        let mut stack = vec![0u32; self.bvh.stack_size()];
        for chunk in self.rays.chunks(S::LANES) {
            let p = load_packet(s, chunk);
            let h = if self.brute {
                self.bvh.brute_packet(s, &p)
            } else {
                self.bvh.traverse_packet(s, &p, &mut stack)
            };
            out.extend(
                unpack_hits(self.bvh, s, &p, &h)
                    .into_iter()
                    .take(chunk.len()),
            );
        }
        out
    }
}

/// Packs up to `LANES` rays into a packet (missing lanes inactive).
#[inline(always)]
pub fn load_packet<S: Simd>(s: S, rays: &[Ray]) -> RayPacket<S> {
    let mut buf = [[0.0f32; spmd::MAX_LANES]; 8];
    for (i, r) in rays.iter().take(S::LANES).enumerate() {
        let v = [
            r.o[0], r.o[1], r.o[2], r.d[0], r.d[1], r.d[2], r.tmin, r.tmax,
        ];
        for k in 0..8 {
            buf[k][i] = v[k];
        }
    }
    RayPacket {
        o: V3::new(s.load(&buf[0]), s.load(&buf[1]), s.load(&buf[2])),
        d: V3::new(s.load(&buf[3]), s.load(&buf[4]), s.load(&buf[5])),
        tmin: s.load(&buf[6]),
        tmax: s.load(&buf[7]),
        active: s.first_n(rays.len()),
    }
}

/// Unpacks a packet's hits (with normals) into one entry per lane.
#[inline(always)]
pub fn unpack_hits<S: Simd>(
    bvh: &Bvh,
    s: S,
    p: &RayPacket<S>,
    h: &PacketHit<S>,
) -> Vec<Option<Hit>> {
    let m = h.hit_mask(s) & p.active;
    let srf = surface(s, &bvh.records, p.o, p.d, h.t, h.slot, m);
    let bits = s.bitmask(m);
    let half = s.bitmask(srf.second_half);
    let mut out = Vec::with_capacity(S::LANES);
    for i in 0..S::LANES {
        if bits & (1 << i) == 0 {
            out.push(None);
            continue;
        }
        let slot = s.extract_i(h.slot, i) as u32;
        out.push(Some(Hit {
            t: s.extract(h.t, i),
            slot,
            prim: bvh.prim_ids[slot as usize],
            n: [
                s.extract(srf.n.x, i),
                s.extract(srf.n.y, i),
                s.extract(srf.n.z, i),
            ],
            second_half: half & (1 << i) != 0,
        }));
    }
    out
}

/// Box exits are inflated by this factor, 1 + 2γ₃ (pbrt), so rounding never loses a box that
/// a ray hits.
pub const BOX_GROW: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Ray–box slab test (§4.3 traversal), per lane: the ray `o + t·d` (`inv` = 1/d) against the
/// box `lo..hi`; lanes may hold different rays (packets) or different boxes (one ray against a
/// wide node's children). Returns the lanes whose ray enters the box in `[tmin, t]`, and the
/// entry distances. `min`/`max` drop a NaN first operand (0·∞ for a ray in a slab plane); the
/// exit is inflated by [`BOX_GROW`] (`grow` = its splat) so rounding never loses a box.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn slab_test<S: Simd>(
    s: S,
    lo: V3<S>,
    hi: V3<S>,
    o: V3<S>,
    inv: V3<S>,
    tmin: S::F32,
    t: S::F32,
    grow: S::F32,
) -> (S::M, S::F32) {
    let tx0 = (lo.x - o.x) * inv.x;
    let tx1 = (hi.x - o.x) * inv.x;
    let ty0 = (lo.y - o.y) * inv.y;
    let ty1 = (hi.y - o.y) * inv.y;
    let tz0 = (lo.z - o.z) * inv.z;
    let tz1 = (hi.z - o.z) * inv.z;
    let entry = s.max(
        s.min(tx0, tx1),
        s.max(s.min(ty0, ty1), s.max(s.min(tz0, tz1), tmin)),
    );
    let exit = s.min(
        s.max(tx0, tx1),
        s.min(s.max(ty0, ty1), s.min(s.max(tz0, tz1), t)),
    );
    (s.le(entry, exit * grow) & s.le(entry, t), entry)
}

/// [`slab_test`] of one node against a packet: lanes whose ray enters the box before its
/// current hit `t`.
#[inline(always)]
pub fn box_test<S: Simd>(
    s: S,
    node: &crate::tree::Node,
    ray: &RayPacket<S>,
    inv: &V3<S>,
    t: S::F32,
    grow: S::F32,
) -> S::M {
    let lo = V3::splat(s, node.min);
    let hi = V3::splat(s, node.max);
    slab_test(s, lo, hi, ray.o, *inv, ray.tmin, t, grow).0
}
