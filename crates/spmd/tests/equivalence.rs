//! Every op of every backend this CPU supports, against the scalar backend (or, for ops that
//! combine lanes, against a lane-by-lane reference), on random inputs rich in edge values:
//! ±0, denormals, ±inf, NaN, huge and tiny magnitudes.
//!
//! Tolerances: bit-identical (any NaN matches any NaN) for every op except `fma` (fused
//! backends: within 1 ulp of the exact `a*b+c` computed in f64), `rcp_fast`/`rsqrt_fast`
//! (within 4 ulp of the exact value, for normal inputs with normal results) and `math::exp`
//! (within 4 ulp of scalar; fma changes rounding inside the polynomial).
//!
//! `BNS_ISA`, when set, restricts the run to that backend (the xtask matrix forces each in turn).

use proptest::prelude::*;
use spmd::{math, Isa, Kernel, Simd};

/// Number of elements per test vector: a multiple of every lane count.
const N: usize = 48;

/// The backends under test: `BNS_ISA` if set, else every supported one.
fn backends() -> Vec<Isa> {
    Isa::under_test()
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Neg,
    Fma,
    Min,
    Max,
    Sqrt,
    Abs,
    Floor,
    Ceil,
    Rcp,
    Rsqrt,
    RcpFast,
    RsqrtFast,
    Exp,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    Select,
    SelectI,
    AddI,
    SubI,
    MulI,
    MinI,
    MaxI,
    AndI,
    OrI,
    XorI,
    Shl,
    Shr,
    Sar,
    EqI,
    LtI,
    GtI,
    ToF32,
    ToI32,
    BitcastI,
    BitcastF,
    MaskAnd,
    MaskOr,
    MaskXor,
    MaskNot,
    Splat,
    SplatI,
    Extract,
}

const FLOAT_OUT: &[Op] = &[
    Op::Add,
    Op::Sub,
    Op::Mul,
    Op::Div,
    Op::Neg,
    Op::Fma,
    Op::Min,
    Op::Max,
    Op::Sqrt,
    Op::Abs,
    Op::Floor,
    Op::Ceil,
    Op::Rcp,
    Op::Rsqrt,
    Op::RcpFast,
    Op::RsqrtFast,
    Op::Exp,
    Op::Select,
    Op::ToF32,
    Op::BitcastF,
    Op::Splat,
    Op::Extract,
];
const INT_OUT: &[Op] = &[
    Op::SelectI,
    Op::AddI,
    Op::SubI,
    Op::MulI,
    Op::MinI,
    Op::MaxI,
    Op::AndI,
    Op::OrI,
    Op::XorI,
    Op::Shl,
    Op::Shr,
    Op::Sar,
    Op::ToI32,
    Op::BitcastI,
    Op::SplatI,
];
const MASK_OUT: &[Op] = &[
    Op::Lt,
    Op::Le,
    Op::Gt,
    Op::Ge,
    Op::Eq,
    Op::Ne,
    Op::EqI,
    Op::LtI,
    Op::GtI,
    Op::MaskAnd,
    Op::MaskOr,
    Op::MaskXor,
    Op::MaskNot,
];

/// Inputs shared by every op.
#[derive(Clone, Debug)]
struct Inputs {
    a: Vec<f32>,
    b: Vec<f32>,
    c: Vec<f32>,
    ia: Vec<i32>,
    ib: Vec<i32>,
    shift: u32,
}

/// Outputs: floats, ints, and masks as 0/1 per lane.
#[derive(Default)]
struct Outputs {
    f: Vec<f32>,
    i: Vec<i32>,
    m: Vec<u8>,
}

/// Applies one op to every chunk of the inputs with backend `S`.
struct Apply<'a> {
    op: Op,
    inp: &'a Inputs,
}

