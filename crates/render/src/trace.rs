//! Ray tracing modalities (paper §4.2 `trace`, §4.5, Figure 4): ball-and-stick with a
//! directional light and hard shadows, ambient occlusion, path tracing with a metal or diffuse
//! BRDF (progressive, f32 accumulation), and shadow rays attenuated by the volume (the
//! soft-shadow effect of §4.5).
//!
//! ## The `trace` step
//! [`trace`] runs the opaque pass (nearest hit in the BVH, surface normal and colour) and/or
//! the volume pass (front to back up to the opaque hit) for a packet of rays and returns both;
//! shaders call it for primary rays and again for secondary rays.
//!
//! ## Secondary rays
//! Shadow and AO rays only need *whether* something is hit: [`occluded`] is a packet traversal
//! with any-hit early exit (a lane that hits anything stops taking part in box tests; the
//! packet stops when every lane has hit). The path tracer's bounced rays go every which way;
//! they are traced one at a time through the 8-wide BVH ([`bvh::WideBvh`]), which tests a
//! node's eight child boxes in one SIMD op. Each ray kind can use either traversal (or the
//! scalar single-ray one); the figures that chose the defaults are at [`SecondaryTraversal`].
//!
//! ## Random numbers
//! Every random number is a pure function of (seed, pixel index, sample index, draw number):
//! an integer hash (Wellons' `lowbias32`) built from `spmd` integer ops, which are exact on
//! every backend. So a picture repeats exactly for a seed, progressive renders give the same
//! result however the samples are split into calls, and every backend draws the same numbers
//! for the same pixel (they differ only where `fma` fusion changes a hit).
//!
//! ## Colour
//! Direct and AO modes produce display values (atom colour × shading, like the `bs` mode).
//! Path tracing works in linear radiance: atom colours are linearised with gamma 2 (`c²`) and
//! the result is tone mapped by exposure, clamp and gamma 2 (`√x`); the environment (every ray
//! that escapes) has the background colour as its radiance, so a white background is a
//! uniform white sky of radiance 1.

use std::time::Instant;

use bvh::{
    box_test, intersect_record, surface, Bvh, PacketHit, Ray, RayPacket, WideEntry, BOX_GROW,
};
use rayon::prelude::*;
use spmd::{Isa, Kernel, Scalar, Simd, V3};
use volume::{Light, VolumeScene};

use crate::framebuffer::{Framebuffer, RenderError};
use crate::tile::{block_width, RenderStats, ViewRays, TILE};
use scene::Camera;
use scene::Model;

/// BRDF of the path tracer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Material {
    /// Lambertian, albedo = atom colour.
    Diffuse,
    /// Conductor: mirror reflection blurred by `roughness`, Schlick Fresnel with F0 = atom
    /// colour.
    Metal,
}

/// What the shader computes per pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Modality {
    /// Diffuse shading from the directional light: colour × (ambient + intensity·max(0, n·l)·V),
    /// V = 1, or the shadow-ray visibility when `shadows`.
    Direct {
        /// Cast a shadow ray per hit.
        shadows: bool,
    },
    /// Ambient occlusion: colour × fraction of `samples` cosine-distributed rays that travel
    /// `distance` Å without hitting geometry.
    Ao {
        /// Rays per hit (≥ 1).
        samples: u32,
        /// Occlusion distance, Å.
        distance: f32,
    },
    /// Path tracing, progressive: every sample is one path of at most `max_depth` hits;
    /// environment = background colour, plus next-event estimation of the directional light
    /// on diffuse surfaces.
    Path {
        /// BRDF.
        material: Material,
        /// Maximum hits per path (≥ 1); a path still bouncing then contributes nothing more.
        max_depth: u32,
        /// Metal only: radius of the random offset added to the mirror direction (0 = mirror).
        roughness: f32,
    },
}

/// How secondary rays (shadow, AO, path bounces) traverse the BVH.
///
/// Measured on ns90k, 1024², 2 threads, AVX2 (AMD EPYC, 2026-11-27), s per frame (path: per
/// sample, metal, 6 hits), packet / single / wide:
///
/// | ray kind | far | close |
/// |---|---|---|
/// | shadow | 0.245 / 0.337 / 0.367 | 0.176 / 0.527 / 0.390 |
/// | AO, 4 samples | 0.609 / 1.076 / 0.960 | 0.489 / 1.866 / 1.496 |
/// | path bounces | 3.73 / 2.99 / 2.04 | 8.40 / 7.11 / 5.25 |
///
/// Shadow rays (all towards one light) and short AO rays from neighbouring pixels stay
/// coherent, so packets win; bounced path rays do not, so the wide BVH wins (1.6-1.8×; on
/// SSE4.1 1.3×, 3.39 vs 2.63 s; the scalar backend tests 8 boxes one at a time, 3.10 vs
/// 3.33 s). Defaults: [`TraceOptions::secondary`] `Packet`, [`TraceOptions::bounces`] `Wide`.
/// (Earlier, AVX-512 on a loaded machine: shadows 0.370 s packet vs 0.659 s single; AO 0.903
/// vs 1.887 s.)
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SecondaryTraversal {
    /// The rays of a pixel block as one packet over the binary BVH (any-hit early exit for
    /// shadow and AO rays).
    #[default]
    Packet,
    /// Each lane alone through the binary BVH on the scalar backend.
    Single,
    /// Each lane alone through the 8-wide BVH ([`Model::wide`]), eight child boxes per SIMD
    /// op.
    Wide,
}

