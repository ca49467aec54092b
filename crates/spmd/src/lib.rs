//! SPMD layer: "varying" values spread across SIMD lanes, "uniform" values shared by all
//! lanes, and one backend per instruction set chosen at run time (paper §3.2, §4.2).
//!
//! Kernels are written once as plain generic functions over [`Simd`] and run through
//! [`Isa::dispatch`], which calls them inside a `#[target_feature]` entry point for the chosen
//! backend so the generic code is compiled with that backend's instructions. Kernels (and every
//! helper they call on the hot path) must be `#[inline(always)]`: a generic function that is
//! not inlined into the entry point is compiled without the target features and every vector
//! op becomes a function call.
//!
//! Backends, one file each: [`Scalar`] (1 lane, the reference), [`Sse41`] (4 lanes),
//! [`Avx2`] (8 lanes, with FMA) and [`Avx512`] (16 lanes, AVX-512F mask registers).
//! Intrinsics live only in this crate.
//!
//! ## Semantics shared by every backend
//! Every operation gives bit-identical results on every backend except where stated:
//! - [`Simd::fma`] is fused (one rounding) on AVX2 and AVX-512 and unfused (`a*b` rounded,
//!   then `+c` rounded) on scalar and SSE4.1.
//! - [`Simd::rcp_fast`] / [`Simd::rsqrt_fast`] are hardware estimates refined by one
//!   Newton-Raphson step; their error bound and domain are documented on the methods.
//! - [`Simd::min`] / [`Simd::max`] follow x86 `minps`: `min(a, b) = if a < b { a } else { b }`,
//!   so a NaN in either operand, or `±0` against `∓0`, yields `b`.
//! - [`Simd::to_i32`] truncates toward zero; NaN and values outside the `i32` range give
//!   `i32::MIN` (x86's "integer indefinite").
//! - Shifts by 32 or more give 0 (logical) or the sign fill (arithmetic).

#![warn(missing_docs)]
use core::fmt::Debug;
use core::ops::{
    Add, AddAssign, BitAnd, BitOr, BitXor, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign,
};

mod isa;
pub mod math;
mod scalar;
mod v3;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use isa::{Isa, IsaError, Kernel};
pub use scalar::Scalar;
pub use v3::V3;
#[cfg(target_arch = "x86_64")]
pub use x86::{avx2::Avx2, avx512::Avx512, sse41::Sse41};

/// Largest lane count of any backend; handy for stack buffers sized up front.
pub const MAX_LANES: usize = 16;

