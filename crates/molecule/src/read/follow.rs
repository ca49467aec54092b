//! Following a trajectory that a running simulation is still writing (`render --follow`).
//!
//! A [`Follower`] remembers where its last complete frame ended (byte offset and line) and, on
//! each [`Follower::try_next`], parses on from there over the bytes up to the file's last
//! newline only: a half-written line is never seen, and a frame the end of the file cuts off
//! means "not yet", not an error. It polls file metadata (no inotify), so it works on NFS.
//! A file that shrinks below what was read, is replaced by another file, or has its already
//! read bytes rewritten (a restarted run) stops it with [`FollowError`].

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{
    new_parser, open_stream_plain, Format, FrameParser, LineReader, ReadError, ReadOptions,
};
use crate::Molecule;

/// Bytes just before the end of the last frame read, compared on every poll to notice a file
/// rewritten in place.
const WITNESS: u64 = 256;

/// Why following a file stopped.
#[derive(Debug, thiserror::Error)]
pub enum FollowError {
    /// Reading or parsing failed (a malformed complete line, or an I/O error).
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The format or compression cannot be followed.
    #[error("{}: --follow {why}", .path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is not supported and what to do instead.
        why: String,
    },
    /// The file is now shorter than what was already read.
    #[error("{}: the file shrank from {was} to {now} bytes while being followed (was the run restarted?); the {frames} frame(s) read so far are kept — start bnsview again to follow the new run", .path.display())]
    Shrunk {
        /// The file.
        path: PathBuf,
        /// Bytes read so far.
        was: u64,
        /// Its size now.
        now: u64,
        /// Complete frames read before.
        frames: usize,
    },
    /// Another file now has this name, or the bytes already read changed.
    #[error("{}: the file was replaced or rewritten while being followed (was the run restarted?); the {frames} frame(s) read so far are kept — start bnsview again to follow the new run", .path.display())]
    Replaced {
        /// The file.
        path: PathBuf,
        /// Complete frames read before.
        frames: usize,
    },
}

/// Identity of an open file: (device, inode) on Unix; `None` elsewhere.
fn identity(meta: &std::fs::Metadata) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some((meta.dev(), meta.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        None
    }
}

/// Reads the complete frames of a growing file, one at a time, as they appear.
pub struct Follower {
    path: Arc<Path>,
    format: Format,
    parser: Box<dyn FrameParser>,
    /// Byte offset and line count where the next frame starts.
    offset: u64,
    lines: u64,
    /// Complete frames read.
    frames: usize,
    /// File identity when opened.
    id: Option<(u64, u64)>,
    /// The last [`WITNESS`] bytes before `offset`.
    witness: Vec<u8>,
    /// File length at the last attempt that found no complete frame (skip re-parsing until
    /// the file grows).
    waited_at: Option<u64>,
}

impl Follower {
    /// Follows `path` from its start. The file must exist; formats whose frames say their own
    /// length (XYZ, `.gro`, LAMMPS dump) can be followed, uncompressed.
    pub fn new(path: &Path, opts: &ReadOptions) -> Result<Follower, FollowError> {
        let unsupported = |why: &str| FollowError::Unsupported {
            path: path.to_path_buf(),
            why: why.to_string(),
        };
        let io_err = |error| ReadError::Io {
            path: path.to_path_buf(),
            error,
        };
        let meta = std::fs::metadata(path).map_err(io_err)?;
        if !meta.is_file() {
            return Err(unsupported("needs a regular file"));
        }
        let (_, gz) = open_stream_plain(path, 0)?;
        if gz {
            return Err(unsupported(
                "needs an uncompressed file: a gzip stream cannot be read while it is written \
                 (write the dump uncompressed, or render the finished file with --frames all)",
            ));
        }
        let format = match opts.format.or_else(|| Format::from_path(path)) {
            Some(f) => f,
            None => super::sniff(path)?.ok_or_else(|| ReadError::UnknownFormat {
                path: path.to_path_buf(),
            })?,
        };
        match format {
            Format::Xyz | Format::Gro | Format::LammpsDump => {}
            Format::Pdb => {
                return Err(unsupported(
                    "cannot follow PDB: a PDB frame does not say how many atoms it has, so a \
                     half-written one cannot be told from a finished one (write XYZ, .gro or a \
                     LAMMPS dump)",
                ))
            }
            Format::LammpsData => {
                return Err(unsupported(
                    "cannot follow a LAMMPS data file (it holds one configuration; follow the \
                     run's dump file)",
                ))
            }
        }
        Ok(Follower {
            path: Arc::from(path),
            format,
            parser: new_parser(format, opts),
            offset: 0,
            lines: 0,
            frames: 0,
            id: identity(&meta),
            witness: Vec::new(),
            waited_at: None,
        })
    }

