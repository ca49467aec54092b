//! Bond detection by uniform-grid neighbour search (paper 4.1 step 2).
//!
//! Atoms i and j are bonded when `min_dist < d(i, j) < cutoff(Zi, Zj)` where the cutoff is,
//! in order of precedence: a per-pair cutoff (`Al-O=2.2`), the global cutoff, or
//! `factor · (rcov_i + rcov_j)` with Cordero covalent radii (default factor 1.15). Distances
//! are compared squared, in `f32` (or `f64` minimum-image when `pbc` is on), by one shared
//! function, so [`build_bonds`] and [`brute_force_bonds`] agree exactly.
//!
//! The grid has cells at least as large as the largest cutoff (larger when that would make
//! more than ~2 cells per atom), so only the 27 neighbouring cells need checking. With
//! `pbc`, the grid lives in fractional coordinates of the cell and distances use the minimum
//! image (so bonds across the boundary connect to the nearest image and never span the box);
//! this assumes the cutoff is below half of each periodic box width.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::elements;
use crate::Molecule;
use rayon::prelude::*;

/// Options for bond detection.
#[derive(Debug, Clone, PartialEq)]
pub struct BondOptions {
    /// Multiplier on the sum of covalent radii (dimensionless, default 1.15).
    pub factor: f32,
    /// One cutoff (Å) for every pair, replacing the covalent-radius rule.
    pub global_cutoff: Option<f32>,
    /// Per element pair cutoffs (Å): `(Z1, Z2, cutoff)`, order of Z1/Z2 irrelevant.
    pub pair_cutoffs: Vec<(u8, u8, f32)>,
    /// Use periodic boundaries (minimum image) when the molecule has a cell.
    pub pbc: bool,
    /// Minimum bond length (Å); closer pairs are overlapping atoms, not bonds. Default 0.4.
    pub min_dist: f32,
}

impl Default for BondOptions {
    fn default() -> Self {
        BondOptions {
            factor: 1.15,
            global_cutoff: None,
            pair_cutoffs: Vec::new(),
            pbc: false,
            min_dist: 0.4,
        }
    }
}

impl BondOptions {
    /// Parse per-pair cutoffs such as `"Al-O=2.2,Si-O=1.9"`.
    pub fn parse_pair_cutoffs(s: &str) -> Result<Vec<(u8, u8, f32)>, String> {
        let mut out = Vec::new();
        for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let err = || format!("'{item}': expected A-B=CUTOFF, e.g. Al-O=2.2");
            let (pair, c) = item.split_once('=').ok_or_else(err)?;
            let (a, b) = pair.split_once('-').ok_or_else(err)?;
            let za = elements::by_symbol(a).ok_or_else(err)?;
            let zb = elements::by_symbol(b).ok_or_else(err)?;
            let c: f32 = c.trim().parse().map_err(|_| err())?;
            if !(c.is_finite() && c > 0.0) {
                return Err(err());
            }
            out.push((za, zb, c));
        }
        Ok(out)
    }

    /// Cutoff (Å) for a pair of atomic numbers.
    pub fn cutoff(&self, a: u8, b: u8) -> f32 {
        if let Some(&(_, _, c)) = self
            .pair_cutoffs
            .iter()
            .find(|(x, y, _)| (*x == a && *y == b) || (*x == b && *y == a))
        {
            return c;
        }
        if let Some(c) = self.global_cutoff {
            return c;
        }
        self.factor * (elements::element(a).covalent_radius + elements::element(b).covalent_radius)
    }
}

/// Pair test shared by the grid and the brute-force builders.
struct Rule<'a> {
    m: &'a Molecule,
    /// Compact element index per atom.
    kind: Vec<u8>,
    nk: usize,
    /// Squared cutoff per compact element pair.
    cut2: Vec<f32>,
    min2: f32,
    max_cut: f32,
    /// Minimum-image data when periodic: fractional coords, H (rows), periodic flags.
    pbc: Option<Pbc>,
}

