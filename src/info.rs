//! `bnsview info`: describe a molecule file or a built-in scene.

use clap::Args;
use molecule::elements;
use molecule::read::Format;
use molecule::Molecule;

use crate::input::InputArgs;

/// Arguments of `bnsview info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    pub input: InputArgs,
    /// Voxels per Å for the volume memory estimate.
    #[arg(long, default_value_t = 4.0)]
    pub voxels_per_angstrom: f32,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
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

/// Run `bnsview info`.
pub fn run(args: InfoArgs) -> anyhow::Result<()> {
    if args.input.file.is_none() && args.input.scene.is_none() {
        anyhow::bail!("give a molecule FILE or --scene NAME (nanobowl, ns90k, ns740k, sio2, anp3)");
    }
    let l = args.input.load(true)?;
    // The same estimate `render` checks before allocating: default model (with the wide
    // BVH) and a u8 volume at --voxels-per-angstrom.
    let settings = scene::SceneSettings {
        model: Some(scene::ModelSettings {
            wide_bvh: true,
            ..Default::default()
        }),
        volume: (!l.molecule.is_empty()).then(|| scene::VolumeSettings {
            voxels_per_angstrom: args.voxels_per_angstrom,
            ..Default::default()
        }),
        ..Default::default()
    };
    let est = scene::MemoryEstimate::new(&l.molecule, l.bonds.len(), &settings)?;
    report(
        &est,
        &args,
        &l.source,
        &l.molecule,
        l.frames,
        l.format,
        l.file_bytes,
        l.load_s,
        &l.bonds,
        l.bond_s,
        &l.warnings,
    );
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn report(
    est: &scene::MemoryEstimate,
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
    let vpa = args.voxels_per_angstrom;
    let dims = est.volume_dims.unwrap_or([0; 3]);
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
            "frame": args.input.frame,
            "frames": frames,
            "atoms": n,
            "elements": counts.iter().map(|(s, c)| (s.clone(), serde_json::json!(c))).collect::<serde_json::Map<_, _>>(),
            "bounds": { "min": lo, "max": hi },
            "cell": m.cell.map(|c| serde_json::json!({"origin": c.origin, "edges": c.edges, "pbc": c.pbc})),
            "file_bonds": m.file_bonds.as_ref().map(Vec::len),
            "bonds": nb,
            "bonds_per_atom": if n > 0 { nb as f64 / n as f64 } else { 0.0 },
            "bond_source": format!("{:?}", args.input.bonds).to_lowercase(),
            "pbc": args.input.pbc,
            "load_seconds": load_s,
            "bond_seconds": bond_s,
            "molecule_bytes": m.memory_bytes(),
            "memory_estimate": est.components().iter().map(|(k, b)| (k.to_string(), serde_json::json!(b))).chain([
                ("total".to_string(), serde_json::json!(est.total())),
                ("volume_dims".to_string(), serde_json::json!(dims)),
                ("voxels_per_angstrom".to_string(), serde_json::json!(vpa)),
            ]).collect::<serde_json::Map<_, _>>(),
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
    p!(
        out,
        "frames:    {frames} (showing frame {})",
        args.input.frame
    );
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
        args.input.bonds,
        if args.input.pbc { ", pbc" } else { "" },
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
        "memory:    ~{:.1} MB estimated for a default render with the wide BVH and a u8 volume:",
        mb(est.total())
    );
    for (name, bytes) in est.components() {
        if bytes > 0 {
            p!(out, "  {name:<12} {:>10.1} MB", mb(bytes));
        }
    }
    p!(
        out,
        "volume:    {}x{}x{} lattice points at {vpa} /Å: {:.1} MB as u8, {:.1} MB as f32",
        dims[0],
        dims[1],
        dims[2],
        mb(est.volume),
        mb(est.volume * 4)
    );
    emit(&out);
}
