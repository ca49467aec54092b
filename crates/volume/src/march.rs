//! Ray marching (paper §4.4): varying rays, each lane independent; box entry/exit, 3D DDA over
//! macrocells skipping cells the transfer function makes empty, fixed steps of 0.5 voxel inside
//! non-empty cells, trilinear interpolation through gathers, classification through the
//! pre-integrated (default) or post-classification table, front-to-back compositing, early
//! termination at α ≥ 0.99 and at the opaque depth `tmax` of the ball-and-stick pass.
//!
//! ## Sample positions
//! Samples lie at `t_k = t_in + k·Δt` (`t_in` the box entry or 0, `Δt` = 0.5 voxel of path),
//! whether or not macrocells are used: skipping only jumps `k` forward over segments whose
//! contribution is exactly zero, so images with and without macrocells agree (up to the
//! rounding of the cell-boundary parameters). Segment `k` spans `[t_k, t_k+1]`; the last one is
//! cut at `t_end = min(box exit, tmax)` and its colour and opacity scaled by the fraction kept
//! (first-order opacity correction of the partial step).
//!
//! ## Output
//! Premultiplied (associated) colour `r, g, b` and opacity `a`, all in `[0, 1]`: composite over
//! a background `bg` as `rgb + (1 − a)·bg`.

use spmd::{Isa, Kernel, Simd, V3};

use crate::gradient::{diffuse_stencil, sample_stencil};
use crate::macrocell::MACROCELL;
use crate::medium::Medium;
pub use crate::sampler::sample_points;
use crate::sampler::{
    bin, cell_occupied, clip_box, trilinear, with_lattice, GridRay, Lattice, OnLattice, Voxels,
};
use crate::scene::Light;
pub use crate::scene::{Lighting, MarchOptions, VolumeScene, VolumeShadows};
use crate::tau::march_tau;
use crate::tf::ClassifiedTf;

// Paper §4.4: a segment's premultiplied colour and opacity, from the pre-integration table
// by its (front, back) values or from the post-classification table by its back value.
// The table is binary16: 2 gathers from 512 KiB instead of 4 from 1 MiB; 1.13× on ns740k
// volume at 1024² (9.73 → 8.62 s side by side under load).
#[inline(always)]
pub(crate) fn classify<S: Simd>(
    s: S,
    tf: &ClassifiedTf,
    front: S::F32,
    back: S::F32,
    m: S::M,
    preint: bool,
) -> [S::F32; 4] {
    if preint {
        let idx = s.shl(s.shl(bin(s, tf, front), 8) + bin(s, tf, back), 1);
        let [rg, ba] = s.gather_i_rows(&tf.preint_half, idx, [0, 1], m);
        let ((r, g), (b, a)) = (s.halves(rg), s.halves(ba));
        [r, g, b, a]
    } else {
        let idx = s.shl(bin(s, tf, back), 2);
        let (p, zero) = (&tf.post, s.splat(0.0));
        [
            s.gather(p, idx, m, zero),
            s.gather(p, idx + s.splat_i(1), m, zero),
            s.gather(p, idx + s.splat_i(2), m, zero),
            s.gather(p, idx + s.splat_i(3), m, zero),
        ]
    }
}

/// Packet entry point: marches `S::LANES` rays (origins `orig` and directions `dir` in world
/// space, Å; `t` measured in units of `|dir|`) from `t = 0` to `min(box exit, tmax)`.
/// Inactive lanes return zeros. Returns premultiplied `[r, g, b, a]`.
#[inline(always)]
pub fn march<S: Simd>(
    s: S,
    scene: &VolumeScene,
    orig: V3<S>,
    dir: V3<S>,
    tmax: S::F32,
    active: S::M,
) -> [S::F32; 4] {
    with_lattice(
        scene.volume,
        Packet {
            s,
            scene,
            orig,
            dir,
            tmax,
            active,
        },
    )
}

/// [`march`]'s packet on one storage format.
struct Packet<'a, S: Simd> {
    s: S,
    scene: &'a VolumeScene<'a>,
    orig: V3<S>,
    dir: V3<S>,
    tmax: S::F32,
    active: S::M,
}

