//! Shared test helpers: a deterministic RNG, synthetic atom sets and an f64 brute-force Φ.
#![allow(dead_code)]

mod rays;
#[allow(unused_imports)]
pub use rays::*;

/// SplitMix64: deterministic, independent of any crate.
pub struct Rng(pub u64);
impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub struct Atoms {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
    pub r: Vec<f32>,
}

/// `n` atoms uniformly in a cube of side `side` Å with radii in [0.3, 1.5] Å.
pub fn random_atoms(n: usize, side: f64, seed: u64) -> Atoms {
    let mut rng = Rng(seed);
    let mut a = Atoms {
        x: vec![],
        y: vec![],
        z: vec![],
        r: vec![],
    };
    for _ in 0..n {
        a.x.push(rng.range(0.0, side) as f32);
        a.y.push(rng.range(0.0, side) as f32);
        a.z.push(rng.range(0.0, side) as f32);
        a.r.push(rng.range(0.3, 1.5) as f32);
    }
    a
}

/// Carbon-like atoms (r = 0.76 Å) on a spherical shell of radius `radius` Å around the
/// origin, ~1.4 Å apart (Fibonacci sphere).
pub fn shell(radius: f64) -> Atoms {
    let n = (4.0 * std::f64::consts::PI * radius * radius * 0.38)
        .round()
        .max(1.0) as usize;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut a = Atoms {
        x: vec![],
        y: vec![],
        z: vec![],
        r: vec![],
    };
    for i in 0..n {
        let zz = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let rr = (1.0 - zz * zz).sqrt();
        let th = golden * i as f64;
        a.x.push((radius * rr * th.cos()) as f32);
        a.y.push((radius * rr * th.sin()) as f32);
        a.z.push((radius * zz) as f32);
        a.r.push(0.76);
    }
    a
}

/// Φ at `p` in double precision over every atom (no cutoff tricks, d < √2·r).
pub fn phi(a: &Atoms, p: [f64; 3]) -> f64 {
    let mut s = 0.0;
    for i in 0..a.x.len() {
        let d2 = (p[0] - a.x[i] as f64).powi(2)
            + (p[1] - a.y[i] as f64).powi(2)
            + (p[2] - a.z[i] as f64).powi(2);
        let r = a.r[i] as f64;
        if d2 < 2.0 * r * r {
            s += r.sqrt() * (-d2 / (r * r)).exp();
        }
    }
    s
}

/// True if `p` is within a relative 1e-4 of some atom's cutoff sphere (where f32 and f64
/// may legitimately disagree about inclusion).
pub fn near_cutoff(a: &Atoms, p: [f64; 3]) -> bool {
    (0..a.x.len()).any(|i| {
        let d2 = (p[0] - a.x[i] as f64).powi(2)
            + (p[1] - a.y[i] as f64).powi(2)
            + (p[2] - a.z[i] as f64).powi(2);
        let c = 2.0 * (a.r[i] as f64).powi(2);
        (d2 / c - 1.0).abs() < 1e-4
    })
}

/// A coolwarm ramp whose opacity rises from 0 at value 0.2 to 0.25 at 0.9.
pub fn ramp_tf() -> volume::TransferFunction {
    // Colour varies with value so colour errors show; transparent below 0.2 (the Gaussian's
    // cutoff, where Φ jumps, is at e^-2 ≈ 0.135 of the peak).
    let mut tf = volume::TransferFunction::preset(volume::Preset::CoolWarm);
    for (i, e) in tf.table.iter_mut().enumerate() {
        let x = i as f32 / 255.0;
        let t = ((x - 0.2) / 0.7).clamp(0.0, 1.0);
        e[3] = 0.25 * t * t * (3.0 - 2.0 * t);
    }
    tf
}
