//! Unwrapping (`molecule::unwrap`) against hand-computed positions and against the positions
//! the molecules had before they were wrapped into the box.

use molecule::bonds::{build_bonds, BondOptions};
use molecule::read::{parse_bytes, Format, ReadOptions};
use molecule::unwrap::{crossing_bonds, unwrap, UnwrapError, UnwrapMethod};
use molecule::{Cell, Molecule};

fn pbc_bonds(m: &Molecule) -> Vec<[u32; 2]> {
    build_bonds(
        m,
        &BondOptions {
            pbc: true,
            ..BondOptions::default()
        },
    )
}

fn assert_close(m: &Molecule, want: &[[f32; 3]], tol: f32) {
    assert_eq!(m.len(), want.len());
    for (i, w) in want.iter().enumerate() {
        let p = m.position(i);
        for k in 0..3 {
            assert!(
                (p[k] - w[k]).abs() <= tol,
                "atom {i}: got {p:?}, want {w:?}"
            );
        }
    }
}

fn dist(m: &Molecule, i: usize, j: usize) -> f32 {
    let (a, b) = (m.position(i), m.position(j));
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A water molecule (O-H 0.9572 Å, H-O-H 104.52°) with its O at x = 0.2 in a 10 Å cube: the
/// first H sticks out of the low x face and is wrapped to the other side.
fn split_water(o_first: bool) -> Molecule {
    let mut m = Molecule::default();
    let atoms = [
        ([0.2, 5.0, 5.0], 8),
        ([9.4428, 5.5859, 5.0], 1), // 0.2 - 0.7572 + 10
        ([0.9572, 5.5859, 5.0], 1), // 0.2 + 0.7572
    ];
    let order: [usize; 3] = if o_first { [0, 1, 2] } else { [1, 0, 2] };
    for k in order {
        m.push(atoms[k].0, atoms[k].1);
    }
    m.cell = Some(Cell::orthogonal([0.0; 3], [10.0; 3]));
    m
}

#[test]
fn split_water_is_put_back_together_by_bonds() {
    let mut m = split_water(true);
    let bonds = pbc_bonds(&m);
    assert_eq!(
        bonds,
        vec![[0, 1], [0, 2]],
        "both O-H bonds, one across the box"
    );
    assert_eq!(crossing_bonds(&m, &bonds), 1);
    assert!(dist(&m, 0, 1) > 9.0, "split before");
    assert_eq!(unwrap(&mut m, &bonds), Ok(UnwrapMethod::Bonds));
    // The O (lowest index) stays; the wrapped H comes back to x = 0.2 - 0.7572.
    assert_close(
        &m,
        &[
            [0.2, 5.0, 5.0],
            [-0.5572, 5.5859, 5.0],
            [0.9572, 5.5859, 5.0],
        ],
        1e-5,
    );
    for h in [1, 2] {
        assert!(
            (dist(&m, 0, h) - 0.9572).abs() < 1e-3,
            "O-H {}",
            dist(&m, 0, h)
        );
    }
    assert_eq!(crossing_bonds(&m, &bonds), 0);

    // With the wrapped H as atom 0 the H stays and the rest moves by +a.
    let mut m = split_water(false);
    let bonds = pbc_bonds(&m);
    unwrap(&mut m, &bonds).unwrap();
    assert_close(
        &m,
        &[
            [9.4428, 5.5859, 5.0],
            [10.2, 5.0, 5.0],
            [10.9572, 5.5859, 5.0],
        ],
        1e-5,
    );
    assert_eq!(crossing_bonds(&m, &bonds), 0);
}

#[test]
fn chain_across_a_corner_and_a_non_periodic_direction() {
    // A 3-atom chain through the (0,0,0) corner of a 10 Å box, hand-given bonds 0-1, 1-2.
    let mut m = Molecule::default();
    m.push([9.5, 9.5, 9.5], 6); // (-0.5,-0.5,-0.5) wrapped
    m.push([0.5, 0.5, 9.5], 6); // (0.5, 0.5,-0.5) wrapped in z
    m.push([1.5, 0.5, 0.5], 6);
    let mut cell = Cell::orthogonal([0.0; 3], [10.0; 3]);
    m.cell = Some(cell);
    let mut u = m.clone();
    unwrap(&mut u, &[[0, 1], [1, 2]]).unwrap();
    assert_close(
        &u,
        &[[9.5, 9.5, 9.5], [10.5, 10.5, 9.5], [11.5, 10.5, 10.5]],
        1e-5,
    );
    // z not periodic: no shift along c.
    cell.pbc = [true, true, false];
    m.cell = Some(cell);
    unwrap(&mut m, &[[0, 1], [1, 2]]).unwrap();
    assert_close(
        &m,
        &[[9.5, 9.5, 9.5], [10.5, 10.5, 9.5], [11.5, 10.5, 0.5]],
        1e-5,
    );
}

const DUMP_ORTHO: &str = "ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
3
ITEM: BOX BOUNDS pp pp pp
0 10
-5 5
0 20
ITEM: ATOMS id type x y z ix iy iz
3 1 1.0 -4.0 19.0 1 2 -1
1 1 1.0 2.0 3.0 0 0 0
2 1 9.5 2.0 3.0 -1 0 0
";

#[test]
fn image_flags_orthogonal_dump() {
    let mut m = parse_bytes(
        DUMP_ORTHO.as_bytes(),
        Format::LammpsDump,
        &ReadOptions::default(),
    )
    .unwrap()
    .remove(0);
    assert!(!m.unwrapped);
    assert_eq!(m.scalar("ix"), Some(&[0.0, -1.0, 1.0][..]), "sorted by id");
    // Bonds are not needed (and not used) with image flags.
    assert_eq!(unwrap(&mut m, &[]), Ok(UnwrapMethod::ImageFlags));
    assert_close(
        &m,
        &[[1.0, 2.0, 3.0], [-0.5, 2.0, 3.0], [11.0, 16.0, -1.0]],
        1e-6,
    );
}

#[test]
fn image_flags_triclinic_dump() {
    // Box a = (10,0,0), b = (2,8,0), c = (1,-1,6): xy = 2, xz = 1, yz = -1, written as the
    // bounding box LAMMPS prints (xlo_bound = 0 + min(0,2,1,3), xhi_bound = 10 + 3, …).
    let dump = "ITEM: TIMESTEP
5
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS xy xz yz pp pp pp
0 13 2
-1 8 1
0 6 -1
ITEM: ATOMS id type x y z ix iy iz
1 1 1.0 1.0 1.0 1 -1 2
2 1 3.0 2.0 1.0 0 0 0
";
    let mut m = parse_bytes(dump.as_bytes(), Format::LammpsDump, &ReadOptions::default())
        .unwrap()
        .remove(0);
    let c = m.cell.unwrap();
    assert_eq!(
        c.edges,
        [[10.0, 0.0, 0.0], [2.0, 8.0, 0.0], [1.0, -1.0, 6.0]]
    );
    assert_eq!(unwrap(&mut m, &[]), Ok(UnwrapMethod::ImageFlags));
    // (1,1,1) + 1·a - 1·b + 2·c = (1+10-2+2, 1-8-2, 1+12)
    assert_close(&m, &[[11.0, -9.0, 13.0], [3.0, 2.0, 1.0]], 1e-6);
}

#[test]
fn unwrapped_columns_are_not_unwrapped_twice() {
    let dump = DUMP_ORTHO.replace("id type x y z ix", "id type xu yu zu ix");
    let mut m = parse_bytes(dump.as_bytes(), Format::LammpsDump, &ReadOptions::default())
        .unwrap()
        .remove(0);
    assert!(m.unwrapped);
    let before = m.clone();
    assert_eq!(unwrap(&mut m, &[]), Ok(UnwrapMethod::AlreadyUnwrapped));
    assert_eq!(m, before);
    // Without image flags the bonds are used.
    let dump = DUMP_ORTHO.replace(" ix iy iz", " q");
    let dump = dump.replace(" 1 2 -1", " 0.5").replace(" 0 0 0", " 0.1");
    let dump = dump.replace(" -1 0 0", " 0.2");
    let m = parse_bytes(dump.as_bytes(), Format::LammpsDump, &ReadOptions::default())
        .unwrap()
        .remove(0);
    assert_eq!(UnwrapMethod::of(&m), UnwrapMethod::Bonds);
}

#[test]
fn unused_coordinate_columns_are_scalars() {
    let dump = DUMP_ORTHO.replace("x y z ix iy iz", "x y z xu yu zu");
    let m = parse_bytes(dump.as_bytes(), Format::LammpsDump, &ReadOptions::default())
        .unwrap()
        .remove(0);
    assert!(!m.unwrapped, "positions from x y z");
    assert_eq!(m.position(1), [9.5, 2.0, 3.0]);
    // xu holds the file's 4th-from-last column (here the old ix values), sorted by id.
    assert_eq!(m.scalar("xu"), Some(&[0.0, -1.0, 1.0][..]));
    assert_eq!(m.scalar("zu"), Some(&[0.0, 0.0, -1.0][..]));
    assert!(m.scalar("x").is_none(), "the used columns are positions");
}

#[test]
fn errors_are_typed() {
    let mut m = split_water(true);
    m.cell = None;
    assert_eq!(unwrap(&mut m, &[[0, 1]]), Err(UnwrapError::NoCell));
    assert!(UnwrapError::NoCell.to_string().contains("cell"));
    let mut m = split_water(true);
    assert_eq!(
        unwrap(&mut m, &[[0, 7]]),
        Err(UnwrapError::BadBond {
            i: 0,
            j: 7,
            atoms: 3
        })
    );
    let mut m = split_water(true);
    m.cell = Some(Cell::orthogonal([0.0; 3], [10.0, 0.0, 10.0]));
    assert_eq!(unwrap(&mut m, &[]), Err(UnwrapError::DegenerateCell));
    let mut m = split_water(true);
    for (name, v) in [("ix", 0.5f32), ("iy", 0.0), ("iz", 0.0)] {
        m.scalars.push((name.into(), vec![v; 3]));
    }
    assert!(matches!(
        unwrap(&mut m, &[]),
        Err(UnwrapError::BadImageFlag {
            column: "ix",
            atom: 1,
            ..
        })
    ));
}

/// SplitMix64: a small deterministic generator for the random cases.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn dir(&mut self) -> [f64; 3] {
        loop {
            let v = [0, 1, 2].map(|_| self.range(-1.0, 1.0));
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.1 && n <= 1.0 {
                return v.map(|c| c / n);
            }
        }
    }
}

