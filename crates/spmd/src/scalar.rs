//! Scalar backend: one lane of plain Rust. The reference every SIMD backend is tested against,
//! written to reproduce the x86 semantics documented in the crate root exactly.

use core::num::Wrapping;

use crate::{gather_out_of_bounds, le_bytes4, Isa, Simd};

/// The scalar reference backend (1 lane). Always available.
#[derive(Clone, Copy, Debug, Default)]
pub struct Scalar;

#[inline(always)]
fn bounds(idx: i32, len: usize) -> usize {
    match usize::try_from(idx) {
        Ok(i) if i < len => i,
        _ => gather_out_of_bounds(idx, len),
    }
}

/// Floor (`up == false`) or ceiling without a libm call (the x86-64 baseline has no
/// `roundss`, so `f32::floor` is a function call that dominated scalar kernels): truncate
/// through `i32` where that is exact (|a| < 2²³), fix up by one, keep the sign of zero.
/// Larger magnitudes, infinities and NaN are already integral and returned as they are.
#[inline(always)]
fn round_toward(a: f32, up: bool) -> f32 {
    if a.is_nan() || a.abs() >= 8_388_608.0 {
        return a;
    }
    let t = a as i32 as f32;
    let r = if !up && t > a {
        t - 1.0
    } else if up && t < a {
        t + 1.0
    } else {
        t
    };
    r.copysign(a)
}

impl Simd for Scalar {
    const LANES: usize = 1;
    const ISA: Isa = Isa::Scalar;
    type F32 = f32;
    type I32 = Wrapping<i32>;
    type M = bool;

    #[inline(always)]
    fn splat(self, x: f32) -> f32 {
        x
    }
    #[inline(always)]
    fn splat_i(self, x: i32) -> Wrapping<i32> {
        Wrapping(x)
    }
    #[inline(always)]
    fn splat_m(self, b: bool) -> bool {
        b
    }
    #[inline(always)]
    fn lane_index(self) -> Wrapping<i32> {
        Wrapping(0)
    }
    #[inline(always)]
    fn first_n(self, n: usize) -> bool {
        n >= 1
    }
    #[inline(always)]
    fn load(self, s: &[f32]) -> f32 {
        s[0]
    }
    #[inline(always)]
    fn load_i(self, s: &[i32]) -> Wrapping<i32> {
        Wrapping(s[0])
    }
    #[inline(always)]
    fn load_partial(self, s: &[f32], fill: f32) -> f32 {
        s.first().copied().unwrap_or(fill)
    }
    #[inline(always)]
    fn store(self, v: f32, out: &mut [f32]) {
        out[0] = v;
    }
    #[inline(always)]
    fn store_i(self, v: Wrapping<i32>, out: &mut [i32]) {
        out[0] = v.0;
    }
    #[inline(always)]
    fn store_masked(self, v: f32, out: &mut [f32], m: bool) {
        if m {
            out[0] = v;
        }
    }
    #[inline(always)]
    fn extract(self, v: f32, lane: usize) -> f32 {
        assert!(lane < 1, "lane {lane} out of range for scalar");
        v
    }
    #[inline(always)]
    fn extract_i(self, v: Wrapping<i32>, lane: usize) -> i32 {
        assert!(lane < 1, "lane {lane} out of range for scalar");
        v.0
    }

