//! The RBF density grid (paper §3.1): Φ(x) = Σᵢ √rᵢ·exp(−d²/rᵢ²) for d < √2·rᵢ, sampled at
//! the lattice points of a regular grid, built in parallel over z-slabs with SIMD along x.
//! Values are f32 sums (atoms in a fixed order), optionally quantised to u8.
//!
//! ## Sampling convention
//! Values live at **lattice points** (voxel corners): sample `(i, j, k)` is Φ at
//! `origin + (i, j, k)·spacing` (Å). The volume's box is `[origin, origin + (dims − 1)·spacing]`
//! and the interpolant between lattice points is trilinear. "Voxel" as a length unit means one
//! `spacing` (= 1 / voxels-per-Å).

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;
use spmd::{Isa, Kernel, Simd};

use crate::grid_size::{check_size, lattice_points};
use crate::VolumeError;
pub use bvh::Watch;

/// How voxel values are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum VolumeFormat {
    /// One byte per voxel, quantised with one global scale (`value = q · scale`,
    /// `scale = max / 255`), as in the paper. Building it runs the splat twice (once for the
    /// global maximum, once to quantise) so no full f32 grid is ever held.
    #[default]
    U8,
    /// Four bytes per voxel, the exact f32 sums.
    F32,
}

impl VolumeFormat {
    /// Bytes per stored voxel.
    pub fn bytes_per_voxel(self) -> u64 {
        match self {
            VolumeFormat::U8 => 1,
            VolumeFormat::F32 => 4,
        }
    }
    /// `"u8"` or `"f32"`.
    pub fn name(self) -> &'static str {
        match self {
            VolumeFormat::U8 => "u8",
            VolumeFormat::F32 => "f32",
        }
    }
}

impl core::str::FromStr for VolumeFormat {
    type Err = VolumeError;
    fn from_str(s: &str) -> Result<Self, VolumeError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "u8" | "byte" | "uint8" => Ok(VolumeFormat::U8),
            "f32" | "float" | "float32" => Ok(VolumeFormat::F32),
            _ => Err(VolumeError::UnknownFormat(s.to_string())),
        }
    }
}

/// Parameters of the density build.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DensityParams {
    /// Grid resolution in voxels per Ångström (the paper uses 4, or 1 for its largest sets).
    pub voxels_per_angstrom: f32,
    /// Storage format.
    pub format: VolumeFormat,
    /// Refuse to build when [`estimate_bytes`] exceeds this many bytes. `None`: 75 % of
    /// `MemAvailable` from `/proc/meminfo` (no limit if that cannot be read).
    pub budget_bytes: Option<u64>,
}

impl Default for DensityParams {
    fn default() -> Self {
        DensityParams {
            voxels_per_angstrom: 4.0,
            format: VolumeFormat::U8,
            budget_bytes: None,
        }
    }
}

/// Placement of the lattice in space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// World position (Å) of lattice point (0, 0, 0).
    pub origin: [f32; 3],
    /// Distance between lattice points (Å per voxel) = 1 / voxels-per-Å.
    pub spacing: f32,
    /// Number of lattice points along x, y, z (each ≥ 2).
    pub dims: [usize; 3],
}

impl Grid {
    /// Lattice covering the atoms' bounds padded by the largest support radius √2·r_max plus
    /// one voxel, so Φ is zero on the boundary.
    pub fn for_atoms(
        x: &[f32],
        y: &[f32],
        z: &[f32],
        r: &[f32],
        voxels_per_angstrom: f32,
    ) -> Result<Grid, VolumeError> {
        let (origin, points) = lattice_points(x, y, z, r, voxels_per_angstrom)?;
        // Saturating: a count past `usize` (atoms 10³⁸ Å apart, or 10³⁰ voxels/Å) stays
        // enormous, for the size check to refuse, instead of wrapping to a small grid.
        let dims = points.map(|n| (n as usize).max(2));
        Ok(Grid {
            origin,
            spacing: 1.0 / voxels_per_angstrom,
            dims,
        })
    }

