//! Unwrapping across the periodic boundaries (issue #15): putting back together the molecules
//! a simulation box has split, by moving atoms by whole lattice vectors of the [`Cell`].
//!
//! Every method gives each atom an integer image `n = (n_a, n_b, n_c)` and moves it to
//! `position + n_a·a + n_b·b + n_c·c` (Å, with the cell's edge vectors `a`, `b`, `c`, so
//! orthogonal and triclinic boxes are handled alike). The images come from, in order
//! ([`UnwrapMethod::of`]):
//!
//! 1. nowhere, when the reader already unwrapped the positions ([`Molecule::unwrapped`]: a
//!    LAMMPS dump whose coordinates are `xu yu zu` or `xsu ysu zsu`, a LAMMPS data file with
//!    image flags). Image flags in such a dump are *not* applied a second time.
//! 2. the LAMMPS image flags `ix iy iz`, per-atom columns of a dump kept as the scalars
//!    `"ix"`, `"iy"`, `"iz"` (all three needed): [`image_flags`].
//! 3. the bonds, by minimum image ([`images_along_bonds`]): each connected component is walked
//!    breadth first from its lowest-index atom, which stays where it is, and every atom is put
//!    at the minimum image of its offset from the atom it was reached from. Afterwards every
//!    bond of the walk's spanning tree equals its minimum-image vector; so does every other
//!    bond unless the component is periodic itself (a network or polymer bonded to its own
//!    image, such as bulk silica), where some bonds must still cross.
//!
//! A molecule unwrapped by bonds may jump by a lattice vector between the frames of a
//! trajectory (when its lowest-index atom crosses the boundary); image flags do not.
//! Bonds for method 3 should be detected with the minimum image
//! ([`crate::bonds::BondOptions::pbc`]), or be the file's topology.

use crate::{Cell, MinimumImage, Molecule};

/// Where the lattice images of [`unwrap`] come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnwrapMethod {
    /// The reader already unwrapped the positions ([`Molecule::unwrapped`]); nothing moves.
    AlreadyUnwrapped,
    /// The LAMMPS image flags `ix iy iz` (per-atom scalars).
    ImageFlags,
    /// Minimum image along the bonds, breadth first from each component's lowest-index atom.
    Bonds,
}

impl UnwrapMethod {
    /// The method [`unwrap`] uses for `m`: already unwrapped, else image flags when the three
    /// columns `ix iy iz` are present, else bonds.
    pub fn of(m: &Molecule) -> UnwrapMethod {
        if m.unwrapped {
            UnwrapMethod::AlreadyUnwrapped
        } else if image_flag_columns(m).is_some() {
            UnwrapMethod::ImageFlags
        } else {
            UnwrapMethod::Bonds
        }
    }

    /// Human description for reports (`-v`).
    pub fn describe(self) -> &'static str {
        match self {
            UnwrapMethod::AlreadyUnwrapped => "positions already unwrapped in the file (xu yu zu)",
            UnwrapMethod::ImageFlags => "image flags ix iy iz",
            UnwrapMethod::Bonds => "minimum image along the bonds",
        }
    }
}

/// Why a molecule could not be unwrapped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UnwrapError {
    /// No cell: nothing to unwrap by.
    #[error("unwrapping needs a periodic cell (box), and the input has none")]
    NoCell,
    /// A cell of zero volume.
    #[error(
        "unwrapping needs a periodic cell (box) of non-zero volume; the input's is degenerate"
    )]
    DegenerateCell,
    /// An image flag that is not an integer.
    #[error("image flag {column} of atom {atom} (1-based) is {value}, not an integer")]
    BadImageFlag {
        /// `ix`, `iy` or `iz`.
        column: &'static str,
        /// 1-based atom index.
        atom: usize,
        /// The value found.
        value: f32,
    },
    /// A bond naming an atom that does not exist.
    #[error("bond {i}-{j} (0-based) names an atom beyond the {atoms} atoms")]
    BadBond {
        /// First atom.
        i: u32,
        /// Second atom.
        j: u32,
        /// Atom count.
        atoms: usize,
    },
    /// A position that is no longer finite in `f32` after the shift.
    #[error("atom {atom} (1-based) is not at a finite position in f32 after unwrapping")]
    NotFinite {
        /// 1-based atom index.
        atom: usize,
    },
}