impl<S: Simd> OnLattice for Packet<'_, S> {
    type Output = [S::F32; 4];
    #[inline(always)]
    fn run<V: Voxels>(self, lat: &Lattice<V>) -> [S::F32; 4] {
        march_impl(
            self.s,
            self.scene,
            lat,
            self.orig,
            self.dir,
            self.tmax,
            self.active,
        )
    }
}

/// Per-lane 3D DDA state over macrocells (grid coordinates / 8).
struct Dda<S: Simd> {
    c: [S::I32; 3],
    step: [S::I32; 3],
    tnext: [S::F32; 3],
    tdelta: [S::F32; 3],
    /// `t` at which the current cell was entered.
    t_in: S::F32,
}

impl<S: Simd> Dda<S> {
    /// The walk of `ray` from the macrocell holding its point at `t` (clamped into the grid).
    #[inline(always)]
    fn start(s: S, ray: &GridRay<S>, t: S::F32, ncells: [i32; 3]) -> Self {
        let (zero, inf) = (s.splat(0.0), s.splat(f32::INFINITY));
        let (d, inv) = (ray.d_a(), ray.inv);
        let mut dda = Dda::<S> {
            c: [s.splat_i(0); 3],
            step: [s.splat_i(1); 3],
            tnext: [inf; 3],
            tdelta: [inf; 3],
            t_in: t,
        };
        for a in 0..3 {
            let flat = s.eq(d[a], zero);
            dda.step[a] = s.select_i(s.gt(d[a], zero), s.splat_i(1), s.splat_i(-1));
            dda.tdelta[a] = s.select(flat, inf, s.abs(inv[a]) * s.splat(MACROCELL as f32));
        }
        dda.restart(s, ray, t, s.splat_m(true), ncells);
        dda
    }

    /// Moves lanes `m` to the macrocell holding the ray's point at `t` (clamped into the grid).
    #[inline(always)]
    fn restart(&mut self, s: S, ray: &GridRay<S>, t: S::F32, m: S::M, ncells: [i32; 3]) {
        let (zero, one, inf) = (s.splat(0.0), s.splat(1.0), s.splat(f32::INFINITY));
        let p = ray.o.mul_add(ray.d, t);
        let (pa, o, d) = ([p.x, p.y, p.z], ray.o_a(), ray.d_a());
        for a in 0..3 {
            let c = s.floor(pa[a] * s.splat(1.0 / MACROCELL as f32));
            let c = s.min(s.max(c, zero), s.splat((ncells[a] - 1) as f32));
            let edge = (c + s.select(s.gt(d[a], zero), one, zero)) * s.splat(MACROCELL as f32);
            let tnext = s.select(s.eq(d[a], zero), inf, (edge - o[a]) * ray.inv[a]);
            self.c[a] = s.select_i(m, s.to_i32(c), self.c[a]);
            self.tnext[a] = s.select(m, tnext, self.tnext[a]);
        }
        self.t_in = s.select(m, t, self.t_in);
    }

    /// Exit parameter of the cube of macrocells within Chebyshev distance `r − 1` of the
    /// current cell (`r ≥ 1` per lane).
    #[inline(always)]
    fn cube_exit(&self, s: S, ray: &GridRay<S>, r: S::I32) -> S::F32 {
        let (zero, inf) = (s.splat(0.0), s.splat(f32::INFINITY));
        let (o, d) = (ray.o_a(), ray.d_a());
        let mut t = inf;
        for a in 0..3 {
            let pos = s.gt(d[a], zero);
            let face = s.select_i(pos, self.c[a] + r, self.c[a] - r + s.splat_i(1));
            let edge = s.to_f32(face) * s.splat(MACROCELL as f32);
            let ta = s.select(s.eq(d[a], zero), inf, (edge - o[a]) * ray.inv[a]);
            t = s.min(t, ta);
        }
        t
    }

    /// Exit parameter of the current cell.
    #[inline(always)]
    fn t_out(&self, s: S) -> S::F32 {
        s.min(self.tnext[0], s.min(self.tnext[1], self.tnext[2]))
    }

