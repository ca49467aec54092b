//! Ray batches and the double-precision reference integration the marchers are tested against.

use spmd::Isa;
use volume::*;

use super::{Atoms, Rng};

pub struct Batch {
    pub o: [Vec<f32>; 3],
    pub d: [Vec<f32>; 3],
    pub tmax: Vec<f32>,
}
impl Batch {
    pub fn new() -> Self {
        Batch {
            o: Default::default(),
            d: Default::default(),
            tmax: vec![],
        }
    }
    pub fn push(&mut self, o: [f64; 3], d: [f64; 3], tmax: f32) {
        for a in 0..3 {
            self.o[a].push(o[a] as f32);
            self.d[a].push(d[a] as f32);
        }
        self.tmax.push(tmax);
    }
    pub fn rays(&self) -> Rays<'_> {
        Rays {
            origin: [&self.o[0], &self.o[1], &self.o[2]],
            dir: [&self.d[0], &self.d[1], &self.d[2]],
            tmax: &self.tmax,
        }
    }
    pub fn render(&self, isa: Isa, sc: &VolumeScene) -> Vec<[f32; 4]> {
        let mut out = vec![[0.0; 4]; self.tmax.len()];
        march_rays(isa, sc, &self.rays(), &mut out);
        out
    }
    pub fn render_particles(&self, isa: Isa, sc: &ParticleScene) -> Vec<[f32; 4]> {
        let mut out = vec![[0.0; 4]; self.tmax.len()];
        march_particle_rays(isa, sc, &self.rays(), &mut out);
        out
    }
}

/// Front-to-back emission-absorption along the ray in f64, step `dv` voxels, classification
/// = linear interpolation of the entries of `tf` over [lo, hi], opacity per voxel.
#[allow(clippy::too_many_arguments)]
pub fn reference(
    field: &dyn Fn([f64; 3]) -> f64,
    tf: &TransferFunction,
    lo: f64,
    hi: f64,
    grid: &Grid,
    o: [f64; 3],
    d: [f64; 3],
    tmax: f64,
) -> [f64; 4] {
    reference_shaded(field, tf, lo, hi, grid, o, d, tmax, 0.002, &|_| 1.0)
}

/// As [`reference`] with step `dv` voxels and each sample's colour scaled by `shade(p)`.
#[allow(clippy::too_many_arguments)]
pub fn reference_shaded(
    field: &dyn Fn([f64; 3]) -> f64,
    tf: &TransferFunction,
    lo: f64,
    hi: f64,
    grid: &Grid,
    o: [f64; 3],
    d: [f64; 3],
    tmax: f64,
    dv: f64,
    shade: &dyn Fn([f64; 3]) -> f64,
) -> [f64; 4] {
    let h = grid.spacing as f64;
    let bmax = grid.max_corner();
    let (mut t0, mut t1) = (0.0f64, tmax);
    for a in 0..3 {
        let inv = 1.0 / d[a];
        let (ta, tb) = (
            (grid.origin[a] as f64 - o[a]) * inv,
            (bmax[a] as f64 - o[a]) * inv,
        );
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    let mut c = [0.0f64; 3];
    let mut trans = 1.0f64;
    if t0 >= t1 {
        return [0.0; 4];
    }
    let dl = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let n = ((t1 - t0) * dl / h / dv).ceil() as usize;
    let dt = (t1 - t0) / n as f64;
    let step_vox = dt * dl / h;
    for i in 0..n {
        let t = t0 + (i as f64 + 0.5) * dt;
        let p = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
        let x = (field(p) - lo) / (hi - lo) * 255.0;
        let e = tf.eval(x);
        let a = 1.0 - (-step_vox * tf::extinction(e[3])).exp();
        let f = if a > 0.0 { shade(p) } else { 1.0 };
        for ch in 0..3 {
            c[ch] += trans * e[ch] * a * f;
        }
        trans *= 1.0 - a;
    }
    [c[0], c[1], c[2], 1.0 - trans]
}

pub fn max_err(a: &[[f32; 4]], b: &[[f64; 4]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..4).map(move |c| (x[c] as f64 - y[c]).abs()))
        .fold(0.0, f64::max)
}

/// Rays through a single atom at the origin: a fan of offsets, oblique directions.
pub fn atom_rays(tmax: f32) -> Batch {
    let mut b = Batch::new();
    let mut rng = Rng(42);
    for i in 0..64 {
        let off = [rng.range(-2.2, 2.2), rng.range(-2.2, 2.2)];
        let d = [1.0, rng.range(-0.3, 0.3), rng.range(-0.3, 0.3)];
        // Start outside the volume on the -x side, passing near the atom.
        let o = [-8.0, off[0] - d[1] * 8.0, off[1] - d[2] * 8.0];
        let tmax = if i % 4 == 3 {
            8.0 + rng.range(-1.0, 1.0) as f32
        } else {
            tmax
        };
        b.push(o, d, tmax);
    }
    b
}

/// The density grid of `atoms` at `vpa` voxels/Å (scalar build) and its macrocells.
pub fn volume_of(atoms: &Atoms, vpa: f32, format: VolumeFormat) -> (Volume, Macrocells) {
    let p = DensityParams {
        voxels_per_angstrom: vpa,
        format,
        budget_bytes: None,
    };
    let v = build_density(
        Isa::Scalar,
        &atoms.x,
        &atoms.y,
        &atoms.z,
        &atoms.r,
        &p,
        None,
    )
    .unwrap();
    let mc = Macrocells::build(&v);
    (v, mc)
}

/// Random rays from outside a 40 Å box towards random points near the origin; a quarter
/// with a finite opaque depth.
pub fn scattered_rays(n: usize, seed: u64) -> Batch {
    let mut rng = Rng(seed);
    let mut b = Batch::new();
    for i in 0..n {
        let o = [
            rng.range(-25.0, 25.0),
            rng.range(-25.0, 25.0),
            30.0 * if i % 2 == 0 { 1.0 } else { -1.0 },
        ];
        let target = [
            rng.range(-15.0, 15.0),
            rng.range(-15.0, 15.0),
            rng.range(-15.0, 15.0),
        ];
        let d: [f64; 3] = core::array::from_fn(|a| target[a] - o[a]);
        let tmax = if i % 4 == 1 {
            rng.range(0.3, 1.2) as f32
        } else {
            f32::INFINITY
        };
        b.push(o, d, tmax);
    }
    // Axis-aligned and inside-the-volume origins, the DDA's edge cases.
    b.push([0.1, 0.2, -40.0], [0.0, 0.0, 1.0], f32::INFINITY);
    b.push([-40.0, 0.0, 0.0], [1.0, 0.0, 0.0], f32::INFINITY);
    b.push([0.0, 3.0, 0.0], [0.0, -1.0, 0.0], f32::INFINITY);
    b.push([9.5, 0.0, 0.0], [0.3, 0.5, -0.2], f32::INFINITY);
    b.push([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], 0.0);
    b
}