impl Kernel for Apply<'_> {
    type Output = Outputs;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Outputs {
        let inp = self.inp;
        let mut out = Outputs {
            f: vec![0.0; N],
            i: vec![0; N],
            m: vec![0; N],
        };
        for k in (0..N).step_by(S::LANES) {
            let a = s.load(&inp.a[k..]);
            let b = s.load(&inp.b[k..]);
            let c = s.load(&inp.c[k..]);
            let ia = s.load_i(&inp.ia[k..]);
            let ib = s.load_i(&inp.ib[k..]);
            let m1 = s.lt(a, b);
            let m2 = s.lt_i(ia, ib);
            let f = match self.op {
                Op::Add => Some(a + b),
                Op::Sub => Some(a - b),
                Op::Mul => Some(a * b),
                Op::Div => Some(a / b),
                Op::Neg => Some(-a),
                Op::Fma => Some(s.fma(a, b, c)),
                Op::Min => Some(s.min(a, b)),
                Op::Max => Some(s.max(a, b)),
                Op::Sqrt => Some(s.sqrt(a)),
                Op::Abs => Some(s.abs(a)),
                Op::Floor => Some(s.floor(a)),
                Op::Ceil => Some(s.ceil(a)),
                Op::Rcp => Some(s.rcp(a)),
                Op::Rsqrt => Some(s.rsqrt(a)),
                Op::RcpFast => Some(s.rcp_fast(a)),
                Op::RsqrtFast => Some(s.rsqrt_fast(a)),
                Op::Exp => Some(math::exp(s, a)),
                Op::Select => Some(s.select(m2, a, b)),
                Op::ToF32 => Some(s.to_f32(ia)),
                Op::BitcastF => Some(s.bitcast_f(ia)),
                Op::Splat => Some(s.splat(inp.a[0])),
                Op::Extract => {
                    // Rebuild the vector lane by lane from `extract`.
                    let mut tmp = [0.0f32; 16];
                    for (l, t) in tmp.iter_mut().enumerate().take(S::LANES) {
                        *t = s.extract(a, l) + s.extract_i(ia, l) as f32;
                    }
                    Some(s.load(&tmp))
                }
                _ => None,
            };
            if let Some(f) = f {
                s.store(f, &mut out.f[k..]);
            }
            let i = match self.op {
                Op::SelectI => Some(s.select_i(m1, ia, ib)),
                Op::AddI => Some(ia + ib),
                Op::SubI => Some(ia - ib),
                Op::MulI => Some(s.mul_i(ia, ib)),
                Op::MinI => Some(s.min_i(ia, ib)),
                Op::MaxI => Some(s.max_i(ia, ib)),
                Op::AndI => Some(ia & ib),
                Op::OrI => Some(ia | ib),
                Op::XorI => Some(ia ^ ib),
                Op::Shl => Some(s.shl(ia, inp.shift)),
                Op::Shr => Some(s.shr(ia, inp.shift)),
                Op::Sar => Some(s.sar(ia, inp.shift)),
                Op::ToI32 => Some(s.to_i32(a)),
                Op::BitcastI => Some(s.bitcast_i(a)),
                Op::SplatI => Some(s.splat_i(inp.ia[0])),
                _ => None,
            };
            if let Some(i) = i {
                s.store_i(i, &mut out.i[k..]);
            }
            let m = match self.op {
                Op::Lt => Some(m1),
                Op::Le => Some(s.le(a, b)),
                Op::Gt => Some(s.gt(a, b)),
                Op::Ge => Some(s.ge(a, b)),
                Op::Eq => Some(s.eq(a, b)),
                Op::Ne => Some(s.ne(a, b)),
                Op::EqI => Some(s.eq_i(ia, ib)),
                Op::LtI => Some(m2),
                Op::GtI => Some(s.gt_i(ia, ib)),
                Op::MaskAnd => Some(m1 & m2),
                Op::MaskOr => Some(m1 | m2),
                Op::MaskXor => Some(m1 ^ m2),
                Op::MaskNot => Some(!m1),
                _ => None,
            };
            if let Some(m) = m {
                let bits = s.bitmask(m);
                for l in 0..S::LANES {
                    out.m[k + l] = (bits >> l & 1) as u8;
                }
            }
        }
        out
    }
}

