//! The seam of `bnsview bench` ([`bnsbench::Pipeline`]): scenes built and frames set up by
//! the same functions and flags as `bnsview render`, so the benchmark times its pictures.
//! (Today the modes' settings are `render` flag strings parsed by clap; a typed
//! settings API of the render crate replaces them.)

use anyhow::Context;
use bnsbench::{BenchMode, FrameSetup, Loaded, Pipeline, PipelineError};
use molecule::scenes::SceneName;
use molecule::Molecule;
use render::{Model, RenderOptions};
use spmd::Isa;
use volume::{LightVolume, Macrocells, MarchOptions, TransferFunction, Volume, VolumeScene};

use crate::bench_cmd::BenchArgs;
use crate::input::{BondSource, InputArgs};
use crate::pipeline::{build_scene, build_volume, GeometryArgs, VolumeArgs};
use crate::render_cmd::{self, load_tf};

/// `bnsview bench`'s pipeline: its seed, geometry flags and transfer function.
pub struct CliPipeline<'a> {
    args: &'a BenchArgs,
}

impl<'a> CliPipeline<'a> {
    /// The pipeline of these flags.
    pub fn new(args: &'a BenchArgs) -> Self {
        CliPipeline { args }
    }
}

/// The `bnsview render` flags that set the volume's marcher options (lighting and
/// volumetric shadows) for the volume modes.
fn volume_flags(mode: BenchMode) -> &'static [&'static str] {
    match mode {
        BenchMode::VolBsLit => &["--mode", "vol+bs", "--lit"],
        BenchMode::VolumeLit => &["--mode", "volume", "--lit"],
        BenchMode::VolBsShadows => &["--mode", "vol+bs", "--shadows", "--volume-shadows"],
        BenchMode::VolumeShadows => &["--mode", "volume", "--volume-shadows"],
        BenchMode::VolumeLitShadows => &["--mode", "volume", "--lit", "--volume-shadows"],
        _ => &[],
    }
}

/// The `bnsview render` flags whose frame a modality mode times (`None`: the mode renders
/// through `render_frame_into`, as `bnsview render` does without modality flags). One
/// sample per pixel: `--ao 1`, `--spp 1`.
fn render_flags(mode: BenchMode) -> Option<&'static [&'static str]> {
    match mode {
        BenchMode::BsShadows => Some(&["--shadows"]),
        BenchMode::BsAo => Some(&["--ao", "1"]),
        BenchMode::Path => Some(&["--mode", "path", "--material", "metal", "--spp", "1"]),
        BenchMode::VolBsShadows => Some(&["--mode", "vol+bs", "--shadows", "--volume-shadows"]),
        _ => None,
    }
}

impl Pipeline for CliPipeline<'_> {
    fn load(&self, scene: SceneName, atoms: usize) -> Result<Loaded, PipelineError> {
        let input = InputArgs {
            file: None,
            scene: Some(scene),
            atoms: Some(atoms),
            seed: self.args.seed,
            format: None,
            types: None,
            atom_style: None,
            frame: 0,
            bonds: BondSource::Auto,
            bond_factor: 1.15,
            bond_cutoff: None,
            pair_cutoffs: None,
            pbc: false,
        };
        let l = input.load(false)?;
        Ok(Loaded {
            molecule: l.molecule,
            bonds: l.bonds,
            load_s: l.load_s,
            bond_s: l.bond_s,
        })
    }

    fn model(&self, m: &Molecule, bonds: &[[u32; 2]]) -> Result<Model, PipelineError> {
        Ok(build_scene(m, bonds, &self.args.geometry)?.0)
    }

    fn sphere(&self, m: &Molecule) -> ([f32; 3], f32) {
        atoms_sphere(m, &self.args.geometry)
    }

    fn volume(
        &self,
        isa: Isa,
        m: &Molecule,
        voxels_per_angstrom: f32,
    ) -> Result<(Volume, Macrocells, f64), PipelineError> {
        let args = VolumeArgs {
            voxels_per_angstrom,
            volume_format: "u8".into(),
        };
        Ok(build_volume(isa, m, &args)?)
    }

    fn transfer_function(&self) -> Result<TransferFunction, PipelineError> {
        Ok(load_tf(&self.args.tf)?)
    }

    fn march_options(&self, mode: BenchMode) -> Result<MarchOptions, PipelineError> {
        let args = render_cmd::parse_render_flags(volume_flags(mode))?;
        Ok(render_cmd::march_options(&args))
    }

    fn frame_setup(&self, mode: BenchMode) -> Result<FrameSetup, PipelineError> {
        Ok(frame_setup(mode)?)
    }

    fn light_volume(
        &self,
        vs: &VolumeScene,
        isa: Isa,
        log: &dyn Fn(String),
    ) -> Option<LightVolume> {
        render_cmd::build_light_volume(vs, isa, log)
    }
}

