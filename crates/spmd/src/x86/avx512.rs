//! AVX-512F backend: 16 lanes of `__m512`, masks in `k` registers (`__mmask16`), fused
//! multiply-add, hardware gathers and masked loads/stores.

use core::arch::x86_64::*;

use super::{assignops, binops, check_lanes, row_gathers};
use crate::{le_bytes4, Isa, Kernel, Simd};

/// Runs AVX-512F intrinsics. SAFETY: only used on values of this file's types, whose
/// existence proves AVX-512F support (see the module docs of `x86`); memory accesses are
/// bounds-checked by the caller as stated at each use.
macro_rules! simd {
    ($e:expr) => {{
        #[allow(unused_unsafe, clippy::macro_metavars_in_unsafe)]
        // SAFETY: see the macro's doc comment: the CPU supports AVX-512F.
        unsafe {
            $e
        }
    }};
}

/// AVX-512F backend token (16 lanes).
#[derive(Clone, Copy, Debug)]
pub struct Avx512 {
    _private: (),
}

impl Avx512 {
    /// The token, if this CPU (and OS) supports AVX-512F (plus AVX2 and FMA, which every
    /// AVX-512 CPU has and the entry point also enables).
    pub fn try_new() -> Option<Avx512> {
        (is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("fma"))
        .then_some(Avx512 { _private: () })
    }
}

/// Varying f32, 16 lanes.
#[derive(Clone, Copy, Debug)]
pub struct F32x16(__m512);
/// Varying i32, 16 lanes.
#[derive(Clone, Copy, Debug)]
pub struct I32x16(__m512i);
/// Varying bool: a 16-bit mask register, bit `i` for lane `i`.
#[derive(Clone, Copy, Debug)]
pub struct M16(__mmask16);

binops!(F32x16, __m512, simd, Add::add => _mm512_add_ps, Sub::sub => _mm512_sub_ps, Mul::mul => _mm512_mul_ps, Div::div => _mm512_div_ps);
binops!(I32x16, __m512i, simd, Add::add => _mm512_add_epi32, Sub::sub => _mm512_sub_epi32, BitAnd::bitand => _mm512_and_si512, BitOr::bitor => _mm512_or_si512, BitXor::bitxor => _mm512_xor_si512);
assignops!(F32x16);

impl core::ops::Neg for F32x16 {
    type Output = F32x16;
    #[inline(always)]
    fn neg(self) -> F32x16 {
        F32x16(simd!(_mm512_castsi512_ps(_mm512_xor_si512(
            _mm512_castps_si512(self.0),
            _mm512_set1_epi32(i32::MIN)
        ))))
    }
}

impl core::ops::BitAnd for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitand(self, o: M16) -> M16 {
        M16(self.0 & o.0)
    }
}
impl core::ops::BitOr for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitor(self, o: M16) -> M16 {
        M16(self.0 | o.0)
    }
}
impl core::ops::BitXor for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitxor(self, o: M16) -> M16 {
        M16(self.0 ^ o.0)
    }
}
impl core::ops::Not for M16 {
    type Output = M16;
    #[inline(always)]
    fn not(self) -> M16 {
        M16(!self.0)
    }
}

#[inline(always)]
fn count(n: u32) -> __m128i {
    simd!(_mm_cvtsi32_si128(n as i32))
}

/// `len` as an i32 bound (slices longer than `i32::MAX` are indexable by any i32 ≥ 0).
#[inline(always)]
fn clamp_len(len: usize) -> i32 {
    len.min(i32::MAX as usize) as i32
}

/// Returns `m` after checking that every active lane satisfies `0 <= idx <= len - width`;
/// panics (naming the lane's index) otherwise.
#[inline(always)]
fn active_in_bounds(s: Avx512, idx: I32x16, m: M16, len: usize, width: i32) -> M16 {
    let hi = s.splat_i(clamp_len(len) - width);
    let bad = m & (s.lt_i(idx, s.splat_i(0)) | s.gt_i(idx, hi));
    if s.any(bad) {
        let mut iv = [0i32; 16];
        s.store_i(idx, &mut iv);
        check_lanes(&iv, s.bitmask(m), len);
    }
    m
}

