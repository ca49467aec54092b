//! Transcendental functions built from the [`Simd`] ops, so every backend runs the same
//! sequence of operations (results differ only where `fma` fuses).

use crate::Simd;

/// `e^x` for varying `x`: Cody-Waite range reduction `x = k·ln2 + r` and a degree-6
/// polynomial for `e^r` (Cephes `expf` coefficients). Relative error below 2e-7 on
/// [-87.3, 88.3]; below -87.3 returns 0, above 88.3 returns +inf (the true value
/// there is within a factor 1.6 of `f32::MAX`); NaN stays NaN.
#[inline(always)]
pub fn exp<S: Simd>(s: S, x: S::F32) -> S::F32 {
    const LOG2E: f32 = core::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let xc = s.min(s.max(x, s.splat(-87.3)), s.splat(88.3));
    let k = s.floor(s.fma(xc, s.splat(LOG2E), s.splat(0.5)));
    let r = xc - k * s.splat(LN2_HI);
    let r = r - k * s.splat(LN2_LO);
    let mut p = s.splat(1.987_569_1e-4);
    p = s.fma(p, r, s.splat(1.398_199_9e-3));
    p = s.fma(p, r, s.splat(8.333_452e-3));
    p = s.fma(p, r, s.splat(4.166_579_6e-2));
    p = s.fma(p, r, s.splat(1.666_666_5e-1));
    p = s.fma(p, r, s.splat(0.5));
    let r2 = r * r;
    let er = s.fma(p, r2, r + s.splat(1.0));
    // 2^k by building the exponent bits; k is in [-126, 127] after the clamp above.
    let ki = s.to_i32(k);
    let two_k = s.bitcast_f(s.shl(ki + s.splat_i(127), 23));
    let res = er * two_k;
    let under = s.lt(x, s.splat(-87.3));
    let over = s.gt(x, s.splat(88.3));
    let res = s.select(under, s.splat(0.0), res);
    let res = s.select(over, s.splat(f32::INFINITY), res);
    s.select(s.ne(x, x), x, res)
}
