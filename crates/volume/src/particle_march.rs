//! Ray marching through a grid-free RBF volume ([`crate::particles`]; Knoll et al. 2014): per
//! ray, the BVH lists the support spheres it crosses, sorted by entry; samples lie where the
//! grid path's would (`t_k = t_in + k·Δt` over the same box, Δt = the step of the classified
//! transfer function in voxels of [`Particles::grid`]); each sample sums the Gaussians of the
//! spheres active there, `S::LANES` consecutive samples at a time (SIMD along the ray, one
//! ray after another). Stretches where no sphere is active and the transfer function makes
//! zero density transparent are skipped, as the grid path skips empty macrocells.
//! Classification (pre-integrated or post), lighting (the analytic gradient of Φ instead of
//! central differences), compositing, the opacity cut-off and the opaque depth `tmax` are the
//! grid path's. Volumetric shadows need the grid (they march the density towards the light
//! from every sample) and are refused by [`ParticleScene::new`].

use std::cell::RefCell;

use bvh::{Bvh, Span, WideBvh};
use spmd::{Isa, Simd, V3};

use crate::march::{classify, march_medium_rays, Rays};
use crate::medium::Medium;
use crate::particles::Particles;
use crate::sampler::{clip_box, facing, GridRay};
use crate::scene::{Light, Lighting, MarchOptions};
use crate::tf::ClassifiedTf;

/// Everything the particle marcher reads. Cheap to create per frame.
#[derive(Clone, Copy, Debug)]
pub struct ParticleScene<'a> {
    /// The atoms and their BVH.
    pub particles: &'a Particles,
    /// The classified transfer function (its `step_voxels` sets the step).
    pub tf: &'a ClassifiedTf,
    /// Options (`macrocells` switches empty-space skipping; `shadows` must be `None`).
    pub opts: MarchOptions,
}

impl<'a> ParticleScene<'a> {
    /// Bundles the parts. Panics if `opts.shadows` is set: volumetric shadows need the grid.
    pub fn new(particles: &'a Particles, tf: &'a ClassifiedTf, opts: MarchOptions) -> Self {
        assert!(
            opts.shadows.is_none(),
            "ParticleScene: volumetric shadows need the density grid"
        );
        ParticleScene {
            particles,
            tf,
            opts,
        }
    }
}

/// The spheres active over a stretch of one ray, structure of arrays: what each sample sums.
#[derive(Default)]
struct Active {
    /// Ray origin minus centre (Å), per axis.
    ox: Vec<f32>,
    oy: Vec<f32>,
    oz: Vec<f32>,
    /// −1/rᵢ².
    nir2: Vec<f32>,
    /// √rᵢ.
    amp: Vec<f32>,
    /// 2·rᵢ², the squared support radius.
    cut2: Vec<f32>,
    /// Where the ray leaves the support sphere.
    t1: Vec<f32>,
}

impl Active {
    fn columns(&mut self) -> [&mut Vec<f32>; 7] {
        [
            &mut self.ox,
            &mut self.oy,
            &mut self.oz,
            &mut self.nir2,
            &mut self.amp,
            &mut self.cut2,
            &mut self.t1,
        ]
    }

    fn clear(&mut self) {
        self.columns().into_iter().for_each(Vec::clear);
    }

    fn push(&mut self, o: [f32; 3], c: [f32; 3], r: f32, t1: f32) {
        self.ox.push(o[0] - c[0]);
        self.oy.push(o[1] - c[1]);
        self.oz.push(o[2] - c[2]);
        self.nir2.push(-1.0 / (r * r));
        self.amp.push(r.sqrt());
        self.cut2.push(2.0 * r * r);
        self.t1.push(t1);
    }

    /// Drops the spheres the ray has left before `t`.
    fn retire(&mut self, t: f32) {
        let mut i = 0;
        while i < self.t1.len() {
            if self.t1[i] < t {
                for v in self.columns() {
                    v.swap_remove(i);
                }
            } else {
                i += 1;
            }
        }
    }
}

/// Length of the first window of path (Å) in which a ray's spheres are fetched from the BVH;
/// each next window is twice as long. A ray that turns opaque early fetches only its first
/// few spheres, a long one needs a few traversals. Volume at 1024², AVX2, 2 cores (EPYC):
/// the whole ray at once 1.14 s nanobowl / 6.2 s ns740k; fixed 8 Å windows 1.6 s nanobowl;
/// doubling from 8 Å 1.3-1.4 / 3.5-3.6 s; doubling from 16 Å the same.
const WINDOW: f32 = 8.0;

/// The spheres along one ray in order of entry, fetched a window of the ray at a time.
struct Stream<'a, S: Simd> {
    s: S,
    bvh: &'a Bvh,
    wide: &'a WideBvh,
    o: [f32; 3],
    d: [f32; 3],
    spans: &'a mut Vec<Span>,
    stack: &'a mut Vec<u32>,
    /// Next span of `spans` to hand out.
    next: usize,
    /// Where the fetched windows end and the ray ends (`t`).
    fetched: f32,
    t_end: f32,
    /// Length of the next window in `t`.
    len: f32,
}

