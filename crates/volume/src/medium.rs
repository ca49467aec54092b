//! What a renderer marches through: the density grid ([`VolumeScene`]) or, grid-free, the
//! atoms themselves ([`ParticleScene`]) — one entry point for both.

use spmd::{Simd, V3};

use crate::march::march;
use crate::particle_march::{march_particles, ParticleScene};
use crate::scene::{MarchOptions, VolumeScene};

/// The volume of a frame, however its density is evaluated.
#[derive(Clone, Copy, Debug)]
pub enum Medium<'a> {
    /// Trilinear samples of a density grid, macrocells, light volume (paper §4.4).
    Grid(VolumeScene<'a>),
    /// Gaussians summed from the atoms at each sample (grid-free).
    Particles(ParticleScene<'a>),
}

impl Medium<'_> {
    /// Marches a packet, as [`march()`] and [`march_particles`] do: premultiplied
    /// `[r, g, b, a]`, zeros on inactive lanes.
    #[inline(always)]
    pub fn march<S: Simd>(
        &self,
        s: S,
        orig: V3<S>,
        dir: V3<S>,
        tmax: S::F32,
        active: S::M,
    ) -> [S::F32; 4] {
        match self {
            Medium::Grid(g) => march(s, g, orig, dir, tmax, active),
            Medium::Particles(p) => march_particles(s, p, orig, dir, tmax, active),
        }
    }

    /// The grid, when there is one (volumetric shadows need it).
    pub fn grid(&self) -> Option<&VolumeScene<'_>> {
        match self {
            Medium::Grid(g) => Some(g),
            Medium::Particles(_) => None,
        }
    }

    /// The marcher's options.
    pub fn opts(&self) -> &MarchOptions {
        match self {
            Medium::Grid(g) => &g.opts,
            Medium::Particles(p) => &p.opts,
        }
    }
}
