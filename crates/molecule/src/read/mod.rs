//! File readers: XYZ / extended XYZ, PDB, LAMMPS dump (text), LAMMPS data, GROMACS `.gro`.
//!
//! [`open`] picks the format from the extension (after stripping `.gz`) or
//! [`ReadOptions::format`], decompresses gzip transparently (detected by its magic bytes, so
//! a misnamed file works too) and returns a [`Trajectory`] that parses frames lazily: only one
//! frame is held in memory at a time, so multi-GB dumps can be streamed.
//!
//! Parsing is hand-written over bytes (no UTF-8 validation, no per-line allocation) with
//! `fast-float2` for numbers. Every error is a [`ReadError`] naming the file, the 1-based line,
//! the 0-based frame and what was expected; no input makes a reader panic.

mod dump;
mod follow;
mod gro;
mod lammps_data;
mod lex;
mod pdb;
mod xyz;

pub use follow::{FollowError, Follower};
pub use lex::CancelTest;
pub(crate) use lex::LineReader;

use crate::Molecule;
use std::fmt;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Supported file formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// XYZ and extended XYZ (multi-frame).
    Xyz,
    /// Protein Data Bank (ATOM/HETATM, MODEL/ENDMDL, CONECT, CRYST1).
    Pdb,
    /// LAMMPS text dump (`ITEM: TIMESTEP` ...).
    LammpsDump,
    /// LAMMPS data file (`read_data` input).
    LammpsData,
    /// GROMACS `.gro` (nm, converted to Å).
    Gro,
}

impl Format {
    /// Canonical name as accepted by `--format`.
    pub fn name(self) -> &'static str {
        match self {
            Format::Xyz => "xyz",
            Format::Pdb => "pdb",
            Format::LammpsDump => "lammps-dump",
            Format::LammpsData => "lammps-data",
            Format::Gro => "gro",
        }
    }

    /// Format implied by a file name's extension (a trailing `.gz` is ignored).
    pub fn from_path(path: &Path) -> Option<Format> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        let ext = name.rsplit_once('.').map(|(_, e)| e)?;
        Some(match ext {
            "xyz" | "extxyz" => Format::Xyz,
            "pdb" | "ent" => Format::Pdb,
            "lammpstrj" | "dump" | "lammpsdump" => Format::LammpsDump,
            "data" | "lmp" | "lammps" => Format::LammpsData,
            "gro" => Format::Gro,
            _ => return None,
        })
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Format {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "xyz" | "extxyz" => Format::Xyz,
            "pdb" => Format::Pdb,
            "lammps-dump" | "dump" | "lammpstrj" => Format::LammpsDump,
            "lammps-data" | "data" => Format::LammpsData,
            "gro" => Format::Gro,
            _ => {
                return Err(format!(
                    "unknown format '{s}' (expected xyz, pdb, lammps-dump, lammps-data or gro)"
                ))
            }
        })
    }
}

/// Options for [`open`].
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Force a format instead of guessing from the file name.
    pub format: Option<Format>,
    /// LAMMPS numeric type → atomic number (`--types 1=Al,2=O`). Takes precedence over masses;
    /// an `element` column in a dump takes precedence over this.
    pub types: Vec<(u32, u8)>,
    /// LAMMPS data atom style (`atomic`, `charge`, `molecular`, `full`) if the `Atoms` header
    /// has no `# style` comment; otherwise guessed from the column count.
    pub atom_style: Option<String>,
}

impl ReadOptions {
    /// Parse a `--types` mapping such as `"1=Al,2=O"`.
    pub fn parse_types(s: &str) -> Result<Vec<(u32, u8)>, String> {
        let mut out = Vec::new();
        for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let (t, e) = item
                .split_once('=')
                .ok_or_else(|| format!("'{item}': expected TYPE=ELEMENT, e.g. 1=Al"))?;
            let t: u32 = t
                .trim()
                .parse()
                .map_err(|_| format!("'{item}': type must be a positive integer"))?;
            let z = crate::elements::by_symbol(e)
                .ok_or_else(|| format!("'{item}': '{}' is not an element symbol", e.trim()))?;
            out.push((t, z));
        }
        Ok(out)
    }

    pub(crate) fn type_element(&self, t: u32) -> Option<u8> {
        self.types.iter().find(|(k, _)| *k == t).map(|(_, z)| *z)
    }
}

