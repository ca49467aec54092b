//! SSE4.1 backend: 4 lanes of `__m128`. No FMA (fused multiply-add is emulated unfused, as
//! on the scalar backend) and no hardware gather (lane loop).

use core::arch::x86_64::*;

use super::{assignops, binops, check_lanes};
use crate::{le_bytes4, Isa, Kernel, Simd};

/// Runs SSE4.1 intrinsics. SAFETY: only used on values of this file's types, whose existence
/// proves SSE4.1 support (see the module docs of `x86`); memory accesses are bounds-checked
/// by the caller as stated at each use.
macro_rules! simd {
    ($e:expr) => {{
        #[allow(unused_unsafe, clippy::macro_metavars_in_unsafe)]
        // SAFETY: see the macro's doc comment: the CPU supports SSE4.1.
        unsafe {
            $e
        }
    }};
}

/// SSE4.1 backend token (4 lanes).
#[derive(Clone, Copy, Debug)]
pub struct Sse41 {
    _private: (),
}

impl Sse41 {
    /// The token, if this CPU supports SSE4.1.
    pub fn try_new() -> Option<Sse41> {
        is_x86_feature_detected!("sse4.1").then_some(Sse41 { _private: () })
    }
}

/// Varying f32, 4 lanes.
#[derive(Clone, Copy, Debug)]
pub struct F32x4(__m128);
/// Varying i32, 4 lanes.
#[derive(Clone, Copy, Debug)]
pub struct I32x4(__m128i);
/// Varying bool, 4 lanes of all-ones / all-zeros.
#[derive(Clone, Copy, Debug)]
pub struct M32x4(__m128);

binops!(F32x4, __m128, simd, Add::add => _mm_add_ps, Sub::sub => _mm_sub_ps, Mul::mul => _mm_mul_ps, Div::div => _mm_div_ps);
binops!(I32x4, __m128i, simd, Add::add => _mm_add_epi32, Sub::sub => _mm_sub_epi32, BitAnd::bitand => _mm_and_si128, BitOr::bitor => _mm_or_si128, BitXor::bitxor => _mm_xor_si128);
binops!(M32x4, __m128, simd, BitAnd::bitand => _mm_and_ps, BitOr::bitor => _mm_or_ps, BitXor::bitxor => _mm_xor_ps);
assignops!(F32x4);

impl core::ops::Neg for F32x4 {
    type Output = F32x4;
    #[inline(always)]
    fn neg(self) -> F32x4 {
        F32x4(simd!(_mm_xor_ps(self.0, _mm_set1_ps(-0.0))))
    }
}

impl core::ops::Not for M32x4 {
    type Output = M32x4;
    #[inline(always)]
    fn not(self) -> M32x4 {
        M32x4(simd!(_mm_xor_ps(
            self.0,
            _mm_castsi128_ps(_mm_set1_epi32(-1))
        )))
    }
}

#[inline(always)]
fn count(n: u32) -> __m128i {
    simd!(_mm_cvtsi32_si128(n as i32))
}

impl Simd for Sse41 {
    const LANES: usize = 4;
    const ISA: Isa = Isa::Sse41;
    type F32 = F32x4;
    type I32 = I32x4;
    type M = M32x4;

