//! Molecular data for bnsview: the [`Molecule`] frame type, the [`elements`] table, file
//! readers ([`read`]), writers ([`mod@write`]), the uniform-grid bond builder ([`bonds`]),
//! unwrapping of molecules split by the periodic boundaries ([`mod@unwrap`]) and the
//! built-in reference scenes ([`scenes`]).
//!
//! All lengths are in Ångström (Å), positions are stored as `f32` structure-of-arrays.
//!
//! Crates doing the heavy lifting: `fast-float2` (float parsing), `memchr` (line splitting),
//! `flate2` (gzip), `rayon` (parallel bonds and scene generation), `thiserror` (errors).
//! Element data was generated from ASE's tables (see [`elements`]); the sample-file oracle is
//! `tests/oracle/make_expected.py` (ASE 3.29).

#![warn(missing_docs)]
pub mod bonds;
pub mod elements;
pub mod motion;
pub mod read;
pub mod scenes;
pub mod unwrap;
pub mod write;

pub use read::{open, Format, FrameIndex, ReadError, ReadOptions, Trajectory};

/// A periodic cell / simulation box: `origin` plus three edge vectors `a`, `b`, `c` (Å).
/// Orthogonal boxes have `a = (lx,0,0)`, `b = (0,ly,0)`, `c = (0,0,lz)`; LAMMPS triclinic boxes
/// have `b = (xy,ly,0)`, `c = (xz,yz,lz)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Lower corner of the box (Å).
    pub origin: [f32; 3],
    /// Edge vectors (Å): `edges[0] = a`, `edges[1] = b`, `edges[2] = c`.
    pub edges: [[f32; 3]; 3],
    /// Whether each direction is periodic (LAMMPS `pp`; XYZ `pbc=`; default true).
    pub pbc: [bool; 3],
}

impl Cell {
    /// Axis-aligned box from lower and upper corners (Å).
    pub fn orthogonal(lo: [f32; 3], hi: [f32; 3]) -> Cell {
        Cell {
            origin: lo,
            edges: [
                [hi[0] - lo[0], 0.0, 0.0],
                [0.0, hi[1] - lo[1], 0.0],
                [0.0, 0.0, hi[2] - lo[2]],
            ],
            pbc: [true; 3],
        }
    }

    /// Volume in Å³ (absolute value of the triple product).
    pub fn volume(&self) -> f64 {
        let [a, b, c] = self.edges.map(|v| v.map(f64::from));
        let cross = [
            b[1] * c[2] - b[2] * c[1],
            b[2] * c[0] - b[0] * c[2],
            b[0] * c[1] - b[1] * c[0],
        ];
        (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]).abs()
    }

    /// Inverse of the edge matrix `H = [a b c]` (columns), for Cartesian → fractional
    /// conversion; `None` if the cell is degenerate.
    pub fn inverse(&self) -> Option<[[f64; 3]; 3]> {
        let h = self.matrix();
        let det = h[0][0] * (h[1][1] * h[2][2] - h[1][2] * h[2][1])
            - h[0][1] * (h[1][0] * h[2][2] - h[1][2] * h[2][0])
            + h[0][2] * (h[1][0] * h[2][1] - h[1][1] * h[2][0]);
        if !det.is_finite() || det.abs() < 1e-12 {
            return None;
        }
        let inv = 1.0 / det;
        let mut r = [[0.0; 3]; 3];
        r[0][0] = (h[1][1] * h[2][2] - h[1][2] * h[2][1]) * inv;
        r[0][1] = (h[0][2] * h[2][1] - h[0][1] * h[2][2]) * inv;
        r[0][2] = (h[0][1] * h[1][2] - h[0][2] * h[1][1]) * inv;
        r[1][0] = (h[1][2] * h[2][0] - h[1][0] * h[2][2]) * inv;
        r[1][1] = (h[0][0] * h[2][2] - h[0][2] * h[2][0]) * inv;
        r[1][2] = (h[0][2] * h[1][0] - h[0][0] * h[1][2]) * inv;
        r[2][0] = (h[1][0] * h[2][1] - h[1][1] * h[2][0]) * inv;
        r[2][1] = (h[0][1] * h[2][0] - h[0][0] * h[2][1]) * inv;
        r[2][2] = (h[0][0] * h[1][1] - h[0][1] * h[1][0]) * inv;
        Some(r)
    }

    /// Edge matrix `H` with the edge vectors as columns: `cart = origin + H · frac`.
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        let e = self.edges;
        let mut h = [[0.0; 3]; 3];
        for (col, v) in e.iter().enumerate() {
            for (row, hr) in h.iter_mut().enumerate() {
                hr[col] = f64::from(v[row]);
            }
        }
        h
    }

    /// Distances (Å) between opposite faces of the cell (perpendicular widths).
    pub fn widths(&self) -> [f64; 3] {
        let v = self.volume();
        let [a, b, c] = self.edges.map(|v| v.map(f64::from));
        let cr = |u: [f64; 3], w: [f64; 3]| {
            let x = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
        };
        [v / cr(b, c), v / cr(c, a), v / cr(a, b)]
    }
}