/// Options of the modalities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceOptions {
    /// What to compute.
    pub modality: Modality,
    /// The light of `Direct` shading and of the path tracer's next-event estimation
    /// (directional, or a point without distance fall-off).
    pub light: Light,
    /// Light intensity (Direct: factor of `max(0, n·l)`; Path: irradiance / π).
    pub light_intensity: f32,
    /// Ambient term of `Direct`.
    pub ambient: f32,
    /// Background colour, RGB in [0, 1] (display values; Path: environment radiance `bg²`).
    pub background: [f32; 3],
    /// Seed of the random numbers.
    pub seed: u32,
    /// Shadow rays (Direct shadows, Path next-event estimation) are attenuated by the volume
    /// when one is given (paper §4.5 soft shadows).
    pub volume_shadows: bool,
    /// Step of shadow rays through the volume, voxels (coarser than the primary 0.5).
    pub shadow_step_voxels: f32,
    /// Path tracing: radiance multiplier before clamp and gamma.
    pub exposure: f32,
    /// Traversal of shadow and AO rays (and the path tracer's light samples).
    pub secondary: SecondaryTraversal,
    /// Traversal of the path tracer's bounced rays (primary rays always go in packets).
    pub bounces: SecondaryTraversal,
}

impl TraceOptions {
    /// Whether these options use the wide BVH (so it is built before the tiles start).
    pub fn uses_wide(&self) -> bool {
        match self.modality {
            Modality::Direct { shadows } => shadows && self.secondary == SecondaryTraversal::Wide,
            Modality::Ao { .. } => self.secondary == SecondaryTraversal::Wide,
            Modality::Path { .. } => {
                self.bounces == SecondaryTraversal::Wide
                    || self.secondary == SecondaryTraversal::Wide
            }
        }
    }
}

impl Default for TraceOptions {
    fn default() -> Self {
        TraceOptions {
            modality: Modality::Direct { shadows: true },
            light: Light::Directional([1.0, 2.0, 1.5]),
            light_intensity: 0.85,
            ambient: 0.2,
            background: [1.0, 1.0, 1.0],
            seed: 1,
            volume_shadows: true,
            shadow_step_voxels: 2.0,
            exposure: 1.0,
            secondary: SecondaryTraversal::Packet,
            bounces: SecondaryTraversal::Wide,
        }
    }
}

/// A progressive f32 accumulation buffer: per pixel the sum of the RGB samples so far.
#[derive(Clone, Debug)]
pub struct Accum {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `3 × width × height` sums, row major, top row first.
    pub rgb: Vec<f32>,
    /// Samples per pixel accumulated so far.
    pub samples: u32,
}

impl Accum {
    /// An empty buffer.
    pub fn new(width: u32, height: u32) -> Result<Accum, RenderError> {
        let n = (width as usize)
            .checked_mul(height as usize)
            .and_then(|n| n.checked_mul(3))
            .filter(|&n| n <= isize::MAX as usize / 4)
            .ok_or(RenderError::TooLarge(width, height))?;
        let mut rgb = Vec::new();
        rgb.try_reserve_exact(n)
            .map_err(|_| RenderError::TooLarge(width, height))?;
        rgb.resize(n, 0.0);
        Ok(Accum {
            width,
            height,
            rgb,
            samples: 0,
        })
    }

    /// Mean of the samples of pixel (x, y).
    pub fn mean(&self, x: u32, y: u32) -> [f32; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        let k = 1.0 / self.samples.max(1) as f32;
        [self.rgb[i] * k, self.rgb[i + 1] * k, self.rgb[i + 2] * k]
    }

