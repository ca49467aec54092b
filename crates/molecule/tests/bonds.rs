//! Grid bond builder == O(N²) brute force on random and clustered point sets, with and
//! without periodic boundaries and with every kind of cutoff option.

use molecule::bonds::{brute_force_bonds, build_bonds, BondOptions};
use molecule::{Cell, Molecule};
use proptest::prelude::*;

const ZS: [u8; 6] = [1, 6, 8, 13, 14, 0];

fn molecule(points: &[([f32; 3], usize)]) -> Molecule {
    let mut m = Molecule::default();
    for (p, z) in points {
        m.push(*p, ZS[*z % ZS.len()]);
    }
    m
}

fn options() -> impl Strategy<Value = BondOptions> {
    (
        0.8f32..1.6,
        prop::option::of(0.5f32..3.0),
        prop::bool::ANY,
        prop::bool::ANY,
    )
        .prop_map(|(factor, global, pair, pbc)| BondOptions {
            factor,
            global_cutoff: global,
            pair_cutoffs: if pair {
                vec![(13, 8, 2.2), (6, 6, 1.0)]
            } else {
                vec![]
            },
            pbc,
            ..BondOptions::default()
        })
}

fn cell() -> impl Strategy<Value = Cell> {
    (
        8f32..20.0,
        8f32..20.0,
        8f32..20.0,
        -3f32..3.0,
        -3f32..3.0,
        -3f32..3.0,
        prop::array::uniform3(prop::bool::ANY),
    )
        .prop_map(|(a, b, c, xy, xz, yz, pbc)| Cell {
            origin: [-1.0, 0.5, 0.0],
            edges: [[a, 0.0, 0.0], [xy, b, 0.0], [xz, yz, c]],
            pbc,
        })
}

fn check(m: &Molecule, o: &BondOptions) {
    let g = build_bonds(m, o);
    let b = brute_force_bonds(m, o);
    assert_eq!(g, b);
    assert!(g.windows(2).all(|w| w[0] < w[1]) && g.iter().all(|p| p[0] < p[1]));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_sets(
        pts in prop::collection::vec((prop::array::uniform3(-2f32..18.0), 0usize..6), 0..400),
        o in options(),
        c in prop::option::of(cell()),
    ) {
        let mut m = molecule(&pts);
        m.cell = c;
        check(&m, &o);
    }

    #[test]
    fn clustered_sets(
        centres in prop::collection::vec(prop::array::uniform3(-30f32..30.0), 1..6),
        pts in prop::collection::vec((0usize..6, prop::array::uniform3(-1.5f32..1.5), 0usize..6), 1..400),
        o in options(),
        c in prop::option::of(cell()),
    ) {
        let points: Vec<([f32; 3], usize)> = pts
            .iter()
            .map(|(k, d, z)| {
                let c = centres[k % centres.len()];
                ([c[0] + d[0], c[1] + d[1], c[2] + d[2]], *z)
            })
            .collect();
        let mut m = molecule(&points);
        m.cell = c;
        check(&m, &o);
    }
}

#[test]
fn pbc_bonds_are_short() {
    // Two atoms at opposite faces of a 10 Å box: bonded through the boundary with pbc only.
    let mut m = Molecule::default();
    m.push([0.2, 5.0, 5.0], 6);
    m.push([9.6, 5.0, 5.0], 6);
    m.cell = Some(Cell::orthogonal([0.0; 3], [10.0; 3]));
    assert!(build_bonds(&m, &BondOptions::default()).is_empty());
    let o = BondOptions {
        pbc: true,
        ..BondOptions::default()
    };
    assert_eq!(build_bonds(&m, &o), vec![[0, 1]]);
}

#[test]
fn min_distance_excludes_overlaps() {
    let mut m = Molecule::default();
    m.push([0.0; 3], 6);
    m.push([0.3, 0.0, 0.0], 6);
    m.push([1.4, 0.0, 0.0], 6);
    assert_eq!(
        build_bonds(&m, &BondOptions::default()),
        vec![[0, 2], [1, 2]]
    );
}

/// The search a viewer's loader stops when the user steps past its frame: never cancelled it
/// is the plain search and counts every atom; cancelled before it starts it searches
/// nothing; cancelled after its first chunk of 4096 atoms, on one thread, it searches no
/// other chunk.
#[test]
fn a_cancelled_bond_search_stops_after_the_chunk_in_hand() {
    use molecule::bonds::{try_build_bonds_with_progress, BondError};
    use molecule::scenes::{generate, SceneName};
    use std::sync::atomic::{AtomicU64, Ordering};
    let m = generate(SceneName::Ns90k, Some(20_000), 1);
    let n = m.len() as u64;
    let opts = BondOptions::default();
    let done = AtomicU64::new(0);
    let all = try_build_bonds_with_progress(&m, &opts, &done, &|| false).unwrap();
    assert_eq!(all, build_bonds(&m, &opts));
    assert_eq!(done.load(Ordering::Relaxed), n);
    assert!(n > 3 * 4096, "{n} atoms");

    let done = AtomicU64::new(0);
    let r = try_build_bonds_with_progress(&m, &opts, &done, &|| true);
    assert!(matches!(r, Err(BondError::Cancelled)), "{r:?}");
    assert_eq!(done.load(Ordering::Relaxed), 0);
    assert!(r.unwrap_err().to_string().contains("cancelled"));

    let done = AtomicU64::new(0);
    let after_one = || done.load(Ordering::Relaxed) > 0;
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let r = one.install(|| try_build_bonds_with_progress(&m, &opts, &done, &after_one));
    assert!(matches!(r, Err(BondError::Cancelled)), "{r:?}");
    assert_eq!(done.load(Ordering::Relaxed), 4096);
}
