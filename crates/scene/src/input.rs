//! Where the atoms come from — a molecule file or a built-in scene — and one frame of it
//! loaded, with its bonds when asked: what `info`, `render` and the viewer start from.

use std::path::PathBuf;
use std::time::Instant;

use molecule::read::{open_counted, Format, FrameIndex, ReadError, ReadOptions};
use molecule::scenes::{try_generate, SceneName};
use molecule::Molecule;

use crate::build::UnwrapReport;
use crate::progress::{Progress, Stage};
use crate::settings::BondSettings;
use crate::SceneError;

/// The source of the frames.
#[derive(Clone, Debug)]
pub enum Input {
    /// A molecule file (xyz, pdb, LAMMPS dump or data, gro; optionally gzip).
    File {
        /// The file.
        path: PathBuf,
        /// How to read it.
        options: ReadOptions,
    },
    /// A built-in reference scene ([`molecule::scenes`]), one frame.
    Builtin {
        /// Which scene.
        name: SceneName,
        /// Atoms (default: the paper's count).
        atoms: Option<usize>,
        /// Random seed.
        seed: u64,
    },
}

/// A frame loaded by [`Input::load`], and what loading it took.
#[derive(Clone, Debug)]
pub struct LoadedFrame {
    /// Human description of the source (path, or scene and seed).
    pub source: String,
    /// Format of the file, if one was read.
    pub format: Option<Format>,
    /// File size in bytes, if one was read.
    pub file_bytes: Option<u64>,
    /// Index of the frame as asked (negative: from the end).
    pub frame: i64,
    /// Frames in the input (1 for a built-in scene; `None` when not counted).
    pub frames: Option<usize>,
    /// The frame (unwrapped, after [`LoadedFrame::bond`] with `unwrap` on).
    pub molecule: Molecule,
    /// Its bonds (pairs i < j; empty until [`LoadedFrame::bond`]).
    pub bonds: Vec<[u32; 2]>,
    /// How the frame was unwrapped (`None`: it was not).
    pub unwrap: Option<UnwrapReport>,
    /// Time to read or generate the frame (s).
    pub load_s: f64,
    /// Time to build the bonds (s), unwrapping included.
    pub bond_s: f64,
    /// Reader warnings (unknown elements, …).
    pub warnings: Vec<String>,
}

impl Input {
    /// The name an output is called after: the file's stem, or the scene's name.
    pub fn stem(&self) -> String {
        match self {
            Input::File { path, .. } => path
                .file_stem()
                .map_or_else(|| "bnsview".into(), |s| s.to_string_lossy().into_owned()),
            Input::Builtin { name, .. } => name.to_string(),
        }
    }

    /// Reads frame `frame` of the file (negative: from the end) or generates the scene
    /// (frame 0 only); `count_frames` also scans the whole file for [`LoadedFrame::frames`].
    /// Reports [`Stage::Generate`], [`Stage::Read`] and [`Stage::CountFrames`] to `progress`.
    pub fn load(
        &self,
        frame: i64,
        count_frames: bool,
        progress: &Progress,
    ) -> Result<LoadedFrame, SceneError> {
        let t0 = Instant::now();
        let mut l = LoadedFrame {
            source: String::new(),
            format: None,
            file_bytes: None,
            frame,
            frames: Some(1),
            molecule: Molecule::default(),
            bonds: Vec::new(),
            unwrap: None,
            load_s: 0.0,
            bond_s: 0.0,
            warnings: Vec::new(),
        };
        match self {
            Input::Builtin { name, atoms, seed } => {
                if frame != 0 {
                    return Err(SceneError::OneFrame { frame });
                }
                progress.start(Stage::Generate, 1)?;
                l.source = format!("scene {name} (seed {seed})");
                l.molecule = try_generate(*name, *atoms, *seed)?;
            }
            Input::File { path, options } => {
                let bytes = std::fs::metadata(path).map(|m| m.len()).ok();
                let mut t = open_counted(path, options, progress.done.clone())?;
                // Bytes decoded are the bar's units when they are the file's. A frame from
                // the end needs the count first; counting first, from the start, makes both
                // stages end at or below their units (the read then seeks to its frame).
                let units = bytes.filter(|_| !t.is_gzip()).unwrap_or(0);
                l.frames = None;
                if count_frames || frame < 0 {
                    progress.start(Stage::CountFrames, units)?;
                    l.frames = Some(t.count_frames()?);
                }
                progress.start(Stage::Read, units)?;
                l.molecule = t.read_frame_at(FrameIndex::from(frame))?;
                l.source = path.display().to_string();
                (l.format, l.file_bytes) = (Some(t.format()), bytes);
                l.warnings = t.warnings().to_vec();
            }
        }
        l.load_s = t0.elapsed().as_secs_f64();
        Ok(l)
    }
}

impl LoadedFrame {
    /// Builds the frame's bonds (and, with [`BondSettings::unwrap`], unwraps it) as
    /// [`crate::Scene::build`] would draw them without half-sticks across the cell.
    pub fn bond(&mut self, settings: &BondSettings) -> Result<(), SceneError> {
        let t = Instant::now();
        let p = settings.prepare(&self.molecule, settings.options.pbc)?;
        self.bonds = p.bonds;
        if let Some(u) = p.unwrapped {
            self.molecule = u;
        }
        self.unwrap = p.unwrap;
        self.bond_s = t.elapsed().as_secs_f64();
        Ok(())
    }
}

impl From<ReadError> for SceneError {
    fn from(e: ReadError) -> SceneError {
        SceneError::Read(Box::new(e))
    }
}