/// The `ix iy iz` scalar columns, if all three are present.
fn image_flag_columns(m: &Molecule) -> Option<[&[f32]; 3]> {
    Some([m.scalar("ix")?, m.scalar("iy")?, m.scalar("iz")?])
}

/// The lattice image of every atom from the `ix iy iz` columns (`None`: not all three there).
pub fn image_flags(m: &Molecule) -> Option<Result<Vec<[i32; 3]>, UnwrapError>> {
    let cols = image_flag_columns(m)?;
    const NAMES: [&str; 3] = ["ix", "iy", "iz"];
    let flag = |k: usize, i: usize| {
        let v = cols[k].get(i).copied().unwrap_or(0.0);
        if v.is_finite() && v.fract() == 0.0 && v.abs() <= i32::MAX as f32 / 2.0 {
            Ok(v as i32)
        } else {
            Err(UnwrapError::BadImageFlag {
                column: NAMES[k],
                atom: i + 1,
                value: v,
            })
        }
    };
    Some(
        (0..m.len())
            .map(|i| Ok([flag(0, i)?, flag(1, i)?, flag(2, i)?]))
            .collect(),
    )
}

/// The lattice image of every atom that makes every bond of a breadth-first spanning tree of
/// `bonds` its minimum-image vector (see the [module docs](self)); `[0; 3]` for the root of
/// each component (its lowest-index atom) and for atoms without bonds. Iterative, O(atoms +
/// bonds), flat arrays (12 B per atom for the images, 4 B per atom for the queue and 8 B per
/// bond for the adjacency). Self-bonds are ignored.
pub fn images_along_bonds(
    m: &Molecule,
    cell: &Cell,
    bonds: &[[u32; 2]],
) -> Result<Vec<[i32; 3]>, UnwrapError> {
    let n = m.len();
    let inv = cell.inverse().ok_or(UnwrapError::DegenerateCell)?;
    let periodic = cell.pbc;
    // Adjacency in compressed rows: degree count, prefix sum, fill.
    let mut start = vec![0u32; n + 1];
    for &[i, j] in bonds {
        if i as usize >= n || j as usize >= n {
            return Err(UnwrapError::BadBond { i, j, atoms: n });
        }
        if i != j {
            start[i as usize + 1] += 1;
            start[j as usize + 1] += 1;
        }
    }
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut adj = vec![0u32; start[n] as usize];
    for &[i, j] in bonds {
        if i != j {
            adj[fill[i as usize] as usize] = j;
            fill[i as usize] += 1;
            adj[fill[j as usize] as usize] = i;
            fill[j as usize] += 1;
        }
    }
    drop(fill);
    let mut image = vec![[0i32; 3]; n];
    let mut seen = vec![false; n];
    let mut queue: Vec<u32> = Vec::with_capacity(n);
    for root in 0..n {
        if seen[root] {
            continue;
        }
        // Every atom below `root` is placed, so `root` is its component's lowest index.
        seen[root] = true;
        queue.clear();
        queue.push(root as u32);
        let mut head = 0;
        while head < queue.len() {
            let p = queue[head] as usize;
            head += 1;
            let pp = m.position(p);
            for &c in &adj[start[p] as usize..start[p + 1] as usize] {
                let c = c as usize;
                if seen[c] {
                    continue;
                }
                seen[c] = true;
                let pc = m.position(c);
                let d = [0, 1, 2].map(|k| f64::from(pc[k]) - f64::from(pp[k]));
                let mut shift = image[p];
                for (r, s) in shift.iter_mut().enumerate() {
                    if periodic[r] {
                        let f = inv[r][0] * d[0] + inv[r][1] * d[1] + inv[r][2] * d[2];
                        *s -= f.round() as i32;
                    }
                }
                image[c] = shift;
                queue.push(c as u32);
            }
        }
    }
    Ok(image)
}