/// A LAMMPS-style triclinic cell with edge lengths log-uniform in [6, 60] Å and tilts up to
/// half an edge, and a random origin.
fn random_cell(rng: &mut Rng) -> Cell {
    let l = [0, 1, 2].map(|_| (rng.range(6f64.ln(), 60f64.ln())).exp());
    let xy = rng.range(-0.5, 0.5) * l[0];
    let xz = rng.range(-0.5, 0.5) * l[0];
    let yz = rng.range(-0.5, 0.5) * l[1];
    Cell {
        origin: [0, 1, 2].map(|_| rng.range(-20.0, 20.0) as f32),
        edges: [
            [l[0] as f32, 0.0, 0.0],
            [xy as f32, l[1] as f32, 0.0],
            [xz as f32, yz as f32, l[2] as f32],
        ],
        pbc: [true; 3],
    }
}

/// `p` moved into the cell (fractional coordinates in [0, 1)), computed in f64.
fn wrap(cell: &Cell, p: [f64; 3]) -> [f32; 3] {
    let inv = cell.inverse().unwrap();
    let h = cell.matrix();
    let d = [0, 1, 2].map(|k| p[k] - f64::from(cell.origin[k]));
    let f = [0, 1, 2].map(|r| {
        let f = inv[r][0] * d[0] + inv[r][1] * d[1] + inv[r][2] * d[2];
        f - f.floor()
    });
    [0, 1, 2].map(|r| {
        (f64::from(cell.origin[r]) + h[r][0] * f[0] + h[r][1] * f[1] + h[r][2] * f[2]) as f32
    })
}

