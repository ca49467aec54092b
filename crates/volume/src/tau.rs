//! The shadow-ray march shared by [`crate::shadow::transmittance`], the marcher's volumetric
//! shadows and the light volume (paper §4.5): `Σ τ(Φ(x_k))·Δ` along a ray in grid
//! coordinates with coarse steps sampled at their midpoints, empty macrocells jumped, and one
//! `exp` at the end. See [`crate::shadow`] for the model.

use spmd::{Simd, V3};

use crate::macrocell::{Macrocells, MACROCELL};
use crate::sampler::{bin, cell_occupied, clip_box, trilinear, GridRay, Lattice, Voxels};
use crate::tf::ClassifiedTf;

// Paper §4.5: transmittance of rays already in grid coordinates (`og`, `dg` in voxels) over
// `(0, tmax)`, steps of `step_voxels`. Steps whose midpoint lies in a macrocell the transfer
// function makes empty jump to that cell's exit instead (their τ is exactly 0), so the empty
// space between the molecule and the light costs one cell look-up per cell instead of four
// samples. Returns 1 for inactive lanes and lanes that miss the box.
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
    let ray = GridRay::new(s, og, dg);
    let og_a = ray.o_a();
    let dg_a = ray.d_a();
    let inv_a = ray.inv;
    let span = clip_box(s, &ray, lat.hi, tmax, step_voxels, active);
    let (t_in, t_end, dt) = (span.t_in, span.t_end, span.dt);
    let mut alive = span.alive;
    let inf = s.splat(f32::INFINITY);
    // Sum of τ·(fraction of a step): the last, partial step is weighted by its length.
    let mut sum = zero;
    let mut t = t_in;
    // Exit of the non-empty macrocell the lane is stepping through (a look-up is due when
    // the next midpoint passes it).
    let mut cell_exit = t_in;
    // T < 1e-3 once Σ τ·Δ > ln 1000.
    let stop = s.splat(6.9 / step_voxels);
    let half = s.splat(0.5);
    let ncells = [
        cells.dims[0] as i32,
        cells.dims[1] as i32,
        cells.dims[2] as i32,
    ];
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
        let tau = s.gather(&tf.tau, bin(s, tf, val), alive, zero);
        sum = s.select(alive, sum + tau * w, sum);
        t = s.select(alive, tb, t);
        alive = alive & s.lt(t, t_end) & s.lt(sum, stop);
    }
    let tr = spmd::math::exp(s, -(sum * s.splat(step_voxels)));
    s.select(active, s.min(tr, one), one)
}