/// A SIMD backend: a zero-sized token whose existence proves the CPU supports its
/// instructions. Varying values are its associated types `F32`, `I32` and `M` (mask).
pub trait Simd: Copy + Send + Sync + Debug + 'static {
    /// Number of lanes of every varying type.
    const LANES: usize;
    /// The instruction set this backend uses.
    const ISA: Isa;

    /// Varying `f32`.
    type F32: Copy
        + Debug
        + Add<Output = Self::F32>
        + Sub<Output = Self::F32>
        + Mul<Output = Self::F32>
        + Div<Output = Self::F32>
        + Neg<Output = Self::F32>
        + AddAssign
        + SubAssign
        + MulAssign;
    /// Varying `i32` (wrapping arithmetic).
    type I32: Copy
        + Debug
        + Add<Output = Self::I32>
        + Sub<Output = Self::I32>
        + BitAnd<Output = Self::I32>
        + BitOr<Output = Self::I32>
        + BitXor<Output = Self::I32>;
    /// Varying boolean: one bit of truth per lane.
    type M: Copy
        + Debug
        + BitAnd<Output = Self::M>
        + BitOr<Output = Self::M>
        + BitXor<Output = Self::M>
        + Not<Output = Self::M>;

    // ----- construction and memory -----

    /// Every lane set to `x` (a uniform value made varying).
    fn splat(self, x: f32) -> Self::F32;
    /// Every lane set to `x`.
    fn splat_i(self, x: i32) -> Self::I32;
    /// Every lane `b`.
    fn splat_m(self, b: bool) -> Self::M;
    /// Lane numbers `0, 1, …, LANES-1` (ISPC's `programIndex`).
    fn lane_index(self) -> Self::I32;
    /// Mask with lanes `0..n` on (all lanes when `n >= LANES`).
    fn first_n(self, n: usize) -> Self::M;
    /// Loads `LANES` values from the front of `s`. Panics if `s.len() < LANES`.
    fn load(self, s: &[f32]) -> Self::F32;
    /// Loads `LANES` values from the front of `s`. Panics if `s.len() < LANES`.
    fn load_i(self, s: &[i32]) -> Self::I32;
    /// Loads the first `min(s.len(), LANES)` values; the remaining lanes are `fill`.
    /// Never reads past the end of `s` (for the tail of an array).
    fn load_partial(self, s: &[f32], fill: f32) -> Self::F32;
    /// Stores all lanes to the front of `out`. Panics if `out.len() < LANES`.
    fn store(self, v: Self::F32, out: &mut [f32]);
    /// Stores all lanes to the front of `out`. Panics if `out.len() < LANES`.
    fn store_i(self, v: Self::I32, out: &mut [i32]);
    /// Stores the active lanes of `v` to `out[lane]`; inactive lanes leave `out` untouched.
    /// Panics if an active lane's index is `>= out.len()`.
    fn store_masked(self, v: Self::F32, out: &mut [f32], m: Self::M);
    /// Value of one lane. Panics if `lane >= LANES`.
    fn extract(self, v: Self::F32, lane: usize) -> f32;
    /// Value of one lane. Panics if `lane >= LANES`.
    fn extract_i(self, v: Self::I32, lane: usize) -> i32;

    // ----- float arithmetic -----

    /// `a * b + c`: fused on AVX2/AVX-512, unfused on scalar/SSE4.1 (see crate docs).
    fn fma(self, a: Self::F32, b: Self::F32, c: Self::F32) -> Self::F32;
    /// x86 `minps` semantics: `if a < b { a } else { b }`.
    fn min(self, a: Self::F32, b: Self::F32) -> Self::F32;
    /// x86 `maxps` semantics: `if a > b { a } else { b }`.
    fn max(self, a: Self::F32, b: Self::F32) -> Self::F32;
    /// Correctly rounded square root (IEEE 754).
    fn sqrt(self, a: Self::F32) -> Self::F32;
    /// Absolute value (clears the sign bit, NaN payload kept).
    fn abs(self, a: Self::F32) -> Self::F32;
    /// Round toward −∞.
    fn floor(self, a: Self::F32) -> Self::F32;
    /// Round toward +∞.
    fn ceil(self, a: Self::F32) -> Self::F32;
    /// `1 / a`, correctly rounded (a division).
    fn rcp(self, a: Self::F32) -> Self::F32;
    /// `1 / sqrt(a)`: a correctly rounded square root, then a correctly rounded division.
    fn rsqrt(self, a: Self::F32) -> Self::F32;
    /// Fast `1 / a`: hardware estimate plus one Newton-Raphson step. Within 4 ulp of the exact
    /// reciprocal when `a` and `1/a` are normal numbers; other inputs are unspecified.
    /// The scalar backend returns the exact `1 / a`.
    fn rcp_fast(self, a: Self::F32) -> Self::F32;
    /// Fast `1 / sqrt(a)`: estimate plus one Newton-Raphson step. Within 4 ulp of the exact
    /// value for normal positive `a`; other inputs are unspecified. Scalar returns `rsqrt`.
    fn rsqrt_fast(self, a: Self::F32) -> Self::F32;

    // ----- comparisons and selection -----

    /// `a < b` per lane (false if either is NaN).
    fn lt(self, a: Self::F32, b: Self::F32) -> Self::M;
    /// `a <= b` per lane (false if either is NaN).
    fn le(self, a: Self::F32, b: Self::F32) -> Self::M;
    /// `a > b` per lane (false if either is NaN).
    fn gt(self, a: Self::F32, b: Self::F32) -> Self::M;
    /// `a >= b` per lane (false if either is NaN).
    fn ge(self, a: Self::F32, b: Self::F32) -> Self::M;
    /// `a == b` per lane (false if either is NaN; `-0 == +0`).
    fn eq(self, a: Self::F32, b: Self::F32) -> Self::M;
    /// `a != b` per lane (true if either is NaN).
    fn ne(self, a: Self::F32, b: Self::F32) -> Self::M;
    /// `m ? a : b` per lane.
    fn select(self, m: Self::M, a: Self::F32, b: Self::F32) -> Self::F32;
    /// `m ? a : b` per lane.
    fn select_i(self, m: Self::M, a: Self::I32, b: Self::I32) -> Self::I32;

    // ----- integer arithmetic -----

    /// Low 32 bits of `a * b` (wrapping).
    fn mul_i(self, a: Self::I32, b: Self::I32) -> Self::I32;
    /// Signed minimum.
    fn min_i(self, a: Self::I32, b: Self::I32) -> Self::I32;
    /// Signed maximum.
    fn max_i(self, a: Self::I32, b: Self::I32) -> Self::I32;
    /// Shift left by `n` bits (0 when `n >= 32`).
    fn shl(self, a: Self::I32, n: u32) -> Self::I32;
    /// Logical shift right by `n` bits (0 when `n >= 32`).
    fn shr(self, a: Self::I32, n: u32) -> Self::I32;
    /// Arithmetic shift right by `n` bits (sign fill when `n >= 32`).
    fn sar(self, a: Self::I32, n: u32) -> Self::I32;
    /// `a == b` per lane.
    fn eq_i(self, a: Self::I32, b: Self::I32) -> Self::M;
    /// Signed `a < b` per lane.
    fn lt_i(self, a: Self::I32, b: Self::I32) -> Self::M;
    /// Signed `a > b` per lane.
    fn gt_i(self, a: Self::I32, b: Self::I32) -> Self::M;

    // ----- conversions -----

    /// `i32 → f32`, rounded to nearest even.
    fn to_f32(self, a: Self::I32) -> Self::F32;
    /// `f32 → i32`, truncated toward zero; NaN and out-of-range give `i32::MIN`.
    fn to_i32(self, a: Self::F32) -> Self::I32;
    /// Reinterprets the bits of each lane.
    fn bitcast_i(self, a: Self::F32) -> Self::I32;
    /// Reinterprets the bits of each lane.
    fn bitcast_f(self, a: Self::I32) -> Self::F32;
    /// The IEEE binary16 values in bits 0-15 and in bits 16-31 of each lane as f32, exactly
    /// (subnormal halves become normal f32s; infinities and NaNs stay so), with the sign bits
    /// 15 and 31 ignored. AVX2 and AVX-512 convert in hardware (F16C); the default works in
    /// the integers, never through an f32 subnormal (an x86 op on one takes a microcode
    /// assist).
    #[inline(always)]
    fn halves(self, w: Self::I32) -> (Self::F32, Self::F32) {
        (
            half_magnitude(self, w & self.splat_i(0x7fff)),
            half_magnitude(self, self.shr(w, 16) & self.splat_i(0x7fff)),
        )
    }

    // ----- masks -----

    /// True if any lane is on.
    fn any(self, m: Self::M) -> bool;
    /// True if every lane is on.
    fn all(self, m: Self::M) -> bool;
    /// True if no lane is on.
    #[inline(always)]
    fn none(self, m: Self::M) -> bool {
        !self.any(m)
    }
    /// Bit `i` set when lane `i` is on.
    fn bitmask(self, m: Self::M) -> u32;
    /// Lane `i` on when bit `i` of `bits` is set (bits above `LANES` ignored).
    fn mask_from_bits(self, bits: u32) -> Self::M;

    // ----- horizontal -----

    /// Minimum over lanes, folded in lane order with [`Simd::min`] semantics.
    fn reduce_min(self, v: Self::F32) -> f32;
    /// Maximum over lanes, folded in lane order with [`Simd::max`] semantics.
    fn reduce_max(self, v: Self::F32) -> f32;
    /// Sum over lanes, added in lane order (deterministic for a given backend).
    fn reduce_add(self, v: Self::F32) -> f32;

    // ----- gathers -----

    /// `m ? s[idx] : fill` per lane. Inactive lanes read nothing, so their indices may be
    /// anything. Panics if an active lane's index is outside `s` (never reads out of bounds).
    fn gather(self, s: &[f32], idx: Self::I32, m: Self::M, fill: Self::F32) -> Self::F32;
    /// `m ? s[idx] : fill` per lane, as [`Simd::gather`].
    fn gather_i(self, s: &[i32], idx: Self::I32, m: Self::M, fill: Self::I32) -> Self::I32;
    /// `m ? s[idx] as i32 : 0` per lane (zero-extended bytes, e.g. a quantised volume), as
    /// [`Simd::gather`].
    #[inline(always)]
    fn gather_u8(self, s: &[u8], idx: Self::I32, m: Self::M) -> Self::I32 {
        self.gather_u8x4(s, idx, m) & self.splat_i(0xff)
    }
    /// `m ? le_u32(s[idx..idx + 4]) : 0` per lane: the four bytes from `idx` on, little
    /// endian (byte `idx` in bits 0-7), bytes past the end of `s` reading as 0 — two x-neighbours
    /// of a quantised volume in one gather. Panics if an active lane's `idx` is outside `s`, as
    /// [`Simd::gather`].
    fn gather_u8x4(self, s: &[u8], idx: Self::I32, m: Self::M) -> Self::I32;
    /// [`Simd::gather_i`] at `idx + o` for each offset `o` of `off` (all `≥ 0`), inactive
    /// lanes 0: neighbouring entries of a table, e.g. one record's fields. The SIMD backends
    /// check the bounds once (`0 ≤ idx < len − max(off)` on every active lane). Panics if
    /// an offset is negative or an active lane reads outside `s`, as [`Simd::gather`].
    #[inline(always)]
    fn gather_i_rows<const N: usize>(
        self,
        s: &[i32],
        idx: Self::I32,
        off: [i32; N],
        m: Self::M,
    ) -> [Self::I32; N] {
        gather_rows_each(self, s, idx, off, m)
    }
    /// [`Simd::gather_u8x4`] at `idx + o` for each offset `o` of `off` (all `≥ 0`): several
    /// rows of a lattice around one index, e.g. a trilinear cell's four x-rows. The SIMD
    /// backends check the bounds once for all rows (`0 ≤ idx ≤ len − 4 − max(off)` on every
    /// active lane) and take the per-row path only when that fails. Panics if an offset is
    /// negative or an active lane reads outside `s`, as [`Simd::gather`].
    #[inline(always)]
    fn gather_u8x4_rows<const N: usize>(
        self,
        s: &[u8],
        idx: Self::I32,
        off: [i32; N],
        m: Self::M,
    ) -> [Self::I32; N] {
        gather_rows_each(self, s, idx, off, m)
    }
}