    #[inline(always)]
    fn fma(self, a: f32, b: f32, c: f32) -> f32 {
        a * b + c
    }
    #[inline(always)]
    fn min(self, a: f32, b: f32) -> f32 {
        if a < b {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn max(self, a: f32, b: f32) -> f32 {
        if a > b {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn sqrt(self, a: f32) -> f32 {
        a.sqrt()
    }
    #[inline(always)]
    fn abs(self, a: f32) -> f32 {
        f32::from_bits(a.to_bits() & 0x7fff_ffff)
    }
    #[inline(always)]
    fn floor(self, a: f32) -> f32 {
        round_toward(a, false)
    }
    #[inline(always)]
    fn ceil(self, a: f32) -> f32 {
        round_toward(a, true)
    }
    #[inline(always)]
    fn rcp(self, a: f32) -> f32 {
        1.0 / a
    }
    #[inline(always)]
    fn rsqrt(self, a: f32) -> f32 {
        1.0 / a.sqrt()
    }
    #[inline(always)]
    fn rcp_fast(self, a: f32) -> f32 {
        1.0 / a
    }
    #[inline(always)]
    fn rsqrt_fast(self, a: f32) -> f32 {
        1.0 / a.sqrt()
    }

    #[inline(always)]
    fn lt(self, a: f32, b: f32) -> bool {
        a < b
    }
    #[inline(always)]
    fn le(self, a: f32, b: f32) -> bool {
        a <= b
    }
    #[inline(always)]
    fn gt(self, a: f32, b: f32) -> bool {
        a > b
    }
    #[inline(always)]
    fn ge(self, a: f32, b: f32) -> bool {
        a >= b
    }
    #[inline(always)]
    fn eq(self, a: f32, b: f32) -> bool {
        a == b
    }
    #[inline(always)]
    fn ne(self, a: f32, b: f32) -> bool {
        a != b
    }
    #[inline(always)]
    fn select(self, m: bool, a: f32, b: f32) -> f32 {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn select_i(self, m: bool, a: Wrapping<i32>, b: Wrapping<i32>) -> Wrapping<i32> {
        if m {
            a
        } else {
            b
        }
    }

    #[inline(always)]
    fn mul_i(self, a: Wrapping<i32>, b: Wrapping<i32>) -> Wrapping<i32> {
        a * b
    }
    #[inline(always)]
    fn min_i(self, a: Wrapping<i32>, b: Wrapping<i32>) -> Wrapping<i32> {
        a.min(b)
    }
    #[inline(always)]
    fn max_i(self, a: Wrapping<i32>, b: Wrapping<i32>) -> Wrapping<i32> {
        a.max(b)
    }
    #[inline(always)]
    fn shl(self, a: Wrapping<i32>, n: u32) -> Wrapping<i32> {
        Wrapping(if n >= 32 { 0 } else { a.0 << n })
    }
    #[inline(always)]
    fn shr(self, a: Wrapping<i32>, n: u32) -> Wrapping<i32> {
        Wrapping(if n >= 32 {
            0
        } else {
            ((a.0 as u32) >> n) as i32
        })
    }
    #[inline(always)]
    fn sar(self, a: Wrapping<i32>, n: u32) -> Wrapping<i32> {
        Wrapping(a.0 >> n.min(31))
    }
    #[inline(always)]
    fn eq_i(self, a: Wrapping<i32>, b: Wrapping<i32>) -> bool {
        a == b
    }
    #[inline(always)]
    fn lt_i(self, a: Wrapping<i32>, b: Wrapping<i32>) -> bool {
        a < b
    }
    #[inline(always)]
    fn gt_i(self, a: Wrapping<i32>, b: Wrapping<i32>) -> bool {
        a > b
    }

    #[inline(always)]
    fn to_f32(self, a: Wrapping<i32>) -> f32 {
        a.0 as f32
    }
    #[inline(always)]
    fn to_i32(self, a: f32) -> Wrapping<i32> {
        // x86 cvttps2dq: NaN and out-of-range give the "integer indefinite" i32::MIN.
        if !(-2_147_483_648.0..2_147_483_648.0).contains(&a) {
            Wrapping(i32::MIN)
        } else {
            Wrapping(a as i32)
        }
    }
    #[inline(always)]
    fn bitcast_i(self, a: f32) -> Wrapping<i32> {
        Wrapping(a.to_bits() as i32)
    }
    #[inline(always)]
    fn bitcast_f(self, a: Wrapping<i32>) -> f32 {
        f32::from_bits(a.0 as u32)
    }

    #[inline(always)]
    fn any(self, m: bool) -> bool {
        m
    }
    #[inline(always)]
    fn all(self, m: bool) -> bool {
        m
    }
    #[inline(always)]
    fn bitmask(self, m: bool) -> u32 {
        m as u32
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u32) -> bool {
        bits & 1 != 0
    }

    #[inline(always)]
    fn reduce_min(self, v: f32) -> f32 {
        v
    }
    #[inline(always)]
    fn reduce_max(self, v: f32) -> f32 {
        v
    }
    #[inline(always)]
    fn reduce_add(self, v: f32) -> f32 {
        v
    }

    #[inline(always)]
    fn gather(self, s: &[f32], idx: Wrapping<i32>, m: bool, fill: f32) -> f32 {
        if m {
            s[bounds(idx.0, s.len())]
        } else {
            fill
        }
    }
    #[inline(always)]
    fn gather_i(
        self,
        s: &[i32],
        idx: Wrapping<i32>,
        m: bool,
        fill: Wrapping<i32>,
    ) -> Wrapping<i32> {
        if m {
            Wrapping(s[bounds(idx.0, s.len())])
        } else {
            fill
        }
    }
    #[inline(always)]
    fn gather_u8(self, s: &[u8], idx: Wrapping<i32>, m: bool) -> Wrapping<i32> {
        if m {
            Wrapping(s[bounds(idx.0, s.len())] as i32)
        } else {
            Wrapping(0)
        }
    }
    #[inline(always)]
    fn gather_u8x4(self, s: &[u8], idx: Wrapping<i32>, m: bool) -> Wrapping<i32> {
        if m {
            Wrapping(le_bytes4(s, bounds(idx.0, s.len())))
        } else {
            Wrapping(0)
        }
    }
}
