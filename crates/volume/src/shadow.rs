//! Volume transmittance along shadow rays (paper §4.5 "use volume rendering for occlusion
//! rays, achieving a soft-shadow effect"; DESIGN "volumetric shadows by marching toward the
//! light").
//!
//! A shadow ray only needs how much light gets through, not colour, so it is marched with a
//! coarser step than the primary ray and sums extinction instead of compositing:
//! `T = exp(−Σ τ(Φ(x_k))·Δ)`, `τ` the extinction per voxel of path of the transfer function
//! ([`ClassifiedTf::tau`], `τ = −ln(1 − a)` with `a` the opacity per voxel), `Δ` the step in
//! voxels, samples at the midpoints of the steps (midpoint rule). One `exp` per ray. Lanes stop
//! once `T < 1e-3`.
//!
//! The same march serves shadow rays from ball-and-stick hits ([`transmittance`]) and from
//! the volume's own samples (volumetric shadows, [`crate::march`]). Empty macrocells are
//! jumped over; the march is clipped to the volume's box.

use spmd::{Simd, V3};

use crate::grid::VolumeData;
use crate::macrocell::{Macrocells, MACROCELL};
use crate::march::{cell_occupied, trilinear, F32Voxels, Lattice, U8Voxels, VolumeScene, Voxels};
use crate::tf::ClassifiedTf;

/// A light source of the shading modes (world space, Å).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Infinitely far away, in this direction *towards* the light (need not be unit).
    Directional([f32; 3]),
    /// A point at this position, no distance fall-off (a lamp for visualisation, not a
    /// physical source: what it lights keeps its brightness however far away it is).
    Point([f32; 3]),
}

impl Light {
    /// The directional light's unit direction (`[0, 1, 0]` for a zero or non-finite one);
    /// `None` for a point light.
    pub fn unit_direction(&self) -> Option<[f32; 3]> {
        match *self {
            Light::Directional(l) => {
                let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
                Some(if n > 0.0 && n.is_finite() {
                    [l[0] / n, l[1] / n, l[2] / n]
                } else {
                    [0.0, 1.0, 0.0]
                })
            }
            Light::Point(_) => None,
        }
    }

    /// Unit directions towards the light from points `p` and the distance to it along them
    /// (`+∞` for a directional light). A point light at a lane's point gives direction
    /// `[0, 1, 0]` and distance 0 (nothing lies between).
    #[inline(always)]
    pub fn towards<S: Simd>(&self, s: S, p: V3<S>) -> (V3<S>, S::F32) {
        match *self {
            Light::Directional(_) => (
                V3::splat(s, self.unit_direction().unwrap_or([0.0, 1.0, 0.0])),
                s.splat(f32::INFINITY),
            ),
            Light::Point(q) => {
                let d = V3::splat(s, q) - p;
                let len2 = d.dot(d);
                let ok = s.gt(len2, s.splat(0.0)) & s.lt(len2, s.splat(f32::INFINITY));
                let len = s.sqrt(len2);
                let u = d.scale(s.splat(1.0) / s.select(ok, len, s.splat(1.0)));
                (
                    V3::select(s, ok, u, V3::splat(s, [0.0, 1.0, 0.0])),
                    s.select(ok, len, s.splat(0.0)),
                )
            }
        }
    }
}

/// Transmittance of the volume along rays `o + t·d` (world space, Å, `d` need not be unit;
/// `t` in units of `|d|`) over `(0, tmax)`, with steps of `step_voxels` voxels.
/// Returns 1 for inactive lanes and for lanes that miss the volume.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn transmittance<S: Simd>(
    s: S,
    scene: &VolumeScene,
    o: V3<S>,
    d: V3<S>,
    tmax: S::F32,
    active: S::M,
    step_voxels: f32,
) -> S::F32 {
    let v = scene.volume;
    let g = &v.grid;
    let inv_h = s.splat(1.0 / g.spacing);
    let og = V3::<S>::new(
        (o.x - s.splat(g.origin[0])) * inv_h,
        (o.y - s.splat(g.origin[1])) * inv_h,
        (o.z - s.splat(g.origin[2])) * inv_h,
    );
    let dg = d.scale(inv_h);
    match &v.data {
        VolumeData::F32(data) => {
            let lat = Lattice::new(g, F32Voxels(data), 1.0);
            march_tau(
                s,
                &lat,
                scene.cells,
                scene.tf,
                og,
                dg,
                tmax,
                active,
                step_voxels,
            )
        }
        VolumeData::U8 { data, scale } => {
            let lat = Lattice::new(g, U8Voxels(data), *scale);
            march_tau(
                s,
                &lat,
                scene.cells,
                scene.tf,
                og,
                dg,
                tmax,
                active,
                step_voxels,
            )
        }
    }
}