struct Pbc {
    frac: Vec<[f64; 3]>,
    h: [[f64; 3]; 3],
    periodic: [bool; 3],
    widths: [f64; 3],
}

impl<'a> Rule<'a> {
    fn new(m: &'a Molecule, opts: &BondOptions) -> Rule<'a> {
        let mut map = [u8::MAX; 256];
        let mut present = Vec::new();
        for &z in &m.elements {
            if map[z as usize] == u8::MAX {
                map[z as usize] = present.len() as u8;
                present.push(z);
            }
        }
        let nk = present.len().max(1);
        let mut cut2 = vec![0f32; nk * nk];
        let mut max_cut = 0f32;
        for (a, &za) in present.iter().enumerate() {
            for (b, &zb) in present.iter().enumerate() {
                let c = opts.cutoff(za, zb);
                let c = if c.is_finite() { c.max(0.0) } else { 0.0 };
                max_cut = max_cut.max(c);
                cut2[a * nk + b] = c * c;
            }
        }
        let kind = m.elements.iter().map(|&z| map[z as usize]).collect();
        let pbc = if opts.pbc {
            m.cell.and_then(|c| {
                let inv = c.inverse()?;
                let o = c.origin.map(f64::from);
                let frac = (0..m.len())
                    .into_par_iter()
                    .map(|i| {
                        let p = [
                            f64::from(m.x[i]) - o[0],
                            f64::from(m.y[i]) - o[1],
                            f64::from(m.z[i]) - o[2],
                        ];
                        [0, 1, 2].map(|r| inv[r][0] * p[0] + inv[r][1] * p[1] + inv[r][2] * p[2])
                    })
                    .collect();
                Some(Pbc {
                    frac,
                    h: c.matrix(),
                    periodic: c.pbc,
                    widths: c.widths(),
                })
            })
        } else {
            None
        };
        Rule {
            m,
            kind,
            nk,
            cut2,
            min2: opts.min_dist * opts.min_dist,
            max_cut,
            pbc,
        }
    }

    #[inline(always)]
    fn bonded(&self, i: usize, j: usize) -> bool {
        let d2 = match &self.pbc {
            None => {
                let m = self.m;
                let dx = m.x[j] - m.x[i];
                let dy = m.y[j] - m.y[i];
                let dz = m.z[j] - m.z[i];
                dx * dx + dy * dy + dz * dz
            }
            Some(p) => {
                let (a, b) = (p.frac[i], p.frac[j]);
                let mut f = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                for (fk, &per) in f.iter_mut().zip(&p.periodic) {
                    if per {
                        *fk -= fk.round();
                    }
                }
                let h = &p.h;
                let mut s = 0f64;
                for row in h {
                    let c = row[0] * f[0] + row[1] * f[1] + row[2] * f[2];
                    s += c * c;
                }
                s as f32
            }
        };
        let c2 = self.cut2[self.kind[i] as usize * self.nk + self.kind[j] as usize];
        d2 > self.min2 && d2 < c2
    }
}

/// All bonds by checking every pair, O(N²) (reference for tests; parallel over i).
/// Same criterion and output order as [`build_bonds`].
pub fn brute_force_bonds(m: &Molecule, opts: &BondOptions) -> Vec<[u32; 2]> {
    let rule = Rule::new(m, opts);
    let n = m.len();
    (0..n)
        .into_par_iter()
        .flat_map_iter(|i| {
            let rule = &rule;
            (i + 1..n)
                .filter(move |&j| rule.bonded(i, j))
                .map(move |j| [i as u32, j as u32])
        })
        .collect()
}

/// Cells along one axis for `ratio` = extent / cell size: `floor(ratio) + 1`, in
/// `1..=2^20` (NaN and infinity give the cap or 1, never an overflow).
fn axis_cells(ratio: f64) -> usize {
    const CAP: f64 = (1u32 << 20) as f64;
    if ratio.is_nan() {
        return 1;
    }
    (ratio.floor() + 1.0).clamp(1.0, CAP) as usize
}

/// Uniform grid: `dims` cells, atoms listed cell by cell.
struct Grid {
    dims: [usize; 3],
    wrap: [bool; 3],
    start: Vec<u32>,
    atoms: Vec<u32>,
    cell_of: Vec<u32>,
}

fn cell_coords(key: u32, dims: [usize; 3]) -> [usize; 3] {
    let k = key as usize;
    [
        k % dims[0],
        (k / dims[0]) % dims[1],
        k / (dims[0] * dims[1]),
    ]
}

impl Grid {
    fn build(rule: &Rule<'_>) -> Grid {
        let m = rule.m;
        let n = m.len();
        let cut = rule.max_cut.max(1e-3) as f64;
        let max_cells = (2 * n + 1024) as f64;
        let (dims, wrap, keys): ([usize; 3], [bool; 3], Vec<u32>) = match &rule.pbc {
            Some(p) => {
                let mut dims = p.widths.map(|w| axis_cells(w / cut - 1.0));
                while (dims[0] * dims[1] * dims[2]) as f64 > max_cells {
                    for d in dims.iter_mut() {
                        *d = (*d * 4 / 5).max(1);
                    }
                }
                let wrap = p.periodic;
                let keys = p
                    .frac
                    .par_iter()
                    .map(|f| {
                        let mut c = [0usize; 3];
                        for k in 0..3 {
                            let v = if wrap[k] { f[k] - f[k].floor() } else { f[k] };
                            let idx = (v * dims[k] as f64).floor();
                            c[k] = if idx.is_finite() {
                                idx.clamp(0.0, (dims[k] - 1) as f64) as usize
                            } else {
                                0
                            };
                        }
                        (c[0] + dims[0] * (c[1] + dims[1] * c[2])) as u32
                    })
                    .collect();
                (dims, wrap, keys)
            }
            None => {
                let (lo, hi) = m.bounds();
                let ext = [0, 1, 2].map(|k| {
                    let e = f64::from(hi[k]) - f64::from(lo[k]);
                    if e.is_finite() {
                        e.max(0.0)
                    } else {
                        0.0
                    }
                });
                let mut s = cut;
                // Cell counts are computed in f64 and capped before the cast, so a huge or
                // infinite extent gives a coarse grid instead of an overflowing one.
                let dims_for = |s: f64| ext.map(|e| axis_cells(e / s));
                let mut dims = dims_for(s);
                while (dims[0] * dims[1] * dims[2]) as f64 > max_cells {
                    s *= 1.25;
                    dims = dims_for(s);
                }
                let lo = lo.map(f64::from);
                let inv = 1.0 / s;
                let keys = (0..n)
                    .into_par_iter()
                    .map(|i| {
                        let p = [m.x[i], m.y[i], m.z[i]];
                        let mut c = [0usize; 3];
                        for k in 0..3 {
                            let idx = ((f64::from(p[k]) - lo[k]) * inv).floor();
                            c[k] = idx.clamp(0.0, (dims[k] - 1) as f64) as usize;
                        }
                        (c[0] + dims[0] * (c[1] + dims[1] * c[2])) as u32
                    })
                    .collect();
                (dims, [false; 3], keys)
            }
        };
        let ncells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; ncells + 1];
        for &k in &keys {
            start[k as usize + 1] += 1;
        }
        for c in 0..ncells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut atoms = vec![0u32; n];
        for (i, &k) in keys.iter().enumerate() {
            let slot = &mut fill[k as usize];
            atoms[*slot as usize] = i as u32;
            *slot += 1;
        }
        Grid {
            dims,
            wrap,
            start,
            atoms,
            cell_of: keys,
        }
    }