    /// Total number of lattice points.
    pub fn voxel_count(&self) -> u64 {
        self.dims
            .iter()
            .fold(1u64, |n, &d| n.saturating_mul(d as u64))
    }

    /// Upper corner of the box (Å).
    pub fn max_corner(&self) -> [f32; 3] {
        core::array::from_fn(|a| self.origin[a] + (self.dims[a] - 1) as f32 * self.spacing)
    }

    /// World position (Å) of lattice point `(i, j, k)`, computed as the build does.
    pub fn point(&self, i: usize, j: usize, k: usize) -> [f32; 3] {
        [
            self.origin[0] + i as f32 * self.spacing,
            self.origin[1] + j as f32 * self.spacing,
            self.origin[2] + k as f32 * self.spacing,
        ]
    }

    /// Linear index of lattice point `(i, j, k)` (x fastest).
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }
}

/// Voxel storage.
#[derive(Clone, Debug, PartialEq)]
pub enum VolumeData {
    /// Exact f32 values.
    F32(Vec<f32>),
    /// Quantised bytes (`value = q · scale`). The vector holds 4 bytes of zero padding after
    /// the last voxel so SIMD gathers may read whole words.
    U8 {
        /// Quantised voxels plus padding.
        data: Vec<u8>,
        /// Value of one quantisation step (= max / 255).
        scale: f32,
    },
}

/// A density volume on a [`Grid`].
#[derive(Clone, Debug)]
pub struct Volume {
    /// Where the lattice is.
    pub grid: Grid,
    /// The voxels.
    pub data: VolumeData,
    /// Largest exact (f32) value before quantisation.
    pub max_value: f32,
}

impl Volume {
    /// Stored value at lattice point `(i, j, k)` (dequantised for u8).
    pub fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        let n = self.grid.index(i, j, k);
        match &self.data {
            VolumeData::F32(v) => v[n],
            VolumeData::U8 { data, scale } => data[n] as f32 * scale,
        }
    }

    /// Storage format.
    pub fn format(&self) -> VolumeFormat {
        match self.data {
            VolumeData::F32(_) => VolumeFormat::F32,
            VolumeData::U8 { .. } => VolumeFormat::U8,
        }
    }

    /// Quantisation step for u8 volumes, `None` for f32.
    pub fn scale(&self) -> Option<f32> {
        match self.data {
            VolumeData::F32(_) => None,
            VolumeData::U8 { scale, .. } => Some(scale),
        }
    }

    /// Bytes held by the voxels.
    pub fn bytes(&self) -> u64 {
        match &self.data {
            VolumeData::F32(v) => v.len() as u64 * 4,
            VolumeData::U8 { data, .. } => data.len() as u64,
        }
    }

    /// Trilinear interpolation at world position `p` (Å), clamped to the box; f64 reference
    /// for tests and tools (the kernels do this in SIMD).
    pub fn sample_trilinear(&self, p: [f64; 3]) -> f64 {
        let g = &self.grid;
        let mut i0 = [0usize; 3];
        let mut f = [0.0f64; 3];
        for a in 0..3 {
            let t =
                ((p[a] - g.origin[a] as f64) / g.spacing as f64).clamp(0.0, (g.dims[a] - 1) as f64);
            let i = (t.floor() as usize).min(g.dims[a] - 2);
            i0[a] = i;
            f[a] = t - i as f64;
        }
        let mut acc = 0.0;
        for c in 0..8 {
            let (dx, dy, dz) = (c & 1, (c >> 1) & 1, c >> 2);
            let w = (if dx == 1 { f[0] } else { 1.0 - f[0] })
                * (if dy == 1 { f[1] } else { 1.0 - f[1] })
                * (if dz == 1 { f[2] } else { 1.0 - f[2] });
            acc += w * self.get(i0[0] + dx, i0[1] + dy, i0[2] + dz) as f64;
        }
        acc
    }
}

