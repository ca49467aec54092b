//! How large a density lattice may be: the points [`Grid::for_atoms`] places (exact, in
//! f64), and the check that refuses a grid over the memory budget or over the 2³¹ points
//! 32-bit gather indices address, with a resolution that fits.

use crate::grid::{check_atoms, estimate_bytes, DensityParams, Grid};
use crate::VolumeError;

/// Refuses `grid` (placed over the atoms `[x, y, z, r]` at `params`' resolution) when its
/// points exceed what 32-bit gather indices address, or when [`estimate_bytes`] exceeds
/// `budget`: [`VolumeError::TooLarge`] with a resolution that fits.
pub fn check_size(
    grid: &Grid,
    [x, y, z, r]: [&[f32]; 4],
    params: &DensityParams,
    budget: Option<u64>,
) -> Result<(), VolumeError> {
    let needed = estimate_bytes(grid, params.format);
    let too_many = grid.voxel_count() > (i32::MAX as u64 - 64);
    if too_many || budget.is_some_and(|b| needed > b) {
        let limit = if too_many {
            (i32::MAX as u64 - 64) * params.format.bytes_per_voxel()
        } else {
            budget.unwrap_or(u64::MAX)
        };
        let limit = match budget {
            Some(b) => b.min(limit),
            None => limit,
        };
        // Bytes grow with the cube of the resolution; round the suggestion down to 1/4 voxel/Å
        // (two significant digits below that). From the exact point counts: `needed`
        // saturates for absurd extents.
        let (_, points) = lattice_points(x, y, z, r, params.voxels_per_angstrom)?;
        let exact = points.iter().product::<f64>() * params.format.bytes_per_voxel() as f64;
        let k = (limit as f64 / exact.max(needed as f64)).cbrt() * 0.97;
        let suggest = suggested_resolution(params.voxels_per_angstrom as f64 * k);
        return Err(VolumeError::TooLarge {
            needed,
            limit,
            dims: grid.dims,
            voxels_per_angstrom: params.voxels_per_angstrom,
            format: params.format,
            suggested_voxels_per_angstrom: suggest,
            index_limit: too_many,
        });
    }
    Ok(())
}

/// The lattice of [`Grid::for_atoms`]: its origin (Å) and its number of points per axis,
/// exact in f64 (unbounded: the caller decides what fits).
pub(crate) fn lattice_points(
    x: &[f32],
    y: &[f32],
    z: &[f32],
    r: &[f32],
    voxels_per_angstrom: f32,
) -> Result<([f32; 3], [f64; 3]), VolumeError> {
    check_atoms(x, y, z, r)?;
    if !(voxels_per_angstrom.is_finite() && voxels_per_angstrom > 0.0) {
        return Err(VolumeError::BadResolution(voxels_per_angstrom));
    }
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    let mut rmax = 0.0f32;
    for i in 0..x.len() {
        for (a, v) in [x[i], y[i], z[i]].into_iter().enumerate() {
            lo[a] = lo[a].min(v);
            hi[a] = hi[a].max(v);
        }
        rmax = rmax.max(r[i]);
    }
    let h = 1.0 / voxels_per_angstrom;
    let pad = core::f32::consts::SQRT_2 * rmax + h;
    let mut points = [0.0f64; 3];
    let mut origin = [0.0f32; 3];
    for a in 0..3 {
        origin[a] = lo[a] - pad;
        let extent = hi[a] as f64 + pad as f64 - origin[a] as f64;
        points[a] = (extent / h as f64).ceil() + 1.0;
    }
    Ok((origin, points))
}

/// A resolution (voxels/Å) at most `v`, for a message: rounded down to 1/4 from 1/4 up,
/// else to two significant digits.
fn suggested_resolution(v: f64) -> f32 {
    if v >= 0.25 {
        return ((v * 4.0).floor() / 4.0) as f32;
    }
    let scale = 10f64.powi(1 - v.log10().floor() as i32);
    ((v * scale).floor() / scale) as f32
}