/// Error from a reader. Parse errors name the file, the 1-based line, the 0-based frame and
/// what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// Operating-system or decompression error. The message includes the underlying
    /// error's text, so it is deliberately not also exposed as `source()` (an error chain
    /// printer would repeat it).
    #[error("{}: {error}", .path.display())]
    Io {
        /// File being read.
        path: PathBuf,
        /// Underlying error.
        error: io::Error,
    },
    /// Malformed content.
    #[error("{}:{line}: frame {frame}: expected {expected}, found {found}", .path.display())]
    Parse {
        /// File being read.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// 0-based frame index.
        frame: usize,
        /// What the reader expected there.
        expected: String,
        /// What it found (abbreviated).
        found: String,
    },
    /// The file (after decompression) has no content.
    #[error("{}: empty file (expected {format} data)", .path.display())]
    Empty {
        /// File being read.
        path: PathBuf,
        /// Format that was expected.
        format: Format,
    },
    /// No frame of the expected format, and the content looks like another format.
    #[error("{}: no {format} data found; the content looks like {looks_like} (pass --format {looks_like})", .path.display())]
    WrongFormat {
        /// File being read.
        path: PathBuf,
        /// Format that was expected (from the extension or `--format`).
        format: Format,
        /// Format the content was sniffed as.
        looks_like: Format,
    },
    /// Format could not be determined.
    #[error("{}: cannot tell the format from the file name or content; pass --format (xyz, pdb, lammps-dump, lammps-data, gro)", .path.display())]
    UnknownFormat {
        /// File being read.
        path: PathBuf,
    },
    /// A frame counted from the end (`-k`) before the first frame.
    #[error("{}: frame -{back} does not exist (the file has {count} frame(s))", .path.display())]
    NoSuchFrameFromEnd {
        /// File being read.
        path: PathBuf,
        /// Requested frame, counted from the end (1 = last).
        back: usize,
        /// Number of frames in the file.
        count: usize,
    },
    /// The caller stopped the read ([`Trajectory::read_frame_unless`]).
    #[error("{}: reading cancelled", .path.display())]
    Cancelled {
        /// File being read.
        path: PathBuf,
    },
    /// `read_frame(k)` past the end.
    #[error("{}: frame {frame} does not exist (the file has {count} frame(s))", .path.display())]
    NoSuchFrame {
        /// File being read.
        path: PathBuf,
        /// Requested frame.
        frame: usize,
        /// Number of frames in the file.
        count: usize,
    },
}

impl ReadError {
    /// True for a frame cut off by the end of the file (a parse error whose found text is
    /// "end of file ..."): the trajectory's truncated tail.
    pub fn is_truncation(&self) -> bool {
        matches!(self, ReadError::Parse { found, .. }
            if found.trim_start_matches('\'').starts_with("end of file"))
    }
}

/// A frame of a trajectory: `FromStart(k)` is the 0-based frame `k`, `FromEnd(k)` the k-th
/// frame from the end (`FromEnd(1)` = last). Parsed from an integer: `2` → `FromStart(2)`,
/// `-1` → `FromEnd(1)`. Resolved by [`Trajectory::resolve_frame`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameIndex {
    /// 0-based index from the first frame.
    FromStart(usize),
    /// 1-based index from the last frame.
    FromEnd(usize),
}

impl From<i64> for FrameIndex {
    fn from(k: i64) -> FrameIndex {
        if k < 0 {
            FrameIndex::FromEnd(k.unsigned_abs() as usize)
        } else {
            FrameIndex::FromStart(k as usize)
        }
    }
}

impl FromStr for FrameIndex {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        s.trim()
            .parse::<i64>()
            .map(FrameIndex::from)
            .map_err(|_| format!("'{s}': expected a frame number (0 = first, -1 = last)"))
    }
}

impl fmt::Display for FrameIndex {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FrameIndex::FromStart(k) => write!(f, "{k}"),
            FrameIndex::FromEnd(k) => write!(f, "-{k}"),
        }
    }
}

