//! `bnsview info`: describe a molecule file or a built-in scene.

use anyhow::{bail, Context};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use molecule::bonds::{build_bonds, BondOptions};
use molecule::elements;
use molecule::read::{open, Format, ReadOptions};
use molecule::scenes::{generate, SceneName};
use molecule::Molecule;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Where bonds come from.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum BondSource {
    /// Geometric rule (uniform-grid neighbour search).
    Auto,
    /// Bonds listed in the file (LAMMPS data `Bonds`, PDB `CONECT`); error if there are none.
    File,
    /// No bonds.
    None,
}

/// Arguments of `bnsview info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Molecule file (xyz, pdb, lammps dump/data, gro; optionally .gz).
    #[arg(required_unless_present = "scene", conflicts_with = "scene")]
    pub file: Option<PathBuf>,
    /// Built-in scene instead of a file: nanobowl, ns90k, ns740k, sio2, anp3.
    #[arg(long)]
    pub scene: Option<SceneName>,
    /// Scene size in atoms (default: the paper's count).
    #[arg(long, requires = "scene")]
    pub atoms: Option<usize>,
    /// Scene random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// File format (default: from the extension or content).
    #[arg(long)]
    pub format: Option<Format>,
    /// LAMMPS type → element mapping, e.g. `1=Al,2=O`.
    #[arg(long)]
    pub types: Option<String>,
    /// LAMMPS data atom style if the file does not say (atomic, charge, molecular, full).
    #[arg(long)]
    pub atom_style: Option<String>,
    /// Frame to describe (0-based).
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// Bond source.
    #[arg(long, value_enum, default_value_t = BondSource::Auto)]
    pub bonds: BondSource,
    /// Bond factor f in d < f·(rcov_i + rcov_j).
    #[arg(long, default_value_t = 1.15)]
    pub bond_factor: f32,
    /// One bond cutoff (Å) for all pairs.
    #[arg(long)]
    pub bond_cutoff: Option<f32>,
    /// Per-pair cutoffs (Å), e.g. `Al-O=2.2,Si-O=1.9`.
    #[arg(long)]
    pub pair_cutoffs: Option<String>,
    /// Periodic boundaries (minimum image) for bonds, using the file's cell.
    #[arg(long)]
    pub pbc: bool,
    /// Voxels per Å for the volume memory estimate.
    #[arg(long, default_value_t = 4.0)]
    pub voxels_per_angstrom: f64,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

/// A spinner on stderr that only appears after half a second and never when stderr is not a
/// terminal.
pub fn spinner(msg: &str) -> ProgressBar {
    let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} ({elapsed})") {
        pb.set_style(style);
    }
    pb.set_message(msg.to_string());
    pb.enable_steady_tick(Duration::from_millis(500));
    pb
}

macro_rules! p {
    ($out:ident, $($t:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($t)*);
    }};
}

/// Print to stdout; a closed pipe (`| head`) is not an error.
fn emit(s: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_all(s.as_bytes());
}

/// Padding (Å) around the atom bounds for the volume estimate.
const VOLUME_PAD: f64 = 2.0;
/// Bytes per BVH node assumed by the estimate.
const BVH_NODE_BYTES: u64 = 32;