/// The minimum-image convention of a cell, with its inverse computed once: a displacement's
/// fractional components along the periodic directions are rounded to the nearest lattice
/// vector and taken off (the rule [`bonds`] measures bond lengths with).
#[derive(Clone, Copy, Debug)]
pub struct MinimumImage {
    h: [[f64; 3]; 3],
    inv: [[f64; 3]; 3],
    periodic: [bool; 3],
}

impl MinimumImage {
    /// The convention of `cell`; `None` if the cell is degenerate.
    pub fn new(cell: &Cell) -> Option<MinimumImage> {
        Some(MinimumImage {
            h: cell.matrix(),
            inv: cell.inverse()?,
            periodic: cell.pbc,
        })
    }

    /// The nearest periodic image of displacement `d` (Å).
    pub fn apply(&self, d: [f64; 3]) -> [f64; 3] {
        let mul = |m: &[[f64; 3]; 3], v: [f64; 3]| {
            [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
        };
        let mut f = mul(&self.inv, d);
        for (fk, &per) in f.iter_mut().zip(&self.periodic) {
            if per {
                *fk -= fk.round();
            }
        }
        mul(&self.h, f)
    }
}

/// One frame of atoms. Positions in Å, structure-of-arrays.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Molecule {
    /// x coordinates (Å).
    pub x: Vec<f32>,
    /// y coordinates (Å).
    pub y: Vec<f32>,
    /// z coordinates (Å).
    pub z: Vec<f32>,
    /// Atomic number per atom; 0 = unknown.
    pub elements: Vec<u8>,
    /// Extra per-atom columns by name (e.g. `"q"` charge in e, `"type"`, `"id"`, `"mass"`);
    /// each vector has `len()` entries.
    pub scalars: Vec<(String, Vec<f32>)>,
    /// Periodic cell / box, if the file has one.
    pub cell: Option<Cell>,
    /// Bonds listed in the file (LAMMPS data `Bonds`, PDB `CONECT`) as 0-based atom indices,
    /// `i < j`, sorted and deduplicated.
    pub file_bonds: Option<Vec<[u32; 2]>>,
    /// The positions are already unwrapped across the periodic boundaries by the reader
    /// (LAMMPS dump `xu yu zu` / `xsu ysu zsu` columns, LAMMPS data image flags), so
    /// [`unwrap`] leaves them as they are.
    pub unwrapped: bool,
}

impl Molecule {
    /// Number of atoms.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// True when there are no atoms.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Empty molecule with room for `n` atoms.
    pub fn with_capacity(n: usize) -> Molecule {
        Molecule {
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            elements: Vec::with_capacity(n),
            ..Default::default()
        }
    }

    /// Append one atom at `p` (Å) with atomic number `z`.
    pub fn push(&mut self, p: [f32; 3], z: u8) {
        self.x.push(p[0]);
        self.y.push(p[1]);
        self.z.push(p[2]);
        self.elements.push(z);
    }

    /// Position of atom `i` (Å).
    pub fn position(&self, i: usize) -> [f32; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }

    /// Axis-aligned bounds `(min, max)` of the atom centres (Å); `([0;3],[0;3])` if empty.
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        if self.is_empty() {
            return ([0.0; 3], [0.0; 3]);
        }
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for (k, v) in [&self.x, &self.y, &self.z].into_iter().enumerate() {
            for &c in v.iter() {
                lo[k] = lo[k].min(c);
                hi[k] = hi[k].max(c);
            }
        }
        (lo, hi)
    }

    /// The scalar column called `name`, if present.
    pub fn scalar(&self, name: &str) -> Option<&[f32]> {
        self.scalars
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// Count of atoms per atomic number, sorted by Z: `(Z, count)`.
    pub fn element_counts(&self) -> Vec<(u8, usize)> {
        let mut c = [0usize; 256];
        for &e in &self.elements {
            c[e as usize] += 1;
        }
        (0..256)
            .filter(|&z| c[z] > 0)
            .map(|z| (z as u8, c[z]))
            .collect()
    }

    /// Bytes used by the per-atom arrays (positions, elements, scalars, file bonds).
    pub fn memory_bytes(&self) -> usize {
        self.len() * 13
            + self.scalars.iter().map(|(_, v)| v.len() * 4).sum::<usize>()
            + self.file_bonds.as_ref().map_or(0, |b| b.len() * 8)
    }
}