    /// The picture: for path tracing (`linear`) exposure, clamp and gamma 2; otherwise the
    /// means are display values, clamped.
    pub fn to_framebuffer(&self, linear: bool, exposure: f32) -> Framebuffer {
        let k = 1.0 / self.samples.max(1) as f32;
        let pixels = self
            .rgb
            .par_chunks(3)
            .map(|c| {
                let mut out = 0xff00_0000u32;
                for (ch, v) in c.iter().enumerate() {
                    let mut x = v * k;
                    if linear {
                        x = (x * exposure).clamp(0.0, 1.0).sqrt();
                    }
                    let b = (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
                    out |= b << (8 * ch);
                }
                out
            })
            .collect();
        Framebuffer {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

/// Renders `spp` more samples per pixel of a modality into `acc` (progressive: call again to
/// add samples; sample numbers continue from `acc.samples`, so the result does not depend on
/// how samples are split between calls). Direct and AO modes trace the pixel centre, so more
/// than one sample only repeats the same value; path tracing jitters within the pixel.
///
/// `volume` is composited in front of the opaque hits in Direct and AO modes and attenuates
/// shadow rays when `opt.volume_shadows`; the path tracer ignores it for primary rays.
#[allow(clippy::too_many_arguments)]
pub fn render_modal_into(
    scene: &Model,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    acc: &mut Accum,
    opt: &TraceOptions,
    spp: u32,
    isa: Isa,
) -> RenderStats {
    let start = Instant::now();
    let (w, h) = (acc.width as usize, acc.height as usize);
    let view = ViewRays::new(camera, w, h);
    let ntx = w.div_ceil(TILE);
    let first_sample = acc.samples;
    if opt.uses_wide() {
        scene.wide();
    }
    if w > 0 && h > 0 && spp > 0 {
        acc.rgb
            .par_chunks_mut(3 * TILE * w)
            .enumerate()
            .for_each(|(ty, band)| {
                let tiles: Vec<Vec<f32>> = (0..ntx)
                    .into_par_iter()
                    .map(|tx| {
                        let mut out = vec![0.0f32; 3 * TILE * TILE];
                        isa.dispatch(ModalKernel {
                            scene,
                            volume,
                            view: &view,
                            opt,
                            x0: tx * TILE,
                            y0: ty * TILE,
                            width: w,
                            first_sample,
                            spp,
                            out: &mut out,
                        });
                        out
                    })
                    .collect();
                let rows = band.len() / (3 * w);
                for (tx, tile) in tiles.iter().enumerate() {
                    let x0 = tx * TILE;
                    let cols = TILE.min(w - x0);
                    for r in 0..rows {
                        let dst = &mut band[3 * (r * w + x0)..3 * (r * w + x0 + cols)];
                        let src = &tile[3 * r * TILE..3 * (r * TILE + cols)];
                        for (d, s) in dst.iter_mut().zip(src) {
                            *d += s;
                        }
                    }
                }
            });
        acc.samples += spp;
    }
    RenderStats {
        isa,
        time: start.elapsed(),
        rays: (w * h) as u64 * spp as u64,
    }
}

/// Convenience: a new accumulation of `spp` samples, tone mapped to a frame.
#[allow(clippy::too_many_arguments)]
pub fn render_modal(
    scene: &Model,
    volume: Option<&VolumeScene>,
    camera: &Camera,
    width: u32,
    height: u32,
    opt: &TraceOptions,
    spp: u32,
    isa: Isa,
) -> Result<(Framebuffer, Accum, RenderStats), RenderError> {
    let mut acc = Accum::new(width, height)?;
    let st = render_modal_into(scene, volume, camera, &mut acc, opt, spp, isa);
    let linear = matches!(opt.modality, Modality::Path { .. });
    Ok((acc.to_framebuffer(linear, opt.exposure), acc, st))
}

/// Ambient occlusion at given surface points (Å) with outward unit normals: the fraction of
/// `samples` cosine-distributed rays from each point (offset along its normal by `offset` Å)
/// that travel `distance` Å without hitting geometry. Random numbers as in the renderer with
/// the point index as the pixel index. For tests and tools.
#[allow(clippy::too_many_arguments)]
pub fn ambient_occlusion_at(
    scene: &Model,
    points: &[[f32; 3]],
    normals: &[[f32; 3]],
    samples: u32,
    distance: f32,
    offset: f32,
    seed: u32,
    isa: Isa,
) -> Vec<f32> {
    assert_eq!(points.len(), normals.len());
    isa.dispatch(AoAtKernel {
        scene,
        points,
        normals,
        samples,
        distance,
        offset,
        seed,
    })
}

struct AoAtKernel<'a> {
    scene: &'a Model,
    points: &'a [[f32; 3]],
    normals: &'a [[f32; 3]],
    samples: u32,
    distance: f32,
    offset: f32,
    seed: u32,
}

impl Kernel for AoAtKernel<'_> {
    type Output = Vec<f32>;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.points.len());
        let mut stack = Stacks::new(self.scene, false);
        let mut buf = [[0.0f32; spmd::MAX_LANES]; 6];
        let mut res = [0.0f32; spmd::MAX_LANES];
        for (c, (pts, nrm)) in self
            .points
            .chunks(S::LANES)
            .zip(self.normals.chunks(S::LANES))
            .enumerate()
        {
            for i in 0..S::LANES {
                let (p, n) = if i < pts.len() {
                    (pts[i], nrm[i])
                } else {
                    ([0.0; 3], [0.0, 0.0, 1.0])
                };
                for a in 0..3 {
                    buf[a][i] = p[a] + n[a] * self.offset;
                    buf[3 + a][i] = n[a];
                }
            }
            let o = V3::new(s.load(&buf[0]), s.load(&buf[1]), s.load(&buf[2]));
            let n = V3::new(s.load(&buf[3]), s.load(&buf[4]), s.load(&buf[5]));
            let m = s.first_n(pts.len());
            let pixel = s.lane_index() + s.splat_i((c * S::LANES) as i32);
            let mut rng = Rng::new(s, self.seed, pixel, 0);
            let ao = ao_factor(
                s,
                self.scene,
                SecondaryTraversal::Packet,
                o,
                n,
                m,
                self.samples,
                self.distance,
                &mut rng,
                &mut stack,
            );
            s.store(ao, &mut res);
            out.extend_from_slice(&res[..pts.len()]);
        }
        out
    }
}