/// Run `bnsview info`.
pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    let bond_opts = BondOptions {
        factor: args.bond_factor,
        global_cutoff: args.bond_cutoff,
        pair_cutoffs: match &args.pair_cutoffs {
            Some(s) => BondOptions::parse_pair_cutoffs(s).map_err(anyhow::Error::msg)?,
            None => Vec::new(),
        },
        pbc: args.pbc,
        ..BondOptions::default()
    };
    let t0 = Instant::now();
    let pb = spinner("loading");
    let (source, m, frames, warnings, format, file_bytes) = if let Some(scene) = args.scene {
        pb.set_message(format!("generating {scene}"));
        let m = generate(scene, args.atoms, args.seed);
        (
            format!("scene {scene} (seed {})", args.seed),
            m,
            1,
            Vec::new(),
            None,
            None,
        )
    } else {
        let path = args.file.clone().context("no input")?;
        let opts = ReadOptions {
            format: args.format,
            types: match &args.types {
                Some(s) => ReadOptions::parse_types(s).map_err(anyhow::Error::msg)?,
                None => Vec::new(),
            },
            atom_style: args.atom_style.clone(),
        };
        let bytes = std::fs::metadata(&path).map(|m| m.len()).ok();
        pb.set_message(format!("reading {}", path.display()));
        let mut t = open(&path, &opts)?;
        let m = t.read_frame(args.frame)?;
        pb.set_message("counting frames".to_string());
        let frames = t.count_frames()?;
        let w = t.warnings().to_vec();
        (
            path.display().to_string(),
            m,
            frames,
            w,
            Some(t.format()),
            bytes,
        )
    };
    let load = t0.elapsed().as_secs_f64();
    for w in &warnings {
        pb.suspend(|| eprintln!("warning: {w}"));
    }
    pb.set_message(format!("building bonds for {} atoms", m.len()));
    let t1 = Instant::now();
    let bonds = match args.bonds {
        BondSource::Auto => build_bonds(&m, &bond_opts),
        BondSource::File => match &m.file_bonds {
            Some(b) => b.clone(),
            None => {
                bail!("--bonds file: the input lists no bonds (LAMMPS data Bonds / PDB CONECT)")
            }
        },
        BondSource::None => Vec::new(),
    };
    let bond_s = t1.elapsed().as_secs_f64();
    pb.finish_and_clear();
    report(
        &args, &source, &m, frames, format, file_bytes, load, &bonds, bond_s, &warnings,
    );
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn report(
    args: &InfoArgs,
    source: &str,
    m: &Molecule,
    frames: usize,
    format: Option<Format>,
    file_bytes: Option<u64>,
    load_s: f64,
    bonds: &[[u32; 2]],
    bond_s: f64,
    warnings: &[String],
) {
    let (lo, hi) = m.bounds();
    let n = m.len() as u64;
    let nb = bonds.len() as u64;
    // BVH: ≤4 primitives per leaf → ~(atoms+bonds)/4 leaves, ~2× that many nodes.
    let bvh_nodes = 2 * (n + nb).div_ceil(4);
    let bvh_bytes = bvh_nodes * BVH_NODE_BYTES;
    let vpa = args.voxels_per_angstrom;
    let dims: Vec<u64> = (0..3)
        .map(|k| {
            ((f64::from(hi[k] - lo[k]) + 2.0 * VOLUME_PAD) * vpa)
                .ceil()
                .max(1.0) as u64
        })
        .collect();
    let voxels: u64 = dims.iter().product();
    let counts: Vec<(String, usize)> = m
        .element_counts()
        .into_iter()
        .map(|(z, c)| (elements::element(z).symbol.to_string(), c))
        .collect();
    if args.json {
        let v = serde_json::json!({
            "source": source,
            "format": format.map(|f| f.name()),
            "file_bytes": file_bytes,
            "frame": args.frame,
            "frames": frames,
            "atoms": n,
            "elements": counts.iter().map(|(s, c)| (s.clone(), serde_json::json!(c))).collect::<serde_json::Map<_, _>>(),
            "bounds": { "min": lo, "max": hi },
            "cell": m.cell.map(|c| serde_json::json!({"origin": c.origin, "edges": c.edges, "pbc": c.pbc})),
            "file_bonds": m.file_bonds.as_ref().map(Vec::len),
            "bonds": nb,
            "bonds_per_atom": if n > 0 { nb as f64 / n as f64 } else { 0.0 },
            "bond_source": format!("{:?}", args.bonds).to_lowercase(),
            "pbc": args.pbc,
            "load_seconds": load_s,
            "bond_seconds": bond_s,
            "molecule_bytes": m.memory_bytes(),
            "bvh_estimate": { "nodes": bvh_nodes, "bytes": bvh_bytes, "formula": "2*ceil((atoms+bonds)/4) nodes * 32 B" },
            "volume_estimate": { "voxels_per_angstrom": vpa, "dims": dims, "voxels": voxels, "bytes_u8": voxels, "bytes_f32": voxels * 4,
                                 "formula": "prod(ceil((max-min+2*2 A)*vpa)) voxels * 1 B (u8)" },
            "warnings": warnings,
        });
        emit(&(serde_json::to_string_pretty(&v).unwrap_or_default() + "\n"));
        return;
    }
    let mut out = String::new();
    let mb = |b: u64| b as f64 / 1e6;
    p!(out, "source:    {source}");
    if let Some(f) = format {
        p!(out, "format:    {f}");
    }
    p!(out, "frames:    {frames} (showing frame {})", args.frame);
    p!(out, "atoms:     {n}");
    let el: Vec<String> = counts.iter().map(|(s, c)| format!("{s} {c}")).collect();
    p!(out, "elements:  {}", el.join(", "));
    p!(
        out,
        "bounds:    [{:.3}, {:.3}, {:.3}] .. [{:.3}, {:.3}, {:.3}] Å",
        lo[0],
        lo[1],
        lo[2],
        hi[0],
        hi[1],
        hi[2]
    );
    if let Some(c) = &m.cell {
        p!(
            out,
            "cell:      origin {:?}, a {:?}, b {:?}, c {:?}",
            c.origin,
            c.edges[0],
            c.edges[1],
            c.edges[2]
        );
    }
    if let Some(fb) = &m.file_bonds {
        p!(out, "file bonds: {}", fb.len());
    }
    p!(
        out,
        "bonds:     {nb} ({:.3} per atom, {:?}{}) built in {:.3} s",
        if n > 0 { nb as f64 / n as f64 } else { 0.0 },
        args.bonds,
        if args.pbc { ", pbc" } else { "" },
        bond_s
    );
    match file_bytes {
        Some(b) => p!(out, "load:      {load_s:.3} s ({:.1} MB file)", mb(b)),
        None => p!(out, "load:      {load_s:.3} s"),
    }
    p!(
        out,
        "molecule:  {:.1} MB in memory",
        mb(m.memory_bytes() as u64)
    );
    p!(
        out,
        "BVH:       ~{:.1} MB (2*ceil((atoms+bonds)/4) = {bvh_nodes} nodes x 32 B)",
        mb(bvh_bytes)
    );
    p!(
        out,
        "volume:    {}x{}x{} voxels at {vpa} /Å (bounds + 2 Å pad): {:.1} MB as u8, {:.1} MB as f32",
        dims[0],
        dims[1],
        dims[2],
        mb(voxels),
        mb(voxels * 4)
    );
    emit(&out);
}