/// A random zigzag chain of `n` carbons (1.5 Å bonds, 109.5° angles, random dihedrals)
/// starting at `start`: no two non-neighbours closer than 2.4 Å.
fn zigzag(rng: &mut Rng, start: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    let mut p = vec![start];
    let mut prev_dir = rng.dir();
    for _ in 1..n {
        // A direction at 180° - 109.5° = 70.5° from the previous bond.
        let d = loop {
            let d = rng.dir();
            let c: f64 = (0..3).map(|k| d[k] * prev_dir[k]).sum();
            if (c - 70.5f64.to_radians().cos()).abs() < 0.02 {
                break d;
            }
        };
        let last = *p.last().unwrap();
        p.push([0, 1, 2].map(|k| last[k] + 1.5 * d[k]));
        prev_dir = d;
    }
    p
}

/// Chains placed anywhere (also far outside the box), wrapped into random triclinic boxes,
/// unwrapped along their (known) bonds: every bond vector is its pre-wrap vector within
/// 1e-3 Å, and each chain is its pre-wrap self moved by one lattice vector.
#[test]
fn random_triclinic_chains_are_restored() {
    let mut rng = Rng(15);
    for trial in 0..200 {
        let cell = random_cell(&mut rng);
        let mut orig = Vec::new();
        let mut bonds = Vec::new();
        let mut chains = Vec::new();
        for _ in 0..1 + trial % 5 {
            let n = 2 + (rng.next() % 40) as usize;
            let start = [0, 1, 2].map(|_| rng.range(-80.0, 80.0));
            let base = orig.len() as u32;
            orig.extend(zigzag(&mut rng, start, n));
            bonds.extend((1..n as u32).map(|k| [base + k - 1, base + k]));
            chains.push(base as usize..orig.len());
        }
        let mut m = Molecule::default();
        for p in &orig {
            m.push(wrap(&cell, *p), 6);
        }
        m.cell = Some(cell);
        assert_eq!(unwrap(&mut m, &bonds), Ok(UnwrapMethod::Bonds));
        for &[i, j] in &bonds {
            let (a, b) = (m.position(i as usize), m.position(j as usize));
            for k in 0..3 {
                let got = f64::from(b[k]) - f64::from(a[k]);
                let want = orig[j as usize][k] - orig[i as usize][k];
                assert!(
                    (got - want).abs() < 1e-3,
                    "trial {trial}, bond {i}-{j}, axis {k}: {got} vs {want} ({cell:?})"
                );
            }
        }
        let inv = cell.inverse().unwrap();
        for r in chains {
            // The shift of the chain's first atom is a lattice vector, shared by the chain.
            let shift = |i: usize| {
                let p = m.position(i);
                [0, 1, 2].map(|k| f64::from(p[k]) - orig[i][k])
            };
            let s0 = shift(r.start);
            for row in &inv {
                let f = row[0] * s0[0] + row[1] * s0[1] + row[2] * s0[2];
                assert!((f - f.round()).abs() < 1e-3, "not a lattice shift: {s0:?}");
            }
            for i in r {
                let s = shift(i);
                for k in 0..3 {
                    assert!((s[k] - s0[k]).abs() < 2e-3, "trial {trial}: atom {i} shift");
                }
            }
        }
    }
}