    /// Upper bound on the pairs the neighbour search tests: the sum over cells and their
    /// distinct neighbouring cells of `n_i · n_j / 2` (O(cells), no allocation).
    fn candidate_pairs(&self) -> u64 {
        let [dx, dy, dz] = self.dims;
        let count = |c: usize| u64::from(self.start[c + 1] - self.start[c]);
        let (mut nx, mut ny, mut nz) = ([0usize; 3], [0usize; 3], [0usize; 3]);
        let mut total = 0u64;
        for z in 0..dz {
            let cz = self.axis_neighbours(z, 2, &mut nz);
            for y in 0..dy {
                let cy = self.axis_neighbours(y, 1, &mut ny);
                for x in 0..dx {
                    let here = count(x + dx * (y + dy * z));
                    if here == 0 {
                        continue;
                    }
                    let cx = self.axis_neighbours(x, 0, &mut nx);
                    let mut around = 0u64;
                    for &c in &nz[..cz] {
                        for &b in &ny[..cy] {
                            for &a in &nx[..cx] {
                                around += count(a + dx * (b + dy * c));
                            }
                        }
                    }
                    total = total.saturating_add(here.saturating_mul(around) / 2);
                }
            }
        }
        total
    }

    /// Distinct neighbour indices along one axis.
    fn axis_neighbours(&self, c: usize, k: usize, out: &mut [usize; 3]) -> usize {
        let d = self.dims[k];
        let mut cnt = 0;
        for off in [-1i64, 0, 1] {
            let v = c as i64 + off;
            let v = if self.wrap[k] {
                v.rem_euclid(d as i64)
            } else if v < 0 || v >= d as i64 {
                continue;
            } else {
                v
            } as usize;
            if !out[..cnt].contains(&v) {
                out[cnt] = v;
                cnt += 1;
            }
        }
        cnt
    }
}

