//! Mutation fuzzing of every reader (issue #20): the sample files in
//! `<workspace>/../shared/data` (a prefix of each, the gzip one decompressed) get random byte
//! mutations — bit flips, inserts, deletes, truncation, spliced tokens such as `1e39`, `NaN`,
//! `-1` and huge counts — and each result is parsed with [`parse_bytes`] and, when it reads,
//! bonded with [`try_build_bonds`]. A panic anywhere fails the test (caught per case so the
//! failing input is reported and shrunk). Cases per reader: env `BNS_FUZZ_CASES` (default
//! 10,000 in release builds, 300 in debug builds).

use molecule::bonds::{try_build_bonds, BondOptions};
use molecule::read::{parse_bytes, Format, ReadOptions};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::io::Read;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::time::Instant;

/// Bytes of each sample kept (whole small files; a prefix of large ones).
const PREFIX: usize = 6 * 1024;

/// `<workspace>/../shared/data`, or the nearest `shared/data` above the crate (worktrees
/// live deeper than the main checkout).
fn data_dir() -> PathBuf {
    let crate_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    crate_dir
        .ancestors()
        .map(|a| a.join("shared/data"))
        .find(|d| d.is_dir())
        .unwrap_or_else(|| panic!("no shared/data above {}", crate_dir.display()))
}

fn sample(name: &str) -> Vec<u8> {
    let p = data_dir().join(name);
    let raw = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut bytes = if name.ends_with(".gz") {
        let mut out = Vec::new();
        flate2::read::MultiGzDecoder::new(&raw[..])
            .take(PREFIX as u64)
            .read_to_end(&mut out)
            .expect("gunzip sample");
        out
    } else {
        raw
    };
    bytes.truncate(PREFIX);
    bytes
}

fn cases() -> u32 {
    std::env::var("BNS_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(if cfg!(debug_assertions) { 300 } else { 10_000 })
}

/// One mutation of a byte buffer.
#[derive(Debug, Clone)]
enum Mutation {
    Flip(usize, u8),
    Insert(usize, u8),
    Delete(usize, usize),
    Truncate(usize),
    Splice(usize, usize, &'static str),
}

const TOKENS: &[&str] = &[
    "1e39",
    "-1e39",
    "3e38",
    "1e20",
    "NaN",
    "inf",
    "-1",
    "0",
    "-0",
    "4294967296",
    "18446744073709551616",
    "99999999999",
    " ",
    "\n",
    "\n\n",
    "#",
    "ITEM: ",
    "atoms",
    "Atoms",
    "Bonds",
    "Masses",
    "MODEL",
    "ENDMDL",
    "CONECT",
    "pbc=\"T T T\"",
    "Lattice=\"1 0 0 0 1 0 0 0 1\"",
    "Properties=species:S:1:pos:R:3",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Flip(p, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Insert(p, b)),
        (any::<usize>(), 1usize..64).prop_map(|(p, n)| Mutation::Delete(p, n)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), 0usize..24, proptest::sample::select(TOKENS))
            .prop_map(|(p, n, t)| Mutation::Splice(p, n, t)),
    ]
}

fn apply(mut b: Vec<u8>, muts: &[Mutation]) -> Vec<u8> {
    for m in muts {
        let len = b.len();
        let at = |p: usize| if len == 0 { 0 } else { p % (len + 1) };
        match *m {
            Mutation::Flip(p, x) if len > 0 => b[p % len] ^= x.max(1),
            Mutation::Flip(..) => {}
            Mutation::Insert(p, x) => b.insert(at(p), x),
            Mutation::Delete(p, n) => {
                let s = at(p);
                b.drain(s..(s + n).min(len));
            }
            Mutation::Truncate(p) => b.truncate(at(p)),
            Mutation::Splice(p, n, t) => {
                let s = at(p);
                b.splice(s..(s + n).min(len), t.bytes());
            }
        }
    }
    b
}

/// Parse (and bond) one mutated input; `Err` with the panic message if anything panicked.
fn run_case(data: &[u8], format: Format) -> Result<(), String> {
    catch_unwind(AssertUnwindSafe(|| {
        if let Ok(frames) = parse_bytes(data, format, &ReadOptions::default()) {
            for m in frames.iter().filter(|m| m.len() <= 20_000) {
                let _ = try_build_bonds(m, &BondOptions::default());
                let pbc = BondOptions {
                    pbc: true,
                    ..Default::default()
                };
                let _ = try_build_bonds(m, &pbc);
            }
        }
    }))
    .map_err(|p| {
        p.downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "panic".into())
    })
}

fn fuzz(name: &str, format: Format) {
    let base = sample(name);
    assert!(
        parse_bytes(&base, format, &ReadOptions::default()).is_ok() || base.len() == PREFIX,
        "{name}: the unmutated sample must read"
    );
    let cfg = Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner = TestRunner::new(cfg);
    let t = Instant::now();
    let slowest = std::cell::Cell::new(0f64);
    let res = runner.run(&proptest::collection::vec(mutation(), 1..8), |muts| {
        let data = apply(base.clone(), &muts);
        let t0 = Instant::now();
        let r = run_case(&data, format);
        slowest.set(slowest.get().max(t0.elapsed().as_secs_f64()));
        prop_assert!(
            r.is_ok(),
            "{name} ({format}): panic {:?} on input {:?}",
            r.err(),
            String::from_utf8_lossy(&data)
        );
        Ok(())
    });
    eprintln!(
        "fuzz {name} ({format}): {} cases in {:.2} s, slowest case {:.1} ms",
        cases(),
        t.elapsed().as_secs_f64(),
        slowest.get() * 1e3
    );
    if let Err(e) = res {
        panic!("{e}");
    }
}

#[test]
fn fuzz_xyz() {
    fuzz("2r9r-1b.xyz", Format::Xyz);
}

#[test]
fn fuzz_pdb() {
    fuzz("adk_open.pdb", Format::Pdb);
}

#[test]
fn fuzz_gro() {
    fuzz("adk_oplsaa.gro", Format::Gro);
}

#[test]
fn fuzz_lammps_data() {
    fuzz("cnt-hexagonal-class1.data", Format::LammpsData);
}

#[test]
fn fuzz_dump_triclinic() {
    fuzz("albite_triclinic.dump", Format::LammpsDump);
}

#[test]
fn fuzz_dump_mass_q() {
    fuzz("mass_q_elem.lammpstrj", Format::LammpsDump);
}

#[test]
fn fuzz_dump_gz() {
    fuzz("spce_water.lammpstrj.gz", Format::LammpsDump);
}

/// The mutator itself: each mutation kind changes the input as described (so the fuzz
/// tests above really feed altered data).
#[test]
fn mutations_apply() {
    let b = b"abc".to_vec();
    assert_eq!(apply(b.clone(), &[Mutation::Truncate(1)]), b"a");
    assert_eq!(apply(b.clone(), &[Mutation::Delete(1, 5)]), b"a");
    assert_eq!(apply(b.clone(), &[Mutation::Insert(3, b'x')]), b"abcx");
    assert_eq!(apply(b.clone(), &[Mutation::Flip(0, 1)]), b"`bc");
    assert_eq!(apply(b, &[Mutation::Splice(1, 1, "1e39")]), b"a1e39c");
}