/// Atoms must be four slices of equal length with finite coordinates and positive radii.
pub(crate) fn check_atoms(x: &[f32], y: &[f32], z: &[f32], r: &[f32]) -> Result<(), VolumeError> {
    let n = x.len();
    if y.len() != n || z.len() != n || r.len() != n {
        return Err(VolumeError::LengthMismatch {
            x: n,
            y: y.len(),
            z: z.len(),
            r: r.len(),
        });
    }
    if n == 0 {
        return Err(VolumeError::NoAtoms);
    }
    for i in 0..n {
        if !(x[i].is_finite() && y[i].is_finite() && z[i].is_finite()) {
            return Err(VolumeError::NonFinite { atom: i });
        }
        if !(r[i].is_finite() && r[i] > 0.0) {
            return Err(VolumeError::BadRadius {
                atom: i,
                radius: r[i],
            });
        }
    }
    Ok(())
}

/// Lattice planes per z-slab (the unit of parallel work).
const SLAB: usize = 4;

/// Bytes the build will hold at its peak for `grid` in `format`: the voxels (+4 bytes of
/// padding), the macrocell grid, and one f32 block (4 planes × 32 rows) per worker thread.
pub fn estimate_bytes(grid: &Grid, format: VolumeFormat) -> u64 {
    let voxels = grid
        .voxel_count()
        .saturating_mul(format.bytes_per_voxel())
        .saturating_add(4);
    let cells: u64 = grid.dims.iter().fold(1u64, |n, &d| {
        n.saturating_mul(
            (d as u64 - 1)
                .div_ceil(crate::macrocell::MACROCELL as u64)
                .max(1),
        )
    });
    let block = (SLAB * YBLOCK * grid.dims[0]) as u64 * 4;
    let scratch = block * rayon::current_num_threads() as u64;
    voxels
        .saturating_add(cells.saturating_mul(8))
        .saturating_add(scratch)
}

/// 75 % of `MemAvailable` in `/proc/meminfo`, or `None` where that cannot be read.
pub fn default_budget_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024 / 4 * 3)
}

/// Units of work [`build_density`] counts for a lattice of `dims` points in
/// `format`: one per slab of 4 lattice planes and pass (u8 makes two passes: maximum, then
/// quantise).
pub fn density_work(dims: [usize; 3], format: VolumeFormat) -> u64 {
    let passes = match format {
        VolumeFormat::F32 => 1,
        VolumeFormat::U8 => 2,
    };
    dims[2].div_ceil(SLAB) as u64 * passes
}