/// A slice the row gathers ([`Simd::gather_i_rows`], [`Simd::gather_u8x4_rows`]) read: how
/// far one read reaches past its index, and that single checked gather.
pub(crate) trait RowTable {
    /// Elements one read spans (4 bytes of a `u8` slice, one `i32`).
    const SPAN: i64;
    /// Elements in the slice.
    fn elements(&self) -> usize;
    /// The checked single gather at `idx` (inactive lanes 0).
    fn gather_at<S: Simd>(&self, s: S, idx: S::I32, m: S::M) -> S::I32;
}

impl RowTable for [u8] {
    const SPAN: i64 = 4;
    #[inline(always)]
    fn elements(&self) -> usize {
        self.len()
    }
    #[inline(always)]
    fn gather_at<S: Simd>(&self, s: S, idx: S::I32, m: S::M) -> S::I32 {
        s.gather_u8x4(self, idx, m)
    }
}

impl RowTable for [i32] {
    const SPAN: i64 = 1;
    #[inline(always)]
    fn elements(&self) -> usize {
        self.len()
    }
    #[inline(always)]
    fn gather_at<S: Simd>(&self, s: S, idx: S::I32, m: S::M) -> S::I32 {
        s.gather_i(self, idx, m, s.splat_i(0))
    }
}

