//! Volume transmittance along shadow rays (paper §4.5 "use volume rendering for occlusion
//! rays, achieving a soft-shadow effect"; DESIGN "volumetric shadows by marching toward the
//! light").
//!
//! A shadow ray only needs how much light gets through, not colour, so it is marched with a
//! coarser step than the primary ray and sums extinction instead of compositing:
//! `T = exp(−Σ τ(Φ(x_k))·Δ)`, `τ` the extinction per voxel of path of the transfer function's
//! opacity (`τ = −ln(1 − α)`, α per voxel), `Δ` the step in voxels, samples at the midpoints
//! of the steps (midpoint rule). One `exp` per ray. Lanes stop once `T < 1e-3`.
//!
//! Macrocells are not used here (the steps are already coarse); the march is clipped to the
//! volume's box.

use spmd::{Simd, V3};

use crate::grid::{Grid, VolumeData};
use crate::march::{trilinear, F32Voxels, Lattice, U8Voxels, VolumeScene, Voxels};
use crate::tf::{ClassifiedTf, TF_SIZE};

/// Extinction per voxel of path for each transfer-function bin (for [`transmittance`]).
#[derive(Clone, Debug)]
pub struct ShadowTf {
    /// `τ` per bin (256 entries), per voxel of path.
    pub tau: Vec<f32>,
    /// Value mapped to bin 0 (as the classified table).
    pub lo: f32,
    /// Value → bin coordinate.
    pub to_bin: f32,
}

impl ShadowTf {
    /// From the classified transfer function the primary rays use (its `post` opacities are
    /// per step of `step_voxels`; τ is converted back to per voxel).
    pub fn new(tf: &ClassifiedTf) -> ShadowTf {
        let tau = (0..TF_SIZE)
            .map(|i| {
                let a = (tf.post[i * 4 + 3] as f64).clamp(0.0, 1.0 - 1e-6);
                (-(1.0 - a).ln() / tf.step_voxels as f64) as f32
            })
            .collect();
        ShadowTf {
            tau,
            lo: tf.lo,
            to_bin: tf.to_bin,
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
    stf: &ShadowTf,
    o: V3<S>,
    d: V3<S>,
    tmax: S::F32,
    active: S::M,
    step_voxels: f32,
) -> S::F32 {
    let v = scene.volume;
    match &v.data {
        VolumeData::F32(data) => {
            let lat = Lattice::new(&v.grid, F32Voxels(data), 1.0);
            march_tau(s, &v.grid, &lat, stf, o, d, tmax, active, step_voxels)
        }
        VolumeData::U8 { data, scale } => {
            let lat = Lattice::new(&v.grid, U8Voxels(data), *scale);
            march_tau(s, &v.grid, &lat, stf, o, d, tmax, active, step_voxels)
        }
    }
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn march_tau<S: Simd, V: Voxels>(
    s: S,
    g: &Grid,
    lat: &Lattice<V>,
    stf: &ShadowTf,
    o: V3<S>,
    d: V3<S>,
    tmax: S::F32,
    active: S::M,
    step_voxels: f32,
) -> S::F32 {
    let zero = s.splat(0.0);
    let one = s.splat(1.0);
    let inv_h = s.splat(1.0 / g.spacing);
    let og = V3::<S>::new(
        (o.x - s.splat(g.origin[0])) * inv_h,
        (o.y - s.splat(g.origin[1])) * inv_h,
        (o.z - s.splat(g.origin[2])) * inv_h,
    );
    let dg = d.scale(inv_h);
    let hi = lat.hi;
    let og_a = [og.x, og.y, og.z];
    let dg_a = [dg.x, dg.y, dg.z];
    let mut t_in = zero;
    let mut t_end = tmax;
    for a in 0..3 {
        let inv = s.rcp(dg_a[a]);
        let t0 = (zero - og_a[a]) * inv;
        let t1 = (s.splat(hi[a]) - og_a[a]) * inv;
        t_in = s.max(s.min(t0, t1), t_in);
        t_end = s.min(s.max(t0, t1), t_end);
    }
    let dt = s.splat(step_voxels) / s.sqrt(dg.dot(dg));
    let inf = s.splat(f32::INFINITY);
    let mut alive = active & s.lt(t_in, t_end) & s.lt(t_end, inf) & s.lt(dt, inf) & s.gt(dt, zero);
    // Sum of τ·(fraction of a step): the last, partial step is weighted by its length.
    let mut sum = zero;
    let mut t = t_in;
    // T < 1e-3 once Σ τ·Δ > ln 1000.
    let stop = s.splat(6.9 / step_voxels);
    let half = s.splat(0.5);
    while s.any(alive) {
        let tb = s.min(t + dt, t_end);
        let w = (tb - t) / dt;
        let p = og.mul_add(dg, (t + tb) * half);
        let val = trilinear(s, lat, p, alive);
        let x = (val - s.splat(stf.lo)) * s.splat(stf.to_bin);
        let x = s.min(s.max(x, zero), s.splat(255.0));
        let bin = s.to_i32(x + half);
        let tau = s.gather(&stf.tau, bin, alive, zero);
        sum = s.select(alive, sum + tau * w, sum);
        t = tb;
        alive = alive & s.lt(t, t_end) & s.lt(sum, stop);
    }
    let tr = spmd::math::exp(s, -(sum * s.splat(step_voxels)));
    s.select(active, s.min(tr, one), one)
}