/// Builds the density volume of the atoms (positions `x, y, z` and covalent radii `r`, Å)
/// on [`Grid::for_atoms`] at `params.voxels_per_angstrom`, using backend `isa`.
///
/// Work: atoms are binned by z-slab (4 lattice planes) and sorted by (y-band, x); rayon runs
/// one task per slab, which computes the slab in y-blocks of 32 rows (an f32 scratch that
/// stays in L2) with SIMD along x, then copies (f32) or quantises (u8) the block out.
///
/// Deterministic: every voxel sums its atoms in a fixed order (by y-band, x, index) whatever
/// the thread count, so the result depends only on the inputs and the ISA (AVX2/AVX-512 fuse
/// multiply-adds in `exp`, which changes the last bits).
///
/// Errors: inconsistent or non-finite input, or [`VolumeError::TooLarge`] (with a suggested
/// resolution) when [`estimate_bytes`] exceeds the budget or the voxel count exceeds what
/// 32-bit gather indices can address.
///
/// `watch`, if given, counts the finished slab passes (up to [`density_work`]) and is asked
/// before each slab pass: once it is cancelled the remaining passes are skipped and the build
/// returns [`VolumeError::Cancelled`] (a caller whose result is no longer wanted gets its
/// cores back within a fraction of a second).
pub fn build_density(
    isa: Isa,
    x: &[f32],
    y: &[f32],
    z: &[f32],
    r: &[f32],
    params: &DensityParams,
    watch: Option<&Watch>,
) -> Result<Volume, VolumeError> {
    let unwatched = AtomicU64::new(0);
    let (done, cancelled): (&AtomicU64, &(dyn Fn() -> bool + Sync)) = match watch {
        Some(w) => (w.done, w.cancelled),
        None => (&unwatched, &|| false),
    };
    let grid = Grid::for_atoms(x, y, z, r, params.voxels_per_angstrom)?;
    let budget = params.budget_bytes.or_else(default_budget_bytes);
    check_size(&grid, [x, y, z, r], params, budget)?;

    let bins = bin_atoms_by_slab(&grid, x, y, z, r);
    let plane = grid.dims[0] * grid.dims[1];
    let atoms = Atoms { x, y, z, r };
    let rmax = r.iter().copied().fold(0.0f32, f32::max);
    let reach_vox = core::f32::consts::SQRT_2 * rmax / grid.spacing + 1.0;
    let ctx = SlabCtx {
        isa,
        grid: &grid,
        atoms: &atoms,
        bins: &bins,
        reach_vox,
    };
    let [nx, ny, _] = grid.dims;
    let fmax = |m: f32, b: &[f32]| m.max(isa.dispatch(BlockMax(b)));

    match params.format {
        VolumeFormat::F32 => {
            let mut data = vec![0.0f32; grid.voxel_count() as usize];
            let max_value = data
                .par_chunks_mut(SLAB * plane)
                .enumerate()
                .map_init(Vec::new, |buf: &mut Vec<f32>, (slab, out)| {
                    let mut m = 0.0f32;
                    if cancelled() {
                        return m;
                    }
                    ctx.splat(slab, buf, |p, y0, block| {
                        let o = (p * ny + y0) * nx;
                        out[o..o + block.len()].copy_from_slice(block);
                        m = fmax(m, block);
                    });
                    done.fetch_add(1, Ordering::Relaxed);
                    m
                })
                .reduce(|| 0.0, f32::max);
            if cancelled() {
                return Err(VolumeError::Cancelled);
            }
            Ok(Volume {
                grid,
                data: VolumeData::F32(data),
                max_value,
            })
        }
        VolumeFormat::U8 => {
            let nslabs = bins.len();
            // Pass 1: the global maximum (values discarded).
            let max_value = (0..nslabs)
                .into_par_iter()
                .map_init(Vec::new, |buf: &mut Vec<f32>, slab| {
                    let mut m = 0.0f32;
                    if cancelled() {
                        return m;
                    }
                    ctx.splat(slab, buf, |_, _, block| m = fmax(m, block));
                    done.fetch_add(1, Ordering::Relaxed);
                    m
                })
                .reduce(|| 0.0, f32::max);
            if cancelled() {
                return Err(VolumeError::Cancelled);
            }
            let scale = if max_value > 0.0 {
                max_value / 255.0
            } else {
                1.0
            };
            let inv = 1.0 / scale;
            // Pass 2: recompute and quantise (round to nearest, error ≤ scale / 2).
            let n = grid.voxel_count() as usize;
            let mut data = vec![0u8; n + 4];
            data[..n]
                .par_chunks_mut(SLAB * plane)
                .enumerate()
                .for_each_init(Vec::new, |buf: &mut Vec<f32>, (slab, out)| {
                    if cancelled() {
                        return;
                    }
                    ctx.splat(slab, buf, |p, y0, block| {
                        let o = (p * ny + y0) * nx;
                        isa.dispatch(Quantise {
                            values: block,
                            inv_scale: inv,
                            out: &mut out[o..o + block.len()],
                        });
                    });
                    done.fetch_add(1, Ordering::Relaxed);
                });
            if cancelled() {
                return Err(VolumeError::Cancelled);
            }
            Ok(Volume {
                grid,
                data: VolumeData::U8 { data, scale },
                max_value,
            })
        }
    }
}