impl Avx512 {
    /// True when `last ≥ 0` and every active lane has `idx ≤ last` as u32 (so `idx ≥ 0`).
    #[inline(always)]
    fn rows_fit(self, idx: I32x16, m: M16, last: i64) -> bool {
        let over = M16(simd!(_mm512_cmpgt_epu32_mask(
            idx.0,
            _mm512_set1_epi32(last.clamp(0, i32::MAX as i64) as i32)
        )));
        last >= 0 && self.none(m & over)
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
        idx: I32x16,
        off: [i32; N],
        m: M16,
    ) -> [I32x16; N] {
        let mut out = [self.splat_i(0); N];
        for (w, o) in out.iter_mut().zip(off) {
            // Bounds: the caller's contract.
            *w = I32x16(simd!(_mm512_mask_i32gather_epi32::<SCALE>(
                _mm512_setzero_si512(),
                m.0,
                (idx + self.splat_i(o)).0,
                base.cast::<i32>()
            )));
        }
        out
    }
}

impl Simd for Avx512 {
    const LANES: usize = 16;
    const ISA: Isa = Isa::Avx512;
    type F32 = F32x16;
    type I32 = I32x16;
    type M = M16;

    #[inline(always)]
    fn splat(self, x: f32) -> F32x16 {
        F32x16(simd!(_mm512_set1_ps(x)))
    }
    #[inline(always)]
    fn splat_i(self, x: i32) -> I32x16 {
        I32x16(simd!(_mm512_set1_epi32(x)))
    }
    #[inline(always)]
    fn splat_m(self, b: bool) -> M16 {
        M16(if b { 0xffff } else { 0 })
    }
    #[inline(always)]
    fn lane_index(self) -> I32x16 {
        I32x16(simd!(_mm512_setr_epi32(
            0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15
        )))
    }
    #[inline(always)]
    fn first_n(self, n: usize) -> M16 {
        M16(if n >= 16 { 0xffff } else { (1u16 << n) - 1 })
    }
    #[inline(always)]
    fn load(self, s: &[f32]) -> F32x16 {
        let s = &s[..16];
        // Bounds: `s` has exactly 16 elements after the slice above.
        F32x16(simd!(_mm512_loadu_ps(s.as_ptr())))
    }
    #[inline(always)]
    fn load_i(self, s: &[i32]) -> I32x16 {
        let s = &s[..16];
        // Bounds: `s` has exactly 16 elements after the slice above.
        I32x16(simd!(_mm512_loadu_si512(s.as_ptr().cast())))
    }
    #[inline(always)]
    fn load_partial(self, s: &[f32], fill: f32) -> F32x16 {
        if s.len() >= 16 {
            return self.load(s);
        }
        let mut a = [fill; 16];
        a[..s.len()].copy_from_slice(s);
        self.load(&a)
    }
    #[inline(always)]
    fn store(self, v: F32x16, out: &mut [f32]) {
        let out = &mut out[..16];
        // Bounds: `out` has exactly 16 elements after the slice above.
        simd!(_mm512_storeu_ps(out.as_mut_ptr(), v.0))
    }
    #[inline(always)]
    fn store_i(self, v: I32x16, out: &mut [i32]) {
        let out = &mut out[..16];
        // Bounds: `out` has exactly 16 elements after the slice above.
        simd!(_mm512_storeu_si512(out.as_mut_ptr().cast(), v.0))
    }
    #[inline(always)]
    fn store_masked(self, v: F32x16, out: &mut [f32], m: M16) {
        let outside = m.0 & !self.first_n(out.len()).0;
        if outside != 0 {
            let lane = outside.trailing_zeros() as i32;
            crate::gather_out_of_bounds(lane, out.len());
        }
        // Bounds: every active lane is < out.len() (checked above); masked-off lanes are
        // not accessed by vmovups with a write mask.
        simd!(_mm512_mask_storeu_ps(out.as_mut_ptr(), m.0, v.0))
    }
    #[inline(always)]
    fn extract(self, v: F32x16, lane: usize) -> f32 {
        let mut a = [0.0; 16];
        self.store(v, &mut a);
        a[lane]
    }
    #[inline(always)]
    fn extract_i(self, v: I32x16, lane: usize) -> i32 {
        let mut a = [0; 16];
        self.store_i(v, &mut a);
        a[lane]
    }