/// Bonds of `m` under `opts`: pairs `[i, j]` with `i < j`, sorted, deterministic regardless
/// of thread count. Uses a uniform grid and rayon.
///
/// Unchecked: never panics, but an absurd cutoff or a far-away atom can make it quadratic
/// and huge. Use [`try_build_bonds`] for untrusted input.
pub fn build_bonds(m: &Molecule, opts: &BondOptions) -> Vec<[u32; 2]> {
    let n = m.len();
    if n < 2 {
        return Vec::new();
    }
    let rule = Rule::new(m, opts);
    if rule.max_cut <= 0.0 {
        return Vec::new();
    }
    let grid = Grid::build(&rule);
    match collect_bonds(&rule, &grid, &AtomicU64::new(0), &|| false) {
        Some(bonds) => bonds,
        None => unreachable!("a search without a cancel test is never cancelled"),
    }
}

/// [`build_bonds`] with limits, for untrusted input: refuses (before any large allocation)
/// when the grid extent is more than [`MAX_EXTENT_CELLS`] cutoffs or not finite
/// ([`BondError::Extent`], naming the farthest atom), and when the estimated number of
/// candidate pairs exceeds [`max_candidate_pairs`] ([`BondError::TooMany`]); the output is
/// reserved with `try_reserve` ([`BondError::Alloc`]). Same bonds as [`build_bonds`] otherwise.
pub fn try_build_bonds(m: &Molecule, opts: &BondOptions) -> Result<Vec<[u32; 2]>, BondError> {
    try_build_bonds_with_progress(m, opts, &AtomicU64::new(0), &|| false)
}