/// Largest value of a block (values are ≥ 0; 0 for an empty block).
struct BlockMax<'a>(&'a [f32]);

impl Kernel for BlockMax<'_> {
    type Output = f32;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> f32 {
        let mut m = s.splat(0.0);
        for c in self.0.chunks(S::LANES) {
            m = s.max(s.load_partial(c, 0.0), m);
        }
        s.reduce_max(m)
    }
}

/// `out = min(round(values · inv_scale), 255)` for non-negative values (u8 quantisation).
struct Quantise<'a, 'b> {
    values: &'a [f32],
    inv_scale: f32,
    out: &'b mut [u8],
}

impl Kernel for Quantise<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn run<S: Simd>(self, s: S) {
        let mut q = [0i32; spmd::MAX_LANES];
        let (k, half, top) = (s.splat(self.inv_scale), s.splat(0.5), s.splat(255.0));
        for (c, o) in self
            .values
            .chunks(S::LANES)
            .zip(self.out.chunks_mut(S::LANES))
        {
            let v = s.min(s.load_partial(c, 0.0) * k + half, top);
            s.store_i(s.to_i32(v), &mut q);
            for (dst, src) in o.iter_mut().zip(q) {
                *dst = src as u8;
            }
        }
    }
}

/// Lattice rows per y-block: a block's f32 scratch (4 planes × 32 rows × nx) stays in L2.
const YBLOCK: usize = 32;

/// Band of an atom's y coordinate (the primary sort key of the slab lists).
#[inline]
fn band_key(grid: &Grid, y: f32) -> u32 {
    ((y - grid.origin[1]) * (1.0 / grid.spacing) / BAND) as u32
}

/// What every slab task shares.
struct SlabCtx<'a> {
    isa: Isa,
    grid: &'a Grid,
    atoms: &'a Atoms<'a>,
    bins: &'a [Vec<u32>],
    /// Largest support radius in voxels, plus one.
    reach_vox: f32,
}

impl SlabCtx<'_> {
    /// Computes z-slab `slab` one y-block at a time in `scratch`, then hands every plane's
    /// rows of the block to `emit(plane, first_row, values)` (`rows × nx` values, x fastest).
    fn splat(
        &self,
        slab: usize,
        scratch: &mut Vec<f32>,
        mut emit: impl FnMut(usize, usize, &[f32]),
    ) {
        let [nx, ny, nz] = self.grid.dims;
        let z0 = slab * SLAB;
        let planes = SLAB.min(nz - z0);
        let list = &self.bins[slab];
        let key = |i: &u32| band_key(self.grid, self.atoms.y[*i as usize]);
        let mut y0 = 0;
        while y0 < ny {
            let rows = YBLOCK.min(ny - y0);
            let len = planes * rows * nx;
            scratch.clear();
            scratch.resize(len, 0.0);
            // Atoms whose centre band can reach rows y0..y0+rows.
            let blo = ((y0 as f32 - self.reach_vox).max(0.0) / BAND) as u32;
            let bhi = (((y0 + rows) as f32 + self.reach_vox) / BAND) as u32;
            let a = list.partition_point(|i| key(i) < blo);
            let b = list.partition_point(|i| key(i) <= bhi);
            self.isa.dispatch(SplatSlab {
                grid: self.grid,
                atoms: self.atoms,
                list: &list[a..b.max(a)],
                z0,
                y0,
                rows,
                out: &mut scratch[..len],
            });
            for p in 0..planes {
                emit(p, y0, &scratch[p * rows * nx..(p + 1) * rows * nx]);
            }
            y0 += rows;
        }
    }
}

struct Atoms<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
    r: &'a [f32],
}

