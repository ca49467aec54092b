//! `bnsview bench`: reproduces the paper's results (§5, Tables 1-3) on this machine.
//!
//! Per scene: preprocess once (generate, bonds, BVH, density volume at the paper's
//! resolution), then for every mode × view × size × thread count × ISA of the plan render a
//! warm-up frame and N timed frames. Prints markdown tables with the paper's figures beside
//! ours (whole machine and per core) and optionally writes every measurement as JSON.

use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use molecule::scenes::SceneName;
use render::{
    render_frame_into, render_modal_into, Accum, Camera, Framebuffer, Model, RenderOptions,
    TraceOptions, View,
};
use serde_json::{json, Value};
use spmd::Isa;
use volume::{ClassifiedTf, Macrocells, MarchOptions, Volume, VolumeScene};

use crate::input::{BondSource, InputArgs};
use crate::pipeline::{build_scene, build_volume, GeometryArgs, VolumeArgs};
use crate::render_cmd::{self, load_tf, parse_size, ViewArg};

/// What a benchmark frame shows: the rows of the paper's Table 3, lit volume alone, and the
/// ray tracing modalities of §4.5 / Figure 4 (one sample per pixel per frame).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum BenchMode {
    /// Ball-and-stick, headlight diffuse shading ("b&s").
    Bs,
    /// Unlit volume rendering alone ("volume").
    Volume,
    /// Ball-and-stick, then the unlit volume in front of it ("vol+b&s").
    #[value(name = "vol+bs")]
    VolBs,
    /// As vol+bs with gradient lighting of the volume ("vol+b&s, lit").
    #[value(name = "vol+bs-lit")]
    VolBsLit,
    /// Volume alone with gradient lighting (not a row of Table 3).
    #[value(name = "volume-lit")]
    VolumeLit,
    /// Ball-and-stick, diffuse light with hard shadows (`bnsview render --shadows`).
    #[value(name = "bs-shadows")]
    BsShadows,
    /// Ball-and-stick, ambient occlusion with 1 ray per pixel (fps per AO sample; `--ao N`
    /// costs about N times as much).
    #[value(name = "bs-ao")]
    BsAo,
    /// Ball-and-stick path traced, metal BRDF, 1 sample per pixel (fps per spp).
    Path,
    /// vol+bs with hard shadows attenuated by the volume, which also shadows itself
    /// (`--volume-shadows`, §4.5).
    #[value(name = "vol+bs-shadows")]
    VolBsShadows,
    /// Unlit volume alone with volumetric shadows (Figure 4, fourth picture).
    #[value(name = "volume-shadows")]
    VolumeShadows,
    /// Gradient-lit volume alone with volumetric shadows (Figure 4, fifth picture).
    #[value(name = "volume-lit-shadows")]
    VolumeLitShadows,
}

impl BenchMode {
    /// The four rows of the paper's Table 3, the default.
    pub const PAPER: [BenchMode; 4] = [
        BenchMode::Bs,
        BenchMode::Volume,
        BenchMode::VolBs,
        BenchMode::VolBsLit,
    ];

    /// The default of `--quick`: the paper's four and the two cheap modalities (at 512² they
    /// add ~10 s to a ~70 s quick run; path tracing and the lit volume would add ~3 minutes).
    pub const QUICK: [BenchMode; 6] = [
        BenchMode::Bs,
        BenchMode::Volume,
        BenchMode::VolBs,
        BenchMode::VolBsLit,
        BenchMode::BsShadows,
        BenchMode::BsAo,
    ];

    /// The modalities issue 6 asks figures of (`--modes modalities`).
    pub const MODALITIES: [BenchMode; 7] = [
        BenchMode::BsShadows,
        BenchMode::BsAo,
        BenchMode::Path,
        BenchMode::VolumeLit,
        BenchMode::VolBsLit,
        BenchMode::VolumeShadows,
        BenchMode::VolumeLitShadows,
    ];

    /// Name as on the command line and in the JSON.
    pub fn name(self) -> &'static str {
        match self {
            BenchMode::Bs => "bs",
            BenchMode::Volume => "volume",
            BenchMode::VolBs => "vol+bs",
            BenchMode::VolBsLit => "vol+bs-lit",
            BenchMode::VolumeLit => "volume-lit",
            BenchMode::BsShadows => "bs-shadows",
            BenchMode::BsAo => "bs-ao",
            BenchMode::Path => "path",
            BenchMode::VolBsShadows => "vol+bs-shadows",
            BenchMode::VolumeShadows => "volume-shadows",
            BenchMode::VolumeLitShadows => "volume-lit-shadows",
        }
    }
    fn geometry(self) -> bool {
        !matches!(
            self,
            BenchMode::Volume
                | BenchMode::VolumeLit
                | BenchMode::VolumeShadows
                | BenchMode::VolumeLitShadows
        )
    }
    fn volume(self) -> bool {
        matches!(
            self,
            BenchMode::Volume
                | BenchMode::VolBs
                | BenchMode::VolBsLit
                | BenchMode::VolumeLit
                | BenchMode::VolBsShadows
                | BenchMode::VolumeShadows
                | BenchMode::VolumeLitShadows
        )
    }
    /// The `bnsview render` flags that set the volume's marcher options (lighting and
    /// volumetric shadows) for the volume modes.
    fn volume_flags(self) -> &'static [&'static str] {
        match self {
            BenchMode::VolBsLit => &["--mode", "vol+bs", "--lit"],
            BenchMode::VolumeLit => &["--mode", "volume", "--lit"],
            BenchMode::VolBsShadows => &["--mode", "vol+bs", "--shadows", "--volume-shadows"],
            BenchMode::VolumeShadows => &["--mode", "volume", "--volume-shadows"],
            BenchMode::VolumeLitShadows => &["--mode", "volume", "--lit", "--volume-shadows"],
            _ => &[],
        }
    }
    /// Row of the paper's Table 3 (CPU), if this mode is one.
    fn paper_row(self) -> Option<usize> {
        BenchMode::PAPER.iter().position(|&m| m == self)
    }
    /// The `bnsview render` flags whose frame a modality mode times (`None`: the mode renders
    /// through `render_frame_into`, as `bnsview render` does without modality flags). One
    /// sample per pixel: `--ao 1`, `--spp 1`.
    fn render_flags(self) -> Option<&'static [&'static str]> {
        match self {
            BenchMode::BsShadows => Some(&["--shadows"]),
            BenchMode::BsAo => Some(&["--ao", "1"]),
            BenchMode::Path => Some(&["--mode", "path", "--material", "metal", "--spp", "1"]),
            BenchMode::VolBsShadows => Some(&["--mode", "vol+bs", "--shadows", "--volume-shadows"]),
            _ => None,
        }
    }
    /// Random samples per pixel of one frame (AO rays, paths), for the stochastic modes.
    fn samples_per_pixel(self) -> Option<u32> {
        match self {
            BenchMode::BsAo | BenchMode::Path => Some(1),
            _ => None,
        }
    }
}

/// An entry of `--modes`: a mode or a named set of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeSel {
    One(BenchMode),
    /// Every mode.
    All,
    /// [`BenchMode::MODALITIES`].
    Modalities,
}

impl ValueEnum for ModeSel {
    fn value_variants<'a>() -> &'a [Self] {
        static V: std::sync::OnceLock<Vec<ModeSel>> = std::sync::OnceLock::new();
        V.get_or_init(|| {
            BenchMode::value_variants()
                .iter()
                .map(|&m| ModeSel::One(m))
                .chain([ModeSel::All, ModeSel::Modalities])
                .collect()
        })
    }
    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        use clap::builder::PossibleValue;
        match self {
            ModeSel::One(m) => m.to_possible_value(),
            ModeSel::All => Some(PossibleValue::new("all").help("Every mode above.")),
            ModeSel::Modalities => Some(PossibleValue::new("modalities").help(
                "bs-shadows, bs-ao, path, volume-lit, vol+bs-lit, volume-shadows, \
                         volume-lit-shadows (issue 6).",
            )),
        }
    }
}

