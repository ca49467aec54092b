//! Typed scene settings: what to build from a molecule frame (model, bonds, volume). The
//! defaults are the `bnsview render` defaults.

use molecule::bonds::BondOptions;
use volume::{Light, TransferFunction, VolumeFormat, VolumeShadows};

use crate::colormap::Colormap;
use crate::model::Style;

/// Which radius of the element table sizes the balls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum RadiusKind {
    /// Covalent radius (Cordero 2008).
    #[default]
    Covalent,
    /// Van der Waals radius (Alvarez 2013).
    Vdw,
}

/// How atoms are coloured.
#[derive(Clone, Debug, PartialEq, Default)]
pub enum ColorBy {
    /// CPK/Jmol colour of the element.
    #[default]
    Element,
    /// A per-atom column of the input (e.g. `q`) through a colormap.
    Column {
        /// Column name ([`molecule::Molecule::scalar`]).
        name: String,
        /// Colormap.
        colormap: Colormap,
        /// Values mapped to the colormap's ends, `lo < hi` (`None`: the column's finite
        /// minimum and maximum in this frame; the range used is [`crate::Model::color_range`]).
        range: Option<(f32, f32)>,
    },
}

/// The ball-and-stick model.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSettings {
    /// Drawing style.
    pub style: Style,
    /// Element radius used for the balls.
    pub radius: RadiusKind,
    /// Ball radius = element radius × this (dimensionless, > 0).
    pub radius_scale: f32,
    /// Stick radius (Å, > 0).
    pub stick_radius: f32,
    /// Colouring.
    pub color: ColorBy,
    /// The 8-wide BVH will be used (secondary or bounce rays `Wide`): counted by
    /// [`crate::MemoryEstimate`] and built by [`crate::Scene::build`].
    pub wide_bvh: bool,
    /// Draw a bond that crosses the periodic boundary of the input's cell as two half-sticks
    /// at the two sides of the cell (the CLI's `--pbc`); off, or without a cell, a bond is
    /// drawn between the two atoms as they are.
    pub periodic_bonds: bool,
    /// Draw the simulation cell's edges as sticks ([`crate::CELL_COLOR`]); an error when the
    /// input has no cell.
    pub draw_cell: bool,
}

impl Default for ModelSettings {
    fn default() -> Self {
        ModelSettings {
            style: Style::BallAndStick,
            radius: RadiusKind::Covalent,
            radius_scale: 0.5,
            stick_radius: 0.15,
            color: ColorBy::Element,
            wide_bvh: false,
            periodic_bonds: false,
            draw_cell: false,
        }
    }
}

/// Where bonds come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum BondSource {
    /// Geometric rule (uniform-grid neighbour search, [`molecule::bonds::try_build_bonds`]).
    #[default]
    Auto,
    /// Bonds listed in the file (LAMMPS data `Bonds`, PDB `CONECT`); an error if there are none.
    File,
    /// No bonds.
    None,
}

/// Bond detection.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct BondSettings {
    /// Source.
    pub source: BondSource,
    /// Rule of [`BondSource::Auto`]: factor (default 1.15), cutoffs (Å), pbc.
    pub options: BondOptions,
    /// Unwrap the frame across the periodic boundaries before building anything
    /// ([`molecule::unwrap`], the CLI's `--unwrap`): by the image flags `ix iy iz` when the
    /// input has them, else by minimum image along the bonds. Needs a cell. The bonds are
    /// then detected with the minimum image whatever `options.pbc` says (or are the file's),
    /// and a bond that still crosses the cell after unwrapping (a molecule bonded to its own
    /// image) is drawn as half-sticks with [`ModelSettings::periodic_bonds`], else not drawn.
    pub unwrap: bool,
}

/// The light volume of volumetric shadows (paper §4.5): transmittance towards one light
/// precomputed every `stride` density voxels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightVolumeSettings {
    /// The light the shadows are cast from.
    pub light: Light,
    /// Step of the shadow rays (density voxels, > 0; CLI default 2).
    pub step_voxels: f32,
    /// Density voxels per light-volume cell: 1, 2, 4 or 8 (default [`LIGHT_VOLUME_STRIDE`]).
    pub stride: usize,
}

/// Default stride (density voxels) of the light volume.
pub const LIGHT_VOLUME_STRIDE: usize = 2;

impl LightVolumeSettings {
    /// The volume crate's shadow description (light and step) of these settings.
    pub fn shadows(&self) -> VolumeShadows {
        VolumeShadows {
            light: self.light,
            step_voxels: self.step_voxels,
        }
    }
}

/// Where the volume's RBF density is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum DensitySource {
    /// Sampled once on a grid of `voxels_per_angstrom`, then interpolated (paper §3.1):
    /// fastest to march, memory grows with the voxels.
    #[default]
    Grid,
    /// Summed from the atoms at every sample through a BVH over their support spheres
    /// (grid-free): exact, memory grows with the atoms; `voxels_per_angstrom` sets only the
    /// step. No volumetric shadows.
    Particles,
}

/// The RBF density volume (paper §3.1) and what is derived from it.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeSettings {
    /// Where the density is evaluated: a grid, or the atoms themselves.
    pub source: DensitySource,
    /// Grid resolution (voxels per Å, > 0; the paper uses 4, and 1 for sio2 and anp3); the
    /// step is half a voxel, whatever the source.
    pub voxels_per_angstrom: f32,
    /// Voxel storage.
    pub format: VolumeFormat,
    /// Transfer function, classified over `[0, max density]`.
    pub tf: TransferFunction,
    /// Ray-marching step the transfer function is classified for (voxels; CLI: 0.5).
    pub step_voxels: f32,
    /// Precomputed light volume (`None`: none, shadows march shadow rays if asked).
    pub light_volume: Option<LightVolumeSettings>,
    /// Density mapped to the top of the transfer function (density units, > 0; `None`: the
    /// frame's maximum). Fixed across a trajectory so the pictures do not flicker.
    pub density_max: Option<f32>,
}

impl Default for VolumeSettings {
    fn default() -> Self {
        VolumeSettings {
            source: DensitySource::Grid,
            voxels_per_angstrom: 4.0,
            format: VolumeFormat::U8,
            tf: TransferFunction::preset(volume::Preset::CoolWarm),
            step_voxels: 0.5,
            light_volume: None,
            density_max: None,
        }
    }
}

/// Everything [`crate::Scene::build`] needs besides the molecule.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSettings {
    /// Ball-and-stick model (`None`: no geometry, e.g. volume-only pictures).
    pub model: Option<ModelSettings>,
    /// Bonds (built only when there is a model).
    pub bonds: BondSettings,
    /// Density volume (`None`: none).
    pub volume: Option<VolumeSettings>,
    /// Refuse to build when the [`crate::MemoryEstimate`] total exceeds this many bytes
    /// (`None`: 75 % of `MemAvailable`, no limit where that cannot be read).
    pub budget_bytes: Option<u64>,
    /// Framebuffer size (width, height pixels) counted by the estimate (`None`: not counted).
    pub frame: Option<(u32, u32)>,
}

impl Default for SceneSettings {
    fn default() -> Self {
        SceneSettings {
            model: Some(ModelSettings::default()),
            bonds: BondSettings::default(),
            volume: None,
            budget_bytes: None,
            frame: None,
        }
    }
}