/// Range of lattice indices `[lo, hi]` (inclusive, clamped to `0..n`) within `reach` Å of
/// coordinate `c` along an axis; `None` if empty.
#[inline(always)]
fn lattice_range(c: f32, reach: f32, origin: f32, h: f32, n: usize) -> Option<(usize, usize)> {
    let lo = ((c - reach - origin) / h).ceil().max(0.0);
    let hi = ((c + reach - origin) / h).floor().min((n - 1) as f32);
    (lo <= hi).then_some((lo as usize, hi as usize))
}

/// Rows of lattice points per y-band: atoms of a slab are visited band by band so the
/// slab rows being written stay in cache.
const BAND: f32 = 8.0;

/// Atom indices per z-slab, each list sorted by (y-band, x, index): a fixed order (so the
/// build is deterministic) with good cache locality.
fn bin_atoms_by_slab(grid: &Grid, x: &[f32], y: &[f32], z: &[f32], r: &[f32]) -> Vec<Vec<u32>> {
    let nslabs = grid.dims[2].div_ceil(SLAB);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nslabs];
    let slack = grid.spacing; // a plane just outside the support is harmless (masked below)
    for i in 0..z.len() {
        let reach = core::f32::consts::SQRT_2 * r[i] + slack;
        if let Some((lo, hi)) =
            lattice_range(z[i], reach, grid.origin[2], grid.spacing, grid.dims[2])
        {
            for b in &mut bins[lo / SLAB..=hi / SLAB] {
                b.push(i as u32);
            }
        }
    }
    let inv = 1.0 / grid.spacing;
    bins.par_iter_mut().for_each(|b| {
        // Keys computed once per atom, not per comparison.
        let mut keyed: Vec<(u64, u32)> = b
            .iter()
            .map(|&i| {
                let band = band_key(grid, y[i as usize]) as u64;
                let col = ((x[i as usize] - grid.origin[0]) * inv) as u32 as u64;
                (band << 32 | col, i)
            })
            .collect();
        keyed.sort_unstable();
        for (slot, (_, i)) in b.iter_mut().zip(keyed) {
            *slot = i;
        }
    });
    bins
}

/// Adds the Gaussians of `list` to a block of the slab starting at plane `z0`, rows
/// `y0 .. y0 + rows`, stored in `out` (planes × rows × nx, x fastest).
struct SplatSlab<'a> {
    grid: &'a Grid,
    atoms: &'a Atoms<'a>,
    list: &'a [u32],
    z0: usize,
    y0: usize,
    rows: usize,
    out: &'a mut [f32],
}

