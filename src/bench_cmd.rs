//! `bnsview bench`: its flags, turned into the [`bnsbench::Config`] of a run (the benchmark
//! itself is the `bnsbench` crate, which renders each mode as `render` renders it: the
//! tests below check that flag for flag).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use molecule::scenes::SceneName;
use spmd::Isa;

use bnsbench::{expand_modes, Config, ModeSel, PlanSpec, TableSel, ViewSel};

use crate::pipeline::GeometryArgs;
use scene::text::{parse_side, parse_size};

/// Arguments of `bnsview bench`. The ISA comes from the global `--isa` (`all` = every
/// backend this CPU supports).
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Which of the paper's tables to reproduce.
    #[arg(long, value_enum, default_value_t = TableSel::All)]
    pub table: TableSel,
    /// Scenes (comma separated; default all five). Tables 1 and 2 use ns740k; with `--table 1`
    /// or `--table 2` and no ns740k among the scenes they use the scenes given.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Option<Vec<SceneName>>,
    /// Modes of Table 3 (comma separated; default bs,volume,vol+bs,vol+bs-lit, with --quick
    /// also bs-shadows,bs-ao). `all` is every mode, `modalities` is
    /// bs-shadows,bs-ao,path,volume-lit,vol+bs-lit. The modalities render one sample per pixel
    /// per frame, as `bnsview render` with the default light, AO distance and material.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub modes: Option<Vec<ModeSel>>,
    /// Views of Table 3 (comma separated; default far,close).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub views: Option<Vec<ViewSel>>,
    /// Frame size of Tables 2 and 3, WIDTHxHEIGHT (default 1024x1024 as in the paper, with
    /// --quick 512x512).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Frame sizes of Table 1 (comma separated, N for N×N or WxH; default 256 … 4096, with
    /// --quick 256 and 512).
    #[arg(long, value_delimiter = ',', value_parser = parse_side)]
    pub sizes: Option<Vec<(u32, u32)>>,
    /// Thread counts (comma separated). Table 2 default: 1 … nproc; Tables 1 and 3 default:
    /// nproc.
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<Vec<u32>>,
    /// Timed frames per measurement, after the warm-up (default 10, with --quick 3).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Warm-up frames before timing.
    #[arg(long, default_value_t = 1)]
    pub warmup: usize,
    /// Small scenes (nanobowl and ns90k full, the others 100K atoms), 512² frames (Table 1:
    /// 256² and 512²), 3 frames after the warm-up, the paper's modes and bs-shadows, bs-ao: a
    /// run of a few minutes (`--quick --modes all` adds path tracing and the other modes).
    #[arg(long)]
    pub quick: bool,
    /// Atoms per scene (overrides the paper's count and --quick).
    #[arg(long)]
    pub atoms: Option<usize>,
    /// Model random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Transfer function of the volume modes (preset or control-point file).
    #[arg(long, default_value = "coolwarm")]
    pub tf: String,
    /// Density grid resolution (voxels per Å) for every scene, instead of the paper's (4, and 1
    /// for sio2 and anp3).
    #[arg(long)]
    pub voxels_per_angstrom: Option<f32>,
    /// March every cell (no macrocell skipping), to measure what skipping buys.
    #[arg(long)]
    pub no_macrocells: bool,
    #[command(flatten)]
    pub geometry: GeometryArgs,
    /// Write every measurement to this JSON file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Overwrite the JSON file if it exists.
    #[arg(short, long)]
    pub force: bool,
    /// Measure nothing: print the tables of earlier runs from their JSON files (repeat the
    /// flag to merge runs; a later file's record of the same measurement wins).
    #[arg(long, value_name = "FILE", conflicts_with = "json")]
    pub report: Vec<PathBuf>,
}

impl BenchArgs {
    /// The run these flags ask for.
    pub fn config(&self) -> Result<Config> {
        Ok(Config {
            spec: PlanSpec {
                table: self.table,
                scenes: self.scenes.clone(),
                modes: self.modes.as_deref().map(expand_modes),
                views: self.views.clone(),
                size: self.size,
                sizes: self.sizes.clone(),
                threads: self.threads.clone(),
                quick: self.quick,
                atoms: self.atoms,
            },
            seed: self.seed,
            model: self.geometry.settings()?,
            tf: volume::TransferFunction::from_spec(&self.tf)?,
            frames: self.frames,
            warmup: self.warmup,
            voxels_per_angstrom: self.voxels_per_angstrom,
            no_macrocells: self.no_macrocells,
            json: self.json.clone(),
            force: self.force,
            command: std::env::args().collect::<Vec<_>>().join(" "),
            version: env!("CARGO_PKG_VERSION").into(),
        })
    }
}