/// Distance in units in the last place between two finite floats of the same sign.
fn ulps(a: f32, b: f32) -> u32 {
    let key = |x: f32| {
        let i = x.to_bits() as i32;
        if i < 0 {
            i32::MIN.wrapping_sub(i) as i64
        } else {
            i as i64
        }
    };
    (key(a) - key(b)).unsigned_abs().min(u32::MAX as u64) as u32
}

fn same_float(a: f32, b: f32) -> bool {
    (a.is_nan() && b.is_nan()) || a.to_bits() == b.to_bits()
}

fn normal_in_range(x: f32) -> bool {
    x.is_normal() && (1e-30..1e30).contains(&x.abs())
}

/// Checks one float output lane against the scalar one, with the op's tolerance.
fn check_float(
    op: Op,
    isa: Isa,
    inp: &Inputs,
    k: usize,
    got: f32,
    want: f32,
) -> Result<(), String> {
    let (a, b, c) = (inp.a[k], inp.b[k], inp.c[k]);
    let ok = match op {
        Op::Fma if matches!(isa, Isa::Avx2 | Isa::Avx512) => {
            let exact = (a as f64).mul_add(b as f64, c as f64) as f32;
            same_float(got, exact)
                || (got.is_finite() && exact.is_finite() && ulps(got, exact) <= 1)
                // a*b+c with a*b overflowing f32 but finite in f64: fused keeps it.
                || (exact.is_nan() && got.is_nan())
        }
        Op::RcpFast | Op::RsqrtFast => {
            let exact = if op == Op::RcpFast {
                (1.0 / a as f64) as f32
            } else {
                (1.0 / (a as f64).sqrt()) as f32
            };
            let in_domain = normal_in_range(a) && (op == Op::RcpFast || a > 0.0);
            !in_domain || ulps(got, exact) <= 4
        }
        Op::Exp => {
            same_float(got, want) || (got.is_finite() && want.is_finite() && ulps(got, want) <= 4)
        }
        _ => same_float(got, want),
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{isa} {op:?} lane {k}: a={a:e} ({:#x}) b={b:e} c={c:e}: got {got:e} ({:#x}), scalar {want:e} ({:#x})",
            a.to_bits(),
            got.to_bits(),
            want.to_bits()
        ))
    }
}