impl Kernel for SplatSlab<'_> {
    type Output = ();
    // Paper §3.1: "iterate over each atom, applying the RBF to each voxel it overlaps within
    // the outer radius" — one slab of z-planes, SIMD over voxels along x. The Gaussian is
    // separable, exp(−d²/r²) = exp(−dx²/r²)·exp(−dy²/r²)·exp(−dz²/r²): each atom's three
    // profiles are computed once per visit, so a row costs a product, not an `exp`.
    #[inline(always)]
    fn run<S: Simd>(self, s: S) {
        let g = self.grid;
        let (nx, ny) = (g.dims[0], g.dims[1]);
        let planes = self.out.len() / (nx * self.rows);
        let ylast = self.y0 + self.rows - 1;
        let h = g.spacing;
        let (mut px, mut py, mut pz) = (Profile::new(), Profile::new(), Profile::new());
        for &ai in self.list {
            let ai = ai as usize;
            let (ax, ay, az, ar) = (
                self.atoms.x[ai],
                self.atoms.y[ai],
                self.atoms.z[ai],
                self.atoms.r[ai],
            );
            let cut2 = 2.0 * ar * ar;
            let reach = core::f32::consts::SQRT_2 * ar;
            let inv_r2 = s.splat(-1.0 / (ar * ar));
            let amp = ar.sqrt();
            let cut2v = s.splat(cut2);
            let Some((zlo, zhi)) = lattice_range(az, reach, g.origin[2], h, g.dims[2]) else {
                continue;
            };
            let zlo = zlo.max(self.z0);
            let zhi = zhi.min(self.z0 + planes - 1);
            if zlo > zhi {
                continue;
            }
            // The support's extent along y and x (√cut2: the mask below is the exact test).
            let wide = cut2.sqrt();
            let Some((ylo0, yhi0)) = lattice_range(ay, wide, g.origin[1], h, ny) else {
                continue;
            };
            let (ylo0, yhi0) = (ylo0.max(self.y0), yhi0.min(ylast));
            let Some((xlo0, xhi0)) = lattice_range(ax, wide, g.origin[0], h, nx) else {
                continue;
            };
            if ylo0 > yhi0 {
                continue;
            }
            px.fill(s, [g.origin[0], h], ax, xlo0..xhi0 + 1, inv_r2);
            py.fill(s, [g.origin[1], h], ay, ylo0..yhi0 + 1, inv_r2);
            pz.fill(s, [g.origin[2], h], az, zlo..zhi + 1, inv_r2);
            // Every row spans the atom's whole x range: the mask `d² < cut²` alone decides
            // which points a row adds to (no square root and lattice range per row).
            for kz in zlo..=zhi {
                let dz = g.origin[2] + kz as f32 * h - az;
                if cut2 - dz * dz <= 0.0 {
                    continue;
                }
                let fz = amp * pz.e[kz - zlo];
                for jy in ylo0..=yhi0 {
                    let dy = g.origin[1] + jy as f32 * h - ay;
                    let dyz2 = dy * dy + dz * dz;
                    if cut2 - dyz2 <= 0.0 {
                        continue;
                    }
                    let row = ((kz - self.z0) * self.rows + jy - self.y0) * nx;
                    let dyz2v = s.splat(dyz2);
                    let fyz = s.splat(fz * py.e[jy - ylo0]);
                    let mut ix = xlo0;
                    while ix <= xhi0 {
                        let o = ix - xlo0;
                        let d2 = s.load(&px.d2[o..]) + dyz2v;
                        let m = s.first_n(xhi0 + 1 - ix) & s.lt(d2, cut2v);
                        let val = s.load(&px.e[o..]) * fyz;
                        let dst = &mut self.out[row + ix..];
                        let acc = s.load_partial(dst, 0.0);
                        s.store_masked(acc + val, dst, m);
                        ix += S::LANES;
                    }
                }
            }
        }
    }
}

/// One axis of an atom's Gaussian at the lattice points of a range: `d²` (Å², from the atom)
/// and `exp(d²·c)` per point, padded by a vector of zeros so any point's vector loads whole.
struct Profile {
    d2: Vec<f32>,
    e: Vec<f32>,
}

impl Profile {
    fn new() -> Profile {
        Profile {
            d2: Vec::new(),
            e: Vec::new(),
        }
    }

    /// Fills the profile of coordinate `p` (Å) at points `range` of the lattice
    /// `[origin, h]` (point i at `origin + i·h`, as [`Grid::point`] computes it).
    #[inline(always)]
    fn fill<S: Simd>(
        &mut self,
        s: S,
        [origin, h]: [f32; 2],
        p: f32,
        range: core::ops::Range<usize>,
        c: S::F32,
    ) {
        let n = range.len();
        self.d2.clear();
        self.e.clear();
        self.d2.resize(n + S::LANES, 0.0);
        self.e.resize(n + S::LANES, 0.0);
        let lanes = s.to_f32(s.lane_index());
        let mut o = 0;
        while o < n {
            let gi = s.splat((range.start + o) as f32) + lanes;
            let d = s.splat(origin) + gi * s.splat(h) - s.splat(p);
            let d2 = d * d;
            s.store(d2, &mut self.d2[o..]);
            s.store(spmd::math::exp(s, d2 * c), &mut self.e[o..]);
            o += S::LANES;
        }
    }
}

impl core::fmt::Display for VolumeFormat {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}
