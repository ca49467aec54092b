//! Bad input: every case gives a typed error naming the line/frame and what was expected;
//! nothing panics (see also the proptest at the end).

use molecule::read::{open, parse_bytes, Format, ReadError, ReadOptions};
use proptest::prelude::*;
use std::path::PathBuf;

fn parse(fmt: Format, s: &str) -> Result<Vec<molecule::Molecule>, ReadError> {
    parse_bytes(s.as_bytes(), fmt, &ReadOptions::default())
}

/// Assert a parse error at `line` (1-based) / `frame` whose message contains `needle`.
fn parse_err(fmt: Format, s: &str, line: u64, frame: usize, needle: &str) {
    match parse(fmt, s) {
        Err(e @ ReadError::Parse { .. }) => {
            let msg = e.to_string();
            if let ReadError::Parse {
                line: l, frame: f, ..
            } = e
            {
                assert_eq!((l, f), (line, frame), "{fmt}: wrong location in: {msg}");
            }
            assert!(msg.contains(needle), "{fmt}: '{msg}' lacks '{needle}'");
            assert!(msg.contains("<memory>"), "names the file: {msg}");
        }
        other => panic!("{fmt}: expected a parse error for {s:?}, got {other:?}"),
    }
}

fn tmp(name: &str, data: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("molecule-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, data).unwrap();
    p
}

const XYZ: &str = "2\ncomment\nC 0 0 0\nO 1.2 0 0\n2\nframe 2\nC 0 0 0.1\nO 1.2 0 0.1\n";

#[test]
fn xyz_ok_and_errors() {
    assert_eq!(parse(Format::Xyz, XYZ).unwrap().len(), 2);
    // truncated frame (second frame loses its last atom)
    let trunc = &XYZ[..XYZ.len() - "O 1.2 0 0.1\n".len()];
    // (a cut last frame is the truncated tail: not a frame, not an error; see hardening.rs)
    assert_eq!(parse(Format::Xyz, trunc).unwrap().len(), 1);
    // count that lies (says 3, has 2 and then the next frame's count)
    parse_err(Format::Xyz, "3\nc\nC 0 0 0\nO 1 0 0\n", 5, 0, "truncated");
    // count too small: the leftover atom line is read as a count line
    parse_err(
        Format::Xyz,
        "1\nc\nC 0 0 0\nO 1 0 0\n",
        4,
        1,
        "number of atoms",
    );
    parse_err(Format::Xyz, "2\nc\nC 0 0 0\nO 1.x 0 0\n", 4, 0, "a number");
    parse_err(Format::Xyz, "2\nc\nC 0 0 0\nO nan 0 0\n", 4, 0, "finite");
    parse_err(Format::Xyz, "2\nc\nC 0 0 inf\nO 1 0 0\n", 3, 0, "finite");
    parse_err(Format::Xyz, "2\nc\nC 0 0\nO 1 0 0\n", 3, 0, "symbol x y z");
    parse_err(Format::Xyz, "abc\n", 1, 0, "number of atoms");
    parse_err(
        Format::Xyz,
        "1\nLattice=\"1 0 0 0 1\" Properties=species:S:1:pos:R:3\nC 0 0 0\n",
        2,
        0,
        "Lattice",
    );
    parse_err(
        Format::Xyz,
        "1\nProperties=species:S:1:pos:R:3:q:R:1\nC 0 0 0\n",
        3,
        0,
        "columns",
    );
}

#[test]
fn extended_xyz() {
    let s = "2\nLattice=\"10 0 0 0 11 0 0 0 12\" Properties=pos:R:3:species:S:1:q:R:1 pbc=\"T T F\"\n1 2 3 Si 0.5\n4 5 6 O -0.5\n";
    let m = &parse(Format::Xyz, s).unwrap()[0];
    assert_eq!(m.elements, vec![14, 8]);
    assert_eq!(m.position(1), [4.0, 5.0, 6.0]);
    assert_eq!(m.scalar("q").unwrap(), &[0.5, -0.5]);
    let c = m.cell.unwrap();
    assert_eq!(c.edges[1], [0.0, 11.0, 0.0]);
    assert_eq!(c.pbc, [true, true, false]);
}

#[test]
fn empty_and_binary_files() {
    for fmt in [
        Format::Xyz,
        Format::Pdb,
        Format::LammpsDump,
        Format::LammpsData,
        Format::Gro,
    ] {
        assert!(
            matches!(parse(fmt, ""), Err(ReadError::Empty { .. })),
            "{fmt}"
        );
        let p = tmp(&format!("empty.{}", fmt.name()), b"");
        let mut t = open(
            &p,
            &ReadOptions {
                format: Some(fmt),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(
            matches!(t.read_frame(0), Err(ReadError::Empty { .. })),
            "{fmt}"
        );
        assert!(
            matches!(t.count_frames(), Err(ReadError::Empty { .. })),
            "{fmt}"
        );
        let garbage: Vec<u8> = (0..5000u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        let e = parse_bytes(&garbage, fmt, &ReadOptions::default()).unwrap_err();
        assert!(e.to_string().contains("binary"), "{fmt}: {e}");
    }
    let p = tmp("noext", b"hello\n");
    assert!(matches!(
        open(&p, &ReadOptions::default()),
        Err(ReadError::UnknownFormat { .. })
    ));
    let missing = std::env::temp_dir().join("definitely-missing-file.xyz");
    assert!(matches!(
        open(&missing, &ReadOptions::default()),
        Err(ReadError::Io { .. })
    ));
}

#[test]
fn unknown_element_is_a_warning() {
    let p = tmp("unk.xyz", b"2\nc\nQq 0 0 0\nC 1 0 0\n");
    let mut t = open(&p, &ReadOptions::default()).unwrap();
    let m = t.read_frame(0).unwrap();
    assert_eq!(m.elements, vec![0, 6]);
    assert_eq!(t.warnings().len(), 1);
    assert!(t.warnings()[0].contains("Qq"));
}

#[test]
fn gzip_and_sniffing() {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(XYZ.as_bytes()).unwrap();
    let gz = e.finish().unwrap();
    let p = tmp("frames.xyz.gz", &gz);
    let mut t = open(&p, &ReadOptions::default()).unwrap();
    assert!(t.is_gzip());
    assert_eq!(t.count_frames().unwrap(), 2);
    assert_eq!(t.read_frame(1).unwrap().z, vec![0.1, 0.1]);
    // content sniffing for a file without a known extension
    let p = tmp("frames.txt", XYZ.as_bytes());
    assert_eq!(
        open(&p, &ReadOptions::default()).unwrap().format(),
        Format::Xyz
    );
    let mut t = open(&p, &ReadOptions::default()).unwrap();
    assert!(matches!(
        t.read_frame(5),
        Err(ReadError::NoSuchFrame { count: 2, .. })
    ));
}

const DUMP: &str = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\nITEM: ATOMS id type x y z q\n2 2 1 1 1 0.5\n1 1 0 0 0 -0.5\n";

#[test]
fn dump_ok_and_errors() {
    let opts = ReadOptions {
        types: ReadOptions::parse_types("1=Al,2=O").unwrap(),
        ..Default::default()
    };
    let m = &parse_bytes(DUMP.as_bytes(), Format::LammpsDump, &opts).unwrap()[0];
    assert_eq!(m.elements, vec![13, 8], "sorted by id, types mapped");
    assert_eq!(m.scalar("q").unwrap(), &[-0.5, 0.5]);
    parse_err(
        Format::LammpsDump,
        &DUMP[..DUMP.len() - 15],
        11,
        0,
        "truncated",
    );
    parse_err(
        Format::LammpsDump,
        &DUMP.replace("1 1 1 0.5", "1 z 1 0.5"),
        10,
        0,
        "a number",
    );
    parse_err(
        Format::LammpsDump,
        &DUMP.replace("1 1 1 0.5", "1 NaN 1 0.5"),
        10,
        0,
        "finite",
    );
    parse_err(
        Format::LammpsDump,
        &DUMP.replace("2 2 1 1 1 0.5", "2 2 1 1"),
        10,
        0,
        "6 columns",
    );
    parse_err(
        Format::LammpsDump,
        &DUMP.replace("x y z", "a b c"),
        9,
        0,
        "coordinate columns",
    );
    parse_err(
        Format::LammpsDump,
        &DUMP.replace("\n2\nITEM: BOX", "\ntwo\nITEM: BOX"),
        4,
        0,
        "number of atoms",
    );
    parse_err(
        Format::LammpsDump,
        &DUMP.replace("0 10\n0 10\n0 10", "0 10\n0 x\n0 10"),
        7,
        0,
        "lo hi",
    );
    parse_err(Format::LammpsDump, "hello\n", 1, 0, "TIMESTEP");
    // second frame truncated
    let two = format!("{DUMP}{}", &DUMP[..DUMP.len() - 20]);
    parse_err(Format::LammpsDump, &two, 21, 1, "6 columns");
    let two = format!("{DUMP}{}", &DUMP[..DUMP.len() - 15]);
    // (the truncated tail rule: one complete frame, no error)
    assert_eq!(parse(Format::LammpsDump, &two).unwrap().len(), 1);
}

const DATA: &str = "title\n\n2 atoms\n1 bonds\n2 atom types\n\n0 10 xlo xhi\n0 10 ylo yhi\n0 10 zlo zhi\n\nMasses\n\n1 26.98\n2 15.999\n\nAtoms # charge\n\n2 2 -1.0 1 1 1\n1 1 1.5 0 0 0\n\nBonds\n\n1 1 1 2\n";

#[test]
fn data_ok_and_errors() {
    let m = &parse(Format::LammpsData, DATA).unwrap()[0];
    assert_eq!(m.elements, vec![13, 8]);
    assert_eq!(m.scalar("q").unwrap(), &[1.5, -1.0]);
    assert_eq!(m.file_bonds.as_deref(), Some(&[[0u32, 1]][..]));
    assert_eq!(m.scalar("id").unwrap(), &[1.0, 2.0]);
    assert_eq!(m.scalar("type").unwrap(), &[1.0, 2.0]);
    // image flags unwrap: x + 1·10, z - 1·10
    let img = DATA
        .replace("1 1 1.5 0 0 0", "1 1 1.5 0 0 0 1 0 -1")
        .replace("2 2 -1.0 1 1 1", "2 2 -1.0 1 1 1 0 0 0");
    let m = &parse(Format::LammpsData, &img).unwrap()[0];
    assert_eq!(m.position(0), [10.0, 0.0, -10.0]);
    // … so the frame is already unwrapped (`unwrap` leaves it); without flags it is not.
    assert!(m.unwrapped);
    assert!(!parse(Format::LammpsData, DATA).unwrap()[0].unwrapped);
    parse_err(
        Format::LammpsData,
        &DATA.replace("2 atoms", "3 atoms"),
        24,
        0,
        "3 lines in the Atoms",
    );
    parse_err(
        Format::LammpsData,
        &DATA.replace("1 1 1.5 0 0 0", "1 1 1.5 0 x 0"),
        19,
        0,
        "a number",
    );
    parse_err(
        Format::LammpsData,
        &DATA.replace("1 1 1.5 0 0 0", "1 1 1.5 0 inf 0"),
        19,
        0,
        "finite",
    );
    parse_err(
        Format::LammpsData,
        &DATA.replace("1 1 1 2", "1 1 1 7"),
        23,
        0,
        "existing atom",
    );
    parse_err(
        Format::LammpsData,
        &DATA.replace("0 10 ylo", "0 q ylo"),
        8,
        0,
        "two finite",
    );
}

const GRO: &str = "t\n2\n    1SOL     OW    1   0.100   0.200   0.300\n    1SOL    HW1    2   0.150   0.200   0.300\n   1.0 1.0 1.0\n";

#[test]
fn gro_ok_and_errors() {
    assert_eq!(
        parse(Format::Gro, &format!("{GRO}{GRO}")).unwrap().len(),
        2,
        "two frames"
    );
    let m = &parse(Format::Gro, GRO).unwrap()[0];
    assert_eq!(m.elements, vec![8, 1]);
    assert!((m.x[1] - 1.5).abs() < 1e-6, "nm -> Å");
    // count that lies: the box line is read as an atom line
    parse_err(
        Format::Gro,
        &GRO.replace("\n2\n", "\n3\n"),
        5,
        0,
        "atom line",
    );
    parse_err(
        Format::Gro,
        &GRO.replace("\n2\n", "\nx\n"),
        2,
        0,
        "number of atoms",
    );
    parse_err(
        Format::Gro,
        &GRO.replace("0.150", "0.1x0"),
        4,
        0,
        "a number",
    );
    parse_err(Format::Gro, &GRO.replace("0.150", "  nan"), 4, 0, "finite");
    parse_err(
        Format::Gro,
        &GRO.replace("   1.0 1.0 1.0", "box"),
        5,
        0,
        "box line",
    );
    parse_err(
        Format::Gro,
        "t\n5\n    1SOL     OW    1   0.100   0.200   0.300\n",
        4,
        0,
        "truncated",
    );
}

const PDB: &str = "CRYST1   10.000   10.000   10.000  90.00  90.00  90.00 P 1           1\nATOM      1  N   MET     1      -1.000   2.000   3.000  1.00 38.38           N\nHETATM    2 FE   HEM     2       1.000   2.000   3.000  1.00  0.00\nCONECT    1    2\nEND\n";

#[test]
fn pdb_ok_and_errors() {
    let m = &parse(Format::Pdb, PDB).unwrap()[0];
    assert_eq!(m.elements, vec![7, 26]);
    assert_eq!(m.file_bonds.as_deref(), Some(&[[0u32, 1]][..]));
    assert_eq!(m.cell.unwrap().edges[2][2], 10.0);
    parse_err(
        Format::Pdb,
        &PDB.replace("-1.000", "-1.0x0"),
        2,
        0,
        "columns 31-38",
    );
    parse_err(
        Format::Pdb,
        &PDB.replace("  2.000   3.000  1.00 38", "    nan   3.000  1.00 38"),
        2,
        0,
        "finite",
    );
    parse_err(
        Format::Pdb,
        "ATOM      1  N   MET     1      -1.000\n",
        1,
        0,
        "columns 31-54",
    );
    assert!(matches!(
        parse(Format::Pdb, "REMARK nothing\nEND\n"),
        Err(ReadError::Empty { .. })
    ));
    // two models
    let two = "MODEL 1\nATOM      1  C   X       1       0.000   0.000   0.000\nENDMDL\nMODEL 2\nATOM      1  C   X       1       1.000   0.000   0.000\nENDMDL\nEND\n";
    assert_eq!(parse(Format::Pdb, two).unwrap().len(), 2);
}

fn samples() -> Vec<(Format, &'static str)> {
    vec![
        (Format::Xyz, XYZ),
        (Format::Xyz, "2\nLattice=\"10 0 0 0 11 0 0 0 12\" Properties=pos:R:3:species:S:1:q:R:1\n1 2 3 Si 0.5\n4 5 6 O -0.5\n"),
        (Format::LammpsDump, DUMP),
        (Format::LammpsData, DATA),
        (Format::Gro, GRO),
        (Format::Pdb, PDB),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_bytes_never_panic(data in proptest::collection::vec(any::<u8>(), 0..600), f in 0usize..5) {
        let fmt = [Format::Xyz, Format::Pdb, Format::LammpsDump, Format::LammpsData, Format::Gro][f];
        let _ = parse_bytes(&data, fmt, &ReadOptions::default());
    }

    #[test]
    fn mutated_inputs_never_panic(
        which in 0usize..6,
        edits in proptest::collection::vec((any::<u16>(), any::<u8>(), 0u8..4), 1..8),
    ) {
        let (fmt, s) = samples()[which];
        let mut b = s.as_bytes().to_vec();
        for (pos, byte, op) in edits {
            if b.is_empty() { break; }
            let i = pos as usize % b.len();
            match op {
                0 => b[i] = byte,
                1 => b.insert(i, byte),
                2 => { b.remove(i); }
                _ => b.truncate(i),
            }
        }
        let _ = parse_bytes(&b, fmt, &ReadOptions::default());
    }

    #[test]
    fn textual_mutations_never_panic(
        which in 0usize..6,
        pos in any::<u16>(),
        tok in prop::sample::select(vec!["nan", "-inf", "1e400", "\n", " ", "ITEM:", "99999999999", "-1", "#", "\"", "=", ":", "Atoms", "ENDMDL"]),
    ) {
        let (fmt, s) = samples()[which];
        let mut b = s.as_bytes().to_vec();
        let i = pos as usize % (b.len() + 1);
        b.splice(i..i, tok.bytes());
        let _ = parse_bytes(&b, fmt, &ReadOptions::default());
    }
}
