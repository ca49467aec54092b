//! Every backend renders a real protein (../shared/data/adk_open.pdb, 3,341 atoms) like the
//! scalar backend. The test reads the PDB itself (fixed columns, element from the atom name)
//! and bonds by brute force, so it does not depend on the molecule crate.

mod common;
use common::render_bs;
use std::path::PathBuf;

use render::{rgba, Camera, Model, ModelOptions, RenderSettings, Style, View};
use spmd::Isa;

fn sample(name: &str) -> PathBuf {
    // Workspace root is two levels above this crate; the data sit beside the repository.
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(name)
}

struct Atoms {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    rcov: Vec<f32>,
    color: Vec<u32>,
}

fn read_pdb(text: &str) -> Atoms {
    let mut a = Atoms {
        x: vec![],
        y: vec![],
        z: vec![],
        rcov: vec![],
        color: vec![],
    };
    for line in text
        .lines()
        .filter(|l| l.starts_with("ATOM") || l.starts_with("HETATM"))
    {
        let f = |r: std::ops::Range<usize>| line[r].trim().parse::<f32>().unwrap();
        a.x.push(f(30..38));
        a.y.push(f(38..46));
        a.z.push(f(46..54));
        let el = line[12..16]
            .trim()
            .chars()
            .find(|c| c.is_ascii_alphabetic())
            .unwrap();
        // Cordero covalent radii (Å) and Jmol colours.
        let (r, c) = match el {
            'H' => (0.31, rgba(255, 255, 255, 255)),
            'C' => (0.76, rgba(144, 144, 144, 255)),
            'N' => (0.71, rgba(48, 80, 248, 255)),
            'O' => (0.66, rgba(255, 13, 13, 255)),
            'S' => (1.05, rgba(255, 255, 48, 255)),
            _ => (0.75, rgba(255, 20, 147, 255)),
        };
        a.rcov.push(r);
        a.color.push(c);
    }
    a
}

fn bonds(a: &Atoms) -> Vec<[u32; 2]> {
    let n = a.x.len();
    let mut b = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let d2 =
                (a.x[i] - a.x[j]).powi(2) + (a.y[i] - a.y[j]).powi(2) + (a.z[i] - a.z[j]).powi(2);
            let cut = 1.15 * (a.rcov[i] + a.rcov[j]);
            if d2 > 0.16 && d2 < cut * cut {
                b.push([i as u32, j as u32]);
            }
        }
    }
    b
}

#[test]
fn protein_renders_alike_on_every_backend() {
    let path = sample("adk_open.pdb");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let atoms = read_pdb(&text);
    assert_eq!(atoms.x.len(), 3341);
    let bonds = bonds(&atoms);
    // A protein has about one bond per atom.
    assert!(
        bonds.len() > 3000 && bonds.len() < 4000,
        "{} bonds",
        bonds.len()
    );
    for style in [Style::BallAndStick, Style::Licorice, Style::Spheres] {
        let opt = ModelOptions {
            style,
            radius_scale: if style == Style::Spheres { 2.0 } else { 0.5 },
            ..Default::default()
        };
        let scene = Model::new(
            &atoms.x,
            &atoms.y,
            &atoms.z,
            &atoms.rcov,
            &atoms.color,
            &bonds,
            &opt,
            None,
        )
        .unwrap();
        scene.bvh.validate(&scene.geometry).unwrap();
        for view in [View::Far, View::Close] {
            let cam = Camera::view(view, scene.center, scene.radius, 40.0, 1.25);
            let ro = RenderSettings::default();
            let (reference, _) = render_bs(&scene, &cam, 250, 200, &ro, Isa::Scalar);
            if let Ok(dir) = std::env::var("BNS_TEST_IMAGES") {
                reference
                    .save_png(format!("{dir}/adk-{style:?}-{view:?}.png"))
                    .unwrap();
            }
            let covered = reference
                .pixels
                .iter()
                .filter(|&&p| p != ro.background_packed())
                .count();
            assert!(
                covered > 2000,
                "{style:?} {view:?}: only {covered} pixels show the protein"
            );
            for isa in Isa::supported() {
                let (fb, _) = render_bs(&scene, &cam, 250, 200, &ro, isa);
                let within = reference
                    .pixels
                    .iter()
                    .zip(&fb.pixels)
                    .filter(|(p, q)| {
                        p.to_le_bytes()
                            .iter()
                            .zip(q.to_le_bytes())
                            .all(|(a, b)| a.abs_diff(b) <= 1)
                    })
                    .count();
                let frac = within as f64 / fb.pixels.len() as f64;
                assert!(frac >= 0.999, "{isa} {style:?} {view:?}: {frac}");
            }
        }
    }
}
