//! Direct volume rendering of the RBF density of a molecule (paper §3.1 and §4.4).
//!
//! Pipeline, each step a separate piece so the expensive ones are not redone needlessly:
//!
//! 1. [`build_density`]: Φ(x) = Σᵢ √rᵢ·exp(−d²/rᵢ²) over atoms with d < √2·rᵢ (rᵢ the
//!    covalent radius, Å), sampled at the **lattice points** (voxel corners) of a grid at
//!    `voxels_per_angstrom` over the atoms' bounds padded by √2·r_max + 1 voxel. Stored as f32
//!    or u8 (one global scale = max / 255). [`estimate_bytes`] tells the memory before anything
//!    is allocated; over budget the build fails with [`VolumeError::TooLarge`], which suggests
//!    a resolution that fits. Parallel over z-slabs (rayon), SIMD along x (`spmd`),
//!    deterministic.
//! 2. [`Macrocells::build`]: min/max per 8³ block of cells including the shared border.
//! 3. [`ClassifiedTf::new`]: per transfer function, value range and step length — the
//!    opacity-corrected post-classification table, the pre-integration table and the
//!    range-max table that decides macrocell emptiness. Changing the transfer function
//!    rebuilds only this (≈ 0.1 s), never the grid.
//! 4. [`march()`] (one SIMD packet, generic over [`spmd::Simd`]) or [`march_rays`] (a batch,
//!    dispatched once) with a [`VolumeScene`] and [`MarchOptions`].
//!
//! Units: positions in Å; "voxel" as a length is one lattice spacing (1 / voxels-per-Å);
//! the step is 0.5 voxel; transfer-function opacity is per voxel of path.
//!
//! Transfer functions: [`Preset`]s (`coolwarm`, `viridis`, `grayscale`) or a text file of
//! control points `value r g b a` — see the [`tf`] module for the format and
//! `crates/volume/tf/density-ramp.tf` for an example file.
//!
//! ## Use from a renderer
//! ```
//! use spmd::Isa;
//! use volume::*;
//! # fn main() -> Result<(), VolumeError> {
//! let isa = Isa::detect();
//! // Once per data set (atoms as SoA slices, Å; r = covalent radius).
//! let (x, y, z, r) = (vec![0.0f32, 1.4], vec![0.0f32, 0.0], vec![0.0f32, 0.0], vec![0.76f32; 2]);
//! let params = DensityParams { voxels_per_angstrom: 4.0, format: VolumeFormat::U8, budget_bytes: None };
//! let vol = build_density(isa, &x, &y, &z, &r, &params, None)?;
//! let cells = Macrocells::build(&vol);
//! // Whenever the transfer function (or its value range) changes.
//! let tf = ClassifiedTf::new(&TransferFunction::preset(Preset::CoolWarm), 0.0, vol.max_value, 0.5);
//! // Per frame.
//! let scene = VolumeScene::new(&vol, &cells, &tf, MarchOptions::default());
//! // Per tile (e.g. inside a rayon task): SoA rays, `tmax` = opaque depth of the b&s pass
//! // in units of |dir| (f32::INFINITY for the volume alone).
//! let (ox, oy, oz) = ([-5.0f32], [0.0f32], [0.0f32]);
//! let (dx, dy, dz) = ([1.0f32], [0.0f32], [0.0f32]);
//! let tmax = [f32::INFINITY];
//! let mut rgba = [[0.0f32; 4]];
//! march_rays(isa, &scene, &Rays { origin: [&ox, &oy, &oz], dir: [&dx, &dy, &dz], tmax: &tmax }, &mut rgba);
//! assert!(rgba[0][3] > 0.0);
//! // Premultiplied: pixel = rgb + (1 - a) * background (the b&s colour in vol+bs mode).
//! # Ok(()) }
//! ```
//! Inside a renderer's own SIMD kernel, call [`march()`] on a packet instead
//! (`march::<S>(s, &scene, orig, dir, tmax, active)` → `[r, g, b, a]` varying).
//!
//! ## Grid-free
//! [`Particles::build`] puts the atoms' support spheres in a BVH instead of sampling a grid;
//! [`ParticleScene`] and [`march_particles`] / [`march_particle_rays`] march it with the same
//! transfer function, options and output (no volumetric shadows). [`Medium`] is either, for
//! a renderer that takes both.
//! ```
//! use spmd::Isa;
//! use volume::*;
//! # fn main() -> Result<(), VolumeError> {
//! let (x, y, z, r) = (vec![0.0f32, 1.4], vec![0.0f32, 0.0], vec![0.0f32, 0.0], vec![0.76f32; 2]);
//! let p = Particles::build(&x, &y, &z, &r, 4.0)?; // 4 /Å: steps of 0.125 Å
//! let tf = ClassifiedTf::new(&TransferFunction::preset(Preset::CoolWarm), 0.0, p.max_value, 0.5);
//! let scene = ParticleScene::new(&p, &tf, MarchOptions::default());
//! let (ox, oy, oz, dx, dy, dz) = ([-5.0f32], [0.0f32], [0.0f32], [1.0f32], [0.0f32], [0.0f32]);
//! let tmax = [f32::INFINITY];
//! let mut rgba = [[0.0f32; 4]];
//! let rays = Rays { origin: [&ox, &oy, &oz], dir: [&dx, &dy, &dz], tmax: &tmax };
//! march_particle_rays(Isa::detect(), &scene, &rays, &mut rgba);
//! assert!(rgba[0][3] > 0.0);
//! # Ok(()) }
//! ```