    /// Moves lanes `m` to the next cell; returns the lanes that left the grid.
    #[inline(always)]
    fn advance(&mut self, s: S, m: S::M, ncells: [i32; 3]) -> S::M {
        let [tx, ty, tz] = self.tnext;
        let ax = m & s.le(tx, ty) & s.le(tx, tz);
        let ay = m & !ax & s.le(ty, tz);
        let az = m & !ax & !ay;
        self.t_in = s.select(m, self.t_out(s), self.t_in);
        let mut out = s.splat_m(false);
        for (a, am) in [ax, ay, az].into_iter().enumerate() {
            self.c[a] = s.select_i(am, self.c[a] + self.step[a], self.c[a]);
            self.tnext[a] = s.select(am, self.tnext[a] + self.tdelta[a], self.tnext[a]);
            out = out
                | (am
                    & (s.lt_i(self.c[a], s.splat_i(0)) | !s.lt_i(self.c[a], s.splat_i(ncells[a]))));
        }
        out
    }
}

// Paper §4.4: per-lane independent marching with macrocell skipping and pre-integration.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn march_impl<S: Simd, V: Voxels>(
    s: S,
    scene: &VolumeScene,
    lat: &Lattice<V>,
    orig: V3<S>,
    dir: V3<S>,
    tmax: S::F32,
    active: S::M,
) -> [S::F32; 4] {
    let g = &scene.volume.grid;
    let tf = scene.tf;
    let opts = &scene.opts;
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let inf = s.splat(f32::INFINITY);

    // Ray in grid coordinates (voxels); t is unchanged by the affine map.
    let ray = GridRay::from_world(s, g, orig, dir);
    let (og, dg) = (ray.o, ray.d);
    let span = clip_box(s, &ray, lat.hi, tmax, tf.step_voxels, active);
    let (t_in, t_end, dt) = (span.t_in, span.t_end, span.dt);
    let mut alive = span.alive;
    let t0 = t_in;

    // Accumulators and marching state.
    let mut acc = [zero; 4];
    let mut k = zero; // index of the next segment
    let mut prev_k = s.splat(-1.0); // segment front index whose value `s_prev` holds
    let mut s_prev = zero;
    let mut cell_out = inf;
    let use_cells = opts.macrocells;
    let ncells = [
        scene.cells.dims[0] as i32,
        scene.cells.dims[1] as i32,
        scene.cells.dims[2] as i32,
    ];
    let mut need = if use_cells { alive } else { s.splat_m(false) };
    let mut marching = if use_cells { s.splat_m(false) } else { alive };

    let mut dda = if use_cells {
        Dda::start(s, &ray, t_in, ncells)
    } else {
        Dda::<S> {
            c: [s.splat_i(0); 3],
            step: [s.splat_i(1); 3],
            tnext: [inf; 3],
            tdelta: [inf; 3],
            t_in,
        }
    };

    let lit = opts.lighting != Lighting::Unlit;
    // Lights in grid coordinates (the grid is isotropic, so directions are unchanged).
    let shade_light = match opts.lighting {
        Lighting::Directional(l) => Some(Light::Directional(l)),
        Lighting::Point(q) => Some(Light::Point(q).in_grid(g)),
        _ => None,
    };
    let headlight = -dir.normalize(s);
    let shadows = opts.shadows.map(|sh| (sh.light.in_grid(g), sh.step_voxels));
    let ambient = s.splat(opts.ambient);
    let cutoff = s.splat(opts.opacity_cutoff);
    let preint = opts.preintegrated;
    // Lanes whose opacity reached the cut-off (composited no more; retired one iteration late).
    let mut opaque = s.splat_m(false);
    loop {
        // Phase 1: lanes that need a cell walk the DDA until a non-empty one (or the end).
        while use_cells && s.any(need) {
            let fin = need & s.ge(dda.t_in, t_end);
            alive = alive & !fin;
            need = need & !fin;
            if s.none(need) {
                break;
            }
            // Distance (macrocells) to the nearest non-empty cell: from the map, or 0/1 from
            // the cell's own range (1: step to the next cell).
            let dist = match scene.empty {
                Some(es) => {
                    let ci = dda.c[0]
                        + s.mul_i(dda.c[1], s.splat_i(ncells[0]))
                        + s.mul_i(dda.c[2], s.splat_i(ncells[0] * ncells[1]));
                    s.gather_u8(&es.distance, ci, need)
                }
                None => {
                    let occupied = cell_occupied(s, scene.cells, tf, dda.c, ncells, need);
                    s.select_i(occupied, s.splat_i(0), s.splat_i(1))
                }
            };
            let ne = need & s.eq_i(dist, s.splat_i(0));
            // First segment touching the cell (never one already composited).
            let kf = s.floor((dda.t_in - t0) / dt);
            let kf = s.select(s.gt(t0 + kf * dt, dda.t_in), kf - one, kf);
            k = s.select(ne, s.max(kf, k), k);
            cell_out = s.select(ne, dda.t_out(s), cell_out);
            marching = marching | ne;
            need = need & !ne;
            // Far from anything visible: jump out of the empty cube around the cell.
            let far = need & s.gt_i(dist, s.splat_i(1));
            if s.any(far) {
                let t_jump = dda.cube_exit(s, &ray, dist);
                dda.restart(s, &ray, t_jump, far, ncells);
            }
            let gone = dda.advance(s, need & !far, ncells);
            alive = alive & !gone;
            need = need & !gone;
        }
        if s.none(alive) {
            break;
        }

        // Phase 2: one segment for every marching lane.
        let tk = t0 + k * dt;
        let valid = marching & s.lt(tk, s.min(cell_out, t_end));
        let leaving = marching & !valid;
        marching = valid;
        if s.any(leaving) {
            let done = leaving & s.ge(tk, t_end);
            if use_cells {
                let next = leaving & !done;
                let gone = dda.advance(s, next, ncells);
                need = need | (next & !gone);
                alive = alive & !(done | gone);
            } else {
                alive = alive & !leaving;
            }
        }
        if s.none(valid) {
            continue;
        }
        let tb = s.min(tk + dt, t_end);
        let frac = (tb - tk) / dt;
        let pg = og.mul_add(dg, tb);
        // Lit: the sample from the rows its gradient needs too (gradient.rs).
        let stencil = if lit {
            Some(sample_stencil(s, lat, pg, valid))
        } else {
            None
        };
        let sb = match &stencil {
            Some(st) => st.value,
            None => trilinear(s, lat, pg, valid),
        };
        let front = valid & s.ne(prev_k, k);
        if preint && s.any(front) {
            let sf = trilinear(s, lat, og.mul_add(dg, tk), front);
            s_prev = s.select(front, sf, s_prev);
        }
        let mut c = classify(s, tf, s_prev, sb, valid, preint);
        if lit || shadows.is_some() {
            let shading = valid & s.gt(c[3], zero);
            if s.any(shading) {
                let mut f = one;
                if let Some(st) = &stencil {
                    let l = match shade_light {
                        Some(light) => light.towards(s, pg).0,
                        None => headlight,
                    };
                    f = diffuse_stencil(s, lat, st, pg, l, shading);
                }
                if let Some((light, step)) = shadows {
                    f *= match scene.light {
                        Some(lv) => lv.sample(s, pg, shading),
                        None => {
                            let (l, dist) = light.towards(s, pg);
                            march_tau(s, lat, scene.cells, tf, pg, l, dist, shading, step)
                        }
                    };
                }
                let shade = ambient + (one - ambient) * f;
                for ch in c.iter_mut().take(3) {
                    *ch *= shade;
                }
            }
        }
        let w = (one - acc[3]) * frac;
        let composited = valid & !opaque;
        for (a, ch) in acc.iter_mut().zip(c) {
            *a = s.select(composited, *a + w * ch, *a);
        }
        s_prev = s.select(valid, sb, s_prev);
        k = s.select(valid, k + one, k);
        prev_k = s.select(valid, k, prev_k);
        // Early termination one iteration late: lanes that passed the cut-off last time stop
        // now, and those passing it now fetch once more without compositing. So the next
        // iteration's gather masks do not wait on this one's table gather (a loop-carried
        // chain through two dependent gathers; the same pictures, 1.1-1.25× on ns740k).
        alive = alive & !opaque;
        marching = marching & !opaque;
        need = need & !opaque;
        opaque = opaque | (valid & s.ge(acc[3], cutoff));
    }
    acc
}

