//! Empty-space distances over the macrocells for one transfer function (paper §4.4's
//! macrocell skipping, extended): per macrocell, the Chebyshev distance in macrocells to the
//! nearest cell the transfer function does not make empty. A ray in a cell at distance
//! `d ≥ 2` jumps to the exit of the cube of `2d − 1` cells around it without testing the
//! cells inside, all of which are empty (`march.rs`, phase 1), instead of walking them one
//! by one: each step of that walk waits on two dependent gathers and a data-dependent
//! branch, about as long as a sample.

use crate::macrocell::Macrocells;
use crate::tf::ClassifiedTf;

/// Largest stored distance: cells farther from anything visible hold this (a safe bound).
pub const MAX_DISTANCE: u8 = 32;

/// Per-macrocell distance to the nearest non-empty macrocell, in macrocells (0: the cell
/// itself is not empty; cells outside the grid count as empty), capped at [`MAX_DISTANCE`].
/// Built per transfer function (milliseconds: ns740k's 2·10⁵ macrocells at 2 voxels/Å);
/// 1 byte per macrocell, i.e. 1/512 byte per voxel.
#[derive(Clone, Debug, PartialEq)]
pub struct EmptySpace {
    /// Macrocells along x, y, z (as [`Macrocells::dims`]).
    pub dims: [usize; 3],
    /// Distances, x fastest: cell `(i, j, k)` at `i + dims.x·(j + dims.y·k)`.
    pub distance: Vec<u8>,
    /// Fingerprint of the macrocells and transfer function it was built for.
    key: u64,
}

impl EmptySpace {
    /// The distances for `tf` over `cells` (emptiness as the marcher's per-cell test: the
    /// transfer function's max opacity over the cell's bin range widened by one bin).
    pub fn build(cells: &Macrocells, tf: &ClassifiedTf) -> EmptySpace {
        let [cx, cy, cz] = cells.dims;
        let mut distance: Vec<u8> = (0..cx * cy * cz)
            .map(
                |i| match occupied(tf, cells.minmax[2 * i], cells.minmax[2 * i + 1]) {
                    true => 0,
                    false => MAX_DISTANCE,
                },
            )
            .collect();
        // The chessboard distance transform in two raster scans over the 26-neighbourhood
        // (exact for this metric: Rosenfeld and Pfaltz 1966): forward from the 13
        // neighbours already visited, then backward from the other 13.
        let at = |x: usize, y: usize, z: usize| x + cx * (y + cy * z);
        let offset = HALF.map(|(dx, dy, dz)| dx + cx as isize * (dy + cy as isize * dz));
        let scan = |d: &mut Vec<u8>, x: usize, y: usize, z: usize, back: bool| {
            let i = at(x, y, z);
            let mut best = d[i];
            let inner = |v: usize, n: usize| v > 0 && v + 1 < n;
            if inner(x, cx) && inner(y, cy) && inner(z, cz) {
                for o in offset {
                    let q = if back {
                        i.wrapping_add_signed(-o)
                    } else {
                        i.wrapping_add_signed(o)
                    };
                    best = best.min(d[q].saturating_add(1));
                }
                d[i] = best.min(MAX_DISTANCE);
                return;
            }
            for (dx, dy, dz) in HALF {
                let (dx, dy, dz) = if back { (-dx, -dy, -dz) } else { (dx, dy, dz) };
                let q = (
                    x.checked_add_signed(dx).filter(|&v| v < cx),
                    y.checked_add_signed(dy).filter(|&v| v < cy),
                    z.checked_add_signed(dz).filter(|&v| v < cz),
                );
                if let (Some(qx), Some(qy), Some(qz)) = q {
                    best = best.min(d[at(qx, qy, qz)].saturating_add(1));
                }
            }
            d[i] = best.min(MAX_DISTANCE);
        };
        for z in 0..cz {
            for y in 0..cy {
                for x in 0..cx {
                    scan(&mut distance, x, y, z, false);
                }
            }
        }
        for z in (0..cz).rev() {
            for y in (0..cy).rev() {
                for x in (0..cx).rev() {
                    scan(&mut distance, x, y, z, true);
                }
            }
        }
        EmptySpace {
            dims: cells.dims,
            distance,
            key: fingerprint(cells, tf),
        }
    }

