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
    /// Image size of the memory estimate, WIDTHxHEIGHT pixels (as `render --size`).
    #[arg(long, default_value = "1024x1024", value_parser = crate::look::parse_size)]
    pub size: (u32, u32),
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
    let modes = mode_estimates(&l.molecule, l.bonds.len(), &args)?;
    report(
        &modes,
        &args,
        &l.source,
        &l.molecule,
        l.frames,
        l.format,
        l.file_bytes,
        l.load_s,
        &l.bonds,
        l.bond_s,
        l.unwrap.as_ref(),
        &l.warnings,
    );
    Ok(())
}

/// The `render` modes `info` estimates: name and estimate.
type ModeEstimates = Vec<(&'static str, scene::MemoryEstimate)>;

/// The estimate `render` checks before allocating, for each mode at `--size` with a u8
/// volume at `--voxels-per-angstrom`: `bs` (model, packets only), `volume` (density alone),
/// `vol+bs` (both) and `path` (model with the wide BVH). The volume modes are left out for
/// a molecule without atoms.
fn mode_estimates(m: &Molecule, bonds: usize, args: &InfoArgs) -> anyhow::Result<ModeEstimates> {
    let bonds_settings = args.input.bond_settings()?;
    let model = |wide_bvh| {
        Some(scene::ModelSettings {
            wide_bvh,
            ..Default::default()
        })
    };
    let volume = Some(scene::VolumeSettings {
        voxels_per_angstrom: args.voxels_per_angstrom,
        ..Default::default()
    });
    let mut modes = vec![("bs", model(false), None), ("path", model(true), None)];
    if !m.is_empty() {
        modes.insert(1, ("volume", None, volume.clone()));
        modes.insert(2, ("vol+bs", model(false), volume));
    }
    modes
        .into_iter()
        .map(|(name, model, volume)| {
            let settings = scene::SceneSettings {
                model,
                volume,
                bonds: bonds_settings.clone(),
                frame: Some(args.size),
                ..Default::default()
            };
            Ok((name, scene::MemoryEstimate::new(m, bonds, &settings)?))
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn report(
    modes: &ModeEstimates,
    args: &InfoArgs,
    source: &str,
    m: &Molecule,
    frames: usize,
    format: Option<Format>,
    file_bytes: Option<u64>,
    load_s: f64,
    bonds: &[[u32; 2]],
    bond_s: f64,
    unwrap: Option<&scene::UnwrapReport>,
    warnings: &[String],
) {
    // The breakdown shown is the largest mode at rest (vol+bs, or bs without atoms).
    let est = modes
        .iter()
        .find(|(n, _)| *n == "vol+bs")
        .unwrap_or(&modes[0]);
    let est = &est.1;
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
            "unwrap": unwrap.map(|u| serde_json::json!({
                "method": format!("{:?}", u.method).to_lowercase(),
                "crossing_bonds": u.crossing,
            })),
            "load_seconds": load_s,
            "bond_seconds": bond_s,
            "molecule_bytes": m.memory_bytes(),
            "peak_rss_estimate": modes.iter().map(|(n, e)| (n.to_string(), serde_json::json!({
                "bytes": e.peak_bytes(),
                "phase": e.peak.phase.name(),
                "live": e.peak.live,
                "retained": e.peak.retained,
                "baseline": e.peak.baseline,
                "at_rest": e.total(),
            }))).collect::<serde_json::Map<_, _>>(),
            "memory_estimate": est.components().iter().map(|(k, b)| (k.to_string(), serde_json::json!(b))).chain([
                ("total".to_string(), serde_json::json!(est.total())),
                ("peak".to_string(), serde_json::json!(est.peak_bytes())),
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
    if let Some(u) = unwrap {
        p!(
            out,
            "{}",
            u.describe().replacen("unwrap:  ", "unwrap:    ", 1)
        );
    }
    match file_bytes {
        Some(b) => p!(out, "load:      {load_s:.3} s ({:.1} MB file)", mb(b)),
        None => p!(out, "load:      {load_s:.3} s"),
    }
    p!(
        out,
        "molecule:  {:.1} MB in memory",
        mb(m.memory_bytes() as u64)
    );
    let (w, h) = args.size;
    p!(
        out,
        "memory:    estimated peak RSS of `render --size {w}x{h}` (u8 volume at {vpa} /Å):"
    );
    for (name, e) in modes {
        let pk = &e.peak;
        p!(
            out,
            "  {name:<12} {:>10.1} MB  ({}: {:.1} MB alive + {:.1} MB kept by the allocator + {:.1} MB baseline)",
            mb(e.peak_bytes()),
            pk.phase.name(),
            mb(pk.live),
            mb(pk.retained),
            mb(pk.baseline)
        );
    }
    p!(out, "  at rest (vol+bs), {:.1} MB:", mb(est.total()));
    for (name, bytes) in est.components() {
        if bytes > 0 {
            p!(out, "    {name:<12} {:>10.1} MB", mb(bytes));
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