/// A parser for one format: reads frames from a [`LineReader`].
pub(crate) trait FrameParser: Send {
    /// Parse the next frame; `Ok(None)` at a clean end of file.
    fn next_frame(&mut self, r: &mut LineReader) -> Result<Option<Molecule>, ReadError>;
    /// Skip the next frame (may be faster than parsing); `Ok(false)` at end of file.
    fn skip_frame(&mut self, r: &mut LineReader) -> Result<bool, ReadError> {
        Ok(self.next_frame(r)?.is_some())
    }
    /// Warnings collected so far (unknown elements, ...).
    fn warnings(&self) -> &[String];
}

fn new_parser(format: Format, opts: &ReadOptions) -> Box<dyn FrameParser> {
    match format {
        Format::Xyz => Box::new(xyz::XyzParser::default()),
        Format::Pdb => Box::new(pdb::PdbParser::default()),
        Format::LammpsDump => Box::new(dump::DumpParser::new(opts.clone())),
        Format::LammpsData => Box::new(lammps_data::DataParser::new(opts.clone())),
        Format::Gro => Box::new(gro::GroParser::default()),
    }
}

/// Open `path` as a byte stream (gzip-decoded if it starts with the gzip magic), positioned at
/// byte `offset` of the *decoded* stream (seek for plain files, skip for gzip).
/// A reader that adds the bytes it yields to a shared count (bytes decoded: after
/// decompression for gzip).
struct Counted<R> {
    inner: R,
    count: Arc<AtomicU64>,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
}

/// [`open_stream_plain`] counting every decoded byte (skipped ones included) in `count`.
fn open_stream(
    path: &Path,
    offset: u64,
    count: &Arc<AtomicU64>,
) -> Result<(Box<dyn Read + Send>, bool), ReadError> {
    let (src, gz) = open_stream_plain(path, 0)?;
    let mut src: Box<dyn Read + Send> = Box::new(Counted {
        inner: src,
        count: count.clone(),
    });
    if offset > 0 {
        if gz {
            io::copy(&mut (&mut src).take(offset), &mut io::sink()).map_err(|error| {
                ReadError::Io {
                    path: path.to_path_buf(),
                    error,
                }
            })?;
        } else {
            let (f, _) = open_stream_plain(path, offset)?;
            src = Box::new(Counted {
                inner: f,
                count: count.clone(),
            });
        }
    }
    Ok((src, gz))
}

fn open_stream_plain(path: &Path, offset: u64) -> Result<(Box<dyn Read + Send>, bool), ReadError> {
    let io_err = |error| ReadError::Io {
        path: path.to_path_buf(),
        error,
    };
    let mut f = File::open(path).map_err(io_err)?;
    let mut magic = [0u8; 2];
    let mut got = 0;
    while got < 2 {
        match f.read(&mut magic[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io_err(e)),
        }
    }
    let gz = got == 2 && magic == [0x1f, 0x8b];
    f.seek(SeekFrom::Start(if gz { 0 } else { offset }))
        .map_err(io_err)?;
    if gz {
        let mut d: Box<dyn Read + Send> = Box::new(flate2::read::MultiGzDecoder::new(
            io::BufReader::with_capacity(1 << 16, f),
        ));
        if offset > 0 {
            io::copy(&mut (&mut d).take(offset), &mut io::sink()).map_err(io_err)?;
        }
        Ok((d, true))
    } else {
        Ok((Box::new(f), false))
    }
}

fn sniff(path: &Path) -> Result<Option<Format>, ReadError> {
    let (src, _) = open_stream_plain(path, 0)?;
    let mut r = LineReader::new(src, Arc::from(path));
    // The first lines (raw, up to 40) for the format-specific checks below.
    let mut head: Vec<Vec<u8>> = Vec::new();
    while head.len() < 40 {
        match r.next_line() {
            Ok(Some((_, line))) => head.push(lex::trim(line).to_vec()),
            Ok(None) => break,
            Err(e) if head.is_empty() => return Err(e),
            Err(_) => break,
        }
    }
    Ok(sniff_lines(&head))
}