/// The largest start index from which every row `idx + o` of `off` reads inside `t`
/// (`len − span − max(off)`; negative when none does). Panics if an offset is negative.
#[inline(always)]
pub(crate) fn rows_last_start<T: RowTable + ?Sized>(t: &T, off: &[i32]) -> i64 {
    assert!(off.iter().all(|&o| o >= 0), "row gather: negative offset");
    let top = off.iter().copied().max().unwrap_or(0) as i64;
    t.elements().min(i32::MAX as usize) as i64 - T::SPAN - top
}

/// Each row of a row gather by its own checked gather: the trait's default and the SIMD
/// backends' path when one check does not cover every row. Panics if an offset is negative.
#[inline(always)]
pub(crate) fn gather_rows_each<S: Simd, T: RowTable + ?Sized, const N: usize>(
    s: S,
    t: &T,
    idx: S::I32,
    off: [i32; N],
    m: S::M,
) -> [S::I32; N] {
    rows_last_start(t, &off);
    let mut out = [s.splat_i(0); N];
    for (w, o) in out.iter_mut().zip(off) {
        *w = t.gather_at(s, idx + s.splat_i(o), m);
    }
    out
}

/// The four bytes of `s` from `i` on as a little-endian `i32`, zero past the end (the lane
/// form of [`Simd::gather_u8x4`]). `i` must be inside `s`.
#[inline(always)]
fn le_bytes4(s: &[u8], i: usize) -> i32 {
    match s.get(i..i + 4) {
        Some(w) => i32::from_le_bytes([w[0], w[1], w[2], w[3]]),
        None => {
            let mut w = [0u8; 4];
            w[..s.len() - i].copy_from_slice(&s[i..]);
            i32::from_le_bytes(w)
        }
    }
}

