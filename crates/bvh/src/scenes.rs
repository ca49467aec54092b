//! Small deterministic random scenes for tests and benchmarks (not the reference data sets,
//! which live in the `molecule` crate).

use crate::geometry::{Aabb, Geometry};
use crate::traverse::Ray;

/// SplitMix64: tiny deterministic generator (tests and benches only).
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
    /// Uniform integer in `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.f64() * n as f64) as usize % n.max(1)
    }
    /// Uniform direction on the unit sphere.
    pub fn dir(&mut self) -> [f64; 3] {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }
}

/// A molecule-like random scene: `n_atoms` atoms on random-walk chains (bond length 1.5 Å,
/// one stick per consecutive pair, plus a cross-link every 7th atom), ball radii 0.3-0.7 Å,
/// stick radius 0.15 Å, at about 0.05 atoms/Å³. `clustered` starts the chains in a few
/// Gaussian blobs instead of uniformly over the box. Colours: one of four per atom.
pub fn random_molecule(n_atoms: usize, clustered: bool, seed: u64) -> Geometry {
    let mut rng = Rng(seed);
    let extent = (n_atoms as f64 / 0.05).cbrt().max(3.0);
    let chain = 50usize;
    let blobs: Vec<[f64; 3]> = (0..8)
        .map(|_| [rng.f64() * extent, rng.f64() * extent, rng.f64() * extent])
        .collect();
    let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
    let (mut radius, mut color) = (Vec::new(), Vec::new());
    let mut bonds = Vec::new();
    let palette = [
        0xff90_9090u32,
        0xff30_30ffu32,
        0xff50_50ffu32,
        0xffff_ffffu32,
    ];
    let mut p = [0.0f64; 3];
    for i in 0..n_atoms {
        if i % chain == 0 {
            p = if clustered {
                let b = blobs[rng.below(blobs.len())];
                let d = rng.dir();
                let r = rng.f64() * extent * 0.12;
                [b[0] + d[0] * r, b[1] + d[1] * r, b[2] + d[2] * r]
            } else {
                [rng.f64() * extent, rng.f64() * extent, rng.f64() * extent]
            };
        } else {
            let d = rng.dir();
            p = [p[0] + 1.5 * d[0], p[1] + 1.5 * d[1], p[2] + 1.5 * d[2]];
            bonds.push([i as u32 - 1, i as u32]);
            if i % 7 == 0 && i % chain >= 3 {
                bonds.push([i as u32 - 3, i as u32]);
            }
        }
        x.push(p[0] as f32);
        y.push(p[1] as f32);
        z.push(p[2] as f32);
        let e = rng.below(4);
        radius.push([0.38f32, 0.3, 0.33, 0.7][e]);
        color.push(palette[e]);
    }
    Geometry::from_atoms(&x, &y, &z, &radius, &color, &bonds, 0.15)
}

/// Primary rays of a `w × w` pinhole view of the box `b` down −z, from 1.6 box extents above
/// its centre (field of view ≈ 43.6°, narrowed by `zoom`), in 4×4 pixel blocks as the renderer
/// casts them (so every backend's packets are neighbouring pixels). For benches and examples.
pub fn camera_rays(b: &Aabb, w: usize, zoom: f32) -> Vec<Ray> {
    let c = b.center();
    let ext = (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0f32, f32::max);
    let eye = [c[0], c[1], c[2] + 1.6 * ext];
    let mut rays = Vec::with_capacity(w * w);
    for by in (0..w).step_by(4) {
        for bx in (0..w).step_by(4) {
            for i in 0..16 {
                let (x, y) = (bx + i % 4, by + i / 4);
                let u = ((x as f32 + 0.5) / w as f32 - 0.5) * 0.8 / zoom;
                let v = (0.5 - (y as f32 + 0.5) / w as f32) * 0.8 / zoom;
                rays.push(Ray::new(eye, [u, v, -1.0]));
            }
        }
    }
    rays
}

/// Test rays for the bounds `b` of `g`: from outside towards random points inside, one in
/// five from near an atom (maybe inside its ball); every 11th with a shorter `tmax`, every
/// 13th with `tmin = 1` Å.
pub fn test_rays(g: &Geometry, b: &Aabb, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    let c = b.center();
    let ext = (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0f32, f32::max) as f64;
    (0..n)
        .map(|i| {
            let target = [
                rng.range(b.min[0] as f64, b.max[0] as f64),
                rng.range(b.min[1] as f64, b.max[1] as f64),
                rng.range(b.min[2] as f64, b.max[2] as f64),
            ];
            let o = if i % 5 == 0 {
                // Inside the scene, maybe inside a ball.
                let a = rng.below(g.balls.len());
                [
                    g.balls.x[a] as f64 + rng.range(-0.3, 0.3),
                    g.balls.y[a] as f64,
                    g.balls.z[a] as f64,
                ]
            } else {
                let d = rng.dir();
                [
                    c[0] as f64 + d[0] * ext * 1.5,
                    c[1] as f64 + d[1] * ext * 1.5,
                    c[2] as f64 + d[2] * ext * 1.5,
                ]
            };
            let mut r = Ray::new(
                [o[0] as f32, o[1] as f32, o[2] as f32],
                [
                    (target[0] - o[0]) as f32,
                    (target[1] - o[1]) as f32,
                    (target[2] - o[2]) as f32,
                ],
            );
            if i % 11 == 0 {
                r.tmax = (ext * 0.7) as f32;
            }
            if i % 13 == 0 {
                r.tmin = 1.0;
            }
            r
        })
        .collect()
}
