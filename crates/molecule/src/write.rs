//! Writers: extended XYZ and LAMMPS text dump, one frame or a whole trajectory file (for
//! `bnsview generate`).

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use flate2::write::GzEncoder;
use flate2::Compression;

use crate::{elements, Molecule};

fn lattice(m: &Molecule) -> String {
    match &m.cell {
        Some(c) => {
            let e = c.edges;
            format!(
                "Lattice=\"{} {} {} {} {} {} {} {} {}\" ",
                e[0][0], e[0][1], e[0][2], e[1][0], e[1][1], e[1][2], e[2][0], e[2][1], e[2][2]
            )
        }
        None => String::new(),
    }
}

/// Write one frame as extended XYZ (`Properties=species:S:1:pos:R:3`, positions in Å with
/// 5 decimals).
pub fn write_xyz<W: Write + ?Sized>(w: &mut W, m: &Molecule, comment: &str) -> io::Result<()> {
    writeln!(w, "{}", m.len())?;
    writeln!(
        w,
        "{}Properties=species:S:1:pos:R:3 comment=\"{}\"",
        lattice(m),
        comment.replace('"', "'")
    )?;
    for i in 0..m.len() {
        writeln!(
            w,
            "{} {:.5} {:.5} {:.5}",
            elements::element(m.elements[i]).symbol,
            m.x[i],
            m.y[i],
            m.z[i]
        )?;
    }
    Ok(())
}

/// Write one frame as a LAMMPS text dump with columns `id type element x y z`; types are
/// numbered by ascending atomic number. The box is the cell if any, else the bounds padded
/// by 1 Å (non-periodic `ff`).
pub fn write_lammps_dump<W: Write + ?Sized>(
    w: &mut W,
    m: &Molecule,
    timestep: u64,
) -> io::Result<()> {
    let counts = m.element_counts();
    let mut type_of = [0u32; 256];
    for (t, (z, _)) in counts.iter().enumerate() {
        type_of[*z as usize] = t as u32 + 1;
    }
    writeln!(
        w,
        "ITEM: TIMESTEP\n{timestep}\nITEM: NUMBER OF ATOMS\n{}",
        m.len()
    )?;
    match &m.cell {
        Some(c) if c.edges[0][1] == 0.0 && c.edges[0][2] == 0.0 && c.edges[1][2] == 0.0 => {
            let o = c.origin;
            let e = c.edges;
            let (xy, xz, yz) = (e[1][0], e[2][0], e[2][1]);
            let (xlo, xhi) = (o[0], o[0] + e[0][0]);
            let (ylo, yhi) = (o[1], o[1] + e[1][1]);
            let (zlo, zhi) = (o[2], o[2] + e[2][2]);
            if xy == 0.0 && xz == 0.0 && yz == 0.0 {
                writeln!(
                    w,
                    "ITEM: BOX BOUNDS pp pp pp\n{xlo} {xhi}\n{ylo} {yhi}\n{zlo} {zhi}"
                )?;
            } else {
                let xlob = xlo + 0f32.min(xy).min(xz).min(xy + xz);
                let xhib = xhi + 0f32.max(xy).max(xz).max(xy + xz);
                let ylob = ylo + 0f32.min(yz);
                let yhib = yhi + 0f32.max(yz);
                writeln!(
                    w,
                    "ITEM: BOX BOUNDS xy xz yz pp pp pp\n{xlob} {xhib} {xy}\n{ylob} {yhib} {xz}\n{zlo} {zhi} {yz}"
                )?;
            }
        }
        _ => {
            let (lo, hi) = m.bounds();
            writeln!(
                w,
                "ITEM: BOX BOUNDS ff ff ff\n{} {}\n{} {}\n{} {}",
                lo[0] - 1.0,
                hi[0] + 1.0,
                lo[1] - 1.0,
                hi[1] + 1.0,
                lo[2] - 1.0,
                hi[2] + 1.0
            )?;
        }
    }
    writeln!(w, "ITEM: ATOMS id type element x y z")?;
    for i in 0..m.len() {
        let z = m.elements[i];
        writeln!(
            w,
            "{} {} {} {:.5} {:.5} {:.5}",
            i + 1,
            type_of[z as usize],
            elements::element(z).symbol,
            m.x[i],
            m.y[i],
            m.z[i]
        )?;
    }
    Ok(())
}

