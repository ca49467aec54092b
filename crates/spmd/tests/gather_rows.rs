//! `Simd::gather_u8x4_rows` and `Simd::gather_i_rows` on every backend against a lane reference.
//!
//! `BNS_ISA`, when set, restricts the run to that backend (the xtask matrix forces each in turn).

use spmd::{Isa, Kernel, Simd};

/// The backends under test: `BNS_ISA` if set, else every supported one.
fn backends() -> Vec<Isa> {
    Isa::under_test()
}

/// `gather_u8x4_rows` and `gather_i_rows` on every backend against a lane-by-lane reference
/// (bytes past the end read as 0, inactive lanes 0), with indices near both ends of the slice
/// so the SIMD backends take both their single-check path and their per-row fallback; and an
/// active lane reading outside the slice panics while an inactive one does not.
#[test]
fn row_gathers_match_a_lane_reference_and_check_bounds() {
    /// Lane `l` gathers at `idx[l]` under `bits`, rows `off`; returns every row's lanes.
    struct Rows<'a> {
        bytes: &'a [u8],
        ints: &'a [i32],
        idx: &'a [i32],
        bits: u32,
        off: [i32; 3],
        out: &'a mut Vec<(Vec<i32>, Vec<i32>)>,
    }
    impl Kernel for Rows<'_> {
        type Output = ();
        fn run<S: Simd>(self, s: S) {
            let m = s.mask_from_bits(self.bits);
            let mut buf = [0i32; spmd::MAX_LANES];
            for chunk in self.idx.chunks_exact(S::LANES) {
                let idx = s.load_i(chunk);
                let b = s.gather_u8x4_rows(self.bytes, idx, self.off, m);
                let i = s.gather_i_rows(self.ints, idx, self.off, m);
                for r in 0..3 {
                    s.store_i(b[r], &mut buf);
                    let bv = buf[..S::LANES].to_vec();
                    s.store_i(i[r], &mut buf);
                    self.out.push((bv, buf[..S::LANES].to_vec()));
                }
            }
        }
    }
    let len = 200usize;
    let bytes: Vec<u8> = (0..len).map(|i| (i * 37 % 251) as u8).collect();
    let ints: Vec<i32> = (0..len as i32).map(|i| i * 1000 - 7).collect();
    let off = [0, 5, 40];
    let byte_ref = |i: usize| {
        let mut w = [0u8; 4];
        for (k, b) in w.iter_mut().enumerate() {
            *b = bytes.get(i + k).copied().unwrap_or(0);
        }
        i32::from_le_bytes(w)
    };
    // 48 indices (a multiple of every lane count): low, middle, and up to the last index
    // where the farthest row still starts inside the slice.
    let top = len as i32 - 1 - 40;
    let mut idx: Vec<i32> = (0..48).map(|k| (k * 7) % (top + 1)).collect();
    idx[47] = top;
    idx[46] = top - 1;
    // Every row of both gathers, lanes of each packet of `idx` under `bits`.
    let run = |isa: Isa, idx: &[i32], bits: u32| {
        let mut out = Vec::new();
        isa.dispatch(Rows {
            bytes: &bytes,
            ints: &ints,
            idx,
            bits,
            off,
            out: &mut out,
        });
        out
    };
    for isa in backends() {
        let lanes = isa.lanes();
        for bits in [u32::MAX, 0x5555_5555, 0] {
            let out = run(isa, &idx, bits);
            for (c, chunk) in idx.chunks_exact(lanes).enumerate() {
                for (r, &o) in off.iter().enumerate() {
                    let (b, i) = &out[c * 3 + r];
                    for l in 0..lanes {
                        let on = bits >> l & 1 != 0;
                        let at = (chunk[l] + o) as usize;
                        let (wb, wi) = if on { (byte_ref(at), ints[at]) } else { (0, 0) };
                        assert_eq!(b[l], wb, "{isa}: u8x4 row {o} lane {l} at {}", chunk[l]);
                        assert_eq!(i[l], wi, "{isa}: i32 row {o} lane {l} at {}", chunk[l]);
                    }
                }
            }
        }
        // One active lane one past the last valid start (the farthest row starts at `len`),
        // or below 0: panics. The same lanes inactive: no panic.
        for bad in [top + 1, -1, i32::MIN, i32::MAX - 10] {
            let mut idx = vec![0i32; lanes];
            idx[lanes - 1] = bad;
            let run = |bits: u32| std::panic::catch_unwind(|| run(isa, &idx, bits));
            assert!(
                run(u32::MAX).is_err(),
                "{isa}: row gather at {bad} did not panic"
            );
            assert!(
                run(!(1 << (lanes - 1))).is_ok(),
                "{isa}: inactive lane at {bad} panicked"
            );
        }
    }
}
