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