/// Format guessed from the first lines of a file (trimmed), if any.
fn sniff_lines(head: &[Vec<u8>]) -> Option<Format> {
    let t = head.iter().find(|l| !l.is_empty())?;
    let is_count = |l: &[u8]| lex::parse_usize(l).is_some();
    // .gro: title, atom count, then fixed-column atom lines (>= 44 columns).
    if head.len() >= 3 && !is_count(&head[0]) && is_count(&head[1]) && head[2].len() >= 36 {
        return Some(Format::Gro);
    }
    // LAMMPS data: title, then header lines such as "N atoms".
    if head.iter().skip(1).any(|l| {
        let w: Vec<&[u8]> = lex::fields(l).collect();
        w.len() == 2 && w[1] == b"atoms" && is_count(w[0])
    }) {
        return Some(Format::LammpsData);
    }
    if t.starts_with(b"ITEM:") {
        Some(Format::LammpsDump)
    } else if lex::parse_usize(t).is_some() {
        Some(Format::Xyz)
    } else if [
        &b"ATOM"[..],
        b"HETATM",
        b"HEADER",
        b"REMARK",
        b"CRYST1",
        b"MODEL",
        b"COMPND",
        b"TITLE",
    ]
    .iter()
    .any(|p| t.starts_with(p))
    {
        Some(Format::Pdb)
    } else {
        None
    }
}

/// The error for a file with no frame of `format`: [`ReadError::WrongFormat`] when the
/// content sniffs as another format, else [`ReadError::Empty`].
fn empty_error(path: &Path, format: Format) -> ReadError {
    match sniff(path) {
        Ok(Some(f)) if f != format => ReadError::WrongFormat {
            path: path.to_path_buf(),
            format,
            looks_like: f,
        },
        _ => ReadError::Empty {
            path: path.to_path_buf(),
            format,
        },
    }
}

/// Open a trajectory. Frames are parsed lazily; see [`Trajectory`].
pub fn open(path: &Path, opts: &ReadOptions) -> Result<Trajectory, ReadError> {
    open_counted(path, opts, Arc::new(AtomicU64::new(0)))
}

/// [`open`] adding every byte it decodes to `decoded` (a count shared with a progress
/// display, such as [`Trajectory::decoded_bytes`] reads).
pub fn open_counted(
    path: &Path,
    opts: &ReadOptions,
    decoded: Arc<AtomicU64>,
) -> Result<Trajectory, ReadError> {
    let format = match opts.format.or_else(|| Format::from_path(path)) {
        Some(f) => f,
        None => sniff(path)?.ok_or_else(|| ReadError::UnknownFormat {
            path: path.to_path_buf(),
        })?,
    };
    let (src, gz) = open_stream(path, 0, &decoded)?;
    let path: Arc<Path> = Arc::from(path);
    let reader = LineReader::new(src, path.clone());
    Ok(Trajectory {
        path,
        format,
        gz,
        opts: opts.clone(),
        reader,
        parser: new_parser(format, opts),
        next_index: 0,
        frame_starts: None,
        count: None,
        failed: false,
        tail_warning: None,
        all_warnings: Vec::new(),
        decoded,
        cancel: None,
    })
}

/// Open `path` and read its first frame (convenience for single-structure files).
pub fn read_first(path: &Path, opts: &ReadOptions) -> Result<Molecule, ReadError> {
    let mut t = open(path, opts)?;
    t.read_frame(0)
}

/// A lazily read sequence of frames from one file.
///
/// Truncated tail: a frame after the first that the end of the file cuts off
/// ([`ReadError::is_truncation`]) is not a frame. Iteration, [`Trajectory::read_frame`] and
/// [`Trajectory::count_frames`] all stop before it and add a warning naming the line, so
/// every caller sees the same frame count. (A cut first frame stays an error.)
///
/// Iterating yields `Result<Molecule, ReadError>` one frame at a time; iteration stops after
/// the first error. [`Trajectory::count_frames`] scans the file once (skipping atom lines
/// where the format allows) and remembers where frames start, so later
/// [`Trajectory::read_frame`] calls seek directly (plain files) or re-decompress (gzip).
pub struct Trajectory {
    path: Arc<Path>,
    format: Format,
    gz: bool,
    opts: ReadOptions,
    reader: LineReader,
    parser: Box<dyn FrameParser>,
    next_index: usize,
    /// (decoded byte offset, lines before) of each frame start, after a full scan.
    frame_starts: Option<Vec<(u64, u64)>>,
    count: Option<usize>,
    failed: bool,
    /// Warning about a truncated last frame, once seen.
    tail_warning: Option<String>,
    /// Parser warnings plus `tail_warning`, rebuilt by [`Trajectory::warnings`].
    all_warnings: Vec<String>,
    /// Bytes decoded from the file so far, over every pass ([`Trajectory::decoded_bytes`]).
    decoded: Arc<AtomicU64>,
    /// The cancel test of the read in progress ([`Trajectory::read_frame_unless`]).
    cancel: Option<CancelTest>,
}