    #[inline(always)]
    fn splat(self, x: f32) -> F32x4 {
        F32x4(simd!(_mm_set1_ps(x)))
    }
    #[inline(always)]
    fn splat_i(self, x: i32) -> I32x4 {
        I32x4(simd!(_mm_set1_epi32(x)))
    }
    #[inline(always)]
    fn splat_m(self, b: bool) -> M32x4 {
        M32x4(simd!(_mm_castsi128_ps(_mm_set1_epi32(-(b as i32)))))
    }
    #[inline(always)]
    fn lane_index(self) -> I32x4 {
        I32x4(simd!(_mm_setr_epi32(0, 1, 2, 3)))
    }
    #[inline(always)]
    fn first_n(self, n: usize) -> M32x4 {
        let n = n.min(4) as i32;
        M32x4(simd!(_mm_castsi128_ps(_mm_cmplt_epi32(
            self.lane_index().0,
            _mm_set1_epi32(n)
        ))))
    }
    #[inline(always)]
    fn load(self, s: &[f32]) -> F32x4 {
        let s = &s[..4];
        // Bounds: `s` has exactly 4 elements after the slice above.
        F32x4(simd!(_mm_loadu_ps(s.as_ptr())))
    }
    #[inline(always)]
    fn load_i(self, s: &[i32]) -> I32x4 {
        let s = &s[..4];
        // Bounds: `s` has exactly 4 elements after the slice above.
        I32x4(simd!(_mm_loadu_si128(s.as_ptr().cast())))
    }
    #[inline(always)]
    fn load_partial(self, s: &[f32], fill: f32) -> F32x4 {
        if s.len() >= 4 {
            return self.load(s);
        }
        let mut a = [fill; 4];
        a[..s.len()].copy_from_slice(s);
        self.load(&a)
    }
    #[inline(always)]
    fn store(self, v: F32x4, out: &mut [f32]) {
        let out = &mut out[..4];
        // Bounds: `out` has exactly 4 elements after the slice above.
        simd!(_mm_storeu_ps(out.as_mut_ptr(), v.0))
    }
    #[inline(always)]
    fn store_i(self, v: I32x4, out: &mut [i32]) {
        let out = &mut out[..4];
        // Bounds: `out` has exactly 4 elements after the slice above.
        simd!(_mm_storeu_si128(out.as_mut_ptr().cast(), v.0))
    }
    #[inline(always)]
    fn store_masked(self, v: F32x4, out: &mut [f32], m: M32x4) {
        let bits = self.bitmask(m);
        if out.len() >= 4 {
            let old = self.load(out);
            self.store(self.select(m, v, old), out);
        } else {
            let mut a = [0.0; 4];
            self.store(v, &mut a);
            for (l, x) in a.iter().enumerate() {
                if bits >> l & 1 != 0 {
                    out[l] = *x;
                }
            }
        }
    }
    #[inline(always)]
    fn extract(self, v: F32x4, lane: usize) -> f32 {
        let mut a = [0.0; 4];
        self.store(v, &mut a);
        a[lane]
    }
    #[inline(always)]
    fn extract_i(self, v: I32x4, lane: usize) -> i32 {
        let mut a = [0; 4];
        self.store_i(v, &mut a);
        a[lane]
    }

