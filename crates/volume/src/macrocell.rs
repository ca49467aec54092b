//! Macrocell grid (paper §4.4): per block of 8³ lattice cells, the min and max of every
//! lattice value a trilinear sample inside the block can touch (the 9³ points including the
//! shared border). Emptiness is *not* stored: it is decided at render time from the current
//! transfer function's range table, so changing the transfer function needs no rebuild.

use rayon::prelude::*;

use crate::grid::{Volume, VolumeData};

/// Lattice cells per macrocell edge.
pub const MACROCELL: usize = 8;

/// Min/max value per macrocell.
#[derive(Clone, Debug)]
pub struct Macrocells {
    /// Macrocells along x, y, z: `ceil((dims − 1) / 8)`.
    pub dims: [usize; 3],
    /// `[min, max]` pairs (dequantised values), x fastest: cell `(i, j, k)` at
    /// `2·(i + dims.x·(j + dims.y·k))`.
    pub minmax: Vec<f32>,
}

impl Macrocells {
    /// Builds the macrocell grid of `vol` (parallel over z-layers of cells; deterministic).
    pub fn build(vol: &Volume) -> Macrocells {
        let g = &vol.grid;
        let dims: [usize; 3] = core::array::from_fn(|a| (g.dims[a] - 1).div_ceil(MACROCELL).max(1));
        let [cx, cy, cz] = dims;
        let mut minmax = vec![0.0f32; 2 * cx * cy * cz];
        let [nx, ny, nz] = g.dims;
        minmax
            .par_chunks_mut(2 * cx * cy)
            .enumerate()
            .for_each(|(k, out)| {
                // Per lattice row y of this cell layer: min/max per cell along x.
                let mut rmin = vec![f32::INFINITY; ny * cx];
                let mut rmax = vec![f32::NEG_INFINITY; ny * cx];
                let z0 = k * MACROCELL;
                let z1 = (z0 + MACROCELL).min(nz - 1);
                for z in z0..=z1 {
                    for y in 0..ny {
                        let base = nx * (y + ny * z);
                        for i in 0..cx {
                            let x0 = i * MACROCELL;
                            let x1 = (x0 + MACROCELL).min(nx - 1);
                            let (mn, mx) = match &vol.data {
                                VolumeData::F32(v) => {
                                    minmax_of(v[base + x0..=base + x1].iter().copied())
                                }
                                VolumeData::U8 { data, .. } => {
                                    let (a, b) = data[base + x0..=base + x1]
                                        .iter()
                                        .fold((u8::MAX, 0u8), |(a, b), &q| (a.min(q), b.max(q)));
                                    (a as f32, b as f32)
                                }
                            };
                            let o = y * cx + i;
                            rmin[o] = rmin[o].min(mn);
                            rmax[o] = rmax[o].max(mx);
                        }
                    }
                }
                let scale = vol.scale().unwrap_or(1.0);
                for j in 0..cy {
                    let y0 = j * MACROCELL;
                    let y1 = (y0 + MACROCELL).min(ny - 1);
                    for i in 0..cx {
                        let (mut mn, mut mx) = (f32::INFINITY, f32::NEG_INFINITY);
                        for y in y0..=y1 {
                            mn = mn.min(rmin[y * cx + i]);
                            mx = mx.max(rmax[y * cx + i]);
                        }
                        // u8: q·scale is exactly how the kernels dequantise.
                        out[2 * (j * cx + i)] = mn * scale;
                        out[2 * (j * cx + i) + 1] = mx * scale;
                    }
                }
            });
        Macrocells { dims, minmax }
    }

    /// `(min, max)` of macrocell `(i, j, k)`.
    pub fn range(&self, i: usize, j: usize, k: usize) -> (f32, f32) {
        let n = 2 * (i + self.dims[0] * (j + self.dims[1] * k));
        (self.minmax[n], self.minmax[n + 1])
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.minmax.len() as u64 * 4
    }
}

fn minmax_of(it: impl Iterator<Item = f32>) -> (f32, f32) {
    it.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    })
}