fn compare_all(inp: &Inputs) -> Result<(), String> {
    for isa in backends() {
        for &op in FLOAT_OUT.iter().chain(INT_OUT).chain(MASK_OUT) {
            let want = Isa::Scalar.dispatch(Apply { op, inp });
            let got = isa.dispatch(Apply { op, inp });
            for k in 0..N {
                if FLOAT_OUT.contains(&op) {
                    check_float(op, isa, inp, k, got.f[k], want.f[k])?;
                }
                if INT_OUT.contains(&op) && got.i[k] != want.i[k] {
                    return Err(format!(
                        "{isa} {op:?} lane {k}: a={:e} ia={} ib={} shift={}: got {}, scalar {}",
                        inp.a[k], inp.ia[k], inp.ib[k], inp.shift, got.i[k], want.i[k]
                    ));
                }
                if MASK_OUT.contains(&op) && got.m[k] != want.m[k] {
                    return Err(format!(
                        "{isa} {op:?} lane {k}: a={:e} b={:e} ia={} ib={}: got {}, scalar {}",
                        inp.a[k], inp.b[k], inp.ia[k], inp.ib[k], got.m[k], want.m[k]
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Floats rich in edge cases: specials, denormals, huge/tiny, integers, random bits, and
/// ordinary values on a log scale.
fn edge_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => prop::sample::select(vec![
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.5,
            1.5,
            -2.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::MIN_POSITIVE,
            f32::MIN_POSITIVE / 3.0,
            -1e-40,
            f32::MAX,
            f32::MIN,
            1e38,
            -1e-38,
            2_147_483_520.0,
            2_147_483_648.0,
            -2_147_483_648.0,
            -2_147_483_904.0,
            88.0,
            -87.0,
            100.0,
            -100.0,
        ]),
        2 => any::<u32>().prop_map(f32::from_bits),
        4 => (-40.0f32..40.0, any::<bool>()).prop_map(|(e, neg)| {
            let x = 10f32.powf(e);
            if neg { -x } else { x }
        }),
        2 => (-200i32..200).prop_map(|i| i as f32 * 0.5),
        2 => -100.0f32..100.0,
    ]
}

fn edge_i32() -> impl Strategy<Value = i32> {
    prop_oneof![
        2 => prop::sample::select(vec![0, 1, -1, i32::MIN, i32::MAX, 16_777_217, -16_777_217, 255, 256]),
        3 => any::<i32>(),
        3 => -1000i32..1000,
    ]
}

fn inputs() -> impl Strategy<Value = Inputs> {
    (
        prop::collection::vec(edge_f32(), N),
        prop::collection::vec(edge_f32(), N),
        prop::collection::vec(edge_f32(), N),
        prop::collection::vec(edge_i32(), N),
        prop::collection::vec(edge_i32(), N),
        prop_oneof![0u32..=33, Just(31), Just(32), Just(1000)],
    )
        .prop_map(|(a, b, c, ia, ib, shift)| Inputs {
            a,
            b,
            c,
            ia,
            ib,
            shift,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn every_op_matches_scalar(inp in inputs()) {
        if let Err(e) = compare_all(&inp) {
            prop_assert!(false, "{}", e);
        }
    }

    #[test]
    fn gathers_read_only_active_lanes(
        data in prop::collection::vec(edge_f32(), 1..70),
        raw_idx in prop::collection::vec(any::<i32>(), N),
        mask_bits in prop::collection::vec(any::<bool>(), N),
        fill in edge_f32(),
    ) {
        // Active lanes get an in-bounds index; inactive lanes keep wild indices (i32::MIN,
        // negative, far past the end) that would fault or be caught if they were read.
        let len = data.len();
        let idx: Vec<i32> = raw_idx
            .iter()
            .zip(&mask_bits)
            .map(|(&r, &on)| if on { r.rem_euclid(len as i32) } else { r | i32::MIN.wrapping_shr((r & 1) as u32) })
            .collect();
        let ints: Vec<i32> = data.iter().map(|x| x.to_bits() as i32).collect();
        let bytes: Vec<u8> = data.iter().map(|x| x.to_bits() as u8).collect();
        for isa in backends() {
            let got = isa.dispatch(Gathers { data: &data, ints: &ints, bytes: &bytes, idx: &idx, on: &mask_bits, fill });
            for k in 0..N {
                let (wf, wi, wb, w4) = if mask_bits[k] {
                    let i = idx[k] as usize;
                    // Four bytes from i on, little endian, zero past the end.
                    let w4 = (0..4).filter(|j| i + j < len).fold(0u32, |w, j| w | (bytes[i + j] as u32) << (8 * j));
                    (data[i], ints[i], bytes[i] as i32, w4 as i32)
                } else {
                    (fill, fill.to_bits() as i32, 0, 0)
                };
                prop_assert!(same_float(got.0[k], wf), "{} gather lane {}: got {} want {}", isa, k, got.0[k], wf);
                prop_assert_eq!(got.1[k], wi, "{} gather_i lane {}", isa, k);
                prop_assert_eq!(got.2[k], wb, "{} gather_u8 lane {} (len {}, idx {})", isa, k, len, idx[k]);
                prop_assert_eq!(got.3[k], w4, "{} gather_u8x4 lane {} (len {}, idx {})", isa, k, len, idx[k]);
            }
        }
    }

    #[test]
    fn masked_and_partial_memory_ops(
        vals in prop::collection::vec(edge_f32(), 16),
        out_len in 0usize..20,
        bits in any::<u32>(),
        fill in edge_f32(),
    ) {
        for isa in backends() {
            let lanes = isa.lanes();
            // Only lanes inside `out` may be active.
            let bits = bits & ((1u32 << lanes.min(out_len)) - 1);
            let (stored, partial) = isa.dispatch(MemOps { vals: &vals, out_len, bits, fill });
            for l in 0..out_len {
                let want = if l < lanes && bits >> l & 1 != 0 { vals[l] } else { -7.25 };
                prop_assert!(same_float(stored[l], want), "{} store_masked lane {}", isa, l);
            }
            for l in 0..lanes {
                let want = if l < out_len { vals[l] } else { fill };
                prop_assert!(same_float(partial[l], want), "{} load_partial lane {}", isa, l);
            }
        }
    }

    #[test]
    fn horizontal_and_mask_queries(vals in prop::collection::vec(edge_f32(), 16), bits in any::<u32>(), n in 0usize..20) {
        for isa in backends() {
            let lanes = isa.lanes();
            let bits = if lanes == 32 { bits } else { bits & ((1u32 << lanes) - 1) };
            let h = isa.dispatch(Horizontal { vals: &vals, bits, n });
            let v = &vals[..lanes];
            let min = v[1..].iter().fold(v[0], |acc, &x| if acc < x { acc } else { x });
            let max = v[1..].iter().fold(v[0], |acc, &x| if acc > x { acc } else { x });
            let sum = v[1..].iter().fold(v[0], |acc, &x| acc + x);
            prop_assert!(same_float(h.min, min), "{} reduce_min", isa);
            prop_assert!(same_float(h.max, max), "{} reduce_max", isa);
            prop_assert!(same_float(h.sum, sum), "{} reduce_add", isa);
            prop_assert_eq!(h.bits, bits, "{} mask_from_bits/bitmask", isa);
            prop_assert_eq!(h.any, bits != 0, "{} any", isa);
            prop_assert_eq!(h.all, bits == (1u32 << lanes) - 1, "{} all", isa);
            prop_assert_eq!(h.none, bits == 0, "{} none", isa);
            prop_assert_eq!(h.first_n, (1u32 << n.min(lanes)) - 1, "{} first_n({})", isa, n);
            prop_assert_eq!(h.splat_m, ((1u32 << lanes) - 1, 0), "{} splat_m", isa);
            prop_assert_eq!(&h.lane_index[..lanes], &(0..lanes as i32).collect::<Vec<_>>()[..], "{} lane_index", isa);
        }
    }
}

struct Gathers<'a> {
    data: &'a [f32],
    ints: &'a [i32],
    bytes: &'a [u8],
    idx: &'a [i32],
    on: &'a [bool],
    fill: f32,
}

impl Kernel for Gathers<'_> {
    type Output = (Vec<f32>, Vec<i32>, Vec<i32>, Vec<i32>);
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Self::Output {
        let (mut f, mut i, mut b, mut b4) = (vec![0.0; N], vec![0; N], vec![0; N], vec![0; N]);
        for k in (0..N).step_by(S::LANES) {
            let bits = (0..S::LANES).fold(0u32, |acc, l| acc | (self.on[k + l] as u32) << l);
            let m = s.mask_from_bits(bits);
            let idx = s.load_i(&self.idx[k..]);
            let fill = s.splat(self.fill);
            s.store(s.gather(self.data, idx, m, fill), &mut f[k..]);
            s.store_i(
                s.gather_i(self.ints, idx, m, s.bitcast_i(fill)),
                &mut i[k..],
            );
            s.store_i(s.gather_u8(self.bytes, idx, m), &mut b[k..]);
            s.store_i(s.gather_u8x4(self.bytes, idx, m), &mut b4[k..]);
        }
        (f, i, b, b4)
    }
}

struct MemOps<'a> {
    vals: &'a [f32],
    out_len: usize,
    bits: u32,
    fill: f32,
}

impl Kernel for MemOps<'_> {
    type Output = (Vec<f32>, Vec<f32>);
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> Self::Output {
        let v = s.load(self.vals);
        let mut out = vec![-7.25f32; self.out_len];
        s.store_masked(v, &mut out, s.mask_from_bits(self.bits));
        let mut partial = vec![0.0; 16];
        s.store(
            s.load_partial(&self.vals[..self.out_len.min(16)], self.fill),
            &mut partial,
        );
        (out, partial)
    }
}

struct Horizontal<'a> {
    vals: &'a [f32],
    bits: u32,
    n: usize,
}

struct HorizontalOut {
    min: f32,
    max: f32,
    sum: f32,
    bits: u32,
    any: bool,
    all: bool,
    none: bool,
    first_n: u32,
    splat_m: (u32, u32),
    lane_index: [i32; 16],
}

impl Kernel for Horizontal<'_> {
    type Output = HorizontalOut;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> HorizontalOut {
        let v = s.load(self.vals);
        let m = s.mask_from_bits(self.bits);
        let mut lane_index = [0i32; 16];
        s.store_i(s.lane_index(), &mut lane_index);
        HorizontalOut {
            min: s.reduce_min(v),
            max: s.reduce_max(v),
            sum: s.reduce_add(v),
            bits: s.bitmask(m),
            any: s.any(m),
            all: s.all(m),
            none: s.none(m),
            first_n: s.bitmask(s.first_n(self.n)),
            splat_m: (s.bitmask(s.splat_m(true)), s.bitmask(s.splat_m(false))),
            lane_index,
        }
    }
}

/// A gather whose active lane points outside the slice must panic, never read.
#[test]
fn gather_out_of_bounds_active_lane_panics() {
    /// Lane 0 gathers at `.0` (the others at 0) from a 5-element slice: f32 (`.1` false) or
    /// 4-byte words (`.1` true); returns lane 0's value.
    struct Oob(i32, bool);
    impl Kernel for Oob {
        type Output = i32;
        #[inline(always)]
        fn run<S: Simd>(self, s: S) -> i32 {
            let idx = s.select_i(
                s.eq_i(s.lane_index(), s.splat_i(0)),
                s.splat_i(self.0),
                s.splat_i(0),
            );
            let all = s.splat_m(true);
            let v = if self.1 {
                s.gather_u8x4(&[7u8, 1, 2, 3, 9], idx, all)
            } else {
                s.to_i32(s.gather(&[1.0, 2.0, 3.0, 4.0, 5.0], idx, all, s.splat(0.0)))
            };
            let mut out = [0i32; spmd::MAX_LANES];
            s.store_i(v, &mut out);
            out[0]
        }
    }
    for isa in backends() {
        for bytes in [false, true] {
            for bad in [5, 6, -1, i32::MAX, i32::MIN] {
                let r = std::panic::catch_unwind(|| isa.dispatch(Oob(bad, bytes)));
                assert!(
                    r.is_err(),
                    "{isa}: gather (bytes: {bytes}) at index {bad} of a 5-element slice did not panic"
                );
            }
        }
        assert_eq!(isa.dispatch(Oob(4, false)), 5);
        // The last byte alone: the three past the end read as zero.
        assert_eq!(isa.dispatch(Oob(4, true)), 9);
        assert_eq!(isa.dispatch(Oob(1, true)), 0x0903_0201);
    }
}

/// `math::exp` against f64 `exp` (the scalar path; the backends are compared above).
#[test]
fn exp_is_accurate() {
    let mut x = -87.0f32;
    while x < 88.0 {
        let got = math::exp(spmd::Scalar, x);
        let want = (x as f64).exp();
        let rel = ((got as f64 - want) / want).abs();
        assert!(rel < 3e-7, "exp({x}) = {got}, want {want}, rel err {rel:e}");
        x += 0.0137;
    }
    assert_eq!(math::exp(spmd::Scalar, -100.0), 0.0);
    assert_eq!(math::exp(spmd::Scalar, 100.0), f32::INFINITY);
    assert!(math::exp(spmd::Scalar, f32::NAN).is_nan());
}