/// Moves every atom of `m` by its lattice image: `position += n_a·a + n_b·b + n_c·c` (Å),
/// computed in `f64` and rounded once to `f32`.
pub fn apply_images(m: &mut Molecule, cell: &Cell, image: &[[i32; 3]]) -> Result<(), UnwrapError> {
    let e = cell.edges.map(|v| v.map(f64::from));
    for (i, n) in image.iter().enumerate().take(m.len()) {
        if *n == [0; 3] {
            continue;
        }
        let nf = n.map(f64::from);
        let shift = [0, 1, 2].map(|k| nf[0] * e[0][k] + nf[1] * e[1][k] + nf[2] * e[2][k]);
        let p = [
            (f64::from(m.x[i]) + shift[0]) as f32,
            (f64::from(m.y[i]) + shift[1]) as f32,
            (f64::from(m.z[i]) + shift[2]) as f32,
        ];
        if p.iter().any(|v| !v.is_finite()) {
            return Err(UnwrapError::NotFinite { atom: i + 1 });
        }
        (m.x[i], m.y[i], m.z[i]) = (p[0], p[1], p[2]);
    }
    Ok(())
}

/// Unwraps `m` in place by [`UnwrapMethod::of`] and returns the method used; `bonds` (pairs of
/// atom indices, detected with the minimum image or from the file) are read only by
/// [`UnwrapMethod::Bonds`]. Errors: no cell (for every method, also when the file is already
/// unwrapped), a degenerate cell, non-integer image flags, a bond beyond the atoms.
pub fn unwrap(m: &mut Molecule, bonds: &[[u32; 2]]) -> Result<UnwrapMethod, UnwrapError> {
    let cell = m.cell.ok_or(UnwrapError::NoCell)?;
    if MinimumImage::new(&cell).is_none() {
        return Err(UnwrapError::DegenerateCell);
    }
    let method = UnwrapMethod::of(m);
    let image = match method {
        UnwrapMethod::AlreadyUnwrapped => return Ok(method),
        UnwrapMethod::ImageFlags => match image_flags(m) {
            Some(r) => r?,
            None => unreachable!("UnwrapMethod::of saw the three columns"),
        },
        UnwrapMethod::Bonds => images_along_bonds(m, &cell, bonds)?,
    };
    apply_images(m, &cell, &image)?;
    Ok(method)
}

/// Number of `bonds` of `m` that still cross the periodic boundary: the vector between the
/// two atoms is not its own minimum image (by more than 1e-3 Å). 0 without a usable cell.
pub fn crossing_bonds(m: &Molecule, bonds: &[[u32; 2]]) -> usize {
    let Some(mi) = m.cell.as_ref().and_then(MinimumImage::new) else {
        return 0;
    };
    bonds.iter().filter(|b| crosses(m, &mi, b)).count()
}

/// Whether bond `[i, j]` of `m` crosses the periodic boundary: its vector (Å) differs from
/// its minimum image `mi` by more than 1e-3 Å, i.e. by a lattice vector.
pub fn crosses(m: &Molecule, mi: &MinimumImage, &[i, j]: &[u32; 2]) -> bool {
    let (pi, pj) = (m.position(i as usize), m.position(j as usize));
    let d = [0, 1, 2].map(|k| f64::from(pj[k]) - f64::from(pi[k]));
    let dm = mi.apply(d);
    (0..3).map(|k| (d[k] - dm[k]).powi(2)).sum::<f64>() > 1e-6
}
