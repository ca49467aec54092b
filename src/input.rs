//! Loading the input shared by `info`, `render` and `bench`: a molecule file or a built-in
//! scene, one frame of it, and its bonds, with a spinner and timings.

use std::path::PathBuf;

use clap::Args;
use molecule::bonds::BondOptions;
use molecule::read::{Format, ReadOptions};
use molecule::scenes::SceneName;
use scene::{BondSource, Input, LoadedFrame};

use crate::progress::{follow_stages, spinner};

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

    /// Where the atoms come from (a file, else the scene, else nanobowl).
    pub fn input(&self) -> anyhow::Result<Input> {
        Ok(match (&self.file, self.scene) {
            (Some(path), _) => Input::File {
                path: path.clone(),
                options: self.read_options()?,
            },
            (None, name) => Input::Builtin {
                name: name.unwrap_or(SceneName::Nanobowl),
                atoms: self.atoms,
                seed: self.seed,
            },
        })
    }

    /// Loads `--frame` with a bar per stage and prints the reader's warnings; `count_frames`
    /// also scans the whole file for the number of frames, `bond` builds the bonds (and
    /// unwraps) as `info` describes them.
    pub fn load(&self, count_frames: bool, bond: bool) -> anyhow::Result<LoadedFrame> {
        let bonds = self.bond_settings()?;
        let input = self.input()?;
        let title = match &input {
            Input::File { path, .. } => path.display().to_string(),
            Input::Builtin { name, .. } => name.to_string(),
        };
        let mut l = follow_stages(&title, |p| input.load(self.frame, count_frames, p))?;
        for w in &l.warnings {
            eprintln!("warning: {w}");
        }
        if bond {
            let pb = spinner(&format!("building bonds for {} atoms", l.molecule.len()));
            l.bond(&bonds)?;
            pb.finish_and_clear();
        }
        Ok(l)
    }
}