/// [`try_build_bonds`] adding to `done` the atoms whose neighbours have been searched (up to
/// the atom count), for a progress display that reads it from another thread, and asking
/// `cancelled` before each chunk of 4096 atoms: once it returns true the search skips the
/// chunks left and returns [`BondError::Cancelled`].
pub fn try_build_bonds_with_progress(
    m: &Molecule,
    opts: &BondOptions,
    done: &AtomicU64,
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<[u32; 2]>, BondError> {
    let n = m.len();
    if n < 2 {
        return Ok(Vec::new());
    }
    let rule = Rule::new(m, opts);
    if rule.max_cut <= 0.0 {
        return Ok(Vec::new());
    }
    if rule.pbc.is_none() {
        check_extent(m, rule.max_cut)?;
    }
    let grid = Grid::build(&rule);
    let estimate = grid.candidate_pairs();
    let cap = max_candidate_pairs(n);
    if estimate > cap {
        return Err(BondError::TooMany {
            estimate,
            atoms: n,
            cap,
            cutoff: rule.max_cut,
        });
    }
    let mut probe: Vec<[u32; 2]> = Vec::new();
    probe
        .try_reserve(estimate.min(16 * n as u64) as usize)
        .map_err(|_| BondError::Alloc {
            bytes: estimate.min(16 * n as u64) * 8,
        })?;
    drop(probe);
    if cancelled() {
        return Err(BondError::Cancelled);
    }
    collect_bonds(&rule, &grid, done, cancelled).ok_or(BondError::Cancelled)
}

/// Largest grid extent, in units of the largest cutoff, that [`try_build_bonds`] accepts
/// (2^24: beyond it `f32` positions cannot resolve bond lengths anyway).
pub const MAX_EXTENT_CELLS: f64 = (1u32 << 24) as f64;

/// Cap on the estimated candidate pairs for `atoms` atoms in [`try_build_bonds`]:
/// `64 · atoms + 2^20` (a dense solid at the default factor needs about 25 per atom).
pub fn max_candidate_pairs(atoms: usize) -> u64 {
    64 * atoms as u64 + (1 << 20)
}

/// Why [`try_build_bonds`] refused.
#[derive(Debug, thiserror::Error)]
pub enum BondError {
    /// The atoms span too large (or a non-finite) extent for the bond grid.
    #[error(
        "atom {atom} (1-based) at {axis} = {coord:e} Å makes the bond search span {extent:e} Å \
         along {axis}, more than 2^24 bond cutoffs ({cutoff} Å); fix the coordinates or pass \
         --bonds none"
    )]
    Extent {
        /// 1-based index of the atom farthest out along `axis`.
        atom: usize,
        /// Axis name (`x`, `y`, `z`).
        axis: char,
        /// Its coordinate (Å).
        coord: f32,
        /// Extent of all atoms along `axis` (Å; may be infinite).
        extent: f64,
        /// Largest bond cutoff (Å).
        cutoff: f32,
    },
    /// Too many atom pairs would be tested / could bond.
    #[error(
        "the bond cutoff ({cutoff} Å) would test about {estimate} atom pairs for {atoms} atoms \
         (up to {} MB of bonds; limit {cap} pairs); lower --bond-cutoff / --bond-factor or \
         pass --bonds none",
        estimate.saturating_mul(8) / 1_000_000
    )]
    TooMany {
        /// Estimated candidate pairs (sum over neighbouring grid cells of n_i·n_j / 2).
        estimate: u64,
        /// Atoms in the molecule.
        atoms: usize,
        /// The limit ([`max_candidate_pairs`]).
        cap: u64,
        /// Largest bond cutoff (Å).
        cutoff: f32,
    },
    /// The search was cancelled by its caller (a newer request made it pointless).
    #[error("the bond search was cancelled")]
    Cancelled,
    /// The bond list could not be allocated.
    #[error("cannot allocate {bytes} bytes for bonds; pass --bonds none or a smaller cutoff")]
    Alloc {
        /// Bytes requested.
        bytes: u64,
    },
}

