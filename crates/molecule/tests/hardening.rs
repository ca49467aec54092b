//! Issue #20 regressions: each test reproduces a reported failure (panic, silent wrong result
//! or confusing message) and checks the fixed behaviour.

use molecule::bonds::{brute_force_bonds, build_bonds, try_build_bonds, BondError, BondOptions};
use molecule::read::{open, parse_bytes, Format, FrameIndex, ReadError, ReadOptions};
use molecule::scenes::{check_atoms, SceneError, MAX_ATOMS};
use molecule::Molecule;
use std::error::Error;
use std::path::PathBuf;

fn tmp(name: &str, data: &[u8]) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bns-hardening-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, data).unwrap();
    p
}

fn opts() -> ReadOptions {
    ReadOptions::default()
}

fn chain(e: &dyn Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        s.push_str(": ");
        s.push_str(&c.to_string());
        cur = c.source();
    }
    s
}

/// Item 1: a far-away atom used to overflow the grid's cell count (index out of bounds).
#[test]
fn far_atom_is_an_error_naming_it() {
    for far in [1e20f32, 3e38] {
        let mut m = Molecule::default();
        m.push([0.0; 3], 6);
        m.push([far, 0.0, 0.0], 6);
        m.push([1.4, 0.0, 0.0], 6);
        let e = try_build_bonds(&m, &BondOptions::default()).unwrap_err();
        match e {
            BondError::Extent { atom, axis, .. } => {
                assert_eq!((atom, axis), (2, 'x'));
            }
            other => panic!("expected Extent, got {other}"),
        }
        // The unchecked builder must not panic either, and agrees with brute force.
        assert_eq!(
            build_bonds(&m, &BondOptions::default()),
            brute_force_bonds(&m, &BondOptions::default())
        );
    }
}

/// Item 2: 1e39 nm is finite in f64 but infinite in f32 Å once scaled.
#[test]
fn gro_scaled_coordinate_must_be_finite() {
    let gro = b"t\n1\n    1SOL     OW    1   1.e39   1.624   1.679\n   1.0   1.0   1.0\n";
    let e = parse_bytes(gro, Format::Gro, &opts()).unwrap_err();
    let s = e.to_string();
    assert!(s.contains("<memory>:3:") && s.contains("finite"), "{s}");
    let gro = b"t\n1\n    1SOL     OW    1   0.126   1.624   1.679\n   1e39   1.0   1.0\n";
    let s = parse_bytes(gro, Format::Gro, &opts())
        .unwrap_err()
        .to_string();
    assert!(s.contains("<memory>:4:"), "{s}");
}

const DATA_HEAD: &str = "t\n\n2 atoms\n1 bonds\n1 atom types\n1 bond types\n\
0 10 xlo xhi\n0 10 ylo yhi\n0 10 zlo zhi\n\nMasses\n\n1 12.011\n\nAtoms # atomic\n\n\
1 1 0 0 0\n2 1 1.4 0 0\n";

/// Item 3: a data file cut before its declared Bonds section is an error naming the section.
#[test]
fn data_missing_bonds_section() {
    let s = format!("{DATA_HEAD}\nVelocities\n\n1 0 0 0\n");
    let e = parse_bytes(s.as_bytes(), Format::LammpsData, &opts()).unwrap_err();
    let s = e.to_string();
    assert!(
        s.contains("Bonds section") && s.contains("Velocities") && s.contains("0 bond lines"),
        "{s}"
    );
    let ok = format!("{DATA_HEAD}\nBonds\n\n1 1 1 2\n");
    let m = parse_bytes(ok.as_bytes(), Format::LammpsData, &opts()).unwrap();
    assert_eq!(m[0].file_bonds, Some(vec![[0, 1]]));
}

#[test]
fn data_box_lo_above_hi() {
    let s = DATA_HEAD.replace("0 10 ylo", "10 0 ylo") + "\nBonds\n\n1 1 1 2\n";
    let e = parse_bytes(s.as_bytes(), Format::LammpsData, &opts()).unwrap_err();
    assert!(e.to_string().contains("lo <= hi"), "{e}");
}

#[test]
fn data_masses_in_kg_per_mol() {
    let s = DATA_HEAD.replace("1 12.011", "1 0.012011") + "\nBonds\n\n1 1 1 2\n";
    let m = parse_bytes(s.as_bytes(), Format::LammpsData, &opts()).unwrap();
    assert_eq!(m[0].elements, vec![6, 6]);
    // g/mol still wins: 1.008 is hydrogen, not a ×1000 match.
    let s = DATA_HEAD.replace("1 12.011", "1 1.008") + "\nBonds\n\n1 1 1 2\n";
    let m = parse_bytes(s.as_bytes(), Format::LammpsData, &opts()).unwrap();
    assert_eq!(m[0].elements, vec![1, 1]);
}

const TRUNCATED_XYZ: &[u8] = b"2\nc\nC 0 0 0\nC 1 0 0\n2\nc\nC 0 0 0\n";

