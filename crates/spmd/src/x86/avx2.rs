//! AVX2 backend: 8 lanes of `__m256`, fused multiply-add, hardware gathers.

use core::arch::x86_64::*;

use super::{assignops, binops, check_lanes, row_gathers};
use crate::{le_bytes4, Isa, Kernel, Simd};

/// Runs AVX2, FMA and F16C intrinsics. SAFETY: only used on values of this file's types, whose existence
/// proves AVX2, FMA and F16C support (see the module docs of `x86`); memory accesses are bounds-checked
/// by the caller as stated at each use.
macro_rules! simd {
    ($e:expr) => {{
        #[allow(unused_unsafe, clippy::macro_metavars_in_unsafe)]
        // SAFETY: see the macro's doc comment: the CPU supports AVX2, FMA and F16C.
        unsafe {
            $e
        }
    }};
}

/// AVX2 + FMA + F16C backend token (8 lanes).
#[derive(Clone, Copy, Debug)]
pub struct Avx2 {
    _private: (),
}

impl Avx2 {
    /// The token, if this CPU supports AVX2, FMA and F16C (every AVX2 CPU from Intel and AMD
    /// has F16C).
    pub fn try_new() -> Option<Avx2> {
        (is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("fma")
            && is_x86_feature_detected!("f16c"))
        .then_some(Avx2 { _private: () })
    }
}

/// Varying f32, 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct F32x8(__m256);
/// Varying i32, 8 lanes.
#[derive(Clone, Copy, Debug)]
pub struct I32x8(__m256i);
/// Varying bool, 8 lanes of all-ones / all-zeros.
#[derive(Clone, Copy, Debug)]
pub struct M32x8(__m256);

binops!(F32x8, __m256, simd, Add::add => _mm256_add_ps, Sub::sub => _mm256_sub_ps, Mul::mul => _mm256_mul_ps, Div::div => _mm256_div_ps);
binops!(I32x8, __m256i, simd, Add::add => _mm256_add_epi32, Sub::sub => _mm256_sub_epi32, BitAnd::bitand => _mm256_and_si256, BitOr::bitor => _mm256_or_si256, BitXor::bitxor => _mm256_xor_si256);
binops!(M32x8, __m256, simd, BitAnd::bitand => _mm256_and_ps, BitOr::bitor => _mm256_or_ps, BitXor::bitxor => _mm256_xor_ps);
assignops!(F32x8);

impl core::ops::Neg for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn neg(self) -> F32x8 {
        F32x8(simd!(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0))))
    }
}

impl core::ops::Not for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn not(self) -> M32x8 {
        M32x8(simd!(_mm256_xor_ps(
            self.0,
            _mm256_castsi256_ps(_mm256_set1_epi32(-1))
        )))
    }
}

#[inline(always)]
fn count(n: u32) -> __m128i {
    simd!(_mm_cvtsi32_si128(n as i32))
}

impl Avx2 {
    /// True when `last ≥ 0` and every active lane has `idx ≤ last` as u32 (so `idx ≥ 0`;
    /// the unsigned compare as a signed one with the sign bits flipped).
    #[inline(always)]
    fn rows_fit(self, idx: I32x8, m: M32x8, last: i64) -> bool {
        let flip = self.splat_i(i32::MIN);
        let top = self.splat_i(last.clamp(0, i32::MAX as i64) as i32);
        last >= 0 && self.none(m & self.gt_i(idx ^ flip, top ^ flip))
    }

    /// The 4-byte words at `base + (idx + o)·SCALE` bytes for each offset `o` of `off`,
    /// active lanes only (no closure: it would not inherit the entry's target features).
    ///
    /// # Safety
    /// Every active lane's 4 bytes at each such address must lie inside one allocation.
    #[inline(always)]
    unsafe fn gather_words<const SCALE: i32, const N: usize>(
        self,
        base: *const u8,
        idx: I32x8,
        off: [i32; N],
        m: M32x8,
    ) -> [I32x8; N] {
        let mut out = [self.splat_i(0); N];
        for (w, o) in out.iter_mut().zip(off) {
            // Bounds: the caller's contract.
            *w = I32x8(simd!(_mm256_mask_i32gather_epi32::<SCALE>(
                _mm256_setzero_si256(),
                base.cast::<i32>(),
                (idx + self.splat_i(o)).0,
                _mm256_castps_si256(m.0)
            )));
        }
        out
    }
}

impl Simd for Avx2 {
    const LANES: usize = 8;
    const ISA: Isa = Isa::Avx2;
    type F32 = F32x8;
    type I32 = I32x8;
    type M = M32x8;

