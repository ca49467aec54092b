//! Secondary-ray queries by a chosen traversal: the packet traversal (§4.3), each lane alone on
//! the scalar backend, or each lane alone through the 8-wide BVH — nearest hit or any hit.

use spmd::{Scalar, Simd, V3};

use crate::traverse::{PacketHit, Ray, RayPacket};
use crate::tree::Bvh;
use crate::wide::{WideBvh, WideEntry};

/// How a packet of (secondary) rays traverses the BVH.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Traversal {
    /// The packet as one over the binary BVH.
    #[default]
    Packet,
    /// Each active lane alone through the binary BVH on the scalar backend.
    Single,
    /// Each active lane alone through the 8-wide BVH.
    Wide,
}

/// Traversal stacks of one task: the binary BVH's (packets and single rays) and the wide
/// BVH's (empty when no wide BVH is given).
#[derive(Clone, Debug)]
pub struct Stacks {
    packet: Vec<u32>,
    wide: Vec<WideEntry>,
}

impl Stacks {
    /// Stacks for queries of `bvh` and, when given, its wide BVH.
    pub fn new(bvh: &Bvh, wide: Option<&WideBvh>) -> Stacks {
        Stacks {
            packet: vec![0; bvh.stack_size()],
            wide: wide.map_or(Vec::new(), |w| vec![WideEntry::default(); w.stack_size()]),
        }
    }

    /// The binary BVH's stack (for [`Bvh::traverse_packets`]).
    pub fn packet(&mut self) -> &mut [u32] {
        &mut self.packet
    }
}

/// The BVH and how to traverse it: `wide` must be `Some` (built from `bvh`) when `how` is
/// [`Traversal::Wide`].
#[derive(Clone, Copy, Debug)]
pub struct Query<'a> {
    /// The binary tree (its records are shared by the wide one).
    pub bvh: &'a Bvh,
    /// Its 8-wide collapse.
    pub wide: Option<&'a WideBvh>,
    /// The traversal.
    pub how: Traversal,
}

impl Query<'_> {
    /// Lanes of `ray` (active ones) that hit anything in `(tmin, tmax)`.
    #[inline(always)]
    pub fn occluded<S: Simd>(&self, s: S, ray: &RayPacket<S>, st: &mut Stacks) -> S::M {
        if self.how == Traversal::Packet {
            return self.bvh.occluded_packet(s, ray, &mut st.packet);
        }
        let (_, slot) = self.lanes::<S, true>(s, ray, st);
        s.gt_i(s.load_i(&slot), s.splat_i(-1))
    }

    /// Nearest hits of `ray` (as [`Bvh::traverse_packet`]: slot −1 where nothing is hit).
    #[inline(always)]
    pub fn closest<S: Simd>(&self, s: S, ray: &RayPacket<S>, st: &mut Stacks) -> PacketHit<S> {
        if self.how == Traversal::Packet {
            return self.bvh.traverse_packet(s, ray, &mut st.packet);
        }
        let (t, slot) = self.lanes::<S, false>(s, ray, st);
        PacketHit {
            t: s.load(&t),
            slot: s.load_i(&slot),
        }
    }

    /// Each active lane traced alone: per lane `(t, slot)`, slot −1 for a miss and for
    /// inactive lanes. `ANY`: stop at the first hit (slot ≥ 0 then only says "occluded").
    #[inline(always)]
    fn lanes<S: Simd, const ANY: bool>(
        &self,
        s: S,
        ray: &RayPacket<S>,
        st: &mut Stacks,
    ) -> ([f32; spmd::MAX_LANES], [i32; spmd::MAX_LANES]) {
        let mut buf = [[0.0f32; spmd::MAX_LANES]; 8];
        for (b, v) in buf.iter_mut().zip([
            ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, ray.tmin, ray.tmax,
        ]) {
            s.store(v, b);
        }
        let wide = if self.how == Traversal::Wide {
            self.wide
        } else {
            None
        };
        let bvh = self.bvh;
        let mut t = [f32::NEG_INFINITY; spmd::MAX_LANES];
        let mut slot = [-1i32; spmd::MAX_LANES];
        let mut bits = s.bitmask(ray.active);
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let r = Ray {
                o: [buf[0][i], buf[1][i], buf[2][i]],
                d: [buf[3][i], buf[4][i], buf[5][i]],
                tmin: buf[6][i],
                tmax: buf[7][i],
            };
            (t[i], slot[i]) = match (wide, ANY) {
                (Some(w), true) => (r.tmax, -i32::from(!w.occluded(s, bvh, &r, &mut st.wide))),
                (Some(w), false) => w.closest(s, bvh, &r, &mut st.wide),
                (None, true) => {
                    let hit = bvh.occluded_packet(Scalar, &scalar_packet(&r), &mut st.packet);
                    (r.tmax, -i32::from(!hit))
                }
                (None, false) => {
                    let h = bvh.traverse_packet(Scalar, &scalar_packet(&r), &mut st.packet);
                    (h.t, h.slot.0)
                }
            };
        }
        (t, slot)
    }
}

/// One ray as a one-lane packet of the scalar backend.
#[inline(always)]
fn scalar_packet(r: &Ray) -> RayPacket<Scalar> {
    RayPacket {
        o: V3::new(r.o[0], r.o[1], r.o[2]),
        d: V3::new(r.d[0], r.d[1], r.d[2]),
        tmin: r.tmin,
        tmax: r.tmax,
        active: true,
    }
}
