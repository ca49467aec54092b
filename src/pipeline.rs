//! The clap flags of the scene (geometry, volume) and their mapping onto the typed
//! [`scene::SceneSettings`]; the building itself is `scene::Scene::build`.

use clap::Args;
use render::{Colormap, Style};
use scene::{ColorBy, ModelSettings, RadiusKind, VolumeSettings};
use volume::VolumeFormat;

/// Geometry options of the ball-and-stick scene.
#[derive(Args, Debug, Clone)]
pub struct GeometryArgs {
    /// Drawing style.
    #[arg(long, value_enum, default_value_t = Style::BallAndStick)]
    pub style: Style,
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
    /// Colormap for `--color COLUMN`.
    #[arg(long, value_enum, default_value_t = Colormap::Viridis)]
    pub colormap: Colormap,
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
                colormap: self.colormap,
            }
        };
        Ok(ModelSettings {
            style: self.style,
            radius: self.radius,
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
