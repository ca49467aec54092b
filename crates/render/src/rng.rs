//! Random numbers of the ray-traced modalities: every random number is a pure function of
//! (seed, pixel index, sample index, draw number), an integer hash (Wellons' `lowbias32`) built
//! from `spmd` integer ops, which are exact on every backend. So a picture repeats exactly for
//! a seed, progressive renders give the same result however the samples are split into calls,
//! and every backend draws the same numbers for the same pixel.

use spmd::{Simd, V3};

/// Per-lane random number stream: `state = hash(state)` per draw.
#[derive(Clone, Copy)]
pub(crate) struct Rng<S: Simd> {
    state: S::I32,
}

/// Wellons' `lowbias32` integer hash (exact integer ops, identical on every backend).
#[inline(always)]
fn hash<S: Simd>(s: S, x: S::I32) -> S::I32 {
    let x = x ^ s.shr(x, 16);
    let x = s.mul_i(x, s.splat_i(0x7feb_352d));
    let x = x ^ s.shr(x, 15);
    let x = s.mul_i(x, s.splat_i(0x846c_a68bu32 as i32));
    x ^ s.shr(x, 16)
}

impl<S: Simd> Rng<S> {
    /// The stream of (seed, pixel, sample).
    #[inline(always)]
    pub(crate) fn new(s: S, seed: u32, pixel: S::I32, sample: u32) -> Self {
        let k = hash(
            s,
            s.splat_i((seed.wrapping_mul(0x9e37_79b9) ^ sample.wrapping_mul(0x85eb_ca6b)) as i32),
        );
        Rng {
            state: hash(s, pixel ^ k),
        }
    }

    /// Uniform in [0, 1) with 24 bits.
    #[inline(always)]
    pub(crate) fn next(&mut self, s: S) -> S::F32 {
        self.state = hash(s, self.state + s.splat_i(0x6d2b_79f5));
        s.to_f32(s.shr(self.state, 8)) * s.splat(1.0 / 16_777_216.0)
    }
}

/// `(cos 2πu, sin 2πu)` for `u` in [0, 1): quadrant reduction and Taylor polynomials on
/// [0, π/2) (error below 1e-7).
#[inline(always)]
pub(crate) fn sincos_turn<S: Simd>(s: S, u: S::F32) -> (S::F32, S::F32) {
    let q4 = u * s.splat(4.0);
    let q = s.floor(q4);
    let x = (q4 - q) * s.splat(core::f32::consts::FRAC_PI_2);
    let x2 = x * x;
    // sin x = x(1 − x²/6 + x⁴/120 − …), cos x = 1 − x²/2 + x⁴/24 − …
    let mut sp = s.splat(-1.0 / 39_916_800.0);
    sp = s.fma(sp, x2, s.splat(1.0 / 362_880.0));
    sp = s.fma(sp, x2, s.splat(-1.0 / 5040.0));
    sp = s.fma(sp, x2, s.splat(1.0 / 120.0));
    sp = s.fma(sp, x2, s.splat(-1.0 / 6.0));
    sp = s.fma(sp, x2, s.splat(1.0));
    let sn = sp * x;
    let mut cp = s.splat(1.0 / 479_001_600.0);
    cp = s.fma(cp, x2, s.splat(-1.0 / 3_628_800.0));
    cp = s.fma(cp, x2, s.splat(1.0 / 40_320.0));
    cp = s.fma(cp, x2, s.splat(-1.0 / 720.0));
    cp = s.fma(cp, x2, s.splat(1.0 / 24.0));
    cp = s.fma(cp, x2, s.splat(-0.5));
    let cs = s.fma(cp, x2, s.splat(1.0));
    let qi = s.to_i32(q) & s.splat_i(3);
    let q1 = s.eq_i(qi, s.splat_i(1));
    let q2 = s.eq_i(qi, s.splat_i(2));
    let q3 = s.eq_i(qi, s.splat_i(3));
    // Rotate by q quarter turns: (c, s) → (−s, c) → (−c, −s) → (s, −c).
    let c = s.select(q1, -sn, s.select(q2, -cs, s.select(q3, sn, cs)));
    let si = s.select(q1, cs, s.select(q2, -sn, s.select(q3, -cs, sn)));
    (c, si)
}

