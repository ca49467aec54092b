//! Reference scenes (scaled down): atom counts, determinism, realistic bond counts.

use molecule::bonds::{brute_force_bonds, build_bonds, BondOptions};
use molecule::scenes::{generate, SceneName};

fn degrees(n: usize, bonds: &[[u32; 2]]) -> Vec<u32> {
    let mut d = vec![0u32; n];
    for b in bonds {
        d[b[0] as usize] += 1;
        d[b[1] as usize] += 1;
    }
    d
}

fn check(name: SceneName, atoms: usize, tol: f64) -> (molecule::Molecule, Vec<[u32; 2]>) {
    let m = generate(name, Some(atoms), 7);
    let rel = (m.len() as f64 - atoms as f64).abs() / atoms as f64;
    assert!(
        rel <= tol,
        "{name}: {} atoms for {atoms} requested",
        m.len()
    );
    assert_eq!(
        m,
        generate(name, Some(atoms), 7),
        "{name}: not deterministic"
    );
    assert!(m.x.iter().chain(&m.y).chain(&m.z).all(|v| v.is_finite()));
    let b = build_bonds(&m, &BondOptions::default());
    (m, b)
}

#[test]
fn onion_has_three_neighbours_per_atom() {
    for (name, n) in [(SceneName::Ns90k, 20_000), (SceneName::Ns740k, 60_000)] {
        let (m, b) = check(name, n, 0.01);
        assert_eq!(b.len() * 2, m.len() * 3, "{name}: 1.5 bonds/atom");
        assert!(degrees(m.len(), &b).iter().all(|&d| d == 3));
        // Bond lengths ≈ 1.42 Å.
        let mut lo = f32::MAX;
        let mut hi = 0f32;
        for &[i, j] in &b {
            let (p, q) = (m.position(i as usize), m.position(j as usize));
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            lo = lo.min(d);
            hi = hi.max(d);
        }
        assert!(lo > 1.25 && hi < 1.6, "{name}: C-C range {lo}..{hi}");
    }
}

#[test]
fn onion_full_size_counts() {
    for name in [SceneName::Ns90k, SceneName::Ns740k] {
        let m = generate(name, None, 1);
        let want = name.default_atoms() as f64;
        assert!(
            (m.len() as f64 - want).abs() / want < 0.01,
            "{name}: {}",
            m.len()
        );
        let b = build_bonds(&m, &BondOptions::default());
        assert_eq!(b.len() * 2, m.len() * 3, "{name}: exactly 1.5 bonds/atom");
    }
}

#[test]
fn sio2_bonds_per_atom() {
    let (m, b) = check(SceneName::Sio2, 60_000, 0.01);
    let per = b.len() as f64 / m.len() as f64;
    assert!((1.25..=1.3334).contains(&per), "sio2: {per} bonds/atom");
    let ec = m.element_counts();
    let si = ec.iter().find(|e| e.0 == 14).unwrap().1 as f64;
    let o = ec.iter().find(|e| e.0 == 8).unwrap().1 as f64;
    // Surface O (bonded to one Si) raise O/Si above 2 for small slabs.
    assert!((2.0..2.2).contains(&(o / si)), "O/Si = {}", o / si);
    // Only Si–O bonds.
    for &[i, j] in &b {
        assert_ne!(m.elements[i as usize], m.elements[j as usize]);
    }
    let d = degrees(m.len(), &b);
    for (k, &z) in m.elements.iter().enumerate() {
        assert!(d[k] <= if z == 14 { 4 } else { 2 });
    }
}

#[test]
fn nanobowl_bonds() {
    let (m, b) = check(SceneName::Nanobowl, 20_000, 0.01);
    let per = b.len() as f64 / m.len() as f64;
    assert!((1.9..=2.4).contains(&per), "nanobowl: {per} bonds/atom");
    for &[i, j] in &b {
        assert_ne!(
            m.elements[i as usize], m.elements[j as usize],
            "only Al-O bonds"
        );
    }
    assert_eq!(b, brute_force_bonds(&m, &BondOptions::default()));
}

#[test]
fn anp3_bonds() {
    let (m, b) = check(SceneName::Anp3, 150_000, 0.01);
    let per = b.len() as f64 / m.len() as f64;
    assert!((0.7..=1.4).contains(&per), "anp3: {per} bonds/atom");
    // Gas: every O that is not bonded to Al has exactly one O neighbour (an O₂ molecule).
    let d = degrees(m.len(), &b);
    let mut oo = vec![0u32; m.len()];
    for &[i, j] in &b {
        if m.elements[i as usize] == 8 && m.elements[j as usize] == 8 {
            oo[i as usize] += 1;
            oo[j as usize] += 1;
        }
    }
    let gas: Vec<usize> = (0..m.len()).filter(|&k| oo[k] > 0).collect();
    assert!(!gas.is_empty());
    assert!(
        gas.iter().all(|&k| oo[k] == 1 && d[k] == 1),
        "O2 molecules isolated"
    );
}

#[test]
fn scene_names_parse() {
    for s in SceneName::ALL {
        assert_eq!(s.name().parse::<SceneName>().unwrap(), s);
    }
    assert!("foo".parse::<SceneName>().is_err());
}