/// Item 4: a truncated last frame is not a frame, for every entry point, with a warning.
#[test]
fn truncated_tail_is_consistent() {
    let p = tmp("trunc.xyz", TRUNCATED_XYZ);
    let mut t = open(&p, &opts()).unwrap();
    assert_eq!(t.count_frames().unwrap(), 1);
    assert!(
        t.warnings().iter().any(|w| w.contains(":8:")),
        "{:?}",
        t.warnings()
    );
    let mut t = open(&p, &opts()).unwrap();
    assert!(t.read_frame(0).is_ok());
    assert!(matches!(
        t.read_frame(1),
        Err(ReadError::NoSuchFrame { count: 1, .. })
    ));
    assert_eq!(open(&p, &opts()).unwrap().count(), 1);
    let last = open(&p, &opts())
        .unwrap()
        .read_frame_at(FrameIndex::FromEnd(1))
        .unwrap();
    assert_eq!(last.len(), 2);
    assert_eq!(
        parse_bytes(TRUNCATED_XYZ, Format::Xyz, &opts())
            .unwrap()
            .len(),
        1
    );
    // A cut *first* frame is still an error.
    assert!(parse_bytes(b"2\nc\nC 0 0 0\n", Format::Xyz, &opts()).is_err());
}

/// Item 5: I/O errors do not print their cause twice; a misnamed file says what it looks like.
#[test]
fn messages_do_not_repeat() {
    let e = open(std::path::Path::new("/nonexistent/x.xyz"), &opts())
        .err()
        .unwrap();
    let s = chain(&e);
    let os = "No such file or directory";
    assert_eq!(s.matches(os).count(), 1, "{s}");
    let gz = {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(&TRUNCATED_XYZ.repeat(200)).unwrap();
        e.finish().unwrap()
    };
    let p = tmp("cut.xyz.gz", &gz[..gz.len() / 2]);
    let e = open(&p, &opts()).unwrap().count_frames().unwrap_err();
    let s = chain(&e);
    assert!(s.matches("deflate").count() <= 1, "{s}");
    let gro = b"t\n1\n    1SOL     OW    1   0.126   1.624   1.679\n   1.0   1.0   1.0\n";
    let p = tmp("gro.pdb", gro);
    let e = open(&p, &opts()).unwrap().read_frame(0).unwrap_err();
    assert!(
        matches!(
            e,
            ReadError::WrongFormat {
                looks_like: Format::Gro,
                ..
            }
        ),
        "{e}"
    );
}

/// Item 6: negative frame indices count from the end; out of range names the count.
#[test]
fn frame_from_end() {
    let x = b"1\na\nC 0 0 0\n1\nb\nC 1 0 0\n1\nc\nC 2 0 0\n";
    let p = tmp("three.xyz", x);
    let mut t = open(&p, &opts()).unwrap();
    assert_eq!(t.read_frame_at("-1".parse().unwrap()).unwrap().x[0], 2.0);
    assert_eq!(t.read_frame_at("-3".parse().unwrap()).unwrap().x[0], 0.0);
    assert_eq!(t.read_frame_at("1".parse().unwrap()).unwrap().x[0], 1.0);
    let e = t.read_frame_at(FrameIndex::FromEnd(4)).unwrap_err();
    assert!(e.to_string().contains("3 frame(s)"), "{e}");
    assert!("x".parse::<FrameIndex>().is_err());
}

/// Item 7: absurd atom counts are refused before allocating.
#[test]
fn absurd_atom_counts() {
    assert!(matches!(
        check_atoms(MAX_ATOMS + 1, None),
        Err(SceneError::TooManyAtoms { .. })
    ));
    let e = check_atoms(1 << 30, Some(1 << 30)).unwrap_err();
    assert!(matches!(e, SceneError::OutOfMemory { .. }));
    assert!(e.to_string().contains("--atoms"));
    assert!(check_atoms(1000, Some(1 << 30)).is_ok());
    // Zero is refused, not quietly made one atom.
    assert!(matches!(check_atoms(0, None), Err(SceneError::NoAtoms)));
    assert!(matches!(
        molecule::scenes::try_generate(molecule::scenes::SceneName::Anp3, Some(0), 1),
        Err(SceneError::NoAtoms)
    ));
    assert!(check_atoms(1, None).is_ok());
}

/// Item 8: huge cutoffs are refused from the grid estimate, before collecting bonds.
#[test]
fn bond_estimate_refuses_huge_cutoffs() {
    let mut m = Molecule::default();
    for i in 0..4000 {
        let f = i as f32;
        m.push(
            [
                f % 20.0 * 1.5,
                (f / 20.0).floor() % 20.0 * 1.5,
                (f / 400.0).floor() * 1.5,
            ],
            6,
        );
    }
    let normal = try_build_bonds(&m, &BondOptions::default()).unwrap();
    assert_eq!(normal, brute_force_bonds(&m, &BondOptions::default()));
    for o in [
        BondOptions {
            global_cutoff: Some(1000.0),
            ..Default::default()
        },
        BondOptions {
            factor: 30.0,
            ..Default::default()
        },
    ] {
        match try_build_bonds(&m, &o) {
            Err(BondError::TooMany {
                estimate, atoms, ..
            }) => {
                assert_eq!(atoms, 4000);
                // Every pair is within 1000 Å: the estimate must cover all of them.
                assert!(estimate >= 4000 * 3999 / 2 / 2, "{estimate}");
            }
            other => panic!("expected TooMany, got {other:?}"),
        }
    }
}