/// A uniformly distributed unit vector.
#[inline(always)]
pub(crate) fn unit_vector<S: Simd>(s: S, rng: &mut Rng<S>) -> V3<S> {
    let z = s.splat(1.0) - s.splat(2.0) * rng.next(s);
    let r = s.sqrt(s.max(s.splat(1.0) - z * z, s.splat(0.0)));
    let (c, si) = sincos_turn(s, rng.next(s));
    V3::new(r * c, r * si, z)
}

/// A cosine-distributed direction about the unit normal `n`: `normalize(n + u)` with `u`
/// uniform on the unit sphere has density cos θ / π (falls back to `n` when `u ≈ −n`).
#[inline(always)]
pub(crate) fn cosine_dir<S: Simd>(s: S, n: V3<S>, rng: &mut Rng<S>) -> V3<S> {
    let d = n + unit_vector(s, rng);
    let l2 = d.dot(d);
    let ok = s.gt(l2, s.splat(1e-12));
    let d = d.scale(s.rsqrt(s.select(ok, l2, s.splat(1.0))));
    V3::select(s, ok, d, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spmd::{Isa, Kernel};

    struct Draw(u32, u32);
    impl Kernel for Draw {
        type Output = Vec<f32>;
        #[inline(always)]
        fn run<S: Simd>(self, s: S) -> Vec<f32> {
            let mut out = Vec::new();
            let mut buf = [0.0f32; spmd::MAX_LANES];
            for base in (0..64).step_by(S::LANES) {
                let pixel = s.lane_index() + s.splat_i(base);
                let mut rng = Rng::new(s, self.0, pixel, self.1);
                for _ in 0..4 {
                    s.store(rng.next(s), &mut buf);
                    out.extend_from_slice(&buf[..S::LANES]);
                }
            }
            out
        }
    }

    #[test]
    fn random_numbers_are_identical_on_every_backend_and_uniform() {
        let reference = Isa::Scalar.dispatch(Draw(7, 3));
        for isa in Isa::under_test() {
            let v = isa.dispatch(Draw(7, 3));
            // Order differs (lanes interleave draws), the multiset must not.
            let mut a = reference.clone();
            let mut b = v.clone();
            a.sort_by(f32::total_cmp);
            b.sort_by(f32::total_cmp);
            assert_eq!(a, b, "{isa}");
        }
        let mean = reference.iter().sum::<f32>() / reference.len() as f32;
        assert!((mean - 0.5).abs() < 0.05, "mean {mean}");
        assert!(reference.iter().all(|&x| (0.0..1.0).contains(&x)));
        assert_ne!(Isa::Scalar.dispatch(Draw(8, 3)), reference);
        assert_ne!(Isa::Scalar.dispatch(Draw(7, 4)), reference);
    }

    struct Trig;
    impl Kernel for Trig {
        type Output = f32;
        #[inline(always)]
        fn run<S: Simd>(self, s: S) -> f32 {
            let mut worst = 0.0f32;
            for i in 0..4096 {
                let u = i as f32 / 4096.0;
                let (c, si) = sincos_turn(s, s.splat(u));
                let a = u as f64 * std::f64::consts::TAU;
                worst = worst
                    .max((s.extract(c, 0) as f64 - a.cos()).abs() as f32)
                    .max((s.extract(si, 0) as f64 - a.sin()).abs() as f32);
            }
            worst
        }
    }

    #[test]
    fn sincos_is_accurate() {
        for isa in Isa::under_test() {
            let e = isa.dispatch(Trig);
            assert!(e < 2e-6, "{isa}: {e}");
        }
    }
}