    /// True if built for `cells` and `tf` (same ranges, same classification).
    pub fn matches(&self, cells: &Macrocells, tf: &ClassifiedTf) -> bool {
        self.dims == cells.dims && self.key == fingerprint(cells, tf)
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.distance.len() as u64
    }
}

/// A hash of everything emptiness depends on: the cells' ranges, the bin mapping and the
/// range table (a multiply-rotate fold over their bits, ~0.3 ms per 10⁵ macrocells, as
/// [`VolumeScene::with_empty_space`](crate::VolumeScene::with_empty_space) checks it per
/// frame).
fn fingerprint(cells: &Macrocells, tf: &ClassifiedTf) -> u64 {
    let dims = cells.dims.iter().map(|&d| d as f32);
    let bits = dims
        .chain(cells.minmax.iter().copied())
        .chain([tf.lo, tf.to_bin])
        .chain(tf.range_max.iter().copied())
        .map(f32::to_bits);
    bits.fold(0u64, |h, b| {
        (h.rotate_left(5) ^ b as u64).wrapping_mul(0x517c_c1b7_2722_0a95)
    })
}

/// The marcher's emptiness test in scalar: max opacity over the widened bin range above 0.
fn occupied(tf: &ClassifiedTf, mn: f32, mx: f32) -> bool {
    let bin = |v: f32| (((v - tf.lo) * tf.to_bin).clamp(0.0, 255.0) + 0.5) as i32;
    let b0 = (bin(mn) - 1).max(0) as usize;
    let b1 = (bin(mx) + 1).min(255) as usize;
    tf.range_max[(b0 << 8) + b1] > 0.0
}

/// The 13 neighbours `(dx, dy, dz)` a forward raster scan (x fastest) has already visited.
const HALF: [(isize, isize, isize); 13] = [
    (-1, -1, -1),
    (0, -1, -1),
    (1, -1, -1),
    (-1, 0, -1),
    (0, 0, -1),
    (1, 0, -1),
    (-1, 1, -1),
    (0, 1, -1),
    (1, 1, -1),
    (-1, -1, 0),
    (0, -1, 0),
    (1, -1, 0),
    (-1, 0, 0),
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tf::{Preset, TransferFunction};

    /// Distances by brute force: the nearest occupied cell over all of them.
    fn brute(cells: &Macrocells, tf: &ClassifiedTf) -> Vec<u8> {
        let [cx, cy, cz] = cells.dims;
        let idx = |i: usize| [i % cx, (i / cx) % cy, i / (cx * cy)];
        let occ: Vec<[usize; 3]> = (0..cx * cy * cz)
            .filter(|&i| occupied(tf, cells.minmax[2 * i], cells.minmax[2 * i + 1]))
            .map(idx)
            .collect();
        (0..cx * cy * cz)
            .map(|i| {
                let p = idx(i);
                let d = occ
                    .iter()
                    .map(|q| (0..3).map(|a| p[a].abs_diff(q[a])).max().unwrap())
                    .min()
                    .unwrap_or(usize::MAX);
                d.min(MAX_DISTANCE as usize) as u8
            })
            .collect()
    }

    #[test]
    fn distances_match_brute_force() {
        // Occupied cells scattered sparsely (a few far apart, so distances reach the cap)
        // in grids of odd shapes, including flat and one-cell ones.
        let tf = ClassifiedTf::new(&TransferFunction::preset(Preset::CoolWarm), 0.0, 1.0, 0.5);
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as f64 / (1u64 << 31) as f64
        };
        for (dims, density) in [
            ([1, 1, 1], 0.0),
            ([1, 1, 1], 1.0),
            ([5, 1, 3], 0.2),
            ([9, 7, 6], 0.05),
            ([40, 3, 70], 0.002),
            ([80, 2, 2], 0.01),
            ([37, 41, 29], 0.0005),
            ([20, 20, 20], 0.0),
        ] {
            let n: usize = dims.iter().product();
            let mut minmax = vec![0.0f32; 2 * n];
            for i in 0..n {
                if next() < density {
                    minmax[2 * i + 1] = 0.9; // occupied under the ramp
                }
            }
            let cells = Macrocells { dims, minmax };
            let es = EmptySpace::build(&cells, &tf);
            let want = brute(&cells, &tf);
            assert_eq!(es.distance, want, "{dims:?} at {density}");
            if density > 0.0 && n > 1000 {
                assert!(want.contains(&0) && want.iter().any(|&d| d > 3), "{dims:?}");
            }
        }
    }
}
