//! Integrators: what one tile of camera rays computes per pixel (paper §4.2 `renderTile` /
//! `trace`, §4.5), one file per modality. The frame driver ([`crate::driver`]) schedules the
//! tiles; [`TileJob`] is the one kernel it dispatches.
//!
//! Direct and AO produce display values (atom colour × shading, like the b&s mode). Path
//! tracing works in linear radiance: atom colours are linearised with gamma 2 (`c²`) and the
//! result is tone mapped by exposure, clamp and gamma 2 (`√x`); the environment (every ray that
//! escapes) has the background colour as its radiance.

mod ao;
mod direct;
mod headlight;
mod path;
mod sampled;

pub(crate) use ao::ao_factor;

use bvh::{surface, PacketHit, Query, RayPacket, Stacks};
use scene::Model;
use spmd::{Kernel, Simd, V3};
use volume::Medium;

use crate::camera_rays::ViewRays;
use crate::settings::{Modality, RenderSettings};
use crate::TILE;

/// A tile's result: packed RGBA8 (headlight modes) or per-pixel RGB sums of `spp` samples
/// (ray-traced modalities), `TILE × TILE` pixels row major.
pub(crate) enum TileOut {
    /// Display pixels.
    Packed(Vec<u32>),
    /// `3 × TILE × TILE` sums.
    Rgb(Vec<f32>),
}

/// One tile of one frame: the kernel the driver dispatches per tile.
pub(crate) struct TileJob<'a> {
    pub(crate) model: Option<&'a Model>,
    pub(crate) volume: Option<&'a Medium<'a>>,
    pub(crate) view: &'a ViewRays,
    pub(crate) set: &'a RenderSettings,
    /// Top-left pixel of the tile.
    pub(crate) x0: usize,
    pub(crate) y0: usize,
    /// Frame width (pixel indices of the random numbers).
    pub(crate) width: usize,
    /// Number of the first sample and samples to take.
    pub(crate) first_sample: u32,
    pub(crate) spp: u32,
}

impl TileJob<'_> {
    /// Runs the tile on `isa`: the headlight modes and the sampled modalities are two
    /// kernels, so each `#[target_feature]` entry point holds one of them (as at a81d852;
    /// one entry holding every integrator is one very large function for LLVM).
    pub(crate) fn dispatch(self, isa: spmd::Isa) -> TileOut {
        match self.set.modality {
            Modality::Headlight => TileOut::Packed(isa.dispatch(HeadlightTile(self))),
            _ => TileOut::Rgb(isa.dispatch(SampledTile(self))),
        }
    }
}

/// The headlight b&s / volume / vol+bs tile kernel (paper §4.2 `renderTile`).
struct HeadlightTile<'a>(TileJob<'a>);

impl Kernel for HeadlightTile<'_> {
    type Output = Vec<u32>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Vec<u32> {
        headlight::tile(s, &self.0)
    }
}

/// The sampled modalities' tile kernel: direct light, AO, path (paper §4.5).
struct SampledTile<'a>(TileJob<'a>);

impl Kernel for SampledTile<'_> {
    type Output = Vec<f32>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Vec<f32> {
        sampled::tile(s, &self.0)
    }
}

/// The secondary-ray query of `model` by `how` (the wide BVH looked up once; `wide`: the
/// settings use it, see [`crate::RenderSettings::uses_wide`]).
#[inline(always)]
pub(crate) fn query(model: &Model, how: crate::SecondaryTraversal, wide: bool) -> Query<'_> {
    let how: bvh::Traversal = how.into();
    Query {
        bvh: &model.bvh,
        wide: (wide && how == bvh::Traversal::Wide).then(|| model.wide()),
        how,
    }
}

/// Traversal stacks for `model`'s binary BVH and, when `wide`, its wide BVH.
pub(crate) fn stacks(model: &Model, wide: bool) -> Stacks {
    Stacks::new(&model.bvh, wide.then(|| model.wide()))
}

/// What [`trace`] found for a packet.
#[derive(Clone, Copy, Debug)]
pub struct Traced<S: Simd> {
    /// Nearest opaque hit (`slot` −1 where none).
    pub hit: PacketHit<S>,
    /// Lanes (active) with an opaque hit.
    pub mask: S::M,
    /// Hit point (garbage where no hit).
    pub p: V3<S>,
    /// Unit normal at the hit, facing the ray's origin side.
    pub n: V3<S>,
    /// Atom colour at the hit, RGB in [0, 1] (display values).
    pub color: V3<S>,
    /// Premultiplied volume colour and opacity in front of the hit (zeros without a volume
    /// pass).
    pub volume: [S::F32; 4],
}

