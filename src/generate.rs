//! `bnsview generate`: write a built-in reference scene to a file.

use anyhow::{bail, Context};
use clap::Args;
use molecule::motion::thermal_frame;
use molecule::scenes::{try_generate, SceneName};
use molecule::write::{write_lammps_dump, write_xyz};
use std::fs::OpenOptions;
use std::io::{BufWriter, Write};
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
    let name = args.output.to_string_lossy().to_ascii_lowercase();
    let gz = name.ends_with(".gz");
    let base = name.strip_suffix(".gz").unwrap_or(&name);
    let xyz = if base.ends_with(".xyz") || base.ends_with(".extxyz") {
        true
    } else if base.ends_with(".lammpstrj") || base.ends_with(".dump") {
        false
    } else {
        bail!(
            "{}: unknown output format; use a .xyz or .lammpstrj name (optionally .gz)",
            args.output.display()
        );
    };
    // Refuse absurd --atoms before creating the output file or allocating anything.
    if let Some(n) = args.atoms {
        molecule::scenes::check_atoms(n, molecule::scenes::available_memory())?;
    }
    let mut opts = OpenOptions::new();
    opts.write(true);
    if args.force {
        opts.create(true).truncate(true);
    } else {
        opts.create_new(true);
    }
    let file = opts.open(&args.output).map_err(|e| {
        if e.kind() == std::io::ErrorKind::AlreadyExists {
            anyhow::anyhow!(
                "{} exists; pass --force to overwrite it",
                args.output.display()
            )
        } else {
            anyhow::Error::new(e).context(format!("cannot create {}", args.output.display()))
        }
    })?;
    let pb = crate::progress::spinner(&format!("generating {}", args.scene));
    let t = Instant::now();
    let m = try_generate(args.scene, args.atoms, args.seed)?;
    let gen_s = t.elapsed().as_secs_f64();
    pb.set_message(format!("writing {} atoms", m.len()));
    let t = Instant::now();
    let comment = format!("bnsview scene {} seed {}", args.scene, args.seed);
    if !(args.temperature.is_finite() && args.temperature >= 0.0) {
        bail!(
            "--temperature {}: expected kelvins, 0 or more",
            args.temperature
        );
    }
    let frames = args.frames;
    let write = |w: &mut dyn Write| -> std::io::Result<()> {
        for k in 0..frames {
            let mk;
            let frame = if frames == 1 {
                &m
            } else {
                pb.set_message(format!(
                    "writing frame {}/{frames} of {} atoms",
                    k + 1,
                    m.len()
                ));
                mk = thermal_frame(&m, k as usize, args.seed, args.temperature);
                &mk
            };
            if xyz {
                write_xyz(w, frame, &format!("{comment} frame {k}"))?;
            } else {
                write_lammps_dump(w, frame, k)?;
            }
        }
        Ok(())
    };
    let buf = BufWriter::with_capacity(1 << 20, file);
    if gz {
        // Buffered in front of the encoder too: the writers make a call per number, and each
        // call into the deflater costs far more than a copy into a buffer.
        let e = flate2::write::GzEncoder::new(buf, flate2::Compression::fast());
        let mut e = BufWriter::with_capacity(1 << 20, e);
        write(&mut e)
            .and_then(|_| e.into_inner().map_err(|e| e.into_error()))
            .and_then(|e| e.finish())
            .and_then(|mut b| b.flush())
    } else {
        let mut b = buf;
        write(&mut b).and_then(|_| b.flush())
    }
    .with_context(|| format!("writing {}", args.output.display()))?;
    pb.finish_and_clear();
    eprintln!(
        "{}: {} frame(s) of {} atoms of {} (seed {}), generated in {:.2} s, written in {:.2} s",
        args.output.display(),
        frames,
        m.len(),
        args.scene,
        args.seed,
        gen_s,
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
