//! Following a growing file: cut at every byte and completed later, the frames seen are
//! exactly the frames of the whole file (never a half-written one); a file that shrinks, is
//! replaced or rewritten stops the follower; compressed files, PDB and data files are refused.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};

use molecule::read::{parse_bytes, FollowError, Follower, Format, ReadOptions};
use molecule::Molecule;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bns-follow-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Atom `i` of frame `k`: coordinates with several digits, so a cut inside a number changes
/// its value (0.5 cut to 0.).
fn pos(k: usize, i: usize) -> [f64; 3] {
    let t = (k * 7 + i * 3) as f64;
    [
        1.25 + 0.5 * t,
        2.5 - 0.125 * t,
        0.75 * i as f64 + 0.0625 * k as f64,
    ]
}

fn dump(frames: usize, atoms: usize) -> String {
    dump_frames(frames, atoms).concat()
}

/// The text of each of `frames` frames: `head(k)`, a line `atom(k, i, position)` per atom,
/// then `tail`.
fn frames_text(
    frames: usize,
    atoms: usize,
    head: impl Fn(usize) -> String,
    atom: impl Fn(usize, usize, [f64; 3]) -> String,
    tail: &str,
) -> Vec<String> {
    (0..frames)
        .map(|k| {
            let lines: String = (0..atoms).map(|i| atom(k, i, pos(k, i)) + "\n").collect();
            head(k) + &lines + tail
        })
        .collect()
}

/// The text of each frame of a dump.
fn dump_frames(frames: usize, atoms: usize) -> Vec<String> {
    let head = |k: usize| {
        format!(
            "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{atoms}\n",
            k * 100
        ) + "ITEM: BOX BOUNDS pp pp pp\n0 20\n0 20\n0 20\nITEM: ATOMS id type x y z\n"
    };
    let atom = |_, i: usize, [x, y, z]: [f64; 3]| format!("{} {} {x} {y} {z}", i + 1, 1 + i % 2);
    frames_text(frames, atoms, head, atom, "")
}

fn xyz_frames(frames: usize, atoms: usize) -> Vec<String> {
    let head = |k| format!("{atoms}\nframe {k}\n");
    let atom = |_, i: usize, [x, y, z]: [f64; 3]| {
        format!(
            "{} {x} {y} {z}",
            if i.is_multiple_of(2) { "O" } else { "H" }
        )
    };
    frames_text(frames, atoms, head, atom, "")
}

fn gro_frames(frames: usize, atoms: usize) -> Vec<String> {
    let head = |k| format!("water t= {k}.0\n{atoms:5}\n");
    let atom = |_, i: usize, p: [f64; 3]| {
        let [x, y, z] = p.map(|v| v / 10.0);
        let name = if i.is_multiple_of(2) { "OW" } else { "HW1" };
        format!(
            "{:5}{:<5}{:>5}{:5}{x:8.3}{y:8.3}{z:8.3}",
            1 + i / 3,
            "SOL",
            name,
            i + 1
        )
    };
    frames_text(
        frames,
        atoms,
        head,
        atom,
        "   2.00000   2.00000   2.00000\n",
    )
}

fn append(path: &Path, bytes: &[u8]) {
    let mut f = OpenOptions::new().append(true).open(path).unwrap();
    f.write_all(bytes).unwrap();
}

/// Every frame the follower has now.
fn drain(f: &mut Follower) -> Vec<Molecule> {
    let mut out = Vec::new();
    while let Some(m) = f.try_next().unwrap() {
        out.push(m);
    }
    out
}

/// For every cut point: the file holds the bytes before the cut, then gets the rest; the
/// frames drained before the cut are exactly those completely written (their last newline
/// included), and with the rest all the whole file's frames, in order.
fn every_cut(frames: &[String], format: Format, ext: &str) {
    let text = frames.concat();
    let full = parse_bytes(text.as_bytes(), format, &ReadOptions::default()).unwrap();
    assert_eq!(full.len(), frames.len());
    let ends: Vec<usize> = frames
        .iter()
        .scan(0, |end, f| {
            *end += f.len();
            Some(*end)
        })
        .collect();
    let dir = scratch(ext);
    let path = dir.join(format!("growing.{ext}"));
    let bytes = text.as_bytes();
    for cut in 0..=bytes.len() {
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let mut f = Follower::new(&path, &ReadOptions::default()).unwrap();
        let mut got = drain(&mut f);
        let complete = ends.iter().filter(|&&e| e <= cut).count();
        assert_eq!(
            got.len(),
            complete,
            "{ext}: frames read with the file cut at {cut}"
        );
        append(&path, &bytes[cut..]);
        got.extend(drain(&mut f));
        assert_eq!(got, full, "{ext}: cut at byte {cut}");
        assert_eq!(f.frames(), full.len());
    }
}