/// The modes of `--modes` in the order given, sets expanded, each once.
fn expand_modes(sel: &[ModeSel]) -> Vec<BenchMode> {
    let mut out: Vec<BenchMode> = Vec::new();
    for s in sel {
        let modes = match s {
            ModeSel::One(m) => vec![*m],
            ModeSel::All => BenchMode::value_variants().to_vec(),
            ModeSel::Modalities => BenchMode::MODALITIES.to_vec(),
        };
        for m in modes {
            if !out.contains(&m) {
                out.push(m);
            }
        }
    }
    out
}

/// Which of the paper's tables to reproduce.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableSel {
    /// Table 1: ns740k, far, volume, frame buffer 256² … 4096².
    #[value(name = "1")]
    T1,
    /// Table 2: ns740k, far, volume, 1024², threads 1 … nproc.
    #[value(name = "2")]
    T2,
    /// Table 3: scenes × modes × far/close at 1024².
    #[value(name = "3")]
    T3,
    /// All three.
    All,
}

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
    pub views: Option<Vec<ViewArg>>,
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

/// Parses `N` (N×N) or `WxH`.
fn parse_side(s: &str) -> Result<(u32, u32), String> {
    if s.contains(['x', 'X']) {
        return parse_size(s);
    }
    match s.trim().parse::<u32>() {
        Ok(n) if n > 0 => Ok((n, n)),
        _ => Err(format!(
            "{s:?}: expected a positive edge length N or WIDTHxHEIGHT"
        )),
    }
}

// ---------------------------------------------------------------------------------------
// The paper's figures (Knoll, Wald et al., UltraVis 2013, §5): a dual 8-core (16 cores)
// 2.7 GHz Xeon E5-2680 (Sandy Bridge, 8-wide AVX), 1024×1024 unless stated otherwise.

/// Cores of the paper's CPU node.
const PAPER_CORES: f64 = 16.0;

/// Table 3, rows "bnsView (CPU) Intel Xeon E5-2680": fps (far, close) at 1024² for the rows
/// b&s, volume, vol+b&s, vol+b&s lit, per scene.
fn paper_table3(scene: SceneName) -> [[f64; 2]; 4] {
    match scene {
        SceneName::Nanobowl => [[63.0, 55.0], [15.1, 7.94], [22.0, 15.0], [6.15, 4.02]],
        SceneName::Ns90k => [[42.0, 45.0], [8.75, 9.31], [8.6, 10.2], [2.42, 2.97]],
        SceneName::Ns740k => [[39.0, 40.0], [6.82, 7.91], [6.07, 7.85], [1.57, 2.46]],
        SceneName::Sio2 => [[33.0, 45.0], [15.3, 7.67], [13.3, 7.65], [4.51, 2.02]],
        SceneName::Anp3 => [[17.4, 30.0], [1.3, 4.0], [1.31, 6.4], [0.35, 1.91]],
    }
}

/// Table 3, preprocessing rows: (geometry MB, BVH MB, volume MB, voxels/Å, bond build s,
/// BVH build s, volume build s).
fn paper_preprocess(scene: SceneName) -> [f64; 7] {
    match scene {
        SceneName::Nanobowl => [0.7, 0.5, 1.1, 4.0, 0.03, 0.08, 0.6],
        SceneName::Ns90k => [6.0, 4.0, 11.0, 4.0, 0.18, 0.9, 1.1],
        SceneName::Ns740k => [52.0, 34.0, 720.0, 4.0, 2.0, 7.5, 128.0],
        SceneName::Sio2 => [130.0, 160.0, 92.0, 1.0, 10.0, 50.0, 35.0],
        SceneName::Anp3 => [504.0, 430.0, 2012.0, 1.0, 28.0, 128.0, 70.0],
    }
}

/// Table 1, row "bnsView": ns740k far, volume, fps by frame-buffer size in megapixels
/// (256² = .0625 MP … 4096² = 16 MP), 16 cores.
const PAPER_TABLE1: [(f64, f64); 5] = [
    (0.0625, 44.0),
    (0.25, 14.0),
    (1.0, 4.0),
    (4.0, 1.1),
    (16.0, 0.3),
];

/// Table 2, row "bnsView": ns740k far, volume, 1024², fps by number of cores.
const PAPER_TABLE2: [(u32, f64); 5] = [(1, 0.394), (2, 0.779), (4, 1.54), (8, 3.05), (16, 5.93)];

/// The paper's Figure 4 caption (§4.5), whole: "Ray tracing modalities with bnsView. From left
/// to right: ball-and-stick with diffuse illumination and shadows (58 fps on the Xeon Phi),
/// ambient occlusion (1.8 fps), and path traced with a metal BRDF (0.25 fps); unlit volume
/// rendering with volumetric shadows (16 fps), and the same with gradient lighting (3.7 fps)."
/// Measured on the Xeon Phi SE10P (61 cores), not the Table 1-3 CPU; no scene, view, frame
/// size, AO sample count or spp is given. Each figure with the caption's words and our mode of
/// the same modality.
const PAPER_FIGURE4: [(&str, f64, Option<BenchMode>); 5] = [
    (
        "ball-and-stick with diffuse illumination and shadows",
        58.0,
        Some(BenchMode::BsShadows),
    ),
    ("ambient occlusion", 1.8, Some(BenchMode::BsAo)),
    ("path traced with a metal BRDF", 0.25, Some(BenchMode::Path)),
    (
        "unlit volume rendering with volumetric shadows",
        16.0,
        Some(BenchMode::VolumeShadows),
    ),
    (
        "the same with gradient lighting",
        3.7,
        Some(BenchMode::VolumeLitShadows),
    ),
];

/// Density resolution the paper used (Table 3).
fn paper_voxels_per_angstrom(scene: SceneName) -> f32 {
    paper_preprocess(scene)[3] as f32
}

// ---------------------------------------------------------------------------------------
// The plan.

const T1: u8 = 1;
const T2: u8 = 2;
const T3: u8 = 4;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct Key {
    scene: SceneName,
    mode: BenchMode,
    far: bool,
    w: u32,
    h: u32,
    threads: u32,
}

impl Key {
    fn view(&self) -> &'static str {
        if self.far {
            "far"
        } else {
            "close"
        }
    }
}