// ---------------------------------------------------------------------------------------
// Random numbers

/// Per-lane random number stream: `state = hash(state)` per draw.
#[derive(Clone, Copy)]
struct Rng<S: Simd> {
    state: S::I32,
}

/// Wellons' `lowbias32` integer hash (exact integer ops, identical on every backend).
#[inline(always)]
fn hash<S: Simd>(s: S, x: S::I32) -> S::I32 {
    let x = x ^ s.shr(x, 16);
    let x = s.mul_i(x, s.splat_i(0x7feb_352d));
    let x = x ^ s.shr(x, 15);
    let x = s.mul_i(x, s.splat_i(0x846c_a68bu32 as i32));
    x ^ s.shr(x, 16)
}

impl<S: Simd> Rng<S> {
    /// The stream of (seed, pixel, sample).
    #[inline(always)]
    fn new(s: S, seed: u32, pixel: S::I32, sample: u32) -> Self {
        let k = hash(
            s,
            s.splat_i((seed.wrapping_mul(0x9e37_79b9) ^ sample.wrapping_mul(0x85eb_ca6b)) as i32),
        );
        Rng {
            state: hash(s, pixel ^ k),
        }
    }

    /// Uniform in [0, 1) with 24 bits.
    #[inline(always)]
    fn next(&mut self, s: S) -> S::F32 {
        self.state = hash(s, self.state + s.splat_i(0x6d2b_79f5));
        s.to_f32(s.shr(self.state, 8)) * s.splat(1.0 / 16_777_216.0)
    }
}

/// `(cos 2πu, sin 2πu)` for `u` in [0, 1): quadrant reduction and Taylor polynomials on
/// [0, π/2) (error below 1e-7).
#[inline(always)]
fn sincos_turn<S: Simd>(s: S, u: S::F32) -> (S::F32, S::F32) {
    let q4 = u * s.splat(4.0);
    let q = s.floor(q4);
    let x = (q4 - q) * s.splat(core::f32::consts::FRAC_PI_2);
    let x2 = x * x;
    // sin x = x(1 − x²/6 + x⁴/120 − …), cos x = 1 − x²/2 + x⁴/24 − …
    let mut sp = s.splat(-1.0 / 39_916_800.0);
    sp = s.fma(sp, x2, s.splat(1.0 / 362_880.0));
    sp = s.fma(sp, x2, s.splat(-1.0 / 5040.0));
    sp = s.fma(sp, x2, s.splat(1.0 / 120.0));
    sp = s.fma(sp, x2, s.splat(-1.0 / 6.0));
    sp = s.fma(sp, x2, s.splat(1.0));
    let sn = sp * x;
    let mut cp = s.splat(1.0 / 479_001_600.0);
    cp = s.fma(cp, x2, s.splat(-1.0 / 3_628_800.0));
    cp = s.fma(cp, x2, s.splat(1.0 / 40_320.0));
    cp = s.fma(cp, x2, s.splat(-1.0 / 720.0));
    cp = s.fma(cp, x2, s.splat(1.0 / 24.0));
    cp = s.fma(cp, x2, s.splat(-0.5));
    let cs = s.fma(cp, x2, s.splat(1.0));
    let qi = s.to_i32(q) & s.splat_i(3);
    let q1 = s.eq_i(qi, s.splat_i(1));
    let q2 = s.eq_i(qi, s.splat_i(2));
    let q3 = s.eq_i(qi, s.splat_i(3));
    // Rotate by q quarter turns: (c, s) → (−s, c) → (−c, −s) → (s, −c).
    let c = s.select(q1, -sn, s.select(q2, -cs, s.select(q3, sn, cs)));
    let si = s.select(q1, cs, s.select(q2, -sn, s.select(q3, -cs, sn)));
    (c, si)
}

/// A uniformly distributed unit vector.
#[inline(always)]
fn unit_vector<S: Simd>(s: S, rng: &mut Rng<S>) -> V3<S> {
    let z = s.splat(1.0) - s.splat(2.0) * rng.next(s);
    let r = s.sqrt(s.max(s.splat(1.0) - z * z, s.splat(0.0)));
    let (c, si) = sincos_turn(s, rng.next(s));
    V3::new(r * c, r * si, z)
}

/// A cosine-distributed direction about the unit normal `n`: `normalize(n + u)` with `u`
/// uniform on the unit sphere has density cos θ / π (falls back to `n` when `u ≈ −n`).
#[inline(always)]
fn cosine_dir<S: Simd>(s: S, n: V3<S>, rng: &mut Rng<S>) -> V3<S> {
    let d = n + unit_vector(s, rng);
    let l2 = d.dot(d);
    let ok = s.gt(l2, s.splat(1e-12));
    let d = d.scale(s.rsqrt(s.select(ok, l2, s.splat(1.0))));
    V3::select(s, ok, d, n)
}

// ---------------------------------------------------------------------------------------
// Traversal of secondary rays