impl Trajectory {
    /// Format being read.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Path being read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes read from the file so far — decompressed bytes for gzip — summed over every pass
    /// (counting frames, seeking back, reading on): a single sequential read of the whole file
    /// decodes its (uncompressed) size once.
    pub fn decoded_bytes(&self) -> u64 {
        self.decoded.load(Ordering::Relaxed)
    }

    /// A new trajectory over the same file with the same options, at its first frame (its
    /// [`Trajectory::decoded_bytes`] counts from zero).
    pub fn reopen(&self) -> Result<Trajectory, ReadError> {
        let opts = ReadOptions {
            format: Some(self.format),
            ..self.opts.clone()
        };
        open(&self.path, &opts)
    }

    /// Whether the file is gzip-compressed.
    pub fn is_gzip(&self) -> bool {
        self.gz
    }

    /// Warnings so far (e.g. unknown element symbols, mapped to Z = 0; a truncated last
    /// frame).
    pub fn warnings(&mut self) -> &[String] {
        self.all_warnings = self.parser.warnings().to_vec();
        if let Some(w) = &self.tail_warning {
            self.all_warnings.push(w.clone());
        }
        &self.all_warnings
    }

    fn note_truncated_tail(&mut self, e: &ReadError, complete: usize) {
        if self.tail_warning.is_none() {
            self.tail_warning = Some(format!(
                "{e}; the file ends inside frame {complete}, which is ignored ({complete} complete frame(s))"
            ));
        }
    }

    /// The 0-based index of `idx`; [`FrameIndex::FromEnd`] counts the frames first.
    /// Errors when the frame does not exist, naming the frame count.
    pub fn resolve_frame(&mut self, idx: FrameIndex) -> Result<usize, ReadError> {
        match idx {
            FrameIndex::FromStart(k) => Ok(k),
            FrameIndex::FromEnd(back) => {
                let count = self.count_frames()?;
                if back == 0 || back > count {
                    return Err(ReadError::NoSuchFrameFromEnd {
                        path: self.path.to_path_buf(),
                        back,
                        count,
                    });
                }
                Ok(count - back)
            }
        }
    }

    /// Read the frame `idx` (from the start or the end, see [`FrameIndex`]).
    pub fn read_frame_at(&mut self, idx: FrameIndex) -> Result<Molecule, ReadError> {
        let k = self.resolve_frame(idx)?;
        self.read_frame(k)
    }

    /// Number of frames (scans the whole file once; cached). An empty file is an error.
    pub fn count_frames(&mut self) -> Result<usize, ReadError> {
        if let Some(c) = self.count {
            return Ok(c);
        }
        let (src, _) = open_stream(&self.path, 0, &self.decoded)?;
        let mut r = LineReader::new(src, self.path.clone());
        let mut p = new_parser(self.format, &self.opts);
        let mut starts = Vec::new();
        loop {
            r.frame = starts.len();
            let at = (r.offset(), r.line_no());
            match p.skip_frame(&mut r) {
                Ok(true) => starts.push(at),
                Ok(false) => break,
                Err(e) if e.is_truncation() && !starts.is_empty() => {
                    self.note_truncated_tail(&e, starts.len());
                    break;
                }
                Err(e) => return Err(e),
            }
        }
        if starts.is_empty() {
            return Err(empty_error(&self.path, self.format));
        }
        self.count = Some(starts.len());
        self.frame_starts = Some(starts);
        Ok(self.count.unwrap_or(0))
    }

    /// [`Trajectory::read_frame`] asking `cancel` first and before each buffer of input
    /// (about 1 MiB): once it returns true the read stops with [`ReadError::Cancelled`] (a
    /// viewer stops reading a time step the user has moved past). The next read of any frame
    /// starts afresh from that frame's start.
    pub fn read_frame_unless(
        &mut self,
        k: usize,
        cancel: CancelTest,
    ) -> Result<Molecule, ReadError> {
        if cancel() {
            return Err(ReadError::Cancelled {
                path: self.path.to_path_buf(),
            });
        }
        self.cancel = Some(cancel);
        let r = self.read_frame(k);
        self.cancel = None;
        self.reader.cancel = None;
        r
    }