#[test]
fn a_dump_cut_anywhere_and_completed_gives_exactly_its_frames() {
    every_cut(&dump_frames(3, 4), Format::LammpsDump, "lammpstrj");
}

#[test]
fn an_xyz_cut_anywhere_and_completed_gives_exactly_its_frames() {
    every_cut(&xyz_frames(3, 4), Format::Xyz, "xyz");
}

#[test]
fn a_gro_cut_anywhere_and_completed_gives_exactly_its_frames() {
    every_cut(&gro_frames(3, 4), Format::Gro, "gro");
}

#[test]
fn a_half_written_number_is_not_read_as_a_shorter_one() {
    let text = dump(1, 2);
    let dir = scratch("halfnum");
    let path = dir.join("d.lammpstrj");
    // Cut after "… 2.5" of the last line's "2.375", keeping the line unterminated.
    let last = text.trim_end().rfind('\n').unwrap() + 1;
    let cut = last + text[last..].find(' ').unwrap() + 5;
    std::fs::write(&path, &text[..cut]).unwrap();
    let mut f = Follower::new(&path, &ReadOptions::default()).unwrap();
    assert!(f.try_next().unwrap().is_none());
    append(&path, &text.as_bytes()[cut..]);
    let m = f.try_next().unwrap().unwrap();
    let [x, y, z] = pos(0, 1);
    assert_eq!([m.x[1], m.y[1], m.z[1]], [x as f32, y as f32, z as f32]);
}

#[test]
fn a_shrunk_replaced_or_rewritten_file_stops_the_follower() {
    let dir = scratch("restart");
    let path = dir.join("d.lammpstrj");
    let two = dump(2, 3);
    std::fs::write(&path, &two).unwrap();
    let mut f = Follower::new(&path, &ReadOptions::default()).unwrap();
    assert_eq!(drain(&mut f).len(), 2);
    // Shrunk: a restarted run truncates the file.
    std::fs::write(&path, dump(1, 3)).unwrap();
    let e = f.try_next().unwrap_err();
    assert!(matches!(e, FollowError::Shrunk { frames: 2, .. }), "{e}");
    assert!(e.to_string().contains("shrank"), "{e}");

    // Rewritten in place, longer than before: the bytes already read differ.
    std::fs::write(&path, &two).unwrap();
    let mut f = Follower::new(&path, &ReadOptions::default()).unwrap();
    assert_eq!(drain(&mut f).len(), 2);
    let other = dump(3, 3).replace("ITEM: TIMESTEP\n100", "ITEM: TIMESTEP\n999");
    std::fs::write(&path, other).unwrap();
    let e = f.try_next().unwrap_err();
    assert!(matches!(e, FollowError::Replaced { frames: 2, .. }), "{e}");

    // Replaced: another file renamed over the name.
    std::fs::write(&path, &two).unwrap();
    let mut f = Follower::new(&path, &ReadOptions::default()).unwrap();
    assert_eq!(drain(&mut f).len(), 2);
    let tmp = dir.join("new.lammpstrj");
    std::fs::write(&tmp, dump(3, 3)).unwrap();
    std::fs::rename(&tmp, &path).unwrap();
    let e = f.try_next().unwrap_err();
    assert!(e.to_string().contains("replaced"), "{e}");
}

#[test]
fn gzip_pdb_and_data_files_cannot_be_followed() {
    let dir = scratch("refused");
    let gz = dir.join("d.lammpstrj");
    std::fs::write(&gz, [0x1f, 0x8b, 8, 0, 0, 0, 0, 0]).unwrap();
    let pdb = dir.join("a.pdb");
    std::fs::write(
        &pdb,
        "ATOM      1  O   HOH     1       0.000   0.000   0.000\n",
    )
    .unwrap();
    let data = dir.join("a.data");
    std::fs::write(&data, "title\n\n1 atoms\n").unwrap();
    for (p, says) in [(&gz, "uncompressed"), (&pdb, "PDB"), (&data, "data file")] {
        let e = Follower::new(p, &ReadOptions::default()).err().unwrap();
        assert!(matches!(e, FollowError::Unsupported { .. }), "{e}");
        assert!(e.to_string().contains(says), "{e}");
    }
    let missing = Follower::new(&dir.join("nope.xyz"), &ReadOptions::default())
        .err()
        .unwrap();
    assert!(missing.to_string().contains("nope.xyz"), "{missing}");
}