#![warn(missing_docs)]

pub mod empty_space;
mod gradient;
pub mod grid;
pub mod grid_size;
pub mod light;
pub mod macrocell;
pub mod march;
pub mod medium;
pub mod particle_march;
pub mod particles;
mod sampler;
pub mod scene;
pub mod shadow;
mod tau;
pub mod tf;

pub use empty_space::EmptySpace;
pub use grid::{
    build_density, default_budget_bytes, density_work, estimate_bytes, DensityParams, Grid, Volume,
    VolumeData, VolumeFormat, Watch,
};
pub use grid_size::check_size;
pub use macrocell::{Macrocells, MACROCELL};
pub use march::{classify_values, march, march_rays, Rays};
pub use medium::Medium;
pub use particle_march::{march_particle_rays, march_particles, ParticleScene};
pub use particles::Particles;
pub use sampler::sample_points;
pub use scene::{Light, LightVolume, Lighting, MarchOptions, VolumeScene, VolumeShadows};
pub use shadow::transmittance;
pub use tf::{
    preintegrate, ClassifiedTf, ControlPoint, Preset, TfError, TransferFunction, TF_SIZE,
};

/// Why a volume could not be built.
#[derive(Debug, thiserror::Error)]
pub enum VolumeError {
    /// The coordinate and radius slices differ in length.
    #[error("atom arrays differ in length: x {x}, y {y}, z {z}, r {r}")]
    LengthMismatch {
        /// Length of x.
        x: usize,
        /// Length of y.
        y: usize,
        /// Length of z.
        z: usize,
        /// Length of r.
        r: usize,
    },
    /// No atoms.
    #[error("no atoms: nothing to build a volume of")]
    NoAtoms,
    /// A coordinate is NaN or infinite.
    #[error("atom {atom} has a non-finite coordinate")]
    NonFinite {
        /// Index of the atom.
        atom: usize,
    },
    /// A radius is not positive and finite.
    #[error("atom {atom} has radius {radius} Å: radii must be positive and finite")]
    BadRadius {
        /// Index of the atom.
        atom: usize,
        /// Its radius.
        radius: f32,
    },
    /// Resolution not positive and finite.
    #[error("voxels per Ångström must be positive and finite, got {0}")]
    BadResolution(f32),
    /// Unknown storage format name.
    #[error("unknown volume format {0:?}: expected u8 or f32")]
    UnknownFormat(String),
    /// The build was stopped by its caller's cancel test (e.g. a viewer that no longer
    /// needs this time step); nothing was kept.
    #[error("the density volume's build was cancelled")]
    Cancelled,
    /// The grid would not fit in memory (or exceeds 2³¹ voxels, the gather index limit).
    #[error(
        "the {format} density volume at {voxels_per_angstrom} voxels/Å would be {}x{}x{} voxels, \
         {} MB, over the {} of {} MB; try --voxels-per-angstrom {suggested_voxels_per_angstrom} \
         or lower{}",
        dims[0], dims[1], dims[2], needed / 1_000_000,
        if *index_limit { "2^31-voxel limit" } else { "memory budget" }, limit / 1_000_000,
        if *format == VolumeFormat::F32 { ", or --volume-format u8" } else { "" }
    )]
    TooLarge {
        /// Bytes the build would need ([`estimate_bytes`]).
        needed: u64,
        /// Bytes allowed.
        limit: u64,
        /// Lattice points per axis.
        dims: [usize; 3],
        /// Requested resolution.
        voxels_per_angstrom: f32,
        /// Requested format.
        format: VolumeFormat,
        /// A resolution that fits.
        suggested_voxels_per_angstrom: f32,
        /// True when the voxel count, not memory, is the limit.
        index_limit: bool,
    },
}