    /// Read frame `k` (0-based). Sequential calls (`k` = the next frame) do not re-read.
    pub fn read_frame(&mut self, k: usize) -> Result<Molecule, ReadError> {
        if k != self.next_index || self.failed {
            self.seek_frame(k)?;
        }
        match self.next_frame()? {
            Some(m) => Ok(m),
            None if k == 0 => Err(empty_error(&self.path, self.format)),
            None => Err(ReadError::NoSuchFrame {
                path: self.path.to_path_buf(),
                frame: k,
                count: k,
            }),
        }
    }

    fn seek_frame(&mut self, k: usize) -> Result<(), ReadError> {
        self.failed = false;
        if let Some(starts) = &self.frame_starts {
            let Some(&(off, line)) = starts.get(k) else {
                return Err(ReadError::NoSuchFrame {
                    path: self.path.to_path_buf(),
                    frame: k,
                    count: starts.len(),
                });
            };
            // Data files have a header shared by all frames: only seek formats with
            // self-contained frames.
            if self.format != Format::LammpsData {
                let (src, _) = open_stream(&self.path, off, &self.decoded)?;
                self.reader = LineReader::new(src, self.path.clone());
                self.reader.set_position(off, line);
                self.parser = new_parser(self.format, &self.opts);
                self.next_index = k;
                return Ok(());
            }
        }
        let (src, _) = open_stream(&self.path, 0, &self.decoded)?;
        self.reader = LineReader::new(src, self.path.clone());
        self.parser = new_parser(self.format, &self.opts);
        self.next_index = 0;
        while self.next_index < k {
            self.reader.frame = self.next_index;
            let more = match self.parser.skip_frame(&mut self.reader) {
                Err(e) if e.is_truncation() && self.next_index > 0 => {
                    self.note_truncated_tail(&e, self.next_index);
                    false
                }
                other => other?,
            };
            if !more {
                return Err(ReadError::NoSuchFrame {
                    path: self.path.to_path_buf(),
                    frame: k,
                    count: self.next_index,
                });
            }
            self.next_index += 1;
        }
        Ok(())
    }

    fn next_frame(&mut self) -> Result<Option<Molecule>, ReadError> {
        if self.failed {
            return Ok(None);
        }
        self.reader.frame = self.next_index;
        self.reader.cancel = self.cancel.clone();
        match self.parser.next_frame(&mut self.reader) {
            Ok(Some(m)) => {
                self.next_index += 1;
                Ok(Some(m))
            }
            Ok(None) => {
                if self.next_index == 0 {
                    self.failed = true;
                    return Err(empty_error(&self.path, self.format));
                }
                Ok(None)
            }
            Err(e) if e.is_truncation() && self.next_index > 0 => {
                self.failed = true;
                self.note_truncated_tail(&e, self.next_index);
                Ok(None)
            }
            Err(e) => {
                self.failed = true;
                Err(e)
            }
        }
    }
}

impl Iterator for Trajectory {
    type Item = Result<Molecule, ReadError>;
    fn next(&mut self) -> Option<Self::Item> {
        self.next_frame().transpose()
    }
}

/// Parse a whole in-memory buffer with the given format (used by tests and fuzzing; the file
/// name in errors is `<memory>`).
pub fn parse_bytes(
    data: &[u8],
    format: Format,
    opts: &ReadOptions,
) -> Result<Vec<Molecule>, ReadError> {
    let path: Arc<Path> = Arc::from(Path::new("<memory>"));
    let src: Box<dyn Read + Send> = Box::new(io::Cursor::new(data.to_vec()));
    let mut r = LineReader::new(src, path.clone());
    let mut p = new_parser(format, opts);
    let mut out = Vec::new();
    loop {
        r.frame = out.len();
        match p.next_frame(&mut r) {
            Ok(Some(m)) => out.push(m),
            Ok(None) => break,
            // Same truncated-tail rule as [`Trajectory`].
            Err(e) if e.is_truncation() && !out.is_empty() => break,
            Err(e) => return Err(e),
        }
    }
    if out.is_empty() {
        return Err(ReadError::Empty {
            path: path.to_path_buf(),
            format,
        });
    }
    Ok(out)
}