/// What to measure, in order, and which tables each measurement belongs to.
fn plan(a: &BenchArgs, nproc: u32) -> Vec<(Key, u8)> {
    let scenes: Vec<SceneName> = match &a.scenes {
        Some(s) => SceneName::ALL
            .into_iter()
            .filter(|x| s.contains(x))
            .collect(),
        None => SceneName::ALL.to_vec(),
    };
    let has_740 = scenes.contains(&SceneName::Ns740k);
    let want = |t: TableSel| a.table == t || a.table == TableSel::All;
    let ns740_scenes: Vec<SceneName> = if has_740 {
        vec![SceneName::Ns740k]
    } else if a.table != TableSel::All {
        scenes.clone()
    } else {
        Vec::new()
    };
    let mut out: Vec<(Key, u8)> = Vec::new();
    let mut push = |k: Key, t: u8| match out.iter_mut().find(|(q, _)| *q == k) {
        Some((_, tags)) => *tags |= t,
        None => out.push((k, t)),
    };
    let default_threads = vec![nproc];
    let size = a
        .size
        .unwrap_or(if a.quick { (512, 512) } else { (1024, 1024) });
    if want(TableSel::T3) {
        let modes = match &a.modes {
            Some(sel) => expand_modes(sel),
            None if a.quick => BenchMode::QUICK.to_vec(),
            None => BenchMode::PAPER.to_vec(),
        };
        let views = a
            .views
            .clone()
            .unwrap_or_else(|| vec![ViewArg::Far, ViewArg::Close]);
        let threads = a.threads.clone().unwrap_or_else(|| default_threads.clone());
        for &scene in &scenes {
            for &mode in &modes {
                for v in &views {
                    for &t in &threads {
                        push(
                            Key {
                                scene,
                                mode,
                                far: *v == ViewArg::Far,
                                w: size.0,
                                h: size.1,
                                threads: t,
                            },
                            T3,
                        );
                    }
                }
            }
        }
    }
    if want(TableSel::T1) {
        let sizes = a.sizes.clone().unwrap_or_else(|| {
            let max = if a.quick { 512 } else { 4096 };
            [256, 512, 1024, 2048, 4096]
                .into_iter()
                .filter(|&s| s <= max)
                .map(|s| (s, s))
                .collect()
        });
        let threads = a.threads.clone().unwrap_or_else(|| default_threads.clone());
        for &scene in &ns740_scenes {
            for &(w, h) in &sizes {
                for &t in &threads {
                    push(
                        Key {
                            scene,
                            mode: BenchMode::Volume,
                            far: true,
                            w,
                            h,
                            threads: t,
                        },
                        T1,
                    );
                }
            }
        }
    }
    if want(TableSel::T2) {
        let threads = a.threads.clone().unwrap_or_else(|| (1..=nproc).collect());
        for &scene in &ns740_scenes {
            for &t in &threads {
                push(
                    Key {
                        scene,
                        mode: BenchMode::Volume,
                        far: true,
                        w: size.0,
                        h: size.1,
                        threads: t,
                    },
                    T2,
                );
            }
        }
    }
    // Group by scene (preprocess each once), in the order of SceneName::ALL.
    out.sort_by_key(|(k, _)| sidx(k.scene));
    out
}

/// Position of a scene in [`SceneName::ALL`] (the order of the paper's tables).
fn sidx(s: SceneName) -> usize {
    SceneName::ALL.iter().position(|x| *x == s).unwrap_or(0)
}

/// Atoms of a scene in this run.
fn scene_atoms(a: &BenchArgs, scene: SceneName) -> usize {
    match a.atoms {
        Some(n) => n,
        None if a.quick => scene.default_atoms().min(100_000),
        None => scene.default_atoms(),
    }
}

// ---------------------------------------------------------------------------------------
// Measurements.

struct Measurement {
    key: Key,
    tables: u8,
    atoms: usize,
    isa: Isa,
    ms: Vec<f64>,
    load1: f64,
}

impl Measurement {
    fn sorted(&self) -> Vec<f64> {
        let mut v = self.ms.clone();
        v.sort_by(f64::total_cmp);
        v
    }
    fn ms_median(&self) -> f64 {
        let v = self.sorted();
        let n = v.len();
        if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
    fn fps(&self) -> f64 {
        1000.0 / self.ms_median()
    }
    fn mrays(&self) -> f64 {
        (self.key.w as f64 * self.key.h as f64) / (self.ms_median() * 1e-3) * 1e-6
    }
    fn json(&self) -> Value {
        let v = self.sorted();
        json!({
            "kind": "frame",
            "tables": tables_list(self.tables),
            "scene": self.key.scene.to_string(),
            "atoms": self.atoms,
            "mode": self.key.mode.name(),
            "samples_per_pixel": self.key.mode.samples_per_pixel(),
            "view": self.key.view(),
            "width": self.key.w,
            "height": self.key.h,
            "isa": self.isa.name(),
            "threads": self.key.threads,
            "frames": self.ms.len(),
            "fps_median": self.fps(),
            "ms_median": self.ms_median(),
            "ms_min": v.first().copied().unwrap_or(f64::NAN),
            "ms_max": v.last().copied().unwrap_or(f64::NAN),
            "mrays_per_s": self.mrays(),
            "ms_all": self.ms,
            "load_avg_1min": self.load1,
        })
    }
}

fn tables_list(t: u8) -> Vec<u8> {
    let mut v = Vec::new();
    for (bit, n) in [(T1, 1), (T2, 2), (T3, 3)] {
        if t & bit != 0 {
            v.push(n);
        }
    }
    v
}

struct Preprocess {
    scene: SceneName,
    atoms: usize,
    bonds: usize,
    load_s: f64,
    bond_s: f64,
    bvh_s: Option<f64>,
    volume_s: Option<f64>,
    geometry_bytes: Option<u64>,
    bvh_bytes: Option<u64>,
    volume_bytes: Option<u64>,
    voxels_per_angstrom: f32,
    volume_dims: Option<[usize; 3]>,
    peak_rss_mb: Option<f64>,
    peak_rss_reset: bool,
}

fn mb(b: u64) -> f64 {
    b as f64 / 1e6
}

impl Preprocess {
    fn json(&self) -> Value {
        json!({
            "kind": "preprocess",
            "scene": self.scene.to_string(),
            "atoms": self.atoms,
            "bonds": self.bonds,
            "load_s": self.load_s,
            "bond_s": self.bond_s,
            "bvh_s": self.bvh_s,
            "volume_s": self.volume_s,
            "geometry_mb": self.geometry_bytes.map(mb),
            "bvh_mb": self.bvh_bytes.map(mb),
            "volume_mb": self.volume_bytes.map(mb),
            "bytes_per_atom": self.bytes_per_atom(),
            "voxels_per_angstrom": self.voxels_per_angstrom,
            "volume_dims": self.volume_dims,
            "peak_rss_mb": self.peak_rss_mb,
            "peak_rss_scope": if self.peak_rss_reset { "this scene" } else { "process so far" },
        })
    }
    /// Geometry + BVH bytes per atom.
    fn bytes_per_atom(&self) -> Option<f64> {
        match (self.geometry_bytes, self.bvh_bytes) {
            (Some(g), Some(b)) => Some((g + b) as f64 / self.atoms.max(1) as f64),
            _ => None,
        }
    }
}

/// Bytes of the ball-and-stick geometry (balls, sticks, the kernels' primitive records and
/// per-slot colours) and of the BVH proper (nodes and slot → primitive ids), the split of the
/// paper's "geometry size" and "BVH size".
fn scene_bytes(s: &Model) -> (u64, u64) {
    let b = &s.geometry.balls;
    let geometry = std::mem::size_of_val(&b.x[..])
        + std::mem::size_of_val(&b.y[..])
        + std::mem::size_of_val(&b.z[..])
        + std::mem::size_of_val(&b.radius[..])
        + std::mem::size_of_val(&b.color[..])
        + std::mem::size_of_val(&s.geometry.sticks.a[..])
        + std::mem::size_of_val(&s.geometry.sticks.b[..])
        + std::mem::size_of_val(&s.bvh.records[..])
        + std::mem::size_of_val(&s.slot_color_a[..])
        + std::mem::size_of_val(&s.slot_color_b[..]);
    let bvh = std::mem::size_of_val(&s.bvh.nodes[..]) + std::mem::size_of_val(&s.bvh.prim_ids[..]);
    (geometry as u64, bvh as u64)
}

/// Peak resident set size of this process (VmHWM), in MB.
fn peak_rss_mb() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0 / 1e6)
}

/// Resets VmHWM to the current RSS (Linux ≥ 4.0), so each scene's peak is its own.
fn reset_peak_rss() -> bool {
    std::fs::OpenOptions::new()
        .write(true)
        .open("/proc/self/clear_refs")
        .and_then(|mut f| f.write_all(b"5"))
        .is_ok()
}

