//! x86-64 backends, one file per instruction set.
//!
//! Soundness argument shared by all three files: each backend's token (`Sse41`, `Avx2`,
//! `Avx512`) has a private field and is only created by `try_new`, which checks the CPU
//! with `is_x86_feature_detected!`, and each varying type has a private field and is only
//! created from a token or from other varying values of the same backend. So whenever an
//! intrinsic runs on such a value, the features it needs are present. Memory intrinsics
//! additionally bounds-check their slices (stated at each use).

pub mod avx2;
pub mod avx512;
pub mod sse41;

/// Implements the std operator traits for a backend's vector newtypes with the given
/// intrinsics. Used inside `unsafe` only through the per-file `simd!` macro.
macro_rules! binops {
    ($ty:ident, $inner:ty, $guard:ident, $( $tr:ident :: $m:ident => $f:path ),* $(,)?) => {
        $(
            impl core::ops::$tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $m(self, o: $ty) -> $ty {
                    $ty($guard!($f(self.0, o.0)))
                }
            }
        )*
    };
}
pub(crate) use binops;

/// `AddAssign` / `SubAssign` / `MulAssign` from the binary operators.
macro_rules! assignops {
    ($ty:ident) => {
        impl core::ops::AddAssign for $ty {
            #[inline(always)]
            fn add_assign(&mut self, o: $ty) {
                *self = *self + o;
            }
        }
        impl core::ops::SubAssign for $ty {
            #[inline(always)]
            fn sub_assign(&mut self, o: $ty) {
                *self = *self - o;
            }
        }
        impl core::ops::MulAssign for $ty {
            #[inline(always)]
            fn mul_assign(&mut self, o: $ty) {
                *self = *self * o;
            }
        }
    };
}
pub(crate) use assignops;

/// The row gathers (`gather_i_rows`, `gather_u8x4_rows`) of a backend that has `rows_fit`
/// and `gather_words`: the same code in AVX2 and AVX-512. One unsigned compare bounds every
/// row (`idx ≤ len − span − max(off)` as u32 also rules out `idx < 0`); a packet that fails
/// it takes the per-row path, which panics on a bad active lane.
macro_rules! row_gathers {
    ($i:ty, $m:ty) => {
        #[inline(always)]
        fn gather_i_rows<const N: usize>(
            self,
            s: &[i32],
            idx: $i,
            off: [i32; N],
            m: $m,
        ) -> [$i; N] {
            if !self.rows_fit(idx, m, crate::rows_last_start(s, &off)) {
                return crate::gather_rows_each(self, s, idx, off, m);
            }
            // SAFETY: `rows_fit`: every active lane's `idx + o` lies in `[0, len − 1]`.
            unsafe { self.gather_words::<4, N>(s.as_ptr().cast(), idx, off, m) }
        }
        #[inline(always)]
        fn gather_u8x4_rows<const N: usize>(
            self,
            s: &[u8],
            idx: $i,
            off: [i32; N],
            m: $m,
        ) -> [$i; N] {
            if !self.rows_fit(idx, m, crate::rows_last_start(s, &off)) {
                return crate::gather_rows_each(self, s, idx, off, m);
            }
            // SAFETY: `rows_fit`: every active lane's `idx + o` lies in `[0, len − 4]`.
            unsafe { self.gather_words::<1, N>(s.as_ptr(), idx, off, m) }
        }
    };
}
pub(crate) use row_gathers;

/// Panics unless every active lane of a gather/store is inside a slice of `len` elements.
/// `idx` and `active` are lane arrays; cheap enough for the lane-loop paths.
#[inline(always)]
pub(crate) fn check_lanes(idx: &[i32], bits: u32, len: usize) {
    for (l, &i) in idx.iter().enumerate() {
        if bits >> l & 1 != 0 && !(i >= 0 && (i as usize) < len) {
            crate::gather_out_of_bounds(i, len);
        }
    }
}