/// [`BondError::Extent`] when the non-periodic grid would span more than
/// [`MAX_EXTENT_CELLS`] cutoffs (or an infinite extent) along some axis.
fn check_extent(m: &Molecule, cut: f32) -> Result<(), BondError> {
    let (lo, hi) = m.bounds();
    for (k, v) in [&m.x, &m.y, &m.z].into_iter().enumerate() {
        let extent = f64::from(hi[k]) - f64::from(lo[k]);
        if extent.is_finite() && extent <= MAX_EXTENT_CELLS * f64::from(cut) {
            continue;
        }
        // The atom farthest from the median is the outlier.
        let mut sorted: Vec<f32> = v.clone();
        sorted.sort_unstable_by(f32::total_cmp);
        let mid = f64::from(sorted[sorted.len() / 2]);
        let (atom, &coord) = v
            .iter()
            .enumerate()
            .max_by(|a, b| {
                let da = (f64::from(*a.1) - mid).abs();
                let db = (f64::from(*b.1) - mid).abs();
                da.total_cmp(&db)
            })
            .unwrap_or((0, &0.0));
        return Err(BondError::Extent {
            atom: atom + 1,
            axis: ['x', 'y', 'z'][k],
            coord,
            extent,
            cutoff: cut,
        });
    }
    Ok(())
}

/// Bonds from a built grid (the parallel neighbour search of [`build_bonds`]), adding each
/// searched chunk's atoms to `done`; `None` when `cancelled` returned true (chunks not yet
/// started are skipped).
fn collect_bonds(
    rule: &Rule<'_>,
    grid: &Grid,
    done: &AtomicU64,
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<Vec<[u32; 2]>> {
    let n = rule.m.len();
    const CHUNK: usize = 4096;
    let chunks: Vec<Vec<[u32; 2]>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            if cancelled() {
                return Vec::new();
            }
            let atoms = c * CHUNK..((c + 1) * CHUNK).min(n);
            let out = chunk_bonds(rule, grid, atoms.clone());
            done.fetch_add(atoms.len() as u64, Ordering::Relaxed);
            out
        })
        .collect();
    if cancelled() {
        return None;
    }
    let total = chunks.iter().map(Vec::len).sum();
    let mut out = Vec::with_capacity(total);
    for c in chunks {
        out.extend_from_slice(&c);
    }
    Some(out)
}

/// The bonds `[i, j]` with `i` in `atoms` and `j > i`, sorted: each atom's neighbour cells
/// searched in the grid.
fn chunk_bonds(rule: &Rule<'_>, grid: &Grid, atoms: std::ops::Range<usize>) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    let mut js: Vec<u32> = Vec::new();
    let (mut nx, mut ny, mut nz) = ([0usize; 3], [0usize; 3], [0usize; 3]);
    for i in atoms {
        let cc = cell_coords(grid.cell_of[i], grid.dims);
        let cx = grid.axis_neighbours(cc[0], 0, &mut nx);
        let cy = grid.axis_neighbours(cc[1], 1, &mut ny);
        let cz = grid.axis_neighbours(cc[2], 2, &mut nz);
        js.clear();
        for &z in &nz[..cz] {
            for &y in &ny[..cy] {
                for &x in &nx[..cx] {
                    let cell = x + grid.dims[0] * (y + grid.dims[1] * z);
                    let (s, e) = (grid.start[cell] as usize, grid.start[cell + 1] as usize);
                    for &j in &grid.atoms[s..e] {
                        if (j as usize) > i && rule.bonded(i, j as usize) {
                            js.push(j);
                        }
                    }
                }
            }
        }
        js.sort_unstable();
        out.extend(js.iter().map(|&j| [i as u32, j]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pair_cutoffs_parse() {
        let v = BondOptions::parse_pair_cutoffs("Al-O=2.2, Si-O=1.9").unwrap();
        assert_eq!(v, vec![(13, 8, 2.2), (14, 8, 1.9)]);
        assert!(BondOptions::parse_pair_cutoffs("Al-Q=2").is_err());
        assert!(BondOptions::parse_pair_cutoffs("AlO=2").is_err());
        let o = BondOptions {
            pair_cutoffs: v,
            global_cutoff: Some(1.0),
            ..Default::default()
        };
        assert_eq!(o.cutoff(8, 13), 2.2);
        assert_eq!(o.cutoff(6, 6), 1.0);
    }
}