/// How `bnsview render` renders a mode's frame.
fn frame_setup(mode: BenchMode) -> anyhow::Result<FrameSetup> {
    let Some(flags) = render_flags(mode) else {
        return Ok(FrameSetup::Frame(RenderOptions::default()));
    };
    let args = render_cmd::parse_render_flags(flags)?;
    render_cmd::check_modalities(&args)?;
    let modality = render_cmd::modality(&args)
        .with_context(|| format!("render flags {flags:?} select no modality"))?;
    Ok(FrameSetup::Modal {
        opt: render_cmd::trace_options(&args, modality),
        spp: render_cmd::samples_per_pixel(&args),
    })
}

/// Bounding sphere of the balls, as [`Model::new`] computes it (centre of the box, radius to
/// the farthest ball surface), for runs that build no BVH.
pub fn atoms_sphere(m: &molecule::Molecule, g: &GeometryArgs) -> ([f32; 3], f32) {
    if m.is_empty() {
        return ([0.0; 3], 1.0);
    }
    let r: Vec<f32> = m
        .elements
        .iter()
        .map(|&z| {
            let e = molecule::elements::element(z);
            let base = match g.radius {
                crate::pipeline::RadiusKind::Covalent => e.covalent_radius,
                crate::pipeline::RadiusKind::Vdw => e.vdw_radius,
            };
            (base * g.radius_scale).max(g.stick_radius)
        })
        .collect();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (i, &ri) in r.iter().enumerate() {
        for (k, c) in [m.x[i], m.y[i], m.z[i]].into_iter().enumerate() {
            lo[k] = lo[k].min(c - ri);
            hi[k] = hi[k].max(c + ri);
        }
    }
    let c = [
        (lo[0] + hi[0]) * 0.5,
        (lo[1] + hi[1]) * 0.5,
        (lo[2] + hi[2]) * 0.5,
    ];
    let rad = (0..m.len())
        .map(|i| {
            let d = [
                (m.x[i] - c[0]) as f64,
                (m.y[i] - c[1]) as f64,
                (m.z[i] - c[2]) as f64,
            ];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() + r[i] as f64
        })
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max) as f32;
    (c, rad.max(1e-3))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry_defaults() -> GeometryArgs {
        use clap::Parser;
        #[derive(Parser)]
        struct P {
            #[command(flatten)]
            g: GeometryArgs,
        }
        P::parse_from(["bench"]).g
    }

    #[test]
    fn volume_only_runs_see_the_same_frame_as_geometry_runs() {
        // The camera of a volume-only run (no BVH) is fitted to the same sphere as Model's.
        let m = molecule::scenes::generate(SceneName::Ns90k, Some(3000), 7);
        let bonds = molecule::bonds::build_bonds(&m, &Default::default());
        let g = geometry_defaults();
        let (scene, _) = build_scene(&m, &bonds, &g).unwrap();
        let (c, r) = atoms_sphere(&m, &g);
        for k in 0..3 {
            assert!(
                (c[k] - scene.center[k]).abs() < 1e-3 * scene.radius,
                "{c:?} {:?}",
                scene.center
            );
        }
        assert!(
            (r - scene.radius).abs() < 1e-3 * scene.radius,
            "{r} {}",
            scene.radius
        );
    }

    #[test]
    fn modality_modes_are_the_render_commands_with_one_sample() {
        use render::{Material, Modality};
        let opts = |m: BenchMode| {
            let a = render_cmd::parse_render_flags(render_flags(m).unwrap()).unwrap();
            render_cmd::check_modalities(&a).unwrap();
            let modality = render_cmd::modality(&a).unwrap();
            (
                render_cmd::trace_options(&a, modality),
                render_cmd::samples_per_pixel(&a),
            )
        };
        let (o, spp) = opts(BenchMode::BsShadows);
        assert_eq!(o.modality, Modality::Direct { shadows: true });
        assert!(!o.volume_shadows);
        assert_eq!(spp, 1);
        let (o, spp) = opts(BenchMode::BsAo);
        assert!(
            matches!(o.modality, Modality::Ao { samples: 1, distance } if distance > 0.0),
            "{o:?}"
        );
        assert_eq!(Some(spp), BenchMode::BsAo.samples_per_pixel());
        let (o, spp) = opts(BenchMode::Path);
        assert!(
            matches!(
                o.modality,
                Modality::Path {
                    material: Material::Metal,
                    ..
                }
            ),
            "{o:?}"
        );
        assert_eq!(Some(spp), BenchMode::Path.samples_per_pixel());
        let (o, _) = opts(BenchMode::VolBsShadows);
        assert_eq!(o.modality, Modality::Direct { shadows: true });
        assert!(o.volume_shadows);
        assert!(BenchMode::VolBsShadows.volume());
        // The volume modes' marcher options: lighting and volumetric shadows as rendered.
        let march = |m: BenchMode| {
            render_cmd::march_options(&render_cmd::parse_render_flags(volume_flags(m)).unwrap())
        };
        let dir = volume::Light::Directional([1.0, 2.0, 1.5]);
        assert_eq!(march(BenchMode::Volume), volume::MarchOptions::default());
        assert_eq!(
            march(BenchMode::VolumeLit).lighting,
            volume::Lighting::Headlight
        );
        let vs = march(BenchMode::VolumeShadows);
        assert_eq!(vs.lighting, volume::Lighting::Unlit);
        assert_eq!(vs.shadows.map(|s| s.light), Some(dir));
        let vls = march(BenchMode::VolumeLitShadows);
        assert_eq!(vls.lighting, volume::Lighting::Directional([1.0, 2.0, 1.5]));
        assert_eq!(vls.shadows.map(|s| s.light), Some(dir));
        assert!(march(BenchMode::VolBsShadows).shadows.is_some());
        for m in [BenchMode::BsShadows, BenchMode::BsAo, BenchMode::Path] {
            assert!(m.geometry() && !m.volume(), "{m:?}");
        }
        // The same seed, light and defaults as `bnsview render` with no flags.
        let plain = render_cmd::parse_render_flags(&[]).unwrap();
        let shadows = opts(BenchMode::BsShadows).0;
        assert_eq!(
            shadows,
            render_cmd::trace_options(&plain, Modality::Direct { shadows: true })
        );
    }

    #[test]
    fn frame_setups_are_the_render_flags() {
        for m in BenchMode::ALL {
            match (frame_setup(m).unwrap(), render_flags(m)) {
                (FrameSetup::Frame(o), None) => {
                    assert_eq!(format!("{o:?}"), format!("{:?}", RenderOptions::default()))
                }
                (FrameSetup::Modal { opt, spp }, Some(f)) => {
                    let a = render_cmd::parse_render_flags(f).unwrap();
                    let modality = render_cmd::modality(&a).unwrap();
                    assert_eq!(opt, render_cmd::trace_options(&a, modality));
                    assert_eq!(spp, render_cmd::samples_per_pixel(&a));
                    assert!(m.geometry(), "{m:?}");
                }
                (s, f) => panic!("{m:?}: {s:?} from {f:?}"),
            }
        }
    }
}