/// A batch of rays as structure-of-arrays slices of equal length (world space, Å).
#[derive(Clone, Copy, Debug)]
pub struct Rays<'a> {
    /// Origins.
    pub origin: [&'a [f32]; 3],
    /// Directions (any length; `t` is in units of it).
    pub dir: [&'a [f32]; 3],
    /// Opaque depth per ray (`f32::INFINITY` for none).
    pub tmax: &'a [f32],
}

impl Rays<'_> {
    /// Number of rays.
    pub fn len(&self) -> usize {
        self.tmax.len()
    }
    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.tmax.is_empty()
    }
}

/// Lanes `i..` of three SoA slices (zeros past their end).
#[inline(always)]
fn load3<S: Simd>(s: S, a: [&[f32]; 3], i: usize) -> V3<S> {
    V3::<S>::new(
        s.load_partial(&a[0][i..], 0.0),
        s.load_partial(&a[1][i..], 0.0),
        s.load_partial(&a[2][i..], 0.0),
    )
}

/// The first `min(out.len(), LANES)` lanes of `c` into `out` as RGBA.
#[inline(always)]
fn store_rgba<S: Simd>(s: S, c: [S::F32; 4], out: &mut [[f32; 4]]) {
    let mut buf = [0.0f32; spmd::MAX_LANES];
    for (ch, v) in c.into_iter().enumerate() {
        s.store(v, &mut buf);
        for (o, b) in out.iter_mut().take(S::LANES).zip(buf) {
            o[ch] = b;
        }
    }
}

