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
    /// Ray `i` in f64: origin, direction, opaque depth.
    pub fn ray64(&self, i: usize) -> ([f64; 3], [f64; 3], f64) {
        let o = [
            self.o[0][i] as f64,
            self.o[1][i] as f64,
            self.o[2][i] as f64,
        ];
        let d = [
            self.d[0][i] as f64,
            self.d[1][i] as f64,
            self.d[2][i] as f64,
        ];
        (o, d, self.tmax[i] as f64)
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

/// The double-precision reference the marchers are tested against: an analytic `field`
/// classified by `tf` over `[lo, hi]` (linear interpolation of its entries, opacity per voxel
/// of `grid`), inside `grid`'s box.
pub struct Reference<'a> {
    pub field: &'a dyn Fn([f64; 3]) -> f64,
    pub tf: &'a TransferFunction,
    pub lo: f64,
    pub hi: f64,
    pub grid: &'a Grid,
}

impl<'a> Reference<'a> {
    /// `field` classified by `tf` over `[0, hi]` inside `grid`'s box.
    pub fn new(
        field: &'a dyn Fn([f64; 3]) -> f64,
        tf: &'a TransferFunction,
        hi: f32,
        grid: &'a Grid,
    ) -> Self {
        Reference {
            field,
            tf,
            lo: 0.0,
            hi: hi as f64,
            grid,
        }
    }

    /// The part `[t0, t1]` of `[t_lo, t_hi]` where `p + t·dir` is inside the box.
    pub fn clip(&self, p: [f64; 3], dir: [f64; 3], t_lo: f64, t_hi: f64) -> (f64, f64) {
        let g = self.grid;
        let bmax = g.max_corner();
        let (mut t0, mut t1) = (t_lo, t_hi);
        for a in 0..3 {
            let inv = 1.0 / dir[a];
            let (ta, tb) = (
                (g.origin[a] as f64 - p[a]) * inv,
                (bmax[a] as f64 - p[a]) * inv,
            );
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        (t0, t1)
    }

    /// Transfer-function entry of the field at `p`.
    fn classify(&self, p: [f64; 3]) -> [f64; 4] {
        self.tf
            .eval(((self.field)(p) - self.lo) / (self.hi - self.lo) * 255.0)
    }

    /// Front-to-back emission-absorption along the ray (midpoint rule, step `dv` voxels),
    /// each sample's colour scaled by `shade(p)`.
    pub fn ray(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        tmax: f64,
        dv: f64,
        shade: &dyn Fn([f64; 3]) -> f64,
    ) -> [f64; 4] {
        let (t0, t1) = self.clip(o, d, 0.0, tmax);
        if t0 >= t1 {
            return [0.0; 4];
        }
        let h = self.grid.spacing as f64;
        let dl = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let n = ((t1 - t0) * dl / h / dv).ceil() as usize;
        let dt = (t1 - t0) / n as f64;
        let step_vox = dt * dl / h;
        let (mut c, mut trans) = ([0.0f64; 3], 1.0f64);
        for i in 0..n {
            let t = t0 + (i as f64 + 0.5) * dt;
            let p = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
            let e = self.classify(p);
            let a = 1.0 - (-step_vox * tf::extinction(e[3])).exp();
            let f = if a > 0.0 { shade(p) } else { 1.0 };
            for ch in 0..3 {
                c[ch] += trans * e[ch] * a * f;
            }
            trans *= 1.0 - a;
        }
        [c[0], c[1], c[2], 1.0 - trans]
    }

    /// [`Reference::ray`] for every ray of `b`.
    pub fn batch(&self, b: &Batch, dv: f64, shade: &dyn Fn([f64; 3]) -> f64) -> Vec<[f64; 4]> {
        (0..b.tmax.len())
            .map(|i| {
                let (o, d, tmax) = b.ray64(i);
                self.ray(o, d, tmax, dv, shade)
            })
            .collect()
    }

    /// Transmittance from `p` towards `light` to the box's exit (or the point light):
    /// midpoint rule with steps of `dv` voxels.
    pub fn transmittance(&self, p: [f64; 3], light: Light, dv: f64) -> f64 {
        let (dir, dist) = match light {
            Light::Directional(l) => {
                let l = l.map(|x| x as f64);
                let n = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
                (l.map(|x| x / n), f64::INFINITY)
            }
            Light::Point(q) => {
                let d: [f64; 3] = core::array::from_fn(|a| q[a] as f64 - p[a]);
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                (d.map(|x| x / n), n)
            }
        };
        let t1 = self.clip(p, dir, 0.0, dist).1.max(0.0);
        let h = self.grid.spacing as f64;
        let n = (t1 / h / dv).ceil() as usize;
        let dt = t1 / n.max(1) as f64;
        let mut sum = 0.0;
        for i in 0..n {
            let t = (i as f64 + 0.5) * dt;
            let e = self.classify([p[0] + dir[0] * t, p[1] + dir[1] * t, p[2] + dir[2] * t]);
            sum += tf::extinction(e[3]) * dt / h;
        }
        (-sum).exp()
    }
}

/// Asserts `got` within `tol` (any channel) of the reference `want`, printing the error
/// in 1/255 under the label `what`.
pub fn assert_near(what: &str, got: &[[f32; 4]], want: &[[f64; 4]], tol: f64) {
    let e = max_err(got, want);
    eprintln!("{what}: max error {e:.5} ({:.2}/255)", e * 255.0);
    assert!(e <= tol, "{what}: max error {e} over {tol}");
}

/// Default options with classification (pre-integrated or post) and empty-space skipping
/// (on or off) in every combination, each with its tolerance (`preint` or `post`) and a label.
pub fn classification_opts(preint: f64, post: f64) -> Vec<(MarchOptions, f64, String)> {
    let mut v = Vec::new();
    for (preintegrated, tol) in [(true, preint), (false, post)] {
        for macrocells in [true, false] {
            let opts = MarchOptions {
                preintegrated,
                macrocells,
                ..Default::default()
            };
            v.push((
                opts,
                tol,
                format!("preint {preintegrated} skip {macrocells}"),
            ));
        }
    }
    v
}

/// Unshaded samples.
pub fn unshaded(_: [f64; 3]) -> f64 {
    1.0
}

/// Asserts `got` within `tol` of `want` channel by channel, naming the ray with `what(i)`.
pub fn assert_agree(got: &[[f32; 4]], want: &[[f32; 4]], tol: f32, what: &dyn Fn(usize) -> String) {
    assert_eq!(got.len(), want.len());
    for (i, (x, y)) in got.iter().zip(want).enumerate() {
        for c in 0..4 {
            assert!(
                (x[c] - y[c]).abs() <= tol,
                "{} ray {i}: {x:?} vs {y:?}",
                what(i)
            );
        }
    }
}

/// `preset` classified over `[0, hi]` for steps of half a voxel.
pub fn preset_tf(preset: Preset, hi: f32) -> ClassifiedTf {
    ClassifiedTf::new(&TransferFunction::preset(preset), 0.0, hi, 0.5)
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