    /// Format being read.
    pub fn format(&self) -> Format {
        self.format
    }

    /// Path being followed.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Complete frames returned so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Reader warnings so far (unknown elements, ...).
    pub fn warnings(&self) -> &[String] {
        self.parser.warnings()
    }

    fn io_err(&self, error: io::Error) -> FollowError {
        FollowError::Read(ReadError::Io {
            path: self.path.to_path_buf(),
            error,
        })
    }

    /// The next complete frame if the file holds one now, else `None` (call again later).
    /// Never blocks; each call costs one `stat` when the file has not grown.
    pub fn try_next(&mut self) -> Result<Option<Molecule>, FollowError> {
        let meta = std::fs::metadata(&self.path).map_err(|e| self.io_err(e))?;
        if self.id.is_some() && identity(&meta) != self.id {
            return Err(FollowError::Replaced {
                path: self.path.to_path_buf(),
                frames: self.frames,
            });
        }
        let len = meta.len();
        if len < self.offset {
            return Err(FollowError::Shrunk {
                path: self.path.to_path_buf(),
                was: self.offset,
                now: len,
                frames: self.frames,
            });
        }
        if len == self.offset || self.waited_at == Some(len) {
            return Ok(None);
        }
        let mut f = File::open(&self.path).map_err(|e| self.io_err(e))?;
        self.check_witness(&mut f)?;
        let complete = last_line_end(&mut f, self.offset, len).map_err(|e| self.io_err(e))?;
        if complete == self.offset {
            self.waited_at = Some(len);
            return Ok(None);
        }
        f.seek(SeekFrom::Start(self.offset))
            .map_err(|e| self.io_err(e))?;
        let src: Box<dyn Read + Send> = Box::new(f.take(complete - self.offset));
        let mut r = LineReader::new(src, self.path.clone());
        r.set_position(self.offset, self.lines);
        r.frame = self.frames;
        match self.parser.next_frame(&mut r) {
            Ok(Some(m)) => {
                self.offset = r.offset();
                self.lines = r.line_no();
                self.frames += 1;
                self.waited_at = None;
                self.witness = read_witness(&self.path, self.offset).map_err(|e| self.io_err(e))?;
                Ok(Some(m))
            }
            Ok(None) => {
                self.waited_at = Some(len);
                Ok(None)
            }
            Err(e) if e.is_truncation() => {
                self.waited_at = Some(len);
                Ok(None)
            }
            Err(e) => Err(e.into()),
        }
    }

    /// Errors when the bytes before `offset` are no longer the ones read.
    fn check_witness(&self, f: &mut File) -> Result<(), FollowError> {
        if self.witness.is_empty() {
            return Ok(());
        }
        let start = self.offset - self.witness.len() as u64;
        let mut now = vec![0u8; self.witness.len()];
        f.seek(SeekFrom::Start(start))
            .and_then(|_| f.read_exact(&mut now))
            .map_err(|e| self.io_err(e))?;
        if now != self.witness {
            return Err(FollowError::Replaced {
                path: self.path.to_path_buf(),
                frames: self.frames,
            });
        }
        Ok(())
    }
}

/// The last [`WITNESS`] bytes before `end`.
fn read_witness(path: &Path, end: u64) -> io::Result<Vec<u8>> {
    let start = end.saturating_sub(WITNESS);
    let mut f = File::open(path)?;
    f.seek(SeekFrom::Start(start))?;
    let mut w = vec![0u8; (end - start) as usize];
    f.read_exact(&mut w)?;
    Ok(w)
}

/// One past the last `\n` in `f[from..len]`, or `from` if there is none: the end of the
/// complete lines.
fn last_line_end(f: &mut File, from: u64, len: u64) -> io::Result<u64> {
    const CHUNK: u64 = 1 << 16;
    let mut buf = vec![0u8; CHUNK as usize];
    let mut hi = len;
    while hi > from {
        let lo = hi.saturating_sub(CHUNK).max(from);
        let b = &mut buf[..(hi - lo) as usize];
        f.seek(SeekFrom::Start(lo))?;
        f.read_exact(b)?;
        if let Some(k) = b.iter().rposition(|&c| c == b'\n') {
            return Ok(lo + k as u64 + 1);
        }
        hi = lo;
    }
    Ok(from)
}
