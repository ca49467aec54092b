//! From a loaded molecule to what the renderer needs: the ball-and-stick scene (geometry +
//! BVH) and the density volume (grid + macrocells). Shared by `render` and `bench`, so both
//! measure the same preprocessing (paper §4.1 steps 3-5).

use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use molecule::elements;
use molecule::Molecule;
use render::{Coloring, Colormap, Model, ModelOptions, Style};
use spmd::Isa;
use volume::{build_density, DensityParams, Macrocells, Volume, VolumeFormat};

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

/// Packs a colour as the framebuffer stores it.
fn pack([r, g, b]: [u8; 3]) -> u32 {
    render::rgba(r, g, b, 255)
}

/// The ball-and-stick scene of a molecule and its build time (s).
pub fn build_scene(
    m: &Molecule,
    bonds: &[[u32; 2]],
    g: &GeometryArgs,
) -> anyhow::Result<(Model, f64)> {
    let t = Instant::now();
    let radius: Vec<f32> = m
        .elements
        .iter()
        .map(|&z| {
            let e = elements::element(z);
            match g.radius {
                RadiusKind::Covalent => e.covalent_radius,
                RadiusKind::Vdw => e.vdw_radius,
            }
        })
        .collect();
    let colors: Vec<u32> = m
        .elements
        .iter()
        .map(|&z| pack(elements::element(z).color))
        .collect();
    let coloring = if g.color == "element" {
        Coloring::PerAtom
    } else {
        let values = m.scalar(&g.color).with_context(|| {
            let names: Vec<&str> = m.scalars.iter().map(|(n, _)| n.as_str()).collect();
            format!(
                "--color {}: the input has no such per-atom column (it has: element{}{})",
                g.color,
                if names.is_empty() { "" } else { ", " },
                names.join(", ")
            )
        })?;
        let colormap = match g.colormap.as_str() {
            "viridis" => Colormap::Viridis,
            "gray" | "grey" => Colormap::Gray,
            other => anyhow::bail!("--colormap {other}: expected viridis or gray"),
        };
        Coloring::Scalar {
            values: values.to_vec(),
            colormap,
            range: None,
        }
    };
    if !(g.radius_scale > 0.0 && g.radius_scale.is_finite()) {
        anyhow::bail!(
            "--radius-scale must be a positive number, got {}",
            g.radius_scale
        );
    }
    if !(g.stick_radius > 0.0 && g.stick_radius.is_finite()) {
        anyhow::bail!(
            "--stick-radius must be a positive number of Å, got {}",
            g.stick_radius
        );
    }
    let opt = ModelOptions {
        radius_scale: g.radius_scale,
        stick_radius: g.stick_radius,
        style: match g.style {
            StyleArg::BallAndStick => Style::BallAndStick,
            StyleArg::Licorice => Style::Licorice,
            StyleArg::Spheres => Style::Spheres,
        },
        coloring,
    };
    let scene = Model::new(&m.x, &m.y, &m.z, &radius, &colors, bonds, &opt);
    Ok((scene, t.elapsed().as_secs_f64()))
}

/// The density volume of a molecule with its macrocells, and the build time (s).
pub fn build_volume(
    isa: Isa,
    m: &Molecule,
    v: &VolumeArgs,
) -> anyhow::Result<(Volume, Macrocells, f64)> {
    let t = Instant::now();
    let format: VolumeFormat = v
        .volume_format
        .parse()
        .map_err(|e| anyhow::anyhow!("--volume-format: {e}"))?;
    let r: Vec<f32> = m
        .elements
        .iter()
        .map(|&z| elements::element(z).covalent_radius)
        .collect();
    let params = DensityParams {
        voxels_per_angstrom: v.voxels_per_angstrom,
        format,
        budget_bytes: None,
    };
    let vol =
        build_density(isa, &m.x, &m.y, &m.z, &r, &params).context("building the density volume")?;
    let cells = Macrocells::build(&vol);
    Ok((vol, cells, t.elapsed().as_secs_f64()))
}

/// Bounding sphere of the atom centres (centre of the bounding box, Å) grown by `pad` Å.
pub fn bounding_sphere(m: &Molecule, pad: f32) -> ([f32; 3], f32) {
    let (lo, hi) = m.bounds();
    let c = [
        (lo[0] + hi[0]) * 0.5,
        (lo[1] + hi[1]) * 0.5,
        (lo[2] + hi[2]) * 0.5,
    ];
    let r2 = (0..m.len())
        .map(|i| (m.x[i] - c[0]).powi(2) + (m.y[i] - c[1]).powi(2) + (m.z[i] - c[2]).powi(2))
        .fold(0.0f32, f32::max);
    (c, r2.sqrt() + pad)
}
