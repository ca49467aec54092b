//! Light volume: the volume's transmittance towards a light, precomputed on a coarse lattice
//! so volumetric shadows cost one trilinear look-up per shaded sample instead of one shadow
//! ray (paper §4.5, Figure 4; DESIGN "volumetric shadows by marching toward the light").
//!
//! Every `stride`-th lattice point of the density grid marches a shadow ray towards the light
//! ([`crate::shadow`]: coarse steps, midpoint rule, empty macrocells jumped) and stores the
//! transmittance `T` quantised to 8 bits. Points whose surrounding macrocells are all empty
//! for the transfer function are never read by the marcher (it only shades samples inside
//! non-empty cells, and `stride` divides the macrocell edge) and are set to 1 without a march.
//! The result depends on the light, the transfer function and the shadow step, not on the
//! camera: build it once per light and reuse it for every frame.
//!
//! Measured (nanobowl, 512², unlit volume with shadows, AVX2, 2 threads): one shadow ray per
//! shaded sample 6.8 s per frame; light volume (stride 2) 1.2 s to build, then 0.34 s per
//! frame (0.22 s without shadows), images within 10/255 of each other (mean 0.5/255).

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;
use spmd::{Isa, Kernel, Simd, V3};

use crate::grid::Grid;
use crate::macrocell::MACROCELL;
use crate::sampler::{with_lattice, Lattice, OnLattice, Voxels};
pub use crate::scene::LightVolume;
use crate::scene::{VolumeScene, VolumeShadows};
use crate::tau::march_tau;

impl LightVolume {
    /// Marches a shadow ray from every `stride`-th lattice point of `scene`'s volume towards
    /// `shadows.light` (parallel over z-planes, SIMD over x, backend `isa`). `stride` must be
    /// 1, 2, 4 or 8.
    pub fn build(isa: Isa, scene: &VolumeScene, shadows: VolumeShadows, stride: usize) -> Self {
        LightVolume::build_with_progress(isa, scene, shadows, stride, &AtomicU64::new(0))
    }

    /// z-planes of the light lattice over `grid` at `stride`: the units of work
    /// [`LightVolume::build_with_progress`] counts.
    pub fn planes(grid: &Grid, stride: usize) -> u64 {
        ((grid.dims[2] - 1).div_ceil(stride.max(1)) + 1) as u64
    }

    /// [`LightVolume::build`] adding each finished z-plane to `done` (up to
    /// [`LightVolume::planes`]), for a progress display that reads it from another thread.
    pub fn build_with_progress(
        isa: Isa,
        scene: &VolumeScene,
        shadows: VolumeShadows,
        stride: usize,
        done: &AtomicU64,
    ) -> Self {
        assert!(
            [1, 2, 4, 8].contains(&stride),
            "light volume stride must divide the macrocell edge"
        );
        let g = &scene.volume.grid;
        let dims: [usize; 3] = core::array::from_fn(|a| (g.dims[a] - 1).div_ceil(stride) + 1);
        let grid = Grid {
            origin: g.origin,
            spacing: g.spacing * stride as f32,
            dims,
        };
        let occupied = occupied_cells(scene);
        let mut data = vec![255u8; dims.iter().product()];
        data.par_chunks_mut(dims[0] * dims[1])
            .enumerate()
            .for_each(|(k, plane)| {
                isa.dispatch(PlaneKernel {
                    scene,
                    occupied: &occupied,
                    shadows,
                    stride,
                    dims,
                    k,
                    plane,
                });
                done.fetch_add(1, Ordering::Relaxed);
            });
        LightVolume {
            grid,
            stride,
            data,
            shadows,
        }
    }
}

/// Per macrocell: does the transfer function make anything in it visible? (As the marcher's
/// test, scalar.)
fn occupied_cells(scene: &VolumeScene) -> Vec<bool> {
    let tf = scene.tf;
    let mm = &scene.cells.minmax;
    (0..mm.len() / 2)
        .map(|c| {
            let b0 = tf.bin(mm[2 * c]).saturating_sub(1);
            let b1 = (tf.bin(mm[2 * c + 1]) + 1).min(255);
            tf.range_max[b0 * 256 + b1] > 0.0
        })
        .collect()
}