    #[inline(always)]
    fn splat(self, x: f32) -> F32x8 {
        F32x8(simd!(_mm256_set1_ps(x)))
    }
    #[inline(always)]
    fn splat_i(self, x: i32) -> I32x8 {
        I32x8(simd!(_mm256_set1_epi32(x)))
    }
    #[inline(always)]
    fn splat_m(self, b: bool) -> M32x8 {
        M32x8(simd!(_mm256_castsi256_ps(_mm256_set1_epi32(-(b as i32)))))
    }
    #[inline(always)]
    fn lane_index(self) -> I32x8 {
        I32x8(simd!(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)))
    }
    #[inline(always)]
    fn first_n(self, n: usize) -> M32x8 {
        let n = n.min(8) as i32;
        M32x8(simd!(_mm256_castsi256_ps(_mm256_cmpgt_epi32(
            _mm256_set1_epi32(n),
            self.lane_index().0
        ))))
    }
    #[inline(always)]
    fn load(self, s: &[f32]) -> F32x8 {
        let s = &s[..8];
        // Bounds: `s` has exactly 8 elements after the slice above.
        F32x8(simd!(_mm256_loadu_ps(s.as_ptr())))
    }
    #[inline(always)]
    fn load_i(self, s: &[i32]) -> I32x8 {
        let s = &s[..8];
        // Bounds: `s` has exactly 8 elements after the slice above.
        I32x8(simd!(_mm256_loadu_si256(s.as_ptr().cast())))
    }
    #[inline(always)]
    fn load_partial(self, s: &[f32], fill: f32) -> F32x8 {
        if s.len() >= 8 {
            return self.load(s);
        }
        let mut a = [fill; 8];
        a[..s.len()].copy_from_slice(s);
        self.load(&a)
    }
    #[inline(always)]
    fn store(self, v: F32x8, out: &mut [f32]) {
        let out = &mut out[..8];
        // Bounds: `out` has exactly 8 elements after the slice above.
        simd!(_mm256_storeu_ps(out.as_mut_ptr(), v.0))
    }
    #[inline(always)]
    fn store_i(self, v: I32x8, out: &mut [i32]) {
        let out = &mut out[..8];
        // Bounds: `out` has exactly 8 elements after the slice above.
        simd!(_mm256_storeu_si256(out.as_mut_ptr().cast(), v.0))
    }
    #[inline(always)]
    fn store_masked(self, v: F32x8, out: &mut [f32], m: M32x8) {
        let bits = self.bitmask(m);
        if out.len() >= 8 {
            let old = self.load(out);
            self.store(self.select(m, v, old), out);
        } else {
            let mut a = [0.0; 8];
            self.store(v, &mut a);
            for (l, x) in a.iter().enumerate() {
                if bits >> l & 1 != 0 {
                    out[l] = *x;
                }
            }
        }
    }
    #[inline(always)]
    fn extract(self, v: F32x8, lane: usize) -> f32 {
        let mut a = [0.0; 8];
        self.store(v, &mut a);
        a[lane]
    }
    #[inline(always)]
    fn extract_i(self, v: I32x8, lane: usize) -> i32 {
        let mut a = [0; 8];
        self.store_i(v, &mut a);
        a[lane]
    }

    #[inline(always)]
    fn fma(self, a: F32x8, b: F32x8, c: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_fmadd_ps(a.0, b.0, c.0)))
    }
    #[inline(always)]
    fn min(self, a: F32x8, b: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_min_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn max(self, a: F32x8, b: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_max_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn sqrt(self, a: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_sqrt_ps(a.0)))
    }
    #[inline(always)]
    fn abs(self, a: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), a.0)))
    }
    #[inline(always)]
    fn floor(self, a: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_floor_ps(a.0)))
    }
    #[inline(always)]
    fn ceil(self, a: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_ceil_ps(a.0)))
    }
    #[inline(always)]
    fn rcp(self, a: F32x8) -> F32x8 {
        self.splat(1.0) / a
    }
    #[inline(always)]
    fn rsqrt(self, a: F32x8) -> F32x8 {
        self.splat(1.0) / self.sqrt(a)
    }
    #[inline(always)]
    fn rcp_fast(self, a: F32x8) -> F32x8 {
        let x = simd!(_mm256_rcp_ps(a.0));
        let e = simd!(_mm256_fnmadd_ps(a.0, x, _mm256_set1_ps(1.0)));
        F32x8(simd!(_mm256_fmadd_ps(x, e, x)))
    }
    #[inline(always)]
    fn rsqrt_fast(self, a: F32x8) -> F32x8 {
        let y = F32x8(simd!(_mm256_rsqrt_ps(a.0)));
        y * (self.splat(1.5) - self.splat(0.5) * a * y * y)
    }

    #[inline(always)]
    fn lt(self, a: F32x8, b: F32x8) -> M32x8 {
        M32x8(simd!(_mm256_cmp_ps::<_CMP_LT_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn le(self, a: F32x8, b: F32x8) -> M32x8 {
        M32x8(simd!(_mm256_cmp_ps::<_CMP_LE_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn gt(self, a: F32x8, b: F32x8) -> M32x8 {
        M32x8(simd!(_mm256_cmp_ps::<_CMP_GT_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn ge(self, a: F32x8, b: F32x8) -> M32x8 {
        M32x8(simd!(_mm256_cmp_ps::<_CMP_GE_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn eq(self, a: F32x8, b: F32x8) -> M32x8 {
        M32x8(simd!(_mm256_cmp_ps::<_CMP_EQ_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn ne(self, a: F32x8, b: F32x8) -> M32x8 {
        M32x8(simd!(_mm256_cmp_ps::<_CMP_NEQ_UQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn select(self, m: M32x8, a: F32x8, b: F32x8) -> F32x8 {
        F32x8(simd!(_mm256_blendv_ps(b.0, a.0, m.0)))
    }
    #[inline(always)]
    fn select_i(self, m: M32x8, a: I32x8, b: I32x8) -> I32x8 {
        I32x8(simd!(_mm256_castps_si256(_mm256_blendv_ps(
            _mm256_castsi256_ps(b.0),
            _mm256_castsi256_ps(a.0),
            m.0
        ))))
    }

    #[inline(always)]
    fn mul_i(self, a: I32x8, b: I32x8) -> I32x8 {
        I32x8(simd!(_mm256_mullo_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn min_i(self, a: I32x8, b: I32x8) -> I32x8 {
        I32x8(simd!(_mm256_min_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn max_i(self, a: I32x8, b: I32x8) -> I32x8 {
        I32x8(simd!(_mm256_max_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn shl(self, a: I32x8, n: u32) -> I32x8 {
        I32x8(simd!(_mm256_sll_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn shr(self, a: I32x8, n: u32) -> I32x8 {
        I32x8(simd!(_mm256_srl_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn sar(self, a: I32x8, n: u32) -> I32x8 {
        I32x8(simd!(_mm256_sra_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn eq_i(self, a: I32x8, b: I32x8) -> M32x8 {
        M32x8(simd!(_mm256_castsi256_ps(_mm256_cmpeq_epi32(a.0, b.0))))
    }
    #[inline(always)]
    fn lt_i(self, a: I32x8, b: I32x8) -> M32x8 {
        M32x8(simd!(_mm256_castsi256_ps(_mm256_cmpgt_epi32(b.0, a.0))))
    }
    #[inline(always)]
    fn gt_i(self, a: I32x8, b: I32x8) -> M32x8 {
        M32x8(simd!(_mm256_castsi256_ps(_mm256_cmpgt_epi32(a.0, b.0))))
    }

    #[inline(always)]
    fn to_f32(self, a: I32x8) -> F32x8 {
        F32x8(simd!(_mm256_cvtepi32_ps(a.0)))
    }
    #[inline(always)]
    fn to_i32(self, a: F32x8) -> I32x8 {
        I32x8(simd!(_mm256_cvttps_epi32(a.0)))
    }
    #[inline(always)]
    fn bitcast_i(self, a: F32x8) -> I32x8 {
        I32x8(simd!(_mm256_castps_si256(a.0)))
    }
    #[inline(always)]
    fn bitcast_f(self, a: I32x8) -> F32x8 {
        F32x8(simd!(_mm256_castsi256_ps(a.0)))
    }

    #[inline(always)]
    fn any(self, m: M32x8) -> bool {
        self.bitmask(m) != 0
    }
    #[inline(always)]
    fn all(self, m: M32x8) -> bool {
        self.bitmask(m) == 0xff
    }
    #[inline(always)]
    fn bitmask(self, m: M32x8) -> u32 {
        simd!(_mm256_movemask_ps(m.0)) as u32
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u32) -> M32x8 {
        let b = simd!(_mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128));
        let v = simd!(_mm256_and_si256(_mm256_set1_epi32(bits as i32), b));
        M32x8(simd!(_mm256_castsi256_ps(_mm256_cmpeq_epi32(v, b))))
    }

    #[inline(always)]
    fn reduce_min(self, v: F32x8) -> f32 {
        let mut a = [0.0; 8];
        self.store(v, &mut a);
        a[1..]
            .iter()
            .fold(a[0], |acc, &x| if acc < x { acc } else { x })
    }
    #[inline(always)]
    fn reduce_max(self, v: F32x8) -> f32 {
        let mut a = [0.0; 8];
        self.store(v, &mut a);
        a[1..]
            .iter()
            .fold(a[0], |acc, &x| if acc > x { acc } else { x })
    }
    #[inline(always)]
    fn reduce_add(self, v: F32x8) -> f32 {
        let mut a = [0.0; 8];
        self.store(v, &mut a);
        a[1..].iter().fold(a[0], |acc, &x| acc + x)
    }

    // F16C in hardware: the low and high halves packed to words (exact: both below 2¹⁵),
    // the 128-bit lanes reordered so each half's eight sit together, then widened (vcvtph2ps).
    #[inline(always)]
    fn halves(self, w: I32x8) -> (F32x8, F32x8) {
        let m = simd!(_mm256_set1_epi32(0x7fff));
        let lo = simd!(_mm256_and_si256(w.0, m));
        let hi = simd!(_mm256_and_si256(_mm256_srli_epi32::<16>(w.0), m));
        let q = simd!(_mm256_permute4x64_epi64::<0b11_01_10_00>(
            _mm256_packus_epi32(lo, hi)
        ));
        (
            F32x8(simd!(_mm256_cvtph_ps(_mm256_castsi256_si128(q)))),
            F32x8(simd!(_mm256_cvtph_ps(_mm256_extracti128_si256::<1>(q)))),
        )
    }

    #[inline(always)]
    fn gather(self, s: &[f32], idx: I32x8, m: M32x8, fill: F32x8) -> F32x8 {
        let m = active_in_bounds(self, idx, m, s.len(), 1);
        // Bounds: every active lane's index is inside `s` (checked just above); inactive
        // lanes are not loaded by vgatherdps.
        F32x8(simd!(_mm256_mask_i32gather_ps::<4>(
            fill.0,
            s.as_ptr(),
            idx.0,
            m.0
        )))
    }
    #[inline(always)]
    fn gather_i(self, s: &[i32], idx: I32x8, m: M32x8, fill: I32x8) -> I32x8 {
        let m = active_in_bounds(self, idx, m, s.len(), 1);
        // Bounds: as in `gather`.
        I32x8(simd!(_mm256_mask_i32gather_epi32::<4>(
            fill.0,
            s.as_ptr(),
            idx.0,
            _mm256_castps_si256(m.0)
        )))
    }
    row_gathers!(I32x8, M32x8);
    #[inline(always)]
    fn gather_u8x4(self, s: &[u8], idx: I32x8, m: M32x8) -> I32x8 {
        // Fast path: one 4-byte gather per active lane, which needs `idx + 3 < len`; lanes
        // near the end of `s` take the lane loop instead.
        if s.len() >= 4 && self.none(m & self.gt_i(idx, self.splat_i(clamp_len(s.len()) - 4))) {
            let m = active_in_bounds(self, idx, m, s.len(), 4);
            // Bounds: every active lane reads s[idx..idx + 4], inside `s` by the test above.
            let w = simd!(_mm256_mask_i32gather_epi32::<1>(
                _mm256_setzero_si256(),
                s.as_ptr().cast::<i32>(),
                idx.0,
                _mm256_castps_si256(m.0)
            ));
            return I32x8(w);
        }
        let (mut iv, mut out) = ([0i32; 8], [0i32; 8]);
        self.store_i(idx, &mut iv);
        let bits = self.bitmask(m);
        check_lanes(&iv, bits, s.len());
        for l in 0..8 {
            if bits >> l & 1 != 0 {
                out[l] = le_bytes4(s, iv[l] as usize);
            }
        }
        self.load_i(&out)
    }
}

/// `len` as an i32 bound (slices longer than `i32::MAX` are indexable by any i32 ≥ 0).
#[inline(always)]
fn clamp_len(len: usize) -> i32 {
    len.min(i32::MAX as usize) as i32
}

/// Returns `m` after checking that every active lane satisfies `0 <= idx <= len - width`;
/// panics (naming the lane's index) otherwise.
#[inline(always)]
fn active_in_bounds(s: Avx2, idx: I32x8, m: M32x8, len: usize, width: i32) -> M32x8 {
    let hi = s.splat_i(clamp_len(len) - width);
    let bad = m & (s.lt_i(idx, s.splat_i(0)) | s.gt_i(idx, hi));
    if s.any(bad) {
        let mut iv = [0i32; 8];
        s.store_i(idx, &mut iv);
        check_lanes(&iv, s.bitmask(m), len);
    }
    m
}

/// Runs `k` compiled for AVX2 + FMA + F16C. Panics if the CPU lacks them.
pub(crate) fn dispatch<K: Kernel>(k: K) -> K::Output {
    let s = Avx2::try_new().expect("AVX2 backend dispatched on a CPU without AVX2, FMA and F16C");
    // SAFETY: `try_new` just confirmed AVX2, FMA and F16C, the features `entry` enables.
    unsafe { entry(s, k) }
}

// Not inlined: one call per task, and a named symbol whose assembly can be checked
// (`cargo xtask asm`).
#[inline(never)]
#[target_feature(enable = "avx2,fma,f16c")]
fn entry<K: Kernel>(s: Avx2, k: K) -> K::Output {
    k.run(s)
}