struct MarchBatch<'a, 'b> {
    medium: &'a Medium<'a>,
    rays: &'a Rays<'a>,
    out: &'b mut [[f32; 4]],
}

impl Kernel for MarchBatch<'_, '_> {
    type Output = ();
    // Paper §4.4: a batch of rays, LANES at a time, through the grid or the particles.
    #[inline(always)]
    fn run<S: Simd>(self, s: S) {
        let n = self.rays.len();
        let r = self.rays;
        let mut i = 0;
        while i < n {
            let orig = load3(s, r.origin, i);
            let dir = load3(s, r.dir, i);
            let tmax = s.load_partial(&r.tmax[i..], 0.0);
            let m = s.first_n(n - i);
            let c = self.medium.march(s, orig, dir, tmax, m);
            store_rgba(s, c, &mut self.out[i..]);
            i += S::LANES;
        }
    }
}

/// Marches every ray of `rays` through `medium` with backend `isa` (one dispatch for the
/// whole batch). Panics if the slices' lengths differ.
pub(crate) fn march_medium_rays(isa: Isa, medium: &Medium, rays: &Rays, out: &mut [[f32; 4]]) {
    let n = rays.len();
    assert!(
        rays.origin
            .iter()
            .chain(rays.dir.iter())
            .all(|a| a.len() == n)
            && out.len() == n,
        "march_rays: ray and output slices must have equal lengths"
    );
    isa.dispatch(MarchBatch { medium, rays, out });
}

/// Marches every ray of `rays` with backend `isa` (one dispatch for the whole batch; call it
/// per tile from a parallel renderer). `out[i]` receives ray `i`'s premultiplied RGBA.
/// Panics if the slices' lengths differ.
pub fn march_rays(isa: Isa, scene: &VolumeScene, rays: &Rays, out: &mut [[f32; 4]]) {
    march_medium_rays(isa, &Medium::Grid(*scene), rays, out);
}

struct ClassifyBatch<'a, 'b> {
    tf: &'a ClassifiedTf,
    values: &'a [f32],
    out: &'b mut [[f32; 4]],
}

impl Kernel for ClassifyBatch<'_, '_> {
    type Output = ();
    // Paper §4.4: post-classification through the 256-entry table (the marcher's lookup).
    #[inline(always)]
    fn run<S: Simd>(self, s: S) {
        let n = self.values.len();
        let mut i = 0;
        while i < n {
            let m = s.first_n(n - i);
            let v = s.load_partial(&self.values[i..], 0.0);
            store_rgba(s, classify(s, self.tf, v, v, m, false), &mut self.out[i..]);
            i += S::LANES;
        }
    }
}

/// Post-classifies `values` (density units) through `tf`'s step-corrected table into
/// premultiplied RGBA, with backend `isa` — the marcher's lookup, for benchmarks and tools.
pub fn classify_values(isa: Isa, tf: &ClassifiedTf, values: &[f32], out: &mut [[f32; 4]]) {
    assert_eq!(values.len(), out.len());
    isa.dispatch(ClassifyBatch { tf, values, out });
}
