//! The clap flags of the scene (geometry, volume) and their mapping onto the typed
//! [`scene::SceneSettings`]; the building itself is `scene::Scene::build`.

use clap::Args;
use render::{Colormap, Style};
use scene::text::parse_range;
use scene::{ColorBy, DensitySource, ModelSettings, RadiusKind, VolumeSettings};
use volume::VolumeFormat;

/// Geometry options of the ball-and-stick scene.
#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Style and colour")]
pub struct GeometryArgs {
    /// Drawing style.
    #[arg(long, value_enum, default_value_t = Style::BallAndStick)]
    pub style: Style,
    /// Radius used for the balls.
    #[arg(long, value_enum, default_value_t = RadiusKind::Covalent)]
    pub radius: RadiusKind,
    /// Ball radius = element radius × this (above 0, up to 1000).
    #[arg(long, default_value_t = 0.5)]
    pub radius_scale: f32,
    /// Stick radius (Å, above 0, up to 1000).
    #[arg(long, default_value_t = 0.15)]
    pub stick_radius: f32,
    /// Colour atoms by `element` (CPK/Jmol colours) or by a per-atom column of the input
    /// (e.g. `q`, `type`, `id`) through `--colormap`.
    #[arg(long, default_value = "element")]
    pub color: String,
    /// Colormap for `--color COLUMN`.
    #[arg(long, value_enum, default_value_t = Colormap::Viridis)]
    pub colormap: Colormap,
    /// Values mapped to the colormap's ends for `--color COLUMN`, `LO:HI` (default: the
    /// column's range in the frame, printed by -v).
    #[arg(long, value_name = "LO:HI", value_parser = parse_range, allow_hyphen_values = true)]
    pub color_range: Option<(f32, f32)>,
    /// Draw a colour legend (the colormap, its range and the column) at the right edge of
    /// the image, for `--color COLUMN`.
    #[arg(long)]
    pub legend: bool,
    /// Draw the simulation cell (box) of the input as thin grey sticks.
    #[arg(long)]
    pub cell: bool,
}

/// Volume options (the density grid).
#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Volume")]
pub struct VolumeArgs {
    /// Where the RBF density comes from: grid (sampled once, interpolated; memory grows with
    /// the voxels) or particles (summed from the atoms at every sample through a BVH; exact,
    /// memory grows with the atoms, no --volume-shadows).
    #[arg(long = "volume", value_enum, default_value = "grid")]
    pub source: DensitySource,
    /// Density grid resolution (voxels per Å; the paper uses 4, and 1 for sio2 and anp3).
    /// The step is half a voxel, with --volume particles too.
    #[arg(long, default_value_t = 4.0)]
    pub voxels_per_angstrom: f32,
    /// Voxel storage: u8 (quantised, one global scale) or f32.
    #[arg(long, default_value = "u8")]
    pub volume_format: String,
    /// Density mapped to the top of the transfer function (default: the frame's maximum,
    /// printed by -v with --frames).
    #[arg(long)]
    pub density_max: Option<f32>,
}

impl GeometryArgs {
    /// The model settings of the flags (`wide_bvh` off: the caller knows the traversal).
    pub fn settings(&self) -> anyhow::Result<ModelSettings> {
        if self.color == "element" && (self.color_range.is_some() || self.legend) {
            anyhow::bail!(
                "--color-range and --legend belong to colouring by a column: add --color COLUMN (e.g. --color q)"
            );
        }
        let color = if self.color == "element" {
            ColorBy::Element
        } else {
            ColorBy::Column {
                name: self.color.clone(),
                colormap: self.colormap,
                range: self.color_range,
            }
        };
        Ok(ModelSettings {
            style: self.style,
            radius: self.radius,
            radius_scale: self.radius_scale,
            stick_radius: self.stick_radius,
            color,
            wide_bvh: false,
            periodic_bonds: false,
            draw_cell: self.cell,
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
            source: self.source,
            voxels_per_angstrom: self.voxels_per_angstrom,
            format,
            density_max: self.density_max,
            ..VolumeSettings::default()
        })
    }
}
