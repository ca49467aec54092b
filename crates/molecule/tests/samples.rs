//! Every sample file in `<workspace>/../shared/data` reads with the right atom/frame/element
//! counts and coordinates matching the ASE oracle (`tests/oracle/expected.json`) to 1e-4 Å;
//! bonds from the grid builder equal brute force on every file.

use molecule::bonds::{brute_force_bonds, build_bonds, BondOptions};
use molecule::elements;
use molecule::read::{open, ReadOptions};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn data_dir() -> PathBuf {
    let ws = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let d = ws.join("../shared/data");
    // Worktrees live one level deeper than the main checkout: look further up.
    let d = if d.is_dir() {
        d
    } else {
        ws.ancestors()
            .map(|a| a.join("shared/data"))
            .find(|d| d.is_dir())
            .unwrap_or(d)
    };
    assert!(
        d.is_dir(),
        "sample data directory not found at {} (expected <workspace>/../shared/data)",
        d.display()
    );
    d
}

fn expected() -> serde_json::Value {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/oracle/expected.json");
    let s = std::fs::read_to_string(&p).expect("tests/oracle/expected.json missing");
    serde_json::from_str(&s).expect("bad expected.json")
}

fn close(a: [f32; 3], b: &serde_json::Value, what: &str) {
    for k in 0..3 {
        let e = b[k].as_f64().unwrap();
        assert!(
            (f64::from(a[k]) - e).abs() <= 1e-4 + 1e-6 * e.abs(),
            "{what}: component {k}: got {} expected {e}",
            a[k]
        );
    }
}

#[test]
fn samples_match_oracle() {
    let dir = data_dir();
    let exp = expected();
    let obj = exp.as_object().unwrap();
    assert_eq!(obj.len(), 7);
    for (name, e) in obj {
        let path = dir.join(name);
        let mut t = open(&path, &ReadOptions::default()).unwrap_or_else(|err| panic!("{err}"));
        let frames = t.count_frames().unwrap();
        assert_eq!(
            frames as u64,
            e["frames"].as_u64().unwrap(),
            "{name}: frames"
        );
        let all: Vec<_> = t.by_ref().collect::<Result<_, _>>().unwrap();
        assert_eq!(all.len(), frames, "{name}: iterated frames");
        let first = &all[0];
        let last = &all[frames - 1];
        let n = first.len();
        assert_eq!(n as u64, e["atoms"].as_u64().unwrap(), "{name}: atoms");
        for m in &all {
            assert_eq!(m.len(), n, "{name}: every frame has the same atoms");
        }
        let mut counts = BTreeMap::new();
        for (z, c) in first.element_counts() {
            counts.insert(elements::element(z).symbol.to_string(), c as u64);
        }
        let ec: BTreeMap<String, u64> = e["element_counts"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(k, v)| (k.clone(), v.as_u64().unwrap()))
            .collect();
        assert_eq!(counts, ec, "{name}: element counts");
        if let Some(tc) = e.get("type_counts") {
            let types = first.scalar("type").expect("type column");
            let mut c = BTreeMap::new();
            for &t in types {
                *c.entry((t as i64).to_string()).or_insert(0u64) += 1;
            }
            let tc: BTreeMap<String, u64> = tc
                .as_object()
                .unwrap()
                .iter()
                .map(|(k, v)| (k.clone(), v.as_u64().unwrap()))
                .collect();
            assert_eq!(c, tc, "{name}: type counts");
        }
        close(first.position(0), &e["first_frame_first_atom"], name);
        close(first.position(n - 1), &e["first_frame_last_atom"], name);
        close(last.position(0), &e["last_frame_first_atom"], name);
        close(last.position(n - 1), &e["last_frame_last_atom"], name);
        if let Some(nb) = e.get("file_bonds") {
            assert_eq!(
                first.file_bonds.as_ref().map(|b| b.len() as u64),
                nb.as_u64(),
                "{name}: file bonds"
            );
        }
        // Random access agrees with sequential reading.
        let k = frames - 1;
        let m = t.read_frame(k).unwrap();
        assert_eq!(&m, last, "{name}: read_frame({k})");
        let m0 = t.read_frame(0).unwrap();
        assert_eq!(&m0, first, "{name}: read_frame(0)");
    }
}

#[test]
fn bonds_match_brute_force_on_samples() {
    let dir = data_dir();
    for name in expected().as_object().unwrap().keys() {
        let m = molecule::read::read_first(&dir.join(name), &ReadOptions::default()).unwrap();
        for pbc in [false, true] {
            let opts = BondOptions {
                pbc,
                ..BondOptions::default()
            };
            let g = build_bonds(&m, &opts);
            let b = brute_force_bonds(&m, &opts);
            assert_eq!(g, b, "{name} (pbc={pbc}): grid vs brute force");
        }
    }
}

#[test]
fn cnt_bonds_from_file_match_geometry() {
    // The nanotube lists its 906 bonds; with minimum image the geometric rule finds them all.
    let m = molecule::read::read_first(
        &data_dir().join("cnt-hexagonal-class1.data"),
        &ReadOptions::default(),
    )
    .unwrap();
    let fb = m.file_bonds.clone().unwrap();
    assert_eq!(fb.len(), 906);
    let g = build_bonds(
        &m,
        &BondOptions {
            pbc: true,
            ..BondOptions::default()
        },
    );
    assert_eq!(g, fb);
}