/// Run `bnsview bench` on the backends `isas`.
pub fn run(a: BenchArgs, isas: Vec<Isa>) -> Result<()> {
    if !a.report.is_empty() {
        return Ok(bnsbench::run_report(&a.report)?);
    }
    Ok(bnsbench::run(&a.config()?, &isas)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bnsbench::{plan, BenchMode};

    fn args(extra: &[&str]) -> BenchArgs {
        use clap::Parser;
        #[derive(Parser)]
        struct P {
            #[command(flatten)]
            b: BenchArgs,
        }
        let mut v = vec!["bench"];
        v.extend_from_slice(extra);
        P::parse_from(v).b
    }

    #[test]
    fn flags_become_the_plan() {
        let p = plan(
            &args(&["--scenes", "nanobowl", "--size", "64x64"])
                .config()
                .unwrap()
                .spec,
            2,
        );
        assert_eq!(p.len(), 8);
        let c = args(&[
            "--scenes", "nanobowl", "--table", "1", "--sizes", "32,64x48",
        ])
        .config()
        .unwrap();
        let p = plan(&c.spec, 2);
        assert_eq!(p.len(), 2);
        assert_eq!((p[1].0.w, p[1].0.h), (64, 48));
        let c = args(&["--views", "close", "--threads", "3", "--quick"])
            .config()
            .unwrap();
        assert_eq!(c.spec.views, Some(vec![ViewSel::Close]));
        assert_eq!(c.spec.threads, Some(vec![3]));
        assert!(c.spec.quick);
        assert_eq!(c.frames, None);
    }

    #[test]
    fn mode_flags_name_the_modes_and_sets() {
        // The order of a set's expansion is bnsbench's (mode.rs tests it); here the flags.
        let modes = |a: &str| args(&["--modes", a]).config().unwrap().spec.modes.unwrap();
        assert_eq!(modes("modalities"), BenchMode::MODALITIES);
        assert_eq!(modes("all"), BenchMode::ALL);
        for mode in BenchMode::ALL {
            assert_eq!(modes(mode.name()), [mode]);
        }
    }

    /// The `bnsview render` flags of each bench mode's picture, one sample per pixel.
    fn render_flags(mode: BenchMode) -> &'static [&'static str] {
        match mode {
            BenchMode::Bs => &[],
            BenchMode::Volume => &["--mode", "volume"],
            BenchMode::VolBs => &["--mode", "vol+bs"],
            BenchMode::VolBsLit => &["--mode", "vol+bs", "--lit"],
            BenchMode::VolumeLit => &["--mode", "volume", "--lit"],
            BenchMode::BsShadows => &["--shadows"],
            BenchMode::BsAo => &["--ao", "1"],
            BenchMode::Path => &["--mode", "path", "--material", "metal", "--spp", "1"],
            BenchMode::VolBsShadows => &["--mode", "vol+bs", "--shadows", "--volume-shadows"],
            BenchMode::VolumeShadows => &["--mode", "volume", "--volume-shadows"],
            BenchMode::VolumeLitShadows => &["--mode", "volume", "--lit", "--volume-shadows"],
        }
    }

    #[test]
    fn every_bench_mode_renders_what_its_render_flags_render() {
        use clap::Parser;
        #[derive(Parser)]
        struct R {
            #[command(flatten)]
            r: crate::look::LookArgs,
        }
        for m in BenchMode::ALL {
            let argv = std::iter::once("render").chain(render_flags(m).iter().copied());
            let a = R::parse_from(argv).r;
            let (look, bench) = (a.look(false).unwrap(), m.look());
            look.validate().unwrap();
            assert_eq!(look.render_settings(), bench.render_settings(), "{m:?}");
            // What is built (the transfer function's table is long: no Debug dump).
            let built = |l: &render::Look| l.scene_settings(Default::default(), (64, 64));
            assert!(built(&look) == built(&bench), "{m:?}");
        }
    }

    #[test]
    fn an_unknown_mode_is_refused_with_the_choices() {
        use clap::Parser;
        #[derive(Parser, Debug)]
        struct P {
            #[command(flatten)]
            b: BenchArgs,
        }
        let e = P::try_parse_from(["bench", "--modes", "bs,shadows"]).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("shadows"), "{msg}");
        for name in ["bs-shadows", "path", "all", "modalities"] {
            assert!(msg.contains(name), "{msg}");
        }
    }
}
