//! Loading the input shared by `info`, `render` and `bench`: a molecule file or a built-in
//! scene, one frame of it, and its bonds, with a spinner and timings.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context};
use clap::Args;
use molecule::bonds::BondOptions;
use molecule::read::{open, Format, FrameIndex, ReadOptions};
use molecule::scenes::{try_generate, SceneName};
use molecule::Molecule;
use scene::BondSource;

use crate::progress::{bar, follow_bytes, spinner};

/// Where the atoms come from and how they are bonded.
#[derive(Args, Debug, Clone)]
#[command(next_help_heading = "Input and bonds")]
pub struct InputArgs {
    /// Molecule file (xyz, pdb, lammps dump/data, gro; optionally .gz).
    #[arg(conflicts_with = "scene")]
    pub file: Option<PathBuf>,
    /// Built-in scene instead of a file: nanobowl, ns90k, ns740k, sio2, anp3.
    #[arg(long)]
    pub scene: Option<SceneName>,
    /// Model size in atoms (default: the paper's count).
    #[arg(long, requires = "scene")]
    pub atoms: Option<usize>,
    /// Model random seed.
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
    /// Frame to describe (0-based; negative counts from the end, -1 = last).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    pub frame: i64,
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
    /// Put molecules split by the periodic boundaries back together before drawing. Needs a
    /// cell; uses ix iy iz when the file has them, else bonds by minimum image (a bond still
    /// crossing the cell is then left out, or drawn as half-sticks with --pbc).
    #[arg(long)]
    pub unwrap: bool,
}

/// A loaded frame with its bonds and what it took.
pub struct Loaded {
    /// Human description of the source (path or scene and seed).
    pub source: String,
    /// The frame.
    pub molecule: Molecule,
    /// Frames in the input (1 for a scene).
    pub frames: usize,
    /// Reader warnings (unknown elements, …).
    pub warnings: Vec<String>,
    /// Format of the file, if one was read.
    pub format: Option<Format>,
    /// File size in bytes, if one was read.
    pub file_bytes: Option<u64>,
    /// Bonds, pairs i<j sorted.
    pub bonds: Vec<[u32; 2]>,
    /// Time to read or generate the frame (s).
    pub load_s: f64,
    /// Time to build the bonds (s), unwrapping included.
    pub bond_s: f64,
    /// How the frame was unwrapped (`--unwrap`; `None` without).
    pub unwrap: Option<scene::UnwrapReport>,
}

impl InputArgs {
    /// Bond settings from the flags.
    pub fn bond_settings(&self) -> anyhow::Result<scene::BondSettings> {
        Ok(scene::BondSettings {
            source: self.bonds,
            options: self.bond_options()?,
            unwrap: self.unwrap,
        })
    }

    /// Bond options from the flags.
    pub fn bond_options(&self) -> anyhow::Result<BondOptions> {
        Ok(BondOptions {
            factor: self.bond_factor,
            global_cutoff: self.bond_cutoff,
            pair_cutoffs: match &self.pair_cutoffs {
                Some(s) => BondOptions::parse_pair_cutoffs(s).map_err(anyhow::Error::msg)?,
                None => Vec::new(),
            },
            pbc: self.pbc,
            ..BondOptions::default()
        })
    }

    /// The reader options of the flags.
    pub fn read_options(&self) -> anyhow::Result<ReadOptions> {
        Ok(ReadOptions {
            format: self.format,
            types: match &self.types {
                Some(s) => ReadOptions::parse_types(s).map_err(anyhow::Error::msg)?,
                None => Vec::new(),
            },
            atom_style: self.atom_style.clone(),
        })
    }

    /// Opens `path` as a trajectory with the flags' reader options.
    pub fn open_trajectory(
        &self,
        path: &std::path::Path,
    ) -> anyhow::Result<molecule::read::Trajectory> {
        Ok(open(path, &self.read_options()?)?)
    }

    /// Reads (or generates) the frame and builds its bonds; `count_frames` also scans the
    /// whole file for the number of frames.
    pub fn load(&self, count_frames: bool) -> anyhow::Result<Loaded> {
        let bonds = self.bond_settings()?;
        let mut l = self.load_frame(count_frames)?;
        let pb = spinner(&format!("building bonds for {} atoms", l.molecule.len()));
        let t1 = Instant::now();
        // The bonds and (with --unwrap) the unwrapped frame, as `render` builds them.
        let p = bonds.prepare(&l.molecule, self.pbc)?;
        l.bonds = p.bonds;
        if let Some(u) = p.unwrapped {
            l.molecule = u;
        }
        l.unwrap = p.unwrap;
        l.bond_s = t1.elapsed().as_secs_f64();
        pb.finish_and_clear();
        Ok(l)
    }

    /// Reads (or generates) the frame without bonds (`bonds` empty, `bond_s` 0: the scene
    /// builds them); `count_frames` as in [`InputArgs::load`].
    pub fn load_frame(&self, count_frames: bool) -> anyhow::Result<Loaded> {
        self.bond_settings()?;
        let t0 = Instant::now();
        let pb = spinner("loading");
        let (source, m, frames, warnings, format, file_bytes) = if let Some(scene) = self.scene {
            if self.frame != 0 {
                bail!(
                    "--frame {}: built-in scenes have a single frame",
                    self.frame
                );
            }
            pb.set_message(format!("generating {scene}"));
            let m = try_generate(scene, self.atoms, self.seed)?;
            (
                format!("scene {scene} (seed {})", self.seed),
                m,
                1,
                Vec::new(),
                None,
                None,
            )
        } else {
            let path = self
                .file
                .clone()
                .context("no input: give a FILE or --scene NAME")?;
            let opts = self.read_options()?;
            let bytes = std::fs::metadata(&path).map(|m| m.len()).ok();
            let mut t = open(&path, &opts)?;
            // A bar over the file's bytes when they are what is read, else a count of them.
            pb.finish_and_clear();
            let what = format!("reading {}", path.display());
            let pb = match bytes.filter(|_| !t.is_gzip()) {
                Some(n) => bar(&what, n, true),
                None => spinner(&what),
            };
            let read = t.decoded_counter();
            let m = follow_bytes(&pb, &read, &what, || {
                t.read_frame_at(FrameIndex::from(self.frame))
            })?;
            let frames = if count_frames {
                pb.set_message(format!("counting the frames of {}", path.display()));
                let before = read.load(std::sync::atomic::Ordering::Relaxed);
                if let Some(n) = bytes.filter(|_| !t.is_gzip()) {
                    pb.set_length(n + before);
                }
                follow_bytes(&pb, &read, "counting frames", || t.count_frames())?
            } else {
                0
            };
            pb.finish_and_clear();
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
        let load_s = t0.elapsed().as_secs_f64();
        for w in &warnings {
            pb.suspend(|| eprintln!("warning: {w}"));
        }
        pb.finish_and_clear();
        Ok(Loaded {
            source,
            molecule: m,
            frames,
            warnings,
            format,
            file_bytes,
            bonds: Vec::new(),
            load_s,
            bond_s: 0.0,
            unwrap: None,
        })
    }
}