/// The binary16 magnitude `h < 2¹⁵` of each lane as f32, in the integers: a normal half's
/// exponent and mantissa moved into place and its exponent rebiased by 112, a subnormal one
/// (`h < 2¹⁰`) as `h·2⁻²⁴` (exact: an integer below 2¹⁰ times a power of two), infinity and
/// NaN (`h ≥ 0x7c00`) with the f32 exponent of all ones and the same mantissa bits.
#[inline(always)]
fn half_magnitude<S: Simd>(s: S, h: S::I32) -> S::F32 {
    let moved = s.shl(h, 13);
    let normal = s.bitcast_f(moved + s.splat_i(112 << 23));
    let special = s.bitcast_f(moved | s.splat_i(0x7f80_0000));
    let subnormal = s.to_f32(h) * s.splat(f32::from_bits(0x3380_0000)); // 2⁻²⁴
    let finite = s.select(s.lt_i(h, s.splat_i(0x400)), subnormal, normal);
    s.select(s.gt_i(h, s.splat_i(0x7bff)), special, finite)
}

/// Panics unless every active lane's index is inside a slice of `len` elements.
/// Shared by the backends' gathers so the message is the same everywhere.
#[cold]
#[inline(never)]
fn gather_out_of_bounds(idx: i32, len: usize) -> ! {
    panic!("spmd gather: active lane index {idx} outside slice of length {len}")
}
