//! `Simd::halves` (binary16 → f32) on every backend against an f64 decode of every pattern.
//!
//! `BNS_ISA`, when set, restricts the run to that backend (the xtask matrix forces each in turn).

use spmd::{Isa, Kernel, Simd};

/// The backends under test: `BNS_ISA` if set, else every supported one.
fn backends() -> Vec<Isa> {
    Isa::under_test()
}

/// A binary16 bit pattern's magnitude from its fields, in f64 (the sign ignored); `None` for
/// NaN.
fn half_ref(h: u16) -> Option<f64> {
    let (e, m) = (((h >> 10) & 31) as i32, (h & 1023) as f64);
    match (e, m) {
        (0, _) => Some(m * 2f64.powi(-24)),
        (31, 0.0) => Some(f64::INFINITY),
        (31, _) => None,
        _ => Some((1.0 + m / 1024.0) * 2f64.powi(e - 15)),
    }
}

/// `halves` decodes every binary16 pattern exactly on every backend, in both halves of a
/// lane, with the sign bits ignored: subnormals, infinities and NaNs included.
#[test]
fn halves_decode_every_binary16_exactly() {
    struct Decode<'a> {
        words: &'a [i32],
        out: &'a mut Vec<(f32, f32)>,
    }
    impl Kernel for Decode<'_> {
        type Output = ();
        fn run<S: Simd>(self, s: S) {
            let (mut lo, mut hi) = ([0.0f32; spmd::MAX_LANES], [0.0f32; spmd::MAX_LANES]);
            for w in self.words.chunks_exact(S::LANES) {
                let (a, b) = s.halves(s.load_i(w));
                s.store(a, &mut lo);
                s.store(b, &mut hi);
                self.out.extend((0..S::LANES).map(|i| (lo[i], hi[i])));
            }
        }
    }
    // Every magnitude in the low half, the same set reversed in the high half, the sign bit
    // set on every other word (ignored); 2¹⁵ words, a multiple of every lane count.
    let n = 0x8000u32;
    let words: Vec<i32> = (0..n)
        .map(|h| {
            let sign = if h % 2 == 1 { 0x8000_8000 } else { 0 };
            (h | (n - 1 - h) << 16 | sign) as i32
        })
        .collect();
    let check = |isa: Isa, h: u32, got: f32| {
        let want = half_ref(h as u16);
        match want {
            Some(v) => assert_eq!(got as f64, v, "{isa}: half {h:#06x}"),
            None => assert!(got.is_nan(), "{isa}: half {h:#06x} is a NaN, got {got}"),
        }
    };
    for isa in backends() {
        let mut out = Vec::new();
        isa.dispatch(Decode {
            words: &words,
            out: &mut out,
        });
        assert_eq!(out.len(), words.len());
        for (h, &(lo, hi)) in (0..n).zip(&out) {
            check(isa, h, lo);
            check(isa, n - 1 - h, hi);
        }
    }
}