    #[inline(always)]
    fn fma(self, a: F32x4, b: F32x4, c: F32x4) -> F32x4 {
        a * b + c
    }
    #[inline(always)]
    fn min(self, a: F32x4, b: F32x4) -> F32x4 {
        F32x4(simd!(_mm_min_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn max(self, a: F32x4, b: F32x4) -> F32x4 {
        F32x4(simd!(_mm_max_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn sqrt(self, a: F32x4) -> F32x4 {
        F32x4(simd!(_mm_sqrt_ps(a.0)))
    }
    #[inline(always)]
    fn abs(self, a: F32x4) -> F32x4 {
        F32x4(simd!(_mm_andnot_ps(_mm_set1_ps(-0.0), a.0)))
    }
    #[inline(always)]
    fn floor(self, a: F32x4) -> F32x4 {
        F32x4(simd!(_mm_floor_ps(a.0)))
    }
    #[inline(always)]
    fn ceil(self, a: F32x4) -> F32x4 {
        F32x4(simd!(_mm_ceil_ps(a.0)))
    }
    #[inline(always)]
    fn rcp(self, a: F32x4) -> F32x4 {
        self.splat(1.0) / a
    }
    #[inline(always)]
    fn rsqrt(self, a: F32x4) -> F32x4 {
        self.splat(1.0) / self.sqrt(a)
    }
    #[inline(always)]
    fn rcp_fast(self, a: F32x4) -> F32x4 {
        let x = F32x4(simd!(_mm_rcp_ps(a.0)));
        x * (self.splat(2.0) - a * x)
    }
    #[inline(always)]
    fn rsqrt_fast(self, a: F32x4) -> F32x4 {
        let y = F32x4(simd!(_mm_rsqrt_ps(a.0)));
        y * (self.splat(1.5) - self.splat(0.5) * a * y * y)
    }

    #[inline(always)]
    fn lt(self, a: F32x4, b: F32x4) -> M32x4 {
        M32x4(simd!(_mm_cmplt_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn le(self, a: F32x4, b: F32x4) -> M32x4 {
        M32x4(simd!(_mm_cmple_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn gt(self, a: F32x4, b: F32x4) -> M32x4 {
        M32x4(simd!(_mm_cmpgt_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn ge(self, a: F32x4, b: F32x4) -> M32x4 {
        M32x4(simd!(_mm_cmpge_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn eq(self, a: F32x4, b: F32x4) -> M32x4 {
        M32x4(simd!(_mm_cmpeq_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn ne(self, a: F32x4, b: F32x4) -> M32x4 {
        M32x4(simd!(_mm_cmpneq_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn select(self, m: M32x4, a: F32x4, b: F32x4) -> F32x4 {
        F32x4(simd!(_mm_blendv_ps(b.0, a.0, m.0)))
    }
    #[inline(always)]
    fn select_i(self, m: M32x4, a: I32x4, b: I32x4) -> I32x4 {
        I32x4(simd!(_mm_castps_si128(_mm_blendv_ps(
            _mm_castsi128_ps(b.0),
            _mm_castsi128_ps(a.0),
            m.0
        ))))
    }

    #[inline(always)]
    fn mul_i(self, a: I32x4, b: I32x4) -> I32x4 {
        I32x4(simd!(_mm_mullo_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn min_i(self, a: I32x4, b: I32x4) -> I32x4 {
        I32x4(simd!(_mm_min_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn max_i(self, a: I32x4, b: I32x4) -> I32x4 {
        I32x4(simd!(_mm_max_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn shl(self, a: I32x4, n: u32) -> I32x4 {
        I32x4(simd!(_mm_sll_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn shr(self, a: I32x4, n: u32) -> I32x4 {
        I32x4(simd!(_mm_srl_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn sar(self, a: I32x4, n: u32) -> I32x4 {
        I32x4(simd!(_mm_sra_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn eq_i(self, a: I32x4, b: I32x4) -> M32x4 {
        M32x4(simd!(_mm_castsi128_ps(_mm_cmpeq_epi32(a.0, b.0))))
    }
    #[inline(always)]
    fn lt_i(self, a: I32x4, b: I32x4) -> M32x4 {
        M32x4(simd!(_mm_castsi128_ps(_mm_cmplt_epi32(a.0, b.0))))
    }
    #[inline(always)]
    fn gt_i(self, a: I32x4, b: I32x4) -> M32x4 {
        M32x4(simd!(_mm_castsi128_ps(_mm_cmpgt_epi32(a.0, b.0))))
    }

    #[inline(always)]
    fn to_f32(self, a: I32x4) -> F32x4 {
        F32x4(simd!(_mm_cvtepi32_ps(a.0)))
    }
    #[inline(always)]
    fn to_i32(self, a: F32x4) -> I32x4 {
        I32x4(simd!(_mm_cvttps_epi32(a.0)))
    }
    #[inline(always)]
    fn bitcast_i(self, a: F32x4) -> I32x4 {
        I32x4(simd!(_mm_castps_si128(a.0)))
    }
    #[inline(always)]
    fn bitcast_f(self, a: I32x4) -> F32x4 {
        F32x4(simd!(_mm_castsi128_ps(a.0)))
    }

    #[inline(always)]
    fn any(self, m: M32x4) -> bool {
        self.bitmask(m) != 0
    }
    #[inline(always)]
    fn all(self, m: M32x4) -> bool {
        self.bitmask(m) == 0xf
    }
    #[inline(always)]
    fn bitmask(self, m: M32x4) -> u32 {
        simd!(_mm_movemask_ps(m.0)) as u32
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u32) -> M32x4 {
        let b = simd!(_mm_setr_epi32(1, 2, 4, 8));
        let v = simd!(_mm_and_si128(_mm_set1_epi32(bits as i32), b));
        M32x4(simd!(_mm_castsi128_ps(_mm_cmpeq_epi32(v, b))))
    }

    #[inline(always)]
    fn reduce_min(self, v: F32x4) -> f32 {
        let mut a = [0.0; 4];
        self.store(v, &mut a);
        a[1..]
            .iter()
            .fold(a[0], |acc, &x| if acc < x { acc } else { x })
    }
    #[inline(always)]
    fn reduce_max(self, v: F32x4) -> f32 {
        let mut a = [0.0; 4];
        self.store(v, &mut a);
        a[1..]
            .iter()
            .fold(a[0], |acc, &x| if acc > x { acc } else { x })
    }
    #[inline(always)]
    fn reduce_add(self, v: F32x4) -> f32 {
        let mut a = [0.0; 4];
        self.store(v, &mut a);
        a[1..].iter().fold(a[0], |acc, &x| acc + x)
    }

    #[inline(always)]
    fn gather(self, s: &[f32], idx: I32x4, m: M32x4, fill: F32x4) -> F32x4 {
        let (mut iv, mut out) = ([0i32; 4], [0.0f32; 4]);
        self.store_i(idx, &mut iv);
        self.store(fill, &mut out);
        let bits = self.bitmask(m);
        check_lanes(&iv, bits, s.len());
        for l in 0..4 {
            if bits >> l & 1 != 0 {
                out[l] = s[iv[l] as usize];
            }
        }
        self.load(&out)
    }
    #[inline(always)]
    fn gather_i(self, s: &[i32], idx: I32x4, m: M32x4, fill: I32x4) -> I32x4 {
        let (mut iv, mut out) = ([0i32; 4], [0i32; 4]);
        self.store_i(idx, &mut iv);
        self.store_i(fill, &mut out);
        let bits = self.bitmask(m);
        check_lanes(&iv, bits, s.len());
        for l in 0..4 {
            if bits >> l & 1 != 0 {
                out[l] = s[iv[l] as usize];
            }
        }
        self.load_i(&out)
    }
    #[inline(always)]
    fn gather_u8x4(self, s: &[u8], idx: I32x4, m: M32x4) -> I32x4 {
        let (mut iv, mut out) = ([0i32; 4], [0i32; 4]);
        self.store_i(idx, &mut iv);
        let bits = self.bitmask(m);
        check_lanes(&iv, bits, s.len());
        for l in 0..4 {
            if bits >> l & 1 != 0 {
                out[l] = le_bytes4(s, iv[l] as usize);
            }
        }
        self.load_i(&out)
    }
}

/// Runs `k` compiled for SSE4.1. Panics if the CPU lacks SSE4.1.
pub(crate) fn dispatch<K: Kernel>(k: K) -> K::Output {
    let s = Sse41::try_new().expect("SSE4.1 backend dispatched on a CPU without SSE4.1");
    // SAFETY: `try_new` just confirmed SSE4.1, the only feature `entry` enables.
    unsafe { entry(s, k) }
}

// Not inlined: one call per task, and a named symbol whose assembly can be checked
// (`cargo xtask asm`).
#[inline(never)]
#[target_feature(enable = "sse4.1")]
fn entry<K: Kernel>(s: Sse41, k: K) -> K::Output {
    k.run(s)
}