/// The 1-, 5- and 15-minute load averages.
fn load_avg() -> [f64; 3] {
    let s = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut it = s.split_whitespace().map(|x| x.parse().unwrap_or(f64::NAN));
    [
        it.next().unwrap_or(f64::NAN),
        it.next().unwrap_or(f64::NAN),
        it.next().unwrap_or(f64::NAN),
    ]
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Bounding sphere of the balls, as [`Model::new`] computes it (centre of the box, radius to
/// the farthest ball surface), for runs that build no BVH.
fn atoms_sphere(m: &molecule::Molecule, g: &GeometryArgs) -> ([f32; 3], f32) {
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

/// The camera of a scene's `far` or `close` view: fitted to the ball-and-stick bounding
/// sphere for every mode, so all modes of a scene see the same frame, as in the paper's
/// Table 3. (`bnsview render --mode volume` without geometry fits the volume box instead,
/// which sits a little farther out.)
fn camera_for(sphere: ([f32; 3], f32), far: bool, w: u32, h: u32) -> Camera {
    let view = if far { View::Far } else { View::Close };
    Camera::view(view, sphere.0, sphere.1, 45.0, w as f32 / h as f32)
}

/// Writes the JSON document (via a temporary file, so a reader never sees half of it).
fn write_json(path: &Path, doc: &Value) -> Result<()> {
    let tmp = path.with_extension("json.tmp");
    let text = serde_json::to_string_pretty(doc)?;
    std::fs::write(&tmp, text + "\n").with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Reads the records of an earlier run.
type Loads = ([f64; 3], [f64; 3]);

fn read_report(path: &Path) -> Result<(Vec<Preprocess>, Vec<Measurement>, Loads, f64)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let doc: Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let bad = |what: &str| anyhow::anyhow!("{}: record without a valid {what}", path.display());
    let mut pre = Vec::new();
    let mut meas = Vec::new();
    for r in doc["records"]
        .as_array()
        .ok_or_else(|| bad("records array"))?
    {
        let scene: SceneName = r["scene"]
            .as_str()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| bad("scene"))?;
        let num = |k: &str| r[k].as_f64();
        let bytes = |k: &str| num(k).map(|v| (v * 1e6).round() as u64);
        match r["kind"].as_str() {
            Some("preprocess") => pre.push(Preprocess {
                scene,
                atoms: num("atoms").ok_or_else(|| bad("atoms"))? as usize,
                bonds: num("bonds").unwrap_or(0.0) as usize,
                load_s: num("load_s").unwrap_or(f64::NAN),
                bond_s: num("bond_s").unwrap_or(f64::NAN),
                bvh_s: num("bvh_s"),
                volume_s: num("volume_s"),
                geometry_bytes: bytes("geometry_mb"),
                bvh_bytes: bytes("bvh_mb"),
                volume_bytes: bytes("volume_mb"),
                voxels_per_angstrom: num("voxels_per_angstrom").unwrap_or(f64::NAN) as f32,
                volume_dims: None,
                peak_rss_mb: num("peak_rss_mb"),
                peak_rss_reset: r["peak_rss_scope"] == "this scene",
            }),
            Some("frame") => {
                let mode = r["mode"]
                    .as_str()
                    .and_then(|m| BenchMode::from_str(m, true).ok())
                    .ok_or_else(|| bad("mode"))?;
                let isa: Isa = r["isa"]
                    .as_str()
                    .and_then(|m| m.parse().ok())
                    .ok_or_else(|| bad("isa"))?;
                let mut tables = 0u8;
                for t in r["tables"].as_array().into_iter().flatten() {
                    tables |= match t.as_u64() {
                        Some(1) => T1,
                        Some(2) => T2,
                        Some(3) => T3,
                        _ => 0,
                    };
                }
                let ms: Vec<f64> = match r["ms_all"].as_array() {
                    Some(v) => v.iter().filter_map(Value::as_f64).collect(),
                    None => vec![num("ms_median").ok_or_else(|| bad("ms_median"))?],
                };
                let key = Key {
                    scene,
                    mode,
                    far: r["view"] == "far",
                    w: num("width").ok_or_else(|| bad("width"))? as u32,
                    h: num("height").ok_or_else(|| bad("height"))? as u32,
                    threads: num("threads").ok_or_else(|| bad("threads"))? as u32,
                };
                meas.push(Measurement {
                    key,
                    tables,
                    atoms: num("atoms").unwrap_or(0.0) as usize,
                    isa,
                    ms,
                    load1: num("load_avg_1min").unwrap_or(f64::NAN),
                });
            }
            _ => return Err(bad("kind")),
        }
    }
    let load =
        |k: &str| -> [f64; 3] { serde_json::from_value(doc[k].clone()).unwrap_or([f64::NAN; 3]) };
    Ok((
        pre,
        meas,
        (load("load_avg_start"), load("load_avg_end")),
        doc["wall_s"].as_f64().unwrap_or(f64::NAN),
    ))
}

/// `bnsview bench --report FILE...`: the tables of earlier runs, merged.
fn run_report(files: &[PathBuf]) -> Result<()> {
    let mut pre: Vec<Preprocess> = Vec::new();
    let mut meas: Vec<Measurement> = Vec::new();
    let mut load = ([f64::NAN; 3], [f64::NAN; 3]);
    let mut wall = 0.0;
    for (i, f) in files.iter().enumerate() {
        let (p, m, l, w) = read_report(f)?;
        if i == 0 {
            load.0 = l.0;
        }
        load.1 = l.1;
        for mut q in p {
            // A later run of the same scene wins, but keeps what only the earlier one built
            // (e.g. a volume-only run has no BVH figures).
            if let Some(i) = pre.iter().position(|x| x.scene == q.scene) {
                let old = pre.remove(i);
                q.bvh_s = q.bvh_s.or(old.bvh_s);
                q.volume_s = q.volume_s.or(old.volume_s);
                q.geometry_bytes = q.geometry_bytes.or(old.geometry_bytes);
                q.bvh_bytes = q.bvh_bytes.or(old.bvh_bytes);
                q.volume_bytes = q.volume_bytes.or(old.volume_bytes);
            }
            pre.push(q);
        }
        for mut q in m {
            // The same measurement in a later file wins and belongs to both files' tables.
            if let Some(i) = meas.iter().position(|x| x.key == q.key && x.isa == q.isa) {
                q.tables |= meas.remove(i).tables;
            }
            meas.push(q);
        }
        wall += w;
    }
    pre.sort_by_key(|p| sidx(p.scene));
    let mut isas: Vec<Isa> = meas.iter().map(|m| m.isa).collect();
    isas.sort();
    isas.dedup();
    let nproc = std::thread::available_parallelism()
        .map(|n| n.get() as u32)
        .unwrap_or(1);
    let mut out = format!(
        "Report of {}",
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    report(&mut out, &pre, &meas, &isas, nproc, load, wall);
    print!("{out}");
    Ok(())
}

/// Run `bnsview bench` on the backends `isas`.
pub fn run(a: BenchArgs, isas: Vec<Isa>) -> Result<()> {
    if !a.report.is_empty() {
        return run_report(&a.report);
    }
    if isas.is_empty() {
        bail!("no ISA to benchmark");
    }
    if let Some(p) = &a.json {
        if p.exists() && !a.force {
            bail!("{} exists; pass --force to overwrite it", p.display());
        }
        if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
            if !dir.is_dir() {
                bail!(
                    "cannot write {}: directory {} does not exist",
                    p.display(),
                    dir.display()
                );
            }
        }
    }
    let frames = a.frames.unwrap_or(if a.quick { 3 } else { 10 });
    if frames == 0 {
        bail!("--frames must be at least 1");
    }
    let nproc = std::thread::available_parallelism()
        .map(|n| n.get() as u32)
        .unwrap_or(1);
    let plan = plan(&a, nproc);
    if plan.is_empty() {
        bail!(
            "nothing to measure: --table {:?} with these --scenes selects no measurement",
            a.table
        );
    }
    let tf = load_tf(&a.tf)?;
    // Frame buffers are allocated per measurement; check the largest fits first.
    for (k, _) in &plan {
        Framebuffer::new(k.w, k.h, 0).with_context(|| format!("a {}x{} frame", k.w, k.h))?;
    }
    let total = plan.len() * isas.len();
    let started = Instant::now();
    let load_start = load_avg();
    let argv: Vec<String> = std::env::args().collect();
    eprintln!(
        "bench: {} measurements ({} ISA{}: {}), {frames} frames after {} warm-up, {} cores, load {:.2}",
        total,
        isas.len(),
        if isas.len() == 1 { "" } else { "s" },
        isas.iter().map(|i| i.name()).collect::<Vec<_>>().join(","),
        a.warmup,
        nproc,
        load_start[0]
    );

    let mut pre: Vec<Preprocess> = Vec::new();
    let mut meas: Vec<Measurement> = Vec::new();
    let mut failures: Vec<String> = Vec::new();
    let mut done = 0usize;
    let mut pools: BTreeMap<u32, rayon::ThreadPool> = BTreeMap::new();

    let doc = |pre: &[Preprocess], meas: &[Measurement], finished: bool| -> Value {
        let mut records: Vec<Value> = pre.iter().map(Preprocess::json).collect();
        records.extend(meas.iter().map(Measurement::json));
        json!({
            "bnsview": env!("CARGO_PKG_VERSION"),
            "command": argv.join(" "),
            "cpu": cpu_model(),
            "cores": nproc,
            "isas": isas.iter().map(|i| i.name()).collect::<Vec<_>>(),
            "load_avg_start": load_start,
            "load_avg_end": load_avg(),
            "wall_s": started.elapsed().as_secs_f64(),
            "finished": finished,
            "records": records,
        })
    };

    let scenes: Vec<SceneName> = {
        let mut s: Vec<SceneName> = plan.iter().map(|(k, _)| k.scene).collect();
        s.dedup();
        s
    };
    for scene in scenes {
        let keys: Vec<(Key, u8)> = plan
            .iter()
            .filter(|(k, _)| k.scene == scene)
            .copied()
            .collect();
        match bench_scene(
            &a, scene, &keys, &isas, &tf, frames, &mut pools, &mut done, total,
        ) {
            Ok((p, m)) => {
                pre.push(p);
                meas.extend(m);
            }
            Err(e) => {
                eprintln!("bench: {scene}: error: {e:#}");
                failures.push(format!("{scene}: {e:#}"));
            }
        }
        if let Some(p) = &a.json {
            write_json(p, &doc(&pre, &meas, false))?;
        }
    }
    let wall = started.elapsed().as_secs_f64();
    if let Some(p) = &a.json {
        write_json(p, &doc(&pre, &meas, failures.is_empty()))?;
    }

    let mut out = String::new();
    report(
        &mut out,
        &pre,
        &meas,
        &isas,
        nproc,
        (load_start, load_avg()),
        wall,
    );
    print!("{out}");
    if let Some(p) = &a.json {
        eprintln!(
            "bench: wrote {} ({} records)",
            p.display(),
            pre.len() + meas.len()
        );
    }
    if !failures.is_empty() {
        bail!(
            "{} scene(s) failed: {}",
            failures.len(),
            failures.join("; ")
        );
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn bench_scene(
    a: &BenchArgs,
    scene: SceneName,
    keys: &[(Key, u8)],
    isas: &[Isa],
    tf: &volume::TransferFunction,
    frames: usize,
    pools: &mut BTreeMap<u32, rayon::ThreadPool>,
    done: &mut usize,
    total: usize,
) -> Result<(Preprocess, Vec<Measurement>)> {
    let need_geometry = keys.iter().any(|(k, _)| k.mode.geometry());
    let need_volume = keys.iter().any(|(k, _)| k.mode.volume());
    let atoms = scene_atoms(a, scene);
    let reset = reset_peak_rss();
    let input = InputArgs {
        file: None,
        scene: Some(scene),
        atoms: Some(atoms),
        seed: a.seed,
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
    eprintln!("bench: {scene}: generating {atoms} atoms and bonds");
    let l = input.load(false)?;
    let m = &l.molecule;
    eprintln!(
        "bench: {scene}: {} atoms, {} bonds (load {:.2} s, bonds {:.2} s)",
        m.len(),
        l.bonds.len(),
        l.load_s,
        l.bond_s
    );
    let build_isa = *isas.iter().max().expect("non-empty");
    let scene_bvh = if need_geometry {
        let (s, _) = build_scene(m, &l.bonds, &a.geometry)?;
        eprintln!(
            "bench: {scene}: BVH {:.2} s ({} nodes, SAH {:.1})",
            s.bvh.stats.build_time.as_secs_f64(),
            s.bvh.stats.nodes,
            s.bvh.stats.sah_cost
        );
        Some(s)
    } else {
        None
    };
    let vpa = a
        .voxels_per_angstrom
        .unwrap_or_else(|| paper_voxels_per_angstrom(scene));
    let vol: Option<(Volume, Macrocells, f64)> = if need_volume {
        let args = VolumeArgs {
            voxels_per_angstrom: vpa,
            volume_format: "u8".into(),
        };
        eprintln!("bench: {scene}: building the density volume at {vpa} voxels/Å");
        let v = build_volume(build_isa, m, &args)?;
        eprintln!(
            "bench: {scene}: volume {:.2} s, {:?} voxels, {:.1} MB",
            v.2,
            v.0.grid.dims,
            mb(v.0.bytes())
        );
        Some(v)
    } else {
        None
    };
    let (geometry_bytes, bvh_bytes) = match &scene_bvh {
        Some(s) => {
            let (g, b) = scene_bytes(s);
            (Some(g), Some(b))
        }
        None => (None, None),
    };
    let p = Preprocess {
        scene,
        atoms: m.len(),
        bonds: l.bonds.len(),
        load_s: l.load_s,
        bond_s: l.bond_s,
        bvh_s: scene_bvh
            .as_ref()
            .map(|s| s.bvh.stats.build_time.as_secs_f64()),
        volume_s: vol.as_ref().map(|v| v.2),
        geometry_bytes,
        bvh_bytes,
        volume_bytes: vol.as_ref().map(|v| v.0.bytes() + v.1.bytes()),
        voxels_per_angstrom: vpa,
        volume_dims: vol.as_ref().map(|v| v.0.grid.dims),
        peak_rss_mb: peak_rss_mb(),
        peak_rss_reset: reset,
    };

    let ctf = vol
        .as_ref()
        .map(|(v, _, _)| ClassifiedTf::new(tf, 0.0, v.max_value, 0.5));
    // The marcher's options of a mode, from the same flags as `bnsview render`.
    let vscene = |mode: BenchMode| -> Result<Option<VolumeScene<'_>>> {
        Ok(match (&vol, &ctf, mode.volume()) {
            (Some((v, cells, _)), Some(ctf), true) => {
                let args = render_cmd::parse_render_flags(mode.volume_flags())?;
                let opts = MarchOptions {
                    macrocells: !a.no_macrocells,
                    ..render_cmd::march_options(&args)
                };
                Some(VolumeScene::new(v, cells, ctf, opts))
            }
            _ => None,
        })
    };
    let sphere = match &scene_bvh {
        Some(s) => (s.center, s.radius),
        None => atoms_sphere(m, &a.geometry),
    };
    let mut out = Vec::new();
    let mut lights: Vec<volume::LightVolume> = Vec::new();
    for &(key, tables) in keys {
        let camera = camera_for(sphere, key.far, key.w, key.h);
        let geo = if key.mode.geometry() {
            scene_bvh.as_ref()
        } else {
            None
        };
        let vs = vscene(key.mode)?;
        // Volumetric shadows read a light volume built once per light and scene, as
        // `bnsview render` builds it once per picture (its build is preprocessing, printed,
        // not part of the frame time).
        let shadows = vs.as_ref().and_then(|v| v.opts.shadows);
        if let (Some(v), Some(sh)) = (&vs, shadows) {
            if !lights.iter().any(|l| l.shadows == sh) {
                let lv = render_cmd::build_light_volume(v, Isa::detect(), &|msg| {
                    eprintln!("bench: {scene}: {msg}")
                });
                lights.extend(lv);
            }
        }
        let light = shadows.and_then(|sh| lights.iter().find(|l| l.shadows == sh));
        let vs = match (vs, light) {
            (Some(v), Some(l)) => Some(v.with_light_volume(l)),
            (v, _) => v,
        };
        let mut renderer = Renderer::new(&key, geo, vs.as_ref())?;
        let pool = match pools.entry(key.threads) {
            std::collections::btree_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::btree_map::Entry::Vacant(e) => e.insert(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(key.threads as usize)
                    .build()
                    .context("building a thread pool")?,
            ),
        };
        for &isa in isas {
            let ms = pool.install(|| {
                for _ in 0..a.warmup {
                    renderer.frame(&camera, isa);
                }
                (0..frames)
                    .map(|_| renderer.frame(&camera, isa))
                    .collect::<Vec<f64>>()
            });
            let load1 = load_avg()[0];
            let m = Measurement {
                key,
                tables,
                atoms: p.atoms,
                isa,
                ms,
                load1,
            };
            *done += 1;
            eprintln!(
                "[{}/{}] {} {} {} {}x{} {}t {}: {:.1} ms median ({:.2} fps, {:.1} Mrays/s), load {:.2}",
                done,
                total,
                scene,
                key.mode.name(),
                key.view(),
                key.w,
                key.h,
                key.threads,
                isa,
                m.ms_median(),
                m.fps(),
                m.mrays(),
                load1
            );
            out.push(m);
        }
    }
    Ok((p, out))
}

/// Renders a mode's frame, again and again.
enum Renderer<'a> {
    /// `render_frame_into`: headlight b&s, volume, vol+b&s (as `bnsview render` without
    /// modality flags).
    Frame {
        geo: Option<&'a Model>,
        vol: Option<&'a VolumeScene<'a>>,
        fb: Framebuffer,
        opt: RenderOptions,
    },
    /// `render_modal_into` with the trace options of the mode's `bnsview render` flags.
    Modal {
        scene: &'a Model,
        vol: Option<&'a VolumeScene<'a>>,
        acc: Accum,
        opt: TraceOptions,
        spp: u32,
    },
}

impl<'a> Renderer<'a> {
    fn new(
        key: &Key,
        geo: Option<&'a Model>,
        vol: Option<&'a VolumeScene<'a>>,
    ) -> Result<Renderer<'a>> {
        let Some(flags) = key.mode.render_flags() else {
            let opt = RenderOptions::default();
            let fb = Framebuffer::new(key.w, key.h, opt.background)?;
            return Ok(Renderer::Frame { geo, vol, fb, opt });
        };
        let args = render_cmd::parse_render_flags(flags)?;
        render_cmd::check_modalities(&args)?;
        let modality = render_cmd::modality(&args)
            .with_context(|| format!("render flags {flags:?} select no modality"))?;
        Ok(Renderer::Modal {
            scene: geo.context("a modality mode without ball-and-stick geometry")?,
            vol,
            acc: Accum::new(key.w, key.h)?,
            opt: render_cmd::trace_options(&args, modality),
            spp: render_cmd::samples_per_pixel(&args),
        })
    }

    /// Renders one complete frame and returns its time in ms. A modality starts from an empty
    /// accumulation every frame (sample numbers from 0, so every frame does the same work).
    fn frame(&mut self, camera: &Camera, isa: Isa) -> f64 {
        match self {
            Renderer::Frame { geo, vol, fb, opt } => {
                let t = Instant::now();
                render_frame_into(*geo, *vol, camera, fb, opt, isa);
                t.elapsed().as_secs_f64() * 1e3
            }
            Renderer::Modal {
                scene,
                vol,
                acc,
                opt,
                spp,
            } => {
                acc.rgb.fill(0.0);
                acc.samples = 0;
                let t = Instant::now();
                render_modal_into(scene, *vol, camera, acc, opt, *spp, isa);
                t.elapsed().as_secs_f64() * 1e3
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Report.

fn f2(x: f64) -> String {
    if !x.is_finite() {
        "-".into()
    } else if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else if x >= 1.0 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}

fn opt_f(x: Option<f64>) -> String {
    x.map(f2).unwrap_or_else(|| "-".into())
}

/// `a / b`, a dash for a missing figure.
fn pair(a: Option<f64>, b: Option<f64>) -> String {
    format!("{} / {}", opt_f(a), opt_f(b))
}

/// The far and close measurements of a scene and mode among `sel` (one ISA, size, threads).
fn far_close<'a>(
    sel: &[&'a Measurement],
    scene: SceneName,
    mode: BenchMode,
) -> [Option<&'a Measurement>; 2] {
    [true, false].map(|far| {
        sel.iter()
            .find(|m| m.key.scene == scene && m.key.mode == mode && m.key.far == far)
            .copied()
    })
}

/// The paper's Figure 4 beside our modality modes, one column per scene, for the
/// measurements `sel` of one ISA, size and thread count; nothing if none is a modality.
fn figure4_table(o: &mut String, sel: &[&Measurement]) {
    use std::fmt::Write as _;
    let Some(k) = sel
        .iter()
        .find(|m| PAPER_FIGURE4.iter().any(|f| f.2 == Some(m.key.mode)))
        .map(|m| (m.key, m.isa))
    else {
        return;
    };
    let scenes: BTreeSet<usize> = sel.iter().map(|m| sidx(m.key.scene)).collect();
    let _ = writeln!(
        o,
        "### The paper's Figure 4 (ray tracing modalities) beside ours, fps far / close, {}x{}, \
         {}, {} thread{}\n\n\
         Paper: Xeon Phi SE10P (61 cores, 1.1 GHz), not the CPU of Tables 1-3; its caption names \
         no scene, view, frame size, AO sample count or samples per pixel. Ours: one sample per \
         pixel per frame (bs-ao: 1 AO ray, path: 1 path); `--ao N` and `--spp N` cost about N \
         times as much.\n",
        k.0.w,
        k.0.h,
        k.1,
        k.0.threads,
        if k.0.threads == 1 { "" } else { "s" }
    );
    let mut head = String::from("| paper (Figure 4) | paper fps | ours |");
    let mut rule = String::from("|---|---|---|");
    for &si in &scenes {
        let _ = write!(head, " {} |", SceneName::ALL[si]);
        rule.push_str("---|");
    }
    let _ = writeln!(o, "{head}\n{rule}");
    for (what, fps, mode) in PAPER_FIGURE4 {
        let mut line = format!(
            "| {what} | {} | {} |",
            f2(fps),
            mode.map_or("-", BenchMode::name)
        );
        for &si in &scenes {
            let ours = mode
                .map(|m| far_close(sel, SceneName::ALL[si], m).map(|x| x.map(Measurement::fps)));
            let [f, c] = ours.unwrap_or([None, None]);
            let _ = write!(line, " {} |", pair(f, c));
        }
        let _ = writeln!(o, "{line}");
    }
    let _ = writeln!(o);
}

fn report(
    o: &mut String,
    pre: &[Preprocess],
    meas: &[Measurement],
    isas: &[Isa],
    nproc: u32,
    (load_start, load_end): ([f64; 3], [f64; 3]),
    wall: f64,
) {
    use std::fmt::Write as _;
    let _ = writeln!(
        o,
        "\nbnsview bench on {} ({} cores), ISA {}; load average {:.2} {:.2} {:.2} at start, {:.2} {:.2} {:.2} at end; wall {:.0} s",
        cpu_model(),
        nproc,
        isas.iter().map(|i| i.name()).collect::<Vec<_>>().join(", "),
        load_start[0],
        load_start[1],
        load_start[2],
        load_end[0],
        load_end[1],
        load_end[2],
        wall
    );
    let _ = writeln!(
        o,
        "Paper: dual 8-core 2.7 GHz Xeon E5-2680 (16 cores, AVX); per core = fps / threads vs paper fps / 16.\n"
    );

    if !pre.is_empty() {
        let _ = writeln!(
            o,
            "### Preprocessing (paper's Table 3 figure in brackets)\n"
        );
        let _ = writeln!(
            o,
            "| scene | atoms | bonds | load s | bonds s | BVH s | volume s (vox/Å) | geometry MB | BVH MB | volume MB | B/atom | peak RSS MB |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|---|---|---|---|");
        for p in pre {
            let pp = paper_preprocess(p.scene);
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} [{}] | {} [{}] | {} [{}] ({}) | {} [{}] | {} [{}] | {} [{}] | {} | {}{} |",
                p.scene,
                p.atoms,
                p.bonds,
                f2(p.load_s),
                f2(p.bond_s),
                pp[4],
                opt_f(p.bvh_s),
                pp[5],
                opt_f(p.volume_s),
                pp[6],
                p.voxels_per_angstrom,
                opt_f(p.geometry_bytes.map(mb)),
                pp[0],
                opt_f(p.bvh_bytes.map(mb)),
                pp[1],
                opt_f(p.volume_bytes.map(mb)),
                pp[2],
                opt_f(p.bytes_per_atom()),
                opt_f(p.peak_rss_mb),
                if p.peak_rss_reset { "" } else { " (process)" }
            );
        }
        let _ = writeln!(o);
    }

    // Table 3: rows scene × mode, far / close side by side.
    let t3: Vec<&Measurement> = meas.iter().filter(|m| m.tables & T3 != 0).collect();
    let combos: BTreeSet<(Isa, u32, u32, u32)> = t3
        .iter()
        .map(|m| (m.isa, m.key.w, m.key.h, m.key.threads))
        .collect();
    for (isa, w, h, threads) in combos {
        // The paper measured at 1024²: at other sizes compare per pixel (ours × pixels/1024²).
        let scale = w as f64 * h as f64 / (1024.0 * 1024.0);
        let _ = writeln!(
            o,
            "### Table 3: fps far / close, {w}x{h}, {isa}, {threads} thread{}{}\n",
            if threads == 1 { "" } else { "s" },
            if scale == 1.0 {
                String::new()
            } else {
                format!(
                    " (paper at 1024²: per-core columns scale ours by {scale:.3}, the pixel ratio)"
                )
            }
        );
        let _ = writeln!(
            o,
            "| scene | atoms | mode | ours fps | paper fps (16 cores) | ours per core | paper per core | per-core ratio |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
        let sel: Vec<&Measurement> = t3
            .iter()
            .filter(|m| (m.isa, m.key.w, m.key.h, m.key.threads) == (isa, w, h, threads))
            .copied()
            .collect();
        let rows: BTreeSet<(usize, BenchMode)> = sel
            .iter()
            .map(|m| (sidx(m.key.scene), m.key.mode))
            .collect();
        for (si, mode) in rows {
            let scene = SceneName::ALL[si];
            let [f, c] = far_close(&sel, scene, mode);
            let atoms = f.or(c).map(|m| m.atoms).unwrap_or(0);
            let ours = [f.map(|m| m.fps()), c.map(|m| m.fps())];
            let paper = mode.paper_row().map(|r| paper_table3(scene)[r]);
            let per_core = |x: Option<f64>| x.map(|v| v * scale / threads as f64);
            let paper_core = |i: usize| paper.map(|p| p[i] / PAPER_CORES);
            let ratio = |i: usize| match (per_core(ours[i]), paper_core(i)) {
                (Some(a), Some(b)) => Some(a / b),
                _ => None,
            };
            let ratio_s = |x: Option<f64>| x.map(|r| format!("{r:.2}×")).unwrap_or("-".into());
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} | {} | {} | {} / {} |",
                scene,
                atoms,
                mode.name(),
                pair(ours[0], ours[1]),
                pair(paper.map(|p| p[0]), paper.map(|p| p[1])),
                pair(per_core(ours[0]), per_core(ours[1])),
                pair(paper_core(0), paper_core(1)),
                ratio_s(ratio(0)),
                ratio_s(ratio(1)),
            );
        }
        let _ = writeln!(o);
        figure4_table(o, &sel);
    }

    // Table 1: frame-buffer size.
    let t1: Vec<&Measurement> = meas.iter().filter(|m| m.tables & T1 != 0).collect();
    let combos: BTreeSet<(usize, Isa, u32)> = t1
        .iter()
        .map(|m| (sidx(m.key.scene), m.isa, m.key.threads))
        .collect();
    for (si, isa, threads) in combos {
        let scene = SceneName::ALL[si];
        let _ = writeln!(
            o,
            "### Table 1: {scene} far, volume, by frame-buffer size, {isa}, {threads} thread{}\n",
            if threads == 1 { "" } else { "s" }
        );
        let _ = writeln!(
            o,
            "| size | MP | ours fps | ms median [min-max] | paper fps (16 cores) | ours per core | paper per core | per-core ratio |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|---|");
        let mut rows: Vec<&&Measurement> = t1
            .iter()
            .filter(|m| (m.key.scene, m.isa, m.key.threads) == (scene, isa, threads))
            .collect();
        rows.sort_by_key(|m| m.key.w as u64 * m.key.h as u64);
        for m in rows {
            let mp = m.key.w as f64 * m.key.h as f64 / (1024.0 * 1024.0);
            let paper = PAPER_TABLE1
                .iter()
                .find(|(p, _)| (p - mp).abs() < 1e-9)
                .map(|x| x.1);
            let v = m.sorted();
            let ours_core = m.fps() / threads as f64;
            let _ = writeln!(
                o,
                "| {}x{} | {} | {} | {} [{}-{}] | {} | {} | {} | {} |",
                m.key.w,
                m.key.h,
                f2(mp),
                f2(m.fps()),
                f2(m.ms_median()),
                f2(v[0]),
                f2(v[v.len() - 1]),
                opt_f(paper),
                f2(ours_core),
                opt_f(paper.map(|p| p / PAPER_CORES)),
                paper
                    .map(|p| format!("{:.2}×", ours_core / (p / PAPER_CORES)))
                    .unwrap_or("-".into())
            );
        }
        let _ = writeln!(o);
    }

    // Table 2: threads.
    let t2: Vec<&Measurement> = meas.iter().filter(|m| m.tables & T2 != 0).collect();
    let combos: BTreeSet<(usize, Isa, u32, u32)> = t2
        .iter()
        .map(|m| (sidx(m.key.scene), m.isa, m.key.w, m.key.h))
        .collect();
    for (si, isa, w, h) in combos {
        let scene = SceneName::ALL[si];
        let scale = w as f64 * h as f64 / (1024.0 * 1024.0);
        let _ = writeln!(
            o,
            "### Table 2: {scene} far, volume, {w}x{h}, by threads, {isa}{}\n",
            if scale == 1.0 {
                String::new()
            } else {
                format!(
                    " (paper at 1024²: ours ÷ paper scales ours by {scale:.3}, the pixel ratio)"
                )
            }
        );
        let _ = writeln!(
            o,
            "| threads | ours fps | ms median [min-max] | speedup over 1 | paper fps (same cores) | paper speedup over 1 | ours ÷ paper |"
        );
        let _ = writeln!(o, "|---|---|---|---|---|---|---|");
        let mut rows: Vec<&&Measurement> = t2
            .iter()
            .filter(|m| (m.key.scene, m.isa, m.key.w, m.key.h) == (scene, isa, w, h))
            .collect();
        rows.sort_by_key(|m| m.key.threads);
        let one = rows.iter().find(|m| m.key.threads == 1).map(|m| m.fps());
        for m in rows {
            let paper = PAPER_TABLE2
                .iter()
                .find(|(c, _)| *c == m.key.threads)
                .map(|x| x.1);
            let v = m.sorted();
            let _ = writeln!(
                o,
                "| {} | {} | {} [{}-{}] | {} | {} | {} | {} |",
                m.key.threads,
                f2(m.fps()),
                f2(m.ms_median()),
                f2(v[0]),
                f2(v[v.len() - 1]),
                one.map(|x| format!("{:.2}×", m.fps() / x))
                    .unwrap_or("-".into()),
                opt_f(paper),
                paper
                    .map(|p| format!("{:.2}×", p / PAPER_TABLE2[0].1))
                    .unwrap_or("-".into()),
                paper
                    .map(|p| format!("{:.2}×", m.fps() * scale / p))
                    .unwrap_or("-".into()),
            );
        }
        let _ = writeln!(o);
    }

    // Speedups over scalar.
    if isas.len() > 1 {
        let _ = writeln!(o, "### fps per ISA (speedup over the first ISA listed)\n");
        let mut head = String::from("| scene | mode | view | size | threads |");
        let mut sep = String::from("|---|---|---|---|---|");
        for i in isas {
            let _ = write!(head, " {i} |");
            sep.push_str("---|");
        }
        let _ = writeln!(o, "{head}\n{sep}");
        let mut keys: Vec<Key> = Vec::new();
        for m in meas {
            if !keys.contains(&m.key) {
                keys.push(m.key);
            }
        }
        for k in keys {
            let fps: Vec<Option<f64>> = isas
                .iter()
                .map(|&i| {
                    meas.iter()
                        .find(|m| m.key == k && m.isa == i)
                        .map(|m| m.fps())
                })
                .collect();
            let base = fps[0];
            let mut line = format!(
                "| {} | {} | {} | {}x{} | {} |",
                k.scene,
                k.mode.name(),
                k.view(),
                k.w,
                k.h,
                k.threads
            );
            for (j, f) in fps.iter().enumerate() {
                match (f, base) {
                    (Some(f), Some(b)) if j > 0 => {
                        let _ = write!(line, " {} ({:.2}×) |", f2(*f), f / b);
                    }
                    (Some(f), _) => {
                        let _ = write!(line, " {} |", f2(*f));
                    }
                    _ => line.push_str(" - |"),
                }
            }
            let _ = writeln!(o, "{line}");
        }
        let _ = writeln!(o);
    }

    // Every measurement.
    let _ = writeln!(o, "### All measurements\n");
    let _ = writeln!(
        o,
        "| scene | atoms | mode | view | size | threads | isa | frames | ms median | ms min | ms max | fps | Mrays/s | load |"
    );
    let _ = writeln!(
        o,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for m in meas {
        let v = m.sorted();
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {}x{} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |",
            m.key.scene,
            m.atoms,
            m.key.mode.name(),
            m.key.view(),
            m.key.w,
            m.key.h,
            m.key.threads,
            m.isa,
            m.ms.len(),
            f2(m.ms_median()),
            f2(v[0]),
            f2(v[v.len() - 1]),
            f2(m.fps()),
            f2(m.mrays()),
            m.load1
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn default_plan_covers_the_three_tables() {
        let p = plan(&args(&[]), 2);
        // Table 3: 5 scenes × 4 modes × 2 views; Table 1 adds 4 sizes (1024² is shared),
        // Table 2 adds 1 thread (2 threads at 1024² is shared).
        assert_eq!(p.len(), 40 + 4 + 1);
        let shared = p
            .iter()
            .find(|(k, _)| {
                k.scene == SceneName::Ns740k
                    && k.mode == BenchMode::Volume
                    && k.far
                    && k.w == 1024
                    && k.threads == 2
            })
            .unwrap();
        assert_eq!(shared.1, T1 | T2 | T3);
        // Grouped by scene.
        let order: Vec<SceneName> = p.iter().map(|(k, _)| k.scene).collect();
        let mut sorted = order.clone();
        sorted.sort_by_key(|s| SceneName::ALL.iter().position(|x| x == s));
        assert_eq!(order, sorted);
    }

    #[test]
    fn tables_one_and_two_need_ns740k_unless_asked_for() {
        let p = plan(&args(&["--scenes", "nanobowl", "--size", "64x64"]), 2);
        assert_eq!(p.len(), 8);
        assert!(p.iter().all(|(_, t)| *t == T3));
        let p = plan(
            &args(&[
                "--scenes", "nanobowl", "--table", "1", "--sizes", "32,64x48",
            ]),
            2,
        );
        assert_eq!(p.len(), 2);
        assert_eq!((p[1].0.w, p[1].0.h), (64, 48));
        let p = plan(&args(&["--table", "2"]), 4);
        let t: Vec<u32> = p.iter().map(|(k, _)| k.threads).collect();
        assert_eq!(t, [1, 2, 3, 4]);
    }

    #[test]
    fn volume_only_runs_see_the_same_frame_as_geometry_runs() {
        // The camera of a volume-only run (no BVH) is fitted to the same sphere as Model's.
        let m = molecule::scenes::generate(SceneName::Ns90k, Some(3000), 7);
        let bonds = molecule::bonds::build_bonds(&m, &Default::default());
        let g = args(&[]).geometry;
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
    fn mode_sets_expand_in_order_each_once() {
        let modes = |a: &[&str]| {
            let mut v = vec!["--scenes", "nanobowl", "--views", "far", "--modes"];
            v.extend_from_slice(a);
            plan(&args(&v), 2)
                .iter()
                .map(|(k, _)| k.mode.name())
                .collect::<Vec<_>>()
        };
        assert_eq!(
            modes(&["modalities"]),
            [
                "bs-shadows",
                "bs-ao",
                "path",
                "volume-lit",
                "vol+bs-lit",
                "volume-shadows",
                "volume-lit-shadows"
            ]
        );
        assert_eq!(
            modes(&["path,modalities,bs"]),
            [
                "path",
                "bs-shadows",
                "bs-ao",
                "volume-lit",
                "vol+bs-lit",
                "volume-shadows",
                "volume-lit-shadows",
                "bs"
            ]
        );
        let all = modes(&["all"]);
        assert_eq!(all.len(), BenchMode::value_variants().len());
        for m in BenchMode::value_variants() {
            assert!(all.contains(&m.name()), "{m:?}");
            // The JSON name reads back as the same mode.
            assert_eq!(BenchMode::from_str(m.name(), true), Ok(*m));
        }
        // The default stays the paper's four; --quick adds the two cheap modalities.
        let default = |extra: &[&str]| {
            let mut v = vec!["--scenes", "nanobowl", "--views", "far", "--table", "3"];
            v.extend_from_slice(extra);
            plan(&args(&v), 2)
                .iter()
                .map(|(k, _)| k.mode)
                .collect::<Vec<_>>()
        };
        assert_eq!(default(&[]), BenchMode::PAPER);
        assert_eq!(default(&["--quick"]), BenchMode::QUICK);
        assert_eq!(default(&["--quick", "--modes", "path"]), [BenchMode::Path]);
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

    #[test]
    fn modality_modes_are_the_render_commands_with_one_sample() {
        use render::{Material, Modality};
        let opts = |m: BenchMode| {
            let a = render_cmd::parse_render_flags(m.render_flags().unwrap()).unwrap();
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
            render_cmd::march_options(&render_cmd::parse_render_flags(m.volume_flags()).unwrap())
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
    fn median_of_even_and_odd_counts() {
        let mut m = Measurement {
            key: Key {
                scene: SceneName::Nanobowl,
                mode: BenchMode::Bs,
                far: true,
                w: 10,
                h: 10,
                threads: 1,
            },
            tables: T3,
            atoms: 1,
            isa: Isa::Scalar,
            ms: vec![3.0, 1.0, 2.0],
            load1: 0.0,
        };
        assert_eq!(m.ms_median(), 2.0);
        m.ms.push(10.0);
        assert_eq!(m.ms_median(), 2.5);
        assert_eq!(m.fps(), 400.0);
    }
}
