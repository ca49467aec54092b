//! `bnsview generate`: write a built-in reference scene to a file.

use anyhow::{bail, Context};
use clap::Args;
use molecule::motion::thermal_frame;
use molecule::scenes::{try_generate, SceneName};
use molecule::write::TrajectoryWriter;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `bnsview generate`.
#[derive(Args, Debug)]
pub struct GenerateArgs {
    /// Model: nanobowl, ns90k, ns740k, sio2, anp3.
    pub scene: SceneName,
    /// Approximate number of atoms (default: the paper's count for the scene).
    #[arg(long)]
    pub atoms: Option<usize>,
    /// Random seed (the scene is identical for identical seed and atom count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output file: .xyz (extended XYZ) or .lammpstrj/.dump (LAMMPS dump); add .gz to compress.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Overwrite the output file if it exists.
    #[arg(long)]
    pub force: bool,
    /// Frames to write: a trajectory of the scene jittered as at --temperature and breathing
    /// by ±2 % every 20 frames (`molecule::motion`), deterministic in --seed.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub frames: u64,
    /// Temperature of the jitter (K; RMS 0.05 Å per component at 300 K).
    #[arg(long, default_value_t = 300.0)]
    pub temperature: f32,
}

/// Run `bnsview generate`.
pub fn run(args: GenerateArgs) -> anyhow::Result<()> {
    if !(args.temperature.is_finite() && args.temperature >= 0.0) {
        bail!(
            "--temperature {}: expected kelvins, 0 or more",
            args.temperature
        );
    }
    // Refuse absurd --atoms before creating the output file or allocating anything.
    if let Some(n) = args.atoms {
        molecule::scenes::check_atoms(n, molecule::scenes::available_memory())?;
    }
    let mut out = TrajectoryWriter::create(&args.output, args.force)?;
    let pb = crate::progress::spinner(&format!("generating {}", args.scene));
    let t = Instant::now();
    let m = try_generate(args.scene, args.atoms, args.seed)?;
    let gen_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let comment = format!("bnsview scene {} seed {}", args.scene, args.seed);
    let frames = args.frames;
    for k in 0..frames {
        pb.set_message(format!(
            "writing frame {}/{frames} of {} atoms",
            k + 1,
            m.len()
        ));
        let written = if frames == 1 {
            out.write(&m, &comment)
        } else {
            out.write(
                &thermal_frame(&m, k as usize, args.seed, args.temperature),
                &comment,
            )
        };
        written.with_context(|| format!("writing {}", args.output.display()))?;
    }
    out.finish()
        .with_context(|| format!("writing {}", args.output.display()))?;
    pb.finish_and_clear();
    eprintln!(
        "{}: {frames} frame(s) of {} atoms of {} (seed {}), generated in {gen_s:.2} s, written in {:.2} s",
        args.output.display(),
        m.len(),
        args.scene,
        args.seed,
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
