//! The simulation cell in the model (issue #20): bonds across a periodic boundary drawn as two
//! half-sticks, one at each side of the cell, and the cell itself drawn as twelve sticks.

use bvh::Geometry;
use molecule::{Cell, MinimumImage};

/// Redraws every stick whose atoms are nearer through the periodic boundary than directly
/// (the minimum image, as the bond search measures it) as two half-sticks: from each atom,
/// half the minimum-image bond long, towards the other atom's nearest image. No stick then
/// spans the cell. Returns the number of bonds split (0 when the cell is degenerate).
pub fn split_periodic_sticks(g: &mut Geometry, cell: &Cell) -> usize {
    let Some(mi) = MinimumImage::new(cell) else {
        return 0;
    };
    let mut split = 0;
    for j in 0..g.sticks.len() {
        let (a, b) = (g.sticks.a[j], g.sticks.b[j]);
        let (pa, pb) = (g.endpoint(a), g.endpoint(b));
        let d = [0, 1, 2].map(|k| f64::from(pb[k]) - f64::from(pa[k]));
        let dm = mi.apply(d);
        // A lattice shift is at least the narrowest cell width, so any shift shows.
        let shift2: f64 = (0..3).map(|k| (d[k] - dm[k]).powi(2)).sum();
        if shift2.is_nan() || shift2 <= 1e-6 {
            continue;
        }
        let half = |p: [f32; 3], sign: f64| {
            [0, 1, 2].map(|k| (f64::from(p[k]) + sign * 0.5 * dm[k]) as f32)
        };
        let color = |i: u32| {
            g.endpoint_color(i)
                .unwrap_or(crate::rgba(200, 200, 200, 255))
        };
        let (ca, cb) = (color(a), color(b));
        let ea = g.push_end(half(pa, 1.0), ca);
        g.sticks.b[j] = ea;
        let eb = g.push_end(half(pb, -1.0), cb);
        g.push_stick(b, eb);
        split += 1;
    }
    split
}

/// Corner `k` (0..8) of `cell` (Å): origin + bit 0 · a + bit 1 · b + bit 2 · c.
fn corner(cell: &Cell, k: usize) -> [f32; 3] {
    let mut p = cell.origin;
    for (bit, e) in cell.edges.iter().enumerate() {
        if k >> bit & 1 == 1 {
            for (pc, ec) in p.iter_mut().zip(e) {
                *pc += ec;
            }
        }
    }
    p
}

/// Adds the twelve edges of `cell` as sticks coloured `color` (packed RGBA8), drawn with the
/// model's stick radius.
pub fn add_cell_edges(g: &mut Geometry, cell: &Cell, color: u32) {
    let ends: Vec<u32> = (0..8).map(|k| g.push_end(corner(cell, k), color)).collect();
    for k in 0..8 {
        for bit in [1, 2, 4] {
            if k & bit == 0 {
                g.push_stick(ends[k], ends[k | bit]);
            }
        }
    }
}