impl<S: Simd> Stream<'_, S> {
    /// The next sphere the ray enters (fetching windows until one holds it), or `None`.
    #[inline(always)]
    fn peek(&mut self) -> Option<Span> {
        loop {
            if let Some(sp) = self.spans.get(self.next) {
                return Some(*sp);
            }
            if self.fetched >= self.t_end {
                return None;
            }
            let (a, first) = (self.fetched, self.next == usize::MAX);
            let b = (a + self.len).min(self.t_end);
            self.spans.clear();
            self.next = 0;
            self.wide.sphere_spans(
                self.s, self.bvh, self.o, self.d, a, b, self.stack, self.spans,
            );
            if !first {
                // Entered at or before `a`: handed out from an earlier window.
                self.spans.retain(|sp| sp.t0 > a);
            }
            self.spans.sort_unstable_by(|x, y| x.t0.total_cmp(&y.t0));
            self.fetched = b;
            self.len *= 2.0;
        }
    }
}

/// Per-thread scratch of the marcher (reused across rays and frames).
#[derive(Default)]
struct Scratch {
    stack: Vec<u32>,
    spans: Vec<Span>,
    active: Active,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Packet entry point, as [`crate::march()`]: marches `S::LANES` rays (world space, Å; `t`
/// in units of `|dir|`) from `t = 0` to `min(box exit, tmax)`, one lane after another.
/// Inactive lanes return zeros. Returns premultiplied `[r, g, b, a]`.
#[inline(always)]
pub fn march_particles<S: Simd>(
    s: S,
    scene: &ParticleScene,
    orig: V3<S>,
    dir: V3<S>,
    tmax: S::F32,
    active: S::M,
) -> [S::F32; 4] {
    let g = &scene.particles.grid;
    let hi = g.dims.map(|n| (n - 1) as f32);
    let ray = GridRay::from_world(s, g, orig, dir);
    let span = clip_box(s, &ray, hi, tmax, scene.tf.step_voxels, active);
    let mut out = [[0.0f32; spmd::MAX_LANES]; 4];
    let mut bits = s.bitmask(span.alive);
    if bits != 0 {
        // Out of the thread-local and back, so the marching itself runs outside a closure
        // (closures do not inherit the backend's target features: its intrinsics would
        // become calls).
        let mut sc = SCRATCH.take();
        while bits != 0 {
            let l = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let o = [
                s.extract(orig.x, l),
                s.extract(orig.y, l),
                s.extract(orig.z, l),
            ];
            let d = [
                s.extract(dir.x, l),
                s.extract(dir.y, l),
                s.extract(dir.z, l),
            ];
            let t = [s.extract(span.t_in, l), s.extract(span.t_end, l)];
            let c = march_ray(s, scene, o, d, t, s.extract(span.dt, l), &mut sc);
            for ch in 0..4 {
                out[ch][l] = c[ch];
            }
        }
        SCRATCH.set(sc);
    }
    [
        s.load(&out[0]),
        s.load(&out[1]),
        s.load(&out[2]),
        s.load(&out[3]),
    ]
}

// Knoll et al. 2014 on the paper's §4.4 compositing: one ray, `t` from `t_in` to `t_end`
// in steps `dt`, sphere lists from the BVH, LANES samples at a time.
#[inline(always)]
fn march_ray<S: Simd>(
    s: S,
    scene: &ParticleScene,
    o: [f32; 3],
    d: [f32; 3],
    [t_in, t_end]: [f32; 2],
    dt: f32,
    sc: &mut Scratch,
) -> [f32; 4] {
    let p = scene.particles;
    let tf = scene.tf;
    let opts = &scene.opts;
    if sc.stack.len() < p.wide.spans_stack_size() {
        sc.stack.resize(p.wide.spans_stack_size(), 0);
    }
    let dlen = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    sc.spans.clear();
    let mut stream = Stream {
        s,
        bvh: &p.bvh,
        wide: &p.wide,
        o,
        d,
        spans: &mut sc.spans,
        stack: &mut sc.stack,
        next: usize::MAX,
        fetched: t_in,
        t_end,
        len: WINDOW / dlen,
    };
    let act = &mut sc.active;
    act.clear();
    let b0 = tf.bin(0.0);
    let skip = opts.macrocells && tf.range_max[b0 * 256 + b0] == 0.0;
    let lit = opts.lighting != Lighting::Unlit;
    let light = match opts.lighting {
        Lighting::Directional(l) => Some(Light::Directional(l)),
        Lighting::Point(q) => Some(Light::Point(q)),
        _ => None,
    };
    let dv = V3::<S>::splat(s, d);
    let ov = V3::<S>::splat(s, o);
    let headlight = -dv.normalize(s);
    let lanes = s.to_f32(s.lane_index());
    let w = S::LANES;
    let mut acc = [0.0f32; 4];
    // Values at points j−1 … j+LANES−1 of the current chunk: [0] is the previous point's.
    let mut vals = [0.0f32; spmd::MAX_LANES + 1];
    let mut rgba = [[0.0f32; spmd::MAX_LANES]; 4];
    let mut j = 0usize;
    loop {
        // Point j is at t_in + j·dt; the segment ending there starts at point j − 1.
        if j > 0 && t_in + (j - 1) as f32 * dt >= t_end {
            break;
        }
        // (Clamped as the points are: a sphere cut by t_end still reaches the last one.)
        let tj = (t_in + j as f32 * dt).min(t_end);
        act.retire(tj);
        if skip && act.t1.is_empty() && (j == 0 || vals[0] == 0.0) {
            // Nothing reaches point j: jump to the last point before the next sphere.
            let Some(sp) = stream.peek() else { break };
            let q = ((sp.t0 - t_in) / dt).floor();
            if q > j as f32 {
                j = q as usize;
                vals[0] = 0.0;
                continue;
            }
        }
        let t_last = (t_in + (j + w - 1) as f32 * dt).min(t_end);
        while let Some(sp) = stream.peek().filter(|sp| sp.t0 <= t_last) {
            let slot = sp.slot as usize;
            act.push(o, p.bvh.records[slot].p0, p.radius[slot], sp.t1);
            stream.next += 1;
        }
        // Φ (and ∇Φ when lit) at points j … j+LANES−1.
        let kv = s.splat(j as f32) + lanes;
        let t = s.min(s.splat(t_in) + kv * s.splat(dt), s.splat(t_end));
        let (val, grad) = density_at(s, act, dv, t, lit);
        s.store(val, &mut vals[1..]);
        // Segment ending at point j + l is valid when it starts before t_end.
        let t_front = s.splat(t_in) + (kv - s.splat(1.0)) * s.splat(dt);
        let valid = s.gt(kv, s.splat(0.0)) & s.lt(t_front, s.splat(t_end));
        let frac = (t - t_front) * s.splat(1.0 / dt);
        let front = s.load(&vals[..w]);
        let mut c = classify(s, tf, front, val, valid, opts.preintegrated);
        if lit {
            let shading = valid & s.gt(c[3], s.splat(0.0));
            if s.any(shading) {
                let l = match light {
                    Some(light) => light.towards(s, ov.mul_add(dv, t)).0,
                    None => headlight,
                };
                let f = facing(s, grad, l);
                let one = s.splat(1.0);
                let ambient = s.splat(opts.ambient);
                let shade = ambient + (one - ambient) * f;
                for ch in c.iter_mut().take(3) {
                    *ch = s.select(shading, *ch * shade, *ch);
                }
            }
        }
        for (ch, v) in c.into_iter().enumerate() {
            s.store(v * frac, &mut rgba[ch]);
        }
        // Front to back, one segment after another.
        let nvalid = s.bitmask(valid);
        let mut bits = nvalid;
        while bits != 0 {
            let l = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let wgt = 1.0 - acc[3];
            for ch in 0..4 {
                acc[ch] += wgt * rgba[ch][l];
            }
            if acc[3] >= opts.opacity_cutoff {
                return acc;
            }
        }
        if nvalid == 0 && j > 0 {
            break;
        }
        vals[0] = vals[w];
        j += w;
    }
    acc
}

// RBF density (paper §3.1) at points `o + t·d` of one ray: Φ = Σ √rᵢ·exp(−|x − cᵢ|²/rᵢ²) over
// the active spheres with |x − cᵢ|² < 2rᵢ², and, when `lit`, its gradient
// ∇Φ = Σ −2/rᵢ² · √rᵢ·exp(…) · (x − cᵢ).
#[inline(always)]
fn density_at<S: Simd>(s: S, act: &Active, d: V3<S>, t: S::F32, lit: bool) -> (S::F32, V3<S>) {
    let zero = s.splat(0.0);
    let mut val = zero;
    let mut grad = V3::<S>::splat(s, [0.0; 3]);
    for i in 0..act.t1.len() {
        let oc = V3::<S>::new(s.splat(act.ox[i]), s.splat(act.oy[i]), s.splat(act.oz[i]));
        let x = oc.mul_add(d, t);
        let d2 = x.dot(x);
        let nir2 = s.splat(act.nir2[i]);
        let inside = s.lt(d2, s.splat(act.cut2[i]));
        let g = s.select(
            inside,
            s.splat(act.amp[i]) * spmd::math::exp(s, d2 * nir2),
            zero,
        );
        val += g;
        if lit {
            grad = grad + x.scale(g * nir2 * s.splat(2.0));
        }
    }
    (val, grad)
}

/// Marches every ray of `rays` through `scene` with backend `isa`, as [`crate::march_rays`]
/// does through a grid. Panics if the slices' lengths differ.
pub fn march_particle_rays(isa: Isa, scene: &ParticleScene, rays: &Rays, out: &mut [[f32; 4]]) {
    march_medium_rays(isa, &Medium::Particles(*scene), rays, out);
}
