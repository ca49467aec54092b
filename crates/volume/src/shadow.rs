//! Volume transmittance along shadow rays (paper §4.5 "use volume rendering for occlusion
//! rays, achieving a soft-shadow effect"; DESIGN "volumetric shadows by marching toward the
//! light").
//!
//! A shadow ray only needs how much light gets through, not colour, so it is marched with a
//! coarser step than the primary ray and sums extinction instead of compositing:
//! `T = exp(−Σ τ(Φ(x_k))·Δ)`, `τ` the extinction per voxel of path of the transfer function
//! ([`ClassifiedTf::tau`](crate::tf::ClassifiedTf::tau), `τ = −ln(1 − a)` with `a` the opacity per voxel), `Δ` the step in
//! voxels, samples at the midpoints of the steps (midpoint rule). One `exp` per ray. Lanes stop
//! once `T < 1e-3`.
//!
//! The same march serves shadow rays from ball-and-stick hits ([`transmittance`]) and from
//! the volume's own samples (volumetric shadows, [`mod@crate::march`]). Empty macrocells are
//! jumped over; the march is clipped to the volume's box.

use spmd::{Simd, V3};

use crate::sampler::{with_lattice, GridRay, Lattice, OnLattice, Voxels};
pub use crate::scene::Light;
use crate::scene::VolumeScene;
use crate::tau::march_tau;

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
    let ray = GridRay::from_world(s, &scene.volume.grid, o, d);
    with_lattice(
        scene.volume,
        ShadowRays {
            s,
            scene,
            ray,
            tmax,
            active,
            step_voxels,
        },
    )
}

/// [`transmittance`]'s packet on one storage format.
struct ShadowRays<'a, S: Simd> {
    s: S,
    scene: &'a VolumeScene<'a>,
    ray: GridRay<S>,
    tmax: S::F32,
    active: S::M,
    step_voxels: f32,
}

impl<S: Simd> OnLattice for ShadowRays<'_, S> {
    type Output = S::F32;
    #[inline(always)]
    fn run<V: Voxels>(self, lat: &Lattice<V>) -> S::F32 {
        let sc = self.scene;
        march_tau(
            self.s,
            lat,
            sc.cells,
            sc.tf,
            self.ray.o,
            self.ray.d,
            self.tmax,
            self.active,
            self.step_voxels,
        )
    }
}