    #[inline(always)]
    fn fma(self, a: F32x16, b: F32x16, c: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_fmadd_ps(a.0, b.0, c.0)))
    }
    #[inline(always)]
    fn min(self, a: F32x16, b: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_min_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn max(self, a: F32x16, b: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_max_ps(a.0, b.0)))
    }
    #[inline(always)]
    fn sqrt(self, a: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_sqrt_ps(a.0)))
    }
    #[inline(always)]
    fn abs(self, a: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_abs_ps(a.0)))
    }
    #[inline(always)]
    fn floor(self, a: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_roundscale_ps::<
            { _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC },
        >(a.0)))
    }
    #[inline(always)]
    fn ceil(self, a: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_roundscale_ps::<
            { _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC },
        >(a.0)))
    }
    #[inline(always)]
    fn rcp(self, a: F32x16) -> F32x16 {
        self.splat(1.0) / a
    }
    #[inline(always)]
    fn rsqrt(self, a: F32x16) -> F32x16 {
        self.splat(1.0) / self.sqrt(a)
    }
    #[inline(always)]
    fn rcp_fast(self, a: F32x16) -> F32x16 {
        let x = simd!(_mm512_rcp14_ps(a.0));
        let e = simd!(_mm512_fnmadd_ps(a.0, x, _mm512_set1_ps(1.0)));
        F32x16(simd!(_mm512_fmadd_ps(x, e, x)))
    }
    #[inline(always)]
    fn rsqrt_fast(self, a: F32x16) -> F32x16 {
        let y = F32x16(simd!(_mm512_rsqrt14_ps(a.0)));
        y * (self.splat(1.5) - self.splat(0.5) * a * y * y)
    }

    #[inline(always)]
    fn lt(self, a: F32x16, b: F32x16) -> M16 {
        M16(simd!(_mm512_cmp_ps_mask::<_CMP_LT_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn le(self, a: F32x16, b: F32x16) -> M16 {
        M16(simd!(_mm512_cmp_ps_mask::<_CMP_LE_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn gt(self, a: F32x16, b: F32x16) -> M16 {
        M16(simd!(_mm512_cmp_ps_mask::<_CMP_GT_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn ge(self, a: F32x16, b: F32x16) -> M16 {
        M16(simd!(_mm512_cmp_ps_mask::<_CMP_GE_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn eq(self, a: F32x16, b: F32x16) -> M16 {
        M16(simd!(_mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn ne(self, a: F32x16, b: F32x16) -> M16 {
        M16(simd!(_mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(a.0, b.0)))
    }
    #[inline(always)]
    fn select(self, m: M16, a: F32x16, b: F32x16) -> F32x16 {
        F32x16(simd!(_mm512_mask_blend_ps(m.0, b.0, a.0)))
    }
    #[inline(always)]
    fn select_i(self, m: M16, a: I32x16, b: I32x16) -> I32x16 {
        I32x16(simd!(_mm512_mask_blend_epi32(m.0, b.0, a.0)))
    }

    #[inline(always)]
    fn mul_i(self, a: I32x16, b: I32x16) -> I32x16 {
        I32x16(simd!(_mm512_mullo_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn min_i(self, a: I32x16, b: I32x16) -> I32x16 {
        I32x16(simd!(_mm512_min_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn max_i(self, a: I32x16, b: I32x16) -> I32x16 {
        I32x16(simd!(_mm512_max_epi32(a.0, b.0)))
    }
    #[inline(always)]
    fn shl(self, a: I32x16, n: u32) -> I32x16 {
        I32x16(simd!(_mm512_sll_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn shr(self, a: I32x16, n: u32) -> I32x16 {
        I32x16(simd!(_mm512_srl_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn sar(self, a: I32x16, n: u32) -> I32x16 {
        I32x16(simd!(_mm512_sra_epi32(a.0, count(n))))
    }
    #[inline(always)]
    fn eq_i(self, a: I32x16, b: I32x16) -> M16 {
        M16(simd!(_mm512_cmpeq_epi32_mask(a.0, b.0)))
    }
    #[inline(always)]
    fn lt_i(self, a: I32x16, b: I32x16) -> M16 {
        M16(simd!(_mm512_cmplt_epi32_mask(a.0, b.0)))
    }
    #[inline(always)]
    fn gt_i(self, a: I32x16, b: I32x16) -> M16 {
        M16(simd!(_mm512_cmpgt_epi32_mask(a.0, b.0)))
    }

    #[inline(always)]
    fn to_f32(self, a: I32x16) -> F32x16 {
        F32x16(simd!(_mm512_cvtepi32_ps(a.0)))
    }
    #[inline(always)]
    fn to_i32(self, a: F32x16) -> I32x16 {
        I32x16(simd!(_mm512_cvttps_epi32(a.0)))
    }
    #[inline(always)]
    fn bitcast_i(self, a: F32x16) -> I32x16 {
        I32x16(simd!(_mm512_castps_si512(a.0)))
    }
    #[inline(always)]
    fn bitcast_f(self, a: I32x16) -> F32x16 {
        F32x16(simd!(_mm512_castsi512_ps(a.0)))
    }

    #[inline(always)]
    fn any(self, m: M16) -> bool {
        m.0 != 0
    }
    #[inline(always)]
    fn all(self, m: M16) -> bool {
        m.0 == 0xffff
    }
    #[inline(always)]
    fn bitmask(self, m: M16) -> u32 {
        m.0 as u32
    }
    #[inline(always)]
    fn mask_from_bits(self, bits: u32) -> M16 {
        M16(bits as u16)
    }

    #[inline(always)]
    fn reduce_min(self, v: F32x16) -> f32 {
        let mut a = [0.0; 16];
        self.store(v, &mut a);
        a[1..]
            .iter()
            .fold(a[0], |acc, &x| if acc < x { acc } else { x })
    }
    #[inline(always)]
    fn reduce_max(self, v: F32x16) -> f32 {
        let mut a = [0.0; 16];
        self.store(v, &mut a);
        a[1..]
            .iter()
            .fold(a[0], |acc, &x| if acc > x { acc } else { x })
    }
    #[inline(always)]
    fn reduce_add(self, v: F32x16) -> f32 {
        let mut a = [0.0; 16];
        self.store(v, &mut a);
        a[1..].iter().fold(a[0], |acc, &x| acc + x)
    }

    // F16C in hardware: each half truncated out of its lane (vpmovdw) and widened
    // (vcvtph2ps), exact for every half.
    #[inline(always)]
    fn halves(self, w: I32x16) -> (F32x16, F32x16) {
        let w = simd!(_mm512_and_si512(w.0, _mm512_set1_epi32(0x7fff_7fff)));
        let lo = simd!(_mm512_cvtph_ps(_mm512_cvtepi32_epi16(w)));
        let hi = simd!(_mm512_cvtph_ps(_mm512_cvtepi32_epi16(_mm512_srli_epi32::<
            16,
        >(w))));
        (F32x16(lo), F32x16(hi))
    }

    #[inline(always)]
    fn gather(self, s: &[f32], idx: I32x16, m: M16, fill: F32x16) -> F32x16 {
        let m = active_in_bounds(self, idx, m, s.len(), 1);
        // Bounds: every active lane's index is inside `s` (checked just above); masked-off
        // lanes are not loaded by vgatherdps.
        F32x16(simd!(_mm512_mask_i32gather_ps::<4>(
            fill.0,
            m.0,
            idx.0,
            s.as_ptr()
        )))
    }
    #[inline(always)]
    fn gather_i(self, s: &[i32], idx: I32x16, m: M16, fill: I32x16) -> I32x16 {
        let m = active_in_bounds(self, idx, m, s.len(), 1);
        // Bounds: as in `gather`.
        I32x16(simd!(_mm512_mask_i32gather_epi32::<4>(
            fill.0,
            m.0,
            idx.0,
            s.as_ptr()
        )))
    }
    row_gathers!(I32x16, M16);
    #[inline(always)]
    fn gather_u8x4(self, s: &[u8], idx: I32x16, m: M16) -> I32x16 {
        // Fast path: one 4-byte gather per active lane, which needs `idx + 3 < len`; lanes
        // near the end of `s` take the lane loop instead.
        if s.len() >= 4 && self.none(m & self.gt_i(idx, self.splat_i(clamp_len(s.len()) - 4))) {
            let m = active_in_bounds(self, idx, m, s.len(), 4);
            // Bounds: every active lane reads s[idx..idx + 4], inside `s` by the test above.
            let w = simd!(_mm512_mask_i32gather_epi32::<1>(
                _mm512_setzero_si512(),
                m.0,
                idx.0,
                s.as_ptr().cast::<i32>()
            ));
            return I32x16(w);
        }
        let (mut iv, mut out) = ([0i32; 16], [0i32; 16]);
        self.store_i(idx, &mut iv);
        let bits = self.bitmask(m);
        check_lanes(&iv, bits, s.len());
        for l in 0..16 {
            if bits >> l & 1 != 0 {
                out[l] = le_bytes4(s, iv[l] as usize);
            }
        }
        self.load_i(&out)
    }
}

/// Runs `k` compiled for AVX-512F. Panics if the CPU lacks it.
pub(crate) fn dispatch<K: Kernel>(k: K) -> K::Output {
    let s = Avx512::try_new().expect("AVX-512 backend dispatched on a CPU without AVX-512F");
    // SAFETY: `try_new` just confirmed AVX-512F, AVX2 and FMA, the features `entry` enables.
    unsafe { entry(s, k) }
}

// Not inlined: one call per task, and a named symbol whose assembly can be checked
// (`cargo xtask asm`).
#[inline(never)]
#[target_feature(enable = "avx512f,avx2,fma")]
fn entry<K: Kernel>(s: Avx512, k: K) -> K::Output {
    k.run(s)
}