struct PlaneKernel<'a, 'b> {
    scene: &'a VolumeScene<'a>,
    occupied: &'a [bool],
    shadows: VolumeShadows,
    stride: usize,
    dims: [usize; 3],
    k: usize,
    plane: &'b mut [u8],
}

impl Kernel for PlaneKernel<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn run<S: Simd>(self, s: S) {
        let vol = self.scene.volume;
        with_lattice(vol, PlaneOn { s, k: self })
    }
}

/// [`plane`] on one storage format.
struct PlaneOn<'a, 'b, S: Simd> {
    s: S,
    k: PlaneKernel<'a, 'b>,
}

impl<S: Simd> OnLattice for PlaneOn<'_, '_, S> {
    type Output = ();
    #[inline(always)]
    fn run<V: Voxels>(self, lat: &Lattice<V>) {
        plane(self.s, self.k, lat)
    }
}

/// Macrocell indices (at most two) whose closed extent holds lattice coordinate `x`.
#[inline(always)]
fn cells_at(x: usize, ncells: usize) -> [usize; 2] {
    let c = (x / MACROCELL).min(ncells - 1);
    let prev = if x.is_multiple_of(MACROCELL) && x > 0 {
        c.saturating_sub(1)
    } else {
        c
    };
    [prev, c]
}

/// Is any of the (at most 2×2×2) macrocells `cx × cy × cz` occupied (grid of `cd` cells)?
#[inline(always)]
fn any_occupied(
    occupied: &[bool],
    cd: [usize; 3],
    cx: [usize; 2],
    cy: [usize; 2],
    cz: [usize; 2],
) -> bool {
    for c2 in cz {
        for c1 in cy {
            for c0 in cx {
                if occupied[c0 + cd[0] * (c1 + cd[1] * c2)] {
                    return true;
                }
            }
        }
    }
    false
}

// Paper §4.5: one z-plane of the light volume, shadow rays from the points of non-empty cells.
#[inline(always)]
fn plane<S: Simd, V: Voxels>(s: S, k: PlaneKernel, lat: &Lattice<V>) {
    let sc = k.scene;
    let g = &sc.volume.grid;
    let cd = sc.cells.dims;
    let st = k.stride;
    let [nx, ny, _] = k.dims;
    let light = k.shadows.light.in_grid(g);
    let z = (k.k * st) as f32;
    let cz = cells_at(k.k * st, cd[2]);
    let mut need = [0i32; spmd::MAX_LANES];
    let mut xs = [0.0f32; spmd::MAX_LANES];
    let mut out = [0.0f32; spmd::MAX_LANES];
    for j in 0..ny {
        let cy = cells_at(j * st, cd[1]);
        let y = (j * st) as f32;
        for i0 in (0..nx).step_by(S::LANES) {
            let n = (nx - i0).min(S::LANES);
            let mut any = false;
            for l in 0..S::LANES {
                let hit =
                    l < n && any_occupied(k.occupied, cd, cells_at((i0 + l) * st, cd[0]), cy, cz);
                need[l] = hit as i32;
                any |= hit;
                xs[l] = ((i0 + l) * st) as f32;
            }
            if !any {
                continue;
            }
            let m = s.gt_i(s.load_i(&need), s.splat_i(0));
            let p = V3::new(s.load(&xs), s.splat(y), s.splat(z));
            let (l, dist) = light.towards(s, p);
            let t = march_tau(
                s,
                lat,
                sc.cells,
                sc.tf,
                p,
                l,
                dist,
                m,
                k.shadows.step_voxels,
            );
            s.store(t, &mut out);
            let row = &mut k.plane[j * nx + i0..j * nx + i0 + n];
            for (o, &t) in row.iter_mut().zip(&out[..n]) {
                *o = (t.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            }
        }
    }
}
