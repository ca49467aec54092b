//! The clap flags of the scene (geometry, volume) and their mapping onto the typed
//! [`scene::SceneSettings`]; the building itself is `scene::Scene::build`.

use std::time::Instant;

use clap::{Args, ValueEnum};
use molecule::Molecule;
use render::{Colormap, Model, Style};
use scene::{ColorBy, ModelSettings, VolumeSettings};
use spmd::Isa;
use volume::{Macrocells, Volume, VolumeFormat};

/// Which radius of the element table sizes the balls.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum RadiusKind {
    /// Covalent radius (Cordero 2008), scaled by `--radius-scale`.
    Covalent,
    /// Van der Waals radius (Alvarez 2013), scaled by `--radius-scale`.
    Vdw,
}

/// Drawing style (`--style`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum StyleArg {
    /// Balls and sticks.
    BallAndStick,
    /// Sticks only, with round caps.
    Licorice,
    /// Balls only (space-filling; use with `--radius vdw --radius-scale 1`).
    Spheres,
}

/// Geometry options of the ball-and-stick scene.
#[derive(Args, Debug, Clone)]
pub struct GeometryArgs {
    /// Drawing style.
    #[arg(long, value_enum, default_value_t = StyleArg::BallAndStick)]
    pub style: StyleArg,
    /// Radius used for the balls.
    #[arg(long, value_enum, default_value_t = RadiusKind::Covalent)]
    pub radius: RadiusKind,
    /// Ball radius = element radius × this.
    #[arg(long, default_value_t = 0.5)]
    pub radius_scale: f32,
    /// Stick radius (Å).
    #[arg(long, default_value_t = 0.15)]
    pub stick_radius: f32,
    /// Colour atoms by `element` (CPK/Jmol colours) or by a per-atom column of the input
    /// (e.g. `q`, `type`, `id`) through `--colormap`.
    #[arg(long, default_value = "element")]
    pub color: String,
    /// Colormap for `--color COLUMN`: viridis or gray.
    #[arg(long, default_value = "viridis")]
    pub colormap: String,
}

/// Volume options (the density grid).
#[derive(Args, Debug, Clone)]
pub struct VolumeArgs {
    /// Density grid resolution (voxels per Å; the paper uses 4, and 1 for sio2 and anp3).
    #[arg(long, default_value_t = 4.0)]
    pub voxels_per_angstrom: f32,
    /// Voxel storage: u8 (quantised, one global scale) or f32.
    #[arg(long, default_value = "u8")]
    pub volume_format: String,
}

impl GeometryArgs {
    /// The model settings of the flags (`wide_bvh` off: the caller knows the traversal).
    pub fn settings(&self) -> anyhow::Result<ModelSettings> {
        let color = if self.color == "element" {
            ColorBy::Element
        } else {
            ColorBy::Column {
                name: self.color.clone(),
                colormap: match self.colormap.as_str() {
                    "viridis" => Colormap::Viridis,
                    "gray" | "grey" => Colormap::Gray,
                    other => anyhow::bail!("--colormap {other}: expected viridis or gray"),
                },
            }
        };
        Ok(ModelSettings {
            style: match self.style {
                StyleArg::BallAndStick => Style::BallAndStick,
                StyleArg::Licorice => Style::Licorice,
                StyleArg::Spheres => Style::Spheres,
            },
            radius: match self.radius {
                RadiusKind::Covalent => scene::RadiusKind::Covalent,
                RadiusKind::Vdw => scene::RadiusKind::Vdw,
            },
            radius_scale: self.radius_scale,
            stick_radius: self.stick_radius,
            color,
            wide_bvh: false,
        })
    }
}

impl VolumeArgs {
    /// The volume settings of the flags (default transfer function, no light volume).
    pub fn settings(&self) -> anyhow::Result<VolumeSettings> {
        let format: VolumeFormat = self
            .volume_format
            .parse()
            .map_err(|e| anyhow::anyhow!("--volume-format: {e}"))?;
        Ok(VolumeSettings {
            voxels_per_angstrom: self.voxels_per_angstrom,
            format,
            ..VolumeSettings::default()
        })
    }
}

/// The ball-and-stick scene of a molecule and its build time (s) (for `bench`).
pub fn build_scene(
    m: &Molecule,
    bonds: &[[u32; 2]],
    g: &GeometryArgs,
) -> anyhow::Result<(Model, f64)> {
    let t = Instant::now();
    let model = g.settings()?.build_model(m, bonds)?;
    Ok((model, t.elapsed().as_secs_f64()))
}

/// The density volume of a molecule with its macrocells, and the build time (s) (for `bench`).
pub fn build_volume(
    isa: Isa,
    m: &Molecule,
    v: &VolumeArgs,
) -> anyhow::Result<(Volume, Macrocells, f64)> {
    let t = Instant::now();
    let (vol, cells) = v.settings()?.build_density(isa, m)?;
    Ok((vol, cells, t.elapsed().as_secs_f64()))
}