/// Why a trajectory file could not be created.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The name says neither XYZ nor LAMMPS dump.
    #[error("{}: unknown output format; use a .xyz or .lammpstrj name (optionally .gz)", path.display())]
    UnknownFormat {
        /// The file name given.
        path: PathBuf,
    },
    /// The file exists and overwriting was not asked for.
    #[error("{} exists; pass --force to overwrite it", path.display())]
    Exists {
        /// The file.
        path: PathBuf,
    },
    /// Creating the file failed.
    #[error("cannot create {}: {source}", path.display())]
    Create {
        /// The file.
        path: PathBuf,
        /// Why.
        source: io::Error,
    },
}

/// Where the frames go: buffered, through gzip for a `.gz` name (buffered in front of the
/// encoder too: the writers make a call per number, and each call into the deflater costs far
/// more than a copy into a buffer).
enum Out {
    Plain(BufWriter<File>),
    Gzip(BufWriter<GzEncoder<BufWriter<File>>>),
}

/// A trajectory file being written, frame by frame: extended XYZ (`.xyz`, `.extxyz`) or
/// LAMMPS dump (`.lammpstrj`, `.dump`), gzip-compressed when the name ends in `.gz`.
pub struct TrajectoryWriter {
    out: Out,
    xyz: bool,
    frames: u64,
}

impl TrajectoryWriter {
    /// Creates `path` (an existing file only with `force`), its format from its name.
    pub fn create(path: &Path, force: bool) -> Result<TrajectoryWriter, WriteError> {
        let name = path.to_string_lossy().to_ascii_lowercase();
        let base = name.strip_suffix(".gz").unwrap_or(&name);
        let xyz = if base.ends_with(".xyz") || base.ends_with(".extxyz") {
            true
        } else if base.ends_with(".lammpstrj") || base.ends_with(".dump") {
            false
        } else {
            return Err(WriteError::UnknownFormat { path: path.into() });
        };
        let mut opts = OpenOptions::new();
        opts.write(true);
        if force {
            opts.create(true).truncate(true);
        } else {
            opts.create_new(true);
        }
        let file = opts.open(path).map_err(|source| match source.kind() {
            io::ErrorKind::AlreadyExists => WriteError::Exists { path: path.into() },
            _ => WriteError::Create {
                path: path.into(),
                source,
            },
        })?;
        let buf = BufWriter::with_capacity(1 << 20, file);
        let out = if name.ends_with(".gz") {
            let e = GzEncoder::new(buf, Compression::fast());
            Out::Gzip(BufWriter::with_capacity(1 << 20, e))
        } else {
            Out::Plain(buf)
        };
        Ok(TrajectoryWriter {
            out,
            xyz,
            frames: 0,
        })
    }

    /// Appends frame `m` (the XYZ comment line is `comment` and the frame number; the
    /// LAMMPS timestep is the frame number).
    pub fn write(&mut self, m: &Molecule, comment: &str) -> io::Result<()> {
        let w: &mut dyn Write = match &mut self.out {
            Out::Plain(w) => w,
            Out::Gzip(w) => w,
        };
        if self.xyz {
            write_xyz(w, m, &format!("{comment} frame {}", self.frames))?;
        } else {
            write_lammps_dump(w, m, self.frames)?;
        }
        self.frames += 1;
        Ok(())
    }

    /// Flushes the buffers and ends the gzip stream.
    pub fn finish(self) -> io::Result<()> {
        match self.out {
            Out::Plain(mut b) => b.flush(),
            Out::Gzip(e) => {
                let e = e.into_inner().map_err(|e| e.into_error())?;
                e.finish()?.flush()
            }
        }
    }
}