/// Paper §4.2 `trace`: the opaque pass (when `model` is given) and then the volume pass (when
/// `volume` is given) marched up to the opaque hit.
#[inline(always)]
pub fn trace<S: Simd>(
    s: S,
    model: Option<&Model>,
    volume: Option<&Medium>,
    ray: &RayPacket<S>,
    stack: &mut [u32],
) -> Traced<S> {
    let mut out = match model {
        Some(sc) => hit_surface(s, sc, ray, sc.bvh.traverse_packet(s, ray, stack)),
        None => traced_none(s),
    };
    if let Some(vs) = volume {
        let depth = s.select(out.mask, out.hit.t, s.splat(f32::INFINITY));
        out.volume = vs.march(s, ray.o, ray.d, depth, ray.active);
    }
    out
}

/// [`trace`]'s opaque pass for secondary rays by the query `q` (no volume pass).
#[inline(always)]
pub(crate) fn trace_secondary<S: Simd>(
    s: S,
    model: &Model,
    q: &Query,
    ray: &RayPacket<S>,
    st: &mut Stacks,
) -> Traced<S> {
    hit_surface(s, model, ray, q.closest(s, ray, st))
}

/// A [`Traced`] with no hit and no volume.
#[inline(always)]
fn traced_none<S: Simd>(s: S) -> Traced<S> {
    let zero = s.splat(0.0);
    Traced {
        hit: PacketHit {
            t: s.splat(f32::INFINITY),
            slot: s.splat_i(-1),
        },
        mask: s.splat_m(false),
        p: V3::splat(s, [0.0; 3]),
        n: V3::splat(s, [0.0, 0.0, 1.0]),
        color: V3::splat(s, [0.0; 3]),
        volume: [zero; 4],
    }
}

/// The opaque pass's result for the hits `h` of `ray`: mask, point, normal facing the ray,
/// atom colour (no volume).
#[inline(always)]
fn hit_surface<S: Simd>(s: S, sc: &Model, ray: &RayPacket<S>, h: PacketHit<S>) -> Traced<S> {
    let zero = s.splat(0.0);
    let mut out = traced_none(s);
    let m = h.hit_mask(s) & ray.active;
    out.hit = h;
    out.mask = m;
    if s.any(m) {
        let srf = surface(s, &sc.bvh.records, ray.o, ray.d, h.t, h.slot, m);
        let flip = s.gt(srf.n.dot(ray.d), zero);
        out.n = V3::select(s, flip, -srf.n, srf.n);
        out.p = ray.o.mul_add(ray.d, h.t);
        let zi = s.splat_i(0);
        let ca = s.gather_i(&sc.slot_color_a, h.slot, m, zi);
        let cb = s.gather_i(&sc.slot_color_b, h.slot, m, zi);
        let c = s.select_i(srf.second_half, cb, ca);
        out.color = V3::new(
            unit_channel(s, c, 0),
            unit_channel(s, c, 8),
            unit_channel(s, c, 16),
        );
    }
    out
}

/// One 8-bit channel of packed colours as a value in [0, 1] (a function, not a closure, so it
/// inherits the entry point's target features).
#[inline(always)]
fn unit_channel<S: Simd>(s: S, c: S::I32, shift: u32) -> S::F32 {
    s.to_f32(s.shr(c, shift) & s.splat_i(255)) * s.splat(1.0 / 255.0)
}

/// Origin of a secondary ray leaving hit `tr` to the side of its normal: the hit point moved
/// along the normal by `64·ε·(max|p| + t + r)` Å (as [`bvh::Bvh::spawn_point`]).
#[inline(always)]
pub(crate) fn spawn<S: Simd>(s: S, model: &Model, tr: &Traced<S>) -> V3<S> {
    let flat: &[f32] = bytemuck::cast_slice(&model.bvh.records);
    let r = s.gather(
        flat,
        s.shl(tr.hit.slot, 3) + s.splat_i(3),
        tr.mask,
        s.splat(0.0),
    );
    let p = tr.p;
    let m = s.max(s.abs(p.x), s.max(s.abs(p.y), s.abs(p.z)));
    let off = s.splat(64.0 * f32::EPSILON) * (m + s.abs(tr.hit.t) + s.abs(r));
    p.mul_add(tr.n, off)
}

/// Premultiplied volume colour over an opaque colour.
#[inline(always)]
pub(crate) fn over_rgb<S: Simd>(s: S, v: [S::F32; 4], c: V3<S>) -> V3<S> {
    let t = s.splat(1.0) - v[3];
    V3::new(v[0] + t * c.x, v[1] + t * c.y, v[2] + t * c.z)
}

/// `TILE` as used by the tile loops.
pub(crate) const TILE_PIXELS: usize = TILE * TILE;