/// Lanes of `ray` (active ones) that hit any primitive in `(tmin, tmax)`: packet traversal
/// with any-hit early exit.
#[inline(always)]
pub fn occluded<S: Simd>(s: S, bvh: &Bvh, ray: &RayPacket<S>, stack: &mut [u32]) -> S::M {
    let nodes = &bvh.nodes[..];
    let records = &bvh.records[..];
    let neg_inf = s.splat(f32::NEG_INFINITY);
    let mut occ = s.splat_m(false);
    if nodes.is_empty() || s.none(ray.active) {
        return occ;
    }
    let d = ray.d;
    let inv = V3::new(s.rcp(d.x), s.rcp(d.y), s.rcp(d.z));
    // Per-lane limit: tmax while searching, −∞ once occluded or inactive (no box passes).
    let mut t = s.select(ray.active, ray.tmax, neg_inf);
    let grow = s.splat(BOX_GROW);
    let lane = s.bitmask(ray.active).trailing_zeros() as usize;
    let neg = [
        s.extract(d.x, lane) < 0.0,
        s.extract(d.y, lane) < 0.0,
        s.extract(d.z, lane) < 0.0,
    ];
    let mut sp = 0usize;
    let mut idx = 0usize;
    loop {
        let node = &nodes[idx];
        let m = box_test(s, node, ray, &inv, t, grow);
        if s.any(m) {
            if node.is_leaf() {
                let first = node.first as usize;
                for (k, rec) in records[first..first + node.count()].iter().enumerate() {
                    let mut tt = t;
                    let mut slot = s.splat_i(-1);
                    intersect_record(
                        s,
                        ray.o,
                        ray.d,
                        rec,
                        bvh.capped,
                        ray.tmin,
                        &mut tt,
                        &mut slot,
                        (first + k) as i32,
                        m,
                    );
                    let hit = s.gt_i(slot, s.splat_i(-1));
                    occ = occ | hit;
                    t = s.select(hit, neg_inf, t);
                }
                if s.none(ray.active & !occ) {
                    return occ;
                }
            } else {
                let c = node.first as usize;
                let (near, far) = if neg[node.axis()] {
                    (c + 1, c)
                } else {
                    (c, c + 1)
                };
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
    occ & ray.active
}

/// Traversal stacks of one task: the binary BVH's (packets and scalar single rays) and the
/// wide BVH's (allocated only when the wide BVH is used).
pub(crate) struct Stacks {
    packet: Vec<u32>,
    wide: Vec<WideEntry>,
}

impl Stacks {
    fn new(scene: &Model, wide: bool) -> Stacks {
        Stacks {
            packet: vec![0; scene.bvh.stack_size()],
            wide: if wide {
                vec![WideEntry::default(); scene.wide().stack_size()]
            } else {
                Vec::new()
            },
        }
    }
}

/// Each active lane of `ray` traced alone by `how` (`Single`: the binary BVH on the scalar
/// backend; `Wide`: the 8-wide BVH): per lane `(t, slot)`, slot −1 for a miss and for
/// inactive lanes. `any`: stop at the first hit (slot ≥ 0 then only says "occluded").
#[inline(always)]
fn single_rays<S: Simd>(
    s: S,
    scene: &Model,
    how: SecondaryTraversal,
    ray: &RayPacket<S>,
    st: &mut Stacks,
    any: bool,
) -> ([f32; spmd::MAX_LANES], [i32; spmd::MAX_LANES]) {
    let mut buf = [[0.0f32; spmd::MAX_LANES]; 8];
    for (b, v) in buf.iter_mut().zip([
        ray.o.x, ray.o.y, ray.o.z, ray.d.x, ray.d.y, ray.d.z, ray.tmin, ray.tmax,
    ]) {
        s.store(v, b);
    }
    let wide = if how == SecondaryTraversal::Wide {
        Some(scene.wide())
    } else {
        None
    };
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
        (t[i], slot[i]) = match (wide, any) {
            (Some(w), true) => (
                r.tmax,
                -i32::from(!w.occluded(s, &scene.bvh, &r, &mut st.wide)),
            ),
            (Some(w), false) => w.closest(s, &scene.bvh, &r, &mut st.wide),
            (None, true) => {
                let hit = occluded(Scalar, &scene.bvh, &scalar_packet(&r), &mut st.packet);
                (r.tmax, -i32::from(!hit))
            }
            (None, false) => {
                let h = scene
                    .bvh
                    .traverse_packet(Scalar, &scalar_packet(&r), &mut st.packet);
                (h.t, h.slot.0)
            }
        };
    }
    (t, slot)
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

/// Lanes of `ray` that hit anything in `(tmin, tmax)`, by the traversal `how`.
#[inline(always)]
fn occluded_by<S: Simd>(
    s: S,
    scene: &Model,
    how: SecondaryTraversal,
    ray: &RayPacket<S>,
    st: &mut Stacks,
) -> S::M {
    if how == SecondaryTraversal::Packet {
        return occluded(s, &scene.bvh, ray, &mut st.packet);
    }
    let (_, slot) = single_rays(s, scene, how, ray, st, true);
    s.gt_i(s.load_i(&slot), s.splat_i(-1))
}

/// Nearest hits of `ray` by the traversal `how` (as [`Bvh::traverse_packet`]: slot −1 where
/// nothing is hit).
#[inline(always)]
fn closest_by<S: Simd>(
    s: S,
    scene: &Model,
    how: SecondaryTraversal,
    ray: &RayPacket<S>,
    st: &mut Stacks,
) -> PacketHit<S> {
    if how == SecondaryTraversal::Packet {
        return scene.bvh.traverse_packet(s, ray, &mut st.packet);
    }
    let (t, slot) = single_rays(s, scene, how, ray, st, false);
    PacketHit {
        t: s.load(&t),
        slot: s.load_i(&slot),
    }
}

// ---------------------------------------------------------------------------------------
// The trace step

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

/// Paper §4.2 `trace`: the opaque pass (when `scene` is given) and then the volume pass (when
/// `volume` is given) marched up to the opaque hit.
#[inline(always)]
pub fn trace<S: Simd>(
    s: S,
    scene: Option<&Model>,
    volume: Option<&VolumeScene>,
    ray: &RayPacket<S>,
    stack: &mut [u32],
) -> Traced<S> {
    let mut out = match scene {
        Some(sc) => hit_surface(s, sc, ray, sc.bvh.traverse_packet(s, ray, stack)),
        None => traced_none(s),
    };
    if let Some(vs) = volume {
        let depth = s.select(out.mask, out.hit.t, s.splat(f32::INFINITY));
        out.volume = volume::march(s, vs, ray.o, ray.d, depth, ray.active);
    }
    out
}

/// [`trace`]'s opaque pass for secondary rays by the traversal `how` (no volume pass).
#[inline(always)]
fn trace_secondary<S: Simd>(
    s: S,
    scene: &Model,
    how: SecondaryTraversal,
    ray: &RayPacket<S>,
    st: &mut Stacks,
) -> Traced<S> {
    hit_surface(s, scene, ray, closest_by(s, scene, how, ray, st))
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
/// along the normal by `64·ε·(max|p| + t + r)` Å (as [`Bvh::spawn_point`]).
#[inline(always)]
fn spawn<S: Simd>(s: S, bvh: &Bvh, tr: &Traced<S>) -> V3<S> {
    let flat: &[f32] = bytemuck::cast_slice(&bvh.records);
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

// ---------------------------------------------------------------------------------------
// Tile kernel

struct ModalKernel<'a> {
    scene: &'a Model,
    volume: Option<&'a VolumeScene<'a>>,
    view: &'a ViewRays,
    opt: &'a TraceOptions,
    x0: usize,
    y0: usize,
    width: usize,
    first_sample: u32,
    spp: u32,
    out: &'a mut Vec<f32>,
}

impl Kernel for ModalKernel<'_> {
    type Output = ();
    #[inline(always)]
    fn run<S: Simd>(self, s: S) {
        modal_tile(s, self)
    }
}

#[inline(always)]
fn modal_tile<S: Simd>(s: S, k: ModalKernel<'_>) {
    let v = k.view;
    let mut stack = Stacks::new(k.scene, k.opt.uses_wide());
    let bw = block_width(S::LANES);
    let bh = S::LANES / bw;
    let mut lx = [0.0f32; spmd::MAX_LANES];
    let mut ly = [0.0f32; spmd::MAX_LANES];
    let mut li = [0i32; spmd::MAX_LANES];
    for i in 0..S::LANES {
        lx[i] = (i % bw) as f32;
        ly[i] = (i / bw) as f32;
        li[i] = ((i / bw) * k.width + i % bw) as i32;
    }
    let (lx, ly, li) = (s.load(&lx), s.load(&ly), s.load_i(&li));
    let du = V3::splat(s, v.du);
    let dv = V3::splat(s, v.dv);
    let path = matches!(k.opt.modality, Modality::Path { .. });
    let mut buf = [[0.0f32; spmd::MAX_LANES]; 3];
    for by in (0..TILE).step_by(bh) {
        for bx in (0..TILE).step_by(bw) {
            let px0 = lx + s.splat((k.x0 + bx) as f32);
            let py0 = ly + s.splat((k.y0 + by) as f32);
            let active = s.lt(px0, s.splat(v.width)) & s.lt(py0, s.splat(v.height));
            if s.none(active) {
                continue;
            }
            let pixel = li + s.splat_i(((k.y0 + by) * k.width + k.x0 + bx) as i32);
            let mut sum = V3::splat(s, [0.0; 3]);
            let samples = if path { k.spp } else { 1 };
            for j in 0..samples {
                let sample = k.first_sample + j;
                let mut rng = Rng::new(s, k.opt.seed, pixel, sample);
                let (jx, jy) = if path {
                    (rng.next(s), rng.next(s))
                } else {
                    (s.splat(0.5), s.splat(0.5))
                };
                let step = du.scale(px0 + jx) + dv.scale(py0 + jy);
                let (o, d) = if v.perspective {
                    (
                        V3::splat(s, v.org),
                        (V3::splat(s, v.dir0) + step).normalize(s),
                    )
                } else {
                    (V3::splat(s, v.org) + step, V3::splat(s, v.dir0))
                };
                let ray = RayPacket {
                    o,
                    d,
                    tmin: s.splat(0.0),
                    tmax: s.splat(f32::INFINITY),
                    active,
                };
                let c = shade_sample(s, &k, &ray, &mut rng, &mut stack);
                sum = sum + c;
            }
            // Direct/AO: one sample stands for all `spp`.
            let w = s.splat(if path { 1.0 } else { k.spp as f32 });
            s.store(sum.x * w, &mut buf[0]);
            s.store(sum.y * w, &mut buf[1]);
            s.store(sum.z * w, &mut buf[2]);
            for (i, ((r, g), b)) in buf[0]
                .iter()
                .zip(&buf[1])
                .zip(&buf[2])
                .take(S::LANES)
                .enumerate()
            {
                let (x, y) = (bx + i % bw, by + i / bw);
                let o = 3 * (y * TILE + x);
                k.out[o] += r;
                k.out[o + 1] += g;
                k.out[o + 2] += b;
            }
        }
    }
}

/// One sample of the chosen modality for a packet of camera rays.
#[inline(always)]
fn shade_sample<S: Simd>(
    s: S,
    k: &ModalKernel<'_>,
    ray: &RayPacket<S>,
    rng: &mut Rng<S>,
    st: &mut Stacks,
) -> V3<S> {
    let opt = k.opt;
    let bg = V3::splat(s, opt.background);
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    match opt.modality {
        Modality::Direct { shadows } => {
            let tr = trace(s, Some(k.scene), k.volume, ray, &mut st.packet);
            let mut c = bg;
            if s.any(tr.mask) {
                let o = spawn(s, &k.scene.bvh, &tr);
                let (l, dist) = opt.light.towards(s, o);
                let ndl = s.max(tr.n.dot(l), zero);
                let lit = tr.mask & s.gt(ndl, zero);
                let mut vis = s.select(lit, one, zero);
                if shadows && s.any(lit) {
                    vis = visibility(s, k, o, l, dist, lit, st);
                }
                let shade = s.splat(opt.ambient) + s.splat(opt.light_intensity) * ndl * vis;
                c = V3::select(s, tr.mask, tr.color.scale(shade), bg);
            }
            over(s, tr.volume, c)
        }
        Modality::Ao { samples, distance } => {
            let tr = trace(s, Some(k.scene), k.volume, ray, &mut st.packet);
            let mut c = bg;
            if s.any(tr.mask) {
                let o = spawn(s, &k.scene.bvh, &tr);
                let ao = ao_factor(
                    s,
                    k.scene,
                    opt.secondary,
                    o,
                    tr.n,
                    tr.mask,
                    samples,
                    distance,
                    rng,
                    st,
                );
                c = V3::select(s, tr.mask, tr.color.scale(ao), bg);
            }
            over(s, tr.volume, c)
        }
        Modality::Path {
            material,
            max_depth,
            roughness,
        } => {
            let env = bg * bg;
            let mut radiance = V3::splat(s, [0.0; 3]);
            let mut tp = V3::splat(s, [1.0; 3]);
            let mut r = *ray;
            for depth in 0..max_depth.max(1) {
                // Camera rays are coherent (packets); bounced rays use `opt.bounces`.
                let tr = if depth == 0 {
                    trace(s, Some(k.scene), None, &r, &mut st.packet)
                } else {
                    trace_secondary(s, k.scene, opt.bounces, &r, st)
                };
                let miss = r.active & !tr.mask;
                radiance = V3::select(s, miss, radiance + tp * env, radiance);
                let alive = tr.mask;
                if s.none(alive) {
                    break;
                }
                let albedo = tr.color * tr.color;
                let o = spawn(s, &k.scene.bvh, &tr);
                let n = tr.n;
                let nd;
                let mut alive2 = alive;
                match material {
                    Material::Diffuse => {
                        if opt.light_intensity > 0.0 {
                            let (l, dist) = opt.light.towards(s, o);
                            let ndl = s.max(n.dot(l), zero);
                            let lit = alive & s.gt(ndl, zero);
                            if s.any(lit) {
                                let vis = visibility(s, k, o, l, dist, lit, st);
                                let e = s.splat(opt.light_intensity) * ndl * vis;
                                radiance =
                                    V3::select(s, lit, radiance + (tp * albedo).scale(e), radiance);
                            }
                        }
                        nd = cosine_dir(s, n, rng);
                        tp = V3::select(s, alive, tp * albedo, tp);
                    }
                    Material::Metal => {
                        let cos_i = -(r.d.dot(n));
                        let refl = r.d.mul_add(n, cos_i + cos_i);
                        let fuzz = unit_vector(s, rng).scale(s.splat(roughness));
                        let d2 = refl + fuzz;
                        let l2 = d2.dot(d2);
                        let ok = s.gt(l2, s.splat(1e-12));
                        let d2 = d2.scale(s.rsqrt(s.select(ok, l2, one)));
                        let d2 = V3::select(s, ok, d2, refl);
                        // Absorbed when the blurred direction points into the surface.
                        alive2 = alive & s.gt(d2.dot(n), zero);
                        // Schlick: F = F0 + (1 − F0)(1 − cos)^5.
                        let m1 = s.max(one - s.max(cos_i, zero), zero);
                        let m2 = m1 * m1;
                        let m5 = m2 * m2 * m1;
                        let f = albedo + (V3::splat(s, [1.0; 3]) - albedo).scale(m5);
                        tp = V3::select(s, alive, tp * f, tp);
                        nd = d2;
                    }
                }
                r = RayPacket {
                    o,
                    d: nd,
                    tmin: zero,
                    tmax: s.splat(f32::INFINITY),
                    active: alive2,
                };
            }
            radiance
        }
    }
}

/// Visibility of the light along unit `l` from origins `o` over `(0, dist)` Å (lanes `m`):
/// 0 where geometry is in the way, else the volume's transmittance when volume shadows are
/// on, else 1.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn visibility<S: Simd>(
    s: S,
    k: &ModalKernel<'_>,
    o: V3<S>,
    l: V3<S>,
    dist: S::F32,
    m: S::M,
    st: &mut Stacks,
) -> S::F32 {
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let sray = RayPacket {
        o,
        d: l,
        tmin: zero,
        tmax: dist,
        active: m,
    };
    let occ = occluded_by(s, k.scene, k.opt.secondary, &sray, st);
    let free = m & !occ;
    let mut vis = s.select(free, one, zero);
    if let (true, Some(vs)) = (k.opt.volume_shadows, k.volume) {
        if s.any(free) {
            let tr = volume::transmittance(s, vs, o, l, dist, free, k.opt.shadow_step_voxels);
            vis = s.select(free, tr, vis);
        }
    }
    vis
}

/// Fraction of `samples` cosine-distributed rays from `o` about `n` that travel `distance`
/// without hitting geometry (lanes `m`; 0 elsewhere).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn ao_factor<S: Simd>(
    s: S,
    scene: &Model,
    how: SecondaryTraversal,
    o: V3<S>,
    n: V3<S>,
    m: S::M,
    samples: u32,
    distance: f32,
    rng: &mut Rng<S>,
    st: &mut Stacks,
) -> S::F32 {
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let mut free = zero;
    let n_samples = samples.max(1);
    for _ in 0..n_samples {
        let d = cosine_dir(s, n, rng);
        let ray = RayPacket {
            o,
            d,
            tmin: zero,
            tmax: s.splat(distance),
            active: m,
        };
        let occ = occluded_by(s, scene, how, &ray, st);
        free += s.select(m & !occ, one, zero);
    }
    free * s.splat(1.0 / n_samples as f32)
}

/// Premultiplied volume colour over an opaque colour.
#[inline(always)]
fn over<S: Simd>(s: S, v: [S::F32; 4], c: V3<S>) -> V3<S> {
    let t = s.splat(1.0) - v[3];
    V3::new(v[0] + t * c.x, v[1] + t * c.y, v[2] + t * c.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Draw(u32, u32);
    impl Kernel for Draw {
        type Output = Vec<f32>;
        #[inline(always)]
        fn run<S: Simd>(self, s: S) -> Vec<f32> {
            let mut out = Vec::new();
            let mut buf = [0.0f32; spmd::MAX_LANES];
            for base in (0..64).step_by(S::LANES) {
                let pixel = s.lane_index() + s.splat_i(base);
                let mut rng = Rng::new(s, self.0, pixel, self.1);
                for _ in 0..4 {
                    s.store(rng.next(s), &mut buf);
                    out.extend_from_slice(&buf[..S::LANES]);
                }
            }
            out
        }
    }

    #[test]
    fn random_numbers_are_identical_on_every_backend_and_uniform() {
        let reference = Isa::Scalar.dispatch(Draw(7, 3));
        for isa in Isa::under_test() {
            let v = isa.dispatch(Draw(7, 3));
            // Order differs (lanes interleave draws), the multiset must not.
            let mut a = reference.clone();
            let mut b = v.clone();
            a.sort_by(f32::total_cmp);
            b.sort_by(f32::total_cmp);
            assert_eq!(a, b, "{isa}");
        }
        let mean = reference.iter().sum::<f32>() / reference.len() as f32;
        assert!((mean - 0.5).abs() < 0.05, "mean {mean}");
        assert!(reference.iter().all(|&x| (0.0..1.0).contains(&x)));
        assert_ne!(Isa::Scalar.dispatch(Draw(8, 3)), reference);
        assert_ne!(Isa::Scalar.dispatch(Draw(7, 4)), reference);
    }

    struct Trig;
    impl Kernel for Trig {
        type Output = f32;
        #[inline(always)]
        fn run<S: Simd>(self, s: S) -> f32 {
            let mut worst = 0.0f32;
            for i in 0..4096 {
                let u = i as f32 / 4096.0;
                let (c, si) = sincos_turn(s, s.splat(u));
                let a = u as f64 * std::f64::consts::TAU;
                worst = worst
                    .max((s.extract(c, 0) as f64 - a.cos()).abs() as f32)
                    .max((s.extract(si, 0) as f64 - a.sin()).abs() as f32);
            }
            worst
        }
    }

    #[test]
    fn sincos_is_accurate() {
        for isa in Isa::under_test() {
            let e = isa.dispatch(Trig);
            assert!(e < 2e-6, "{isa}: {e}");
        }
    }
}