/// [`transmittance`] of rays already in grid coordinates (`og`, `dg` in voxels). Steps whose
/// midpoint lies in a macrocell the transfer function makes empty jump to that cell's exit
/// instead (their τ is exactly 0), so the empty space between the molecule and the light
/// costs one cell look-up per cell instead of four samples.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn march_tau<S: Simd, V: Voxels>(
    s: S,
    lat: &Lattice<V>,
    cells: &Macrocells,
    tf: &ClassifiedTf,
    og: V3<S>,
    dg: V3<S>,
    tmax: S::F32,
    active: S::M,
    step_voxels: f32,
) -> S::F32 {
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let hi = lat.hi;
    let og_a = [og.x, og.y, og.z];
    let dg_a = [dg.x, dg.y, dg.z];
    let inv_a = [s.rcp(dg.x), s.rcp(dg.y), s.rcp(dg.z)];
    let mut t_in = zero;
    let mut t_end = tmax;
    for a in 0..3 {
        let t0 = (zero - og_a[a]) * inv_a[a];
        let t1 = (s.splat(hi[a]) - og_a[a]) * inv_a[a];
        t_in = s.max(s.min(t0, t1), t_in);
        t_end = s.min(s.max(t0, t1), t_end);
    }
    let dt = s.splat(step_voxels) / s.sqrt(dg.dot(dg));
    let inf = s.splat(f32::INFINITY);
    let mut alive = active & s.lt(t_in, t_end) & s.lt(t_end, inf) & s.lt(dt, inf) & s.gt(dt, zero);
    // Sum of τ·(fraction of a step): the last, partial step is weighted by its length.
    let mut sum = zero;
    let mut t = t_in;
    // Exit of the non-empty macrocell the lane is stepping through (a look-up is due when
    // the next midpoint passes it).
    let mut cell_exit = t_in;
    // T < 1e-3 once Σ τ·Δ > ln 1000.
    let stop = s.splat(6.9 / step_voxels);
    let half = s.splat(0.5);
    let ncells = cells.dims.map(|d| d as i32);
    let cell = s.splat(MACROCELL as f32);
    let inv_cell = s.splat(1.0 / MACROCELL as f32);
    while s.any(alive) {
        let tmid = s.min(t + dt * half, t_end);
        let need = alive & s.ge(tmid, cell_exit);
        if s.any(need) {
            // The macrocell holding the next midpoint, and where the ray leaves it.
            let p = og.mul_add(dg, tmid);
            let pa = [p.x, p.y, p.z];
            let mut c = [s.splat_i(0); 3];
            let mut exit = inf;
            for a in 0..3 {
                let cf = s.floor(pa[a] * inv_cell);
                let cf = s.min(s.max(cf, zero), s.splat((ncells[a] - 1) as f32));
                c[a] = s.to_i32(cf);
                let edge = (cf + s.select(s.gt(dg_a[a], zero), one, zero)) * cell;
                let te = (edge - og_a[a]) * inv_a[a];
                exit = s.min(exit, s.select(s.eq(dg_a[a], zero), inf, te));
            }
            let occupied = cell_occupied(s, cells, tf, c, ncells, need);
            let empty = need & !occupied;
            // Jump over an empty cell (at least to the midpoint, against rounding).
            t = s.select(empty, s.max(exit, tmid), t);
            cell_exit = s.select(need, s.max(exit, tmid), cell_exit);
            alive = alive & !(empty & s.ge(t, t_end));
            if s.any(empty) {
                continue;
            }
        }
        let tb = s.min(t + dt, t_end);
        let w = (tb - t) / dt;
        let p = og.mul_add(dg, (t + tb) * half);
        let val = trilinear(s, lat, p, alive);
        let x = (val - s.splat(tf.lo)) * s.splat(tf.to_bin);
        let x = s.min(s.max(x, zero), s.splat(255.0));
        let bin = s.to_i32(x + half);
        let tau = s.gather(&tf.tau, bin, alive, zero);
        sum = s.select(alive, sum + tau * w, sum);
        t = s.select(alive, tb, t);
        alive = alive & s.lt(t, t_end) & s.lt(sum, stop);
    }
    let tr = spmd::math::exp(s, -(sum * s.splat(step_voxels)));
    s.select(active, s.min(tr, one), one)
}