/// Whether two atoms of chain `c` other than neighbours (also in the periodic images of
/// `cell`, up to two lattice vectors away) are closer than 2 Å (the chain folded back onto
/// itself or touches its own image).
fn self_contact(cell: &Cell, c: &[[f64; 3]]) -> bool {
    let h = cell.matrix();
    for i in 0..c.len() {
        for j in i..c.len() {
            for t in 0..125 {
                let n = [t % 5, t / 5 % 5, t / 25].map(|v| v as f64 - 2.0);
                if (j <= i + 1) && n == [0.0; 3] {
                    continue;
                }
                let d2: f64 = (0..3)
                    .map(|k| {
                        let l = h[k][0] * n[0] + h[k][1] * n[1] + h[k][2] * n[2];
                        (c[j][k] - c[i][k] + l).powi(2)
                    })
                    .sum();
                if d2 < 4.0 {
                    return true;
                }
            }
        }
    }
    false
}

/// The same with the bonds detected by minimum image (one short chain per box, so the chain
/// cannot touch its own image): the detected bonds are the chain's, and unwrapping by them
/// restores it.
#[test]
fn random_chains_unwrap_by_detected_bonds() {
    let mut rng = Rng(1515);
    for trial in 0..200 {
        let cell = random_cell(&mut rng);
        let w = cell.widths().into_iter().fold(f64::INFINITY, f64::min);
        // Extent below w - 2 Å (bond cutoff 1.75 Å): no contact with its own images.
        let n = (((w - 2.5) / 1.3) as usize).clamp(2, 8);
        let start = [0, 1, 2].map(|_| rng.range(-30.0, 30.0));
        let orig = loop {
            let c = zigzag(&mut rng, start, n);
            if !self_contact(&cell, &c) {
                break c;
            }
        };
        let mut m = Molecule::default();
        for p in &orig {
            m.push(wrap(&cell, *p), 6);
        }
        m.cell = Some(cell);
        let bonds = pbc_bonds(&m);
        let want: Vec<[u32; 2]> = (1..n as u32).map(|k| [k - 1, k]).collect();
        assert_eq!(bonds, want, "trial {trial}");
        unwrap(&mut m, &bonds).unwrap();
        assert_eq!(crossing_bonds(&m, &bonds), 0);
        for &[i, j] in &bonds {
            let (a, b) = (m.position(i as usize), m.position(j as usize));
            for k in 0..3 {
                let got = f64::from(b[k]) - f64::from(a[k]);
                let want = orig[j as usize][k] - orig[i as usize][k];
                assert!((got - want).abs() < 1e-3, "trial {trial}: {got} vs {want}");
            }
        }
    }
}
