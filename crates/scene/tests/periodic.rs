//! The cell in the model (issue #20): periodic bonds as two half-sticks (against a hand-made
//! water molecule and against minimum-image distances computed here), the drawn cell's
//! edges, and the colour range of colouring by a column.

use bvh::Prim;
use molecule::bonds::BondOptions;
use molecule::{Cell, Molecule};
use scene::{
    BondSettings, ColorBy, Colormap, Model, ModelSettings, Scene, SceneError, SceneSettings,
    CELL_COLOR,
};
use spmd::Isa;

fn molecule(atoms: &[(u8, [f32; 3])], cell: Option<Cell>) -> Molecule {
    let mut m = Molecule::default();
    for &(z, p) in atoms {
        m.elements.push(z);
        m.x.push(p[0]);
        m.y.push(p[1]);
        m.z.push(p[2]);
    }
    m.cell = cell;
    m
}

fn settings(pbc: bool, periodic_bonds: bool, draw_cell: bool) -> SceneSettings {
    SceneSettings {
        model: Some(ModelSettings {
            periodic_bonds,
            draw_cell,
            ..ModelSettings::default()
        }),
        bonds: BondSettings {
            options: BondOptions {
                pbc,
                ..BondOptions::default()
            },
            ..BondSettings::default()
        },
        budget_bytes: Some(u64::MAX),
        ..SceneSettings::default()
    }
}

/// Every stick as (first endpoint, second endpoint) in Å.
fn sticks(md: &Model) -> Vec<([f32; 3], [f32; 3])> {
    let g = &md.geometry;
    (0..g.sticks.len())
        .map(|j| (g.endpoint(g.sticks.a[j]), g.endpoint(g.sticks.b[j])))
        .collect()
}

fn dist(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>().sqrt()
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    dist(a, b) < 1e-4
}

/// A water molecule split by the x boundary of a 10 Å box: O–H1 crosses it, O–H2 does not.
fn split_water() -> Molecule {
    molecule(
        &[
            (8, [0.3, 5.0, 5.0]),
            (1, [9.8, 5.3, 5.0]),
            (1, [0.9, 5.6, 5.0]),
        ],
        Some(Cell::orthogonal([0.0; 3], [10.0; 3])),
    )
}

#[test]
fn a_bond_across_the_boundary_is_two_half_sticks_at_the_two_sides() {
    let m = split_water();
    let s = Scene::build(Isa::Scalar, &m, &settings(true, true, false)).unwrap();
    assert_eq!(s.bonds, vec![[0, 1], [0, 2]]);
    let st = sticks(s.model.as_ref().unwrap());
    assert_eq!(st.len(), 3, "{st:?}");
    // O–H1 through the boundary: d = (-0.5, 0.3, 0), so the halves end at O + d/2 and H1 - d/2.
    let (o, h1, h2) = ([0.3, 5.0, 5.0], [9.8, 5.3, 5.0], [0.9, 5.6, 5.0]);
    let want = [(o, [0.05, 5.15, 5.0]), (o, h2), (h1, [10.05, 5.15, 5.0])];
    for w in want {
        assert!(
            st.iter().any(|&(a, b)| close(a, w.0) && close(b, w.1)),
            "no stick {w:?} in {st:?}"
        );
    }
    // Without the split the same bond spans the box (what the issue saw).
    let s = Scene::build(Isa::Scalar, &m, &settings(true, false, false)).unwrap();
    let longest = sticks(s.model.as_ref().unwrap())
        .iter()
        .map(|&(a, b)| dist(a, b))
        .fold(0.0, f32::max);
    assert!(longest > 9.0, "{longest}");
}

#[test]
fn half_sticks_take_their_atoms_colour() {
    let m = split_water();
    let s = Scene::build(Isa::Scalar, &m, &settings(true, true, false)).unwrap();
    let md = s.model.as_ref().unwrap();
    let g = &md.geometry;
    let n = g.balls.len() as u32;
    let mut halves = 0;
    for j in 0..g.sticks.len() {
        let (a, b) = (g.sticks.a[j], g.sticks.b[j]);
        if b >= n {
            halves += 1;
            assert_eq!(g.endpoint_color(b), g.endpoint_color(a), "stick {j}");
        }
    }
    assert_eq!(halves, 2);
    // And the slot colour tables agree: both halves of a half-stick are its atom's colour.
    for (slot, &id) in md.bvh.prim_ids.iter().enumerate() {
        if let Prim::Stick(j) = g.prim(id) {
            if g.sticks.b[j as usize] >= n {
                assert_eq!(md.slot_color_a[slot], md.slot_color_b[slot]);
            }
        }
    }
}

/// A small deterministic generator (xorshift), so the test needs no crate.
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[test]
fn no_stick_is_longer_than_half_the_cell_and_every_bond_keeps_its_minimum_image_length() {
    // Boxes from 6 to 60 Å on a log scale, carbon atoms at random, a triclinic tilt.
    for (case, seed) in (1..=6u64).enumerate() {
        let mut r = Rng(seed * 0x9e37_79b9_7f4a_7c15);
        let edge = 6.0 * 10f32.powf(case as f32 / 5.0);
        let tilt = 0.3 * edge * r.f();
        let cell = Cell {
            origin: [-1.0, 2.0, 0.5],
            edges: [[edge, 0.0, 0.0], [tilt, edge, 0.0], [0.0, 0.0, edge]],
            pbc: [true; 3],
        };
        let n = (edge * edge * edge / 12.0) as usize;
        let atoms: Vec<(u8, [f32; 3])> = (0..n)
            .map(|_| {
                let f = [r.f(), r.f(), r.f()];
                let p = [0, 1, 2]
                    .map(|k| cell.origin[k] + (0..3).map(|e| cell.edges[e][k] * f[e]).sum::<f32>());
                (6, p)
            })
            .collect();
        let m = molecule(&atoms, Some(cell));
        let s = Scene::build(Isa::Scalar, &m, &settings(true, true, false)).unwrap();
        let md = s.model.as_ref().unwrap();
        let half_width = cell.widths().into_iter().fold(f64::INFINITY, f64::min) as f32 / 2.0;
        let st = sticks(md);
        assert!(!s.bonds.is_empty(), "case {case}: no bonds to test");
        for &(a, b) in &st {
            assert!(dist(a, b) <= half_width, "case {case}: stick {a:?}-{b:?}");
        }
        // Every bond is one whole stick of its direct length, or two halves of half its
        // minimum-image length (computed here from the fractional coordinates).
        let mi = molecule::MinimumImage::new(&cell).unwrap();
        let g = &md.geometry;
        let mut halves = vec![0usize; m.len()];
        for j in 0..g.sticks.len() {
            if (g.sticks.b[j] as usize) >= m.len() {
                halves[g.sticks.a[j] as usize] += 1;
            }
        }
        let split: usize = halves.iter().sum();
        assert_eq!(st.len(), s.bonds.len() + split / 2, "case {case}");
        for &[i, j] in &s.bonds {
            let (pi, pj) = (g.endpoint(i), g.endpoint(j));
            let d = [0, 1, 2].map(|k| f64::from(pj[k]) - f64::from(pi[k]));
            let dm = mi.apply(d);
            let len_min = (dm.iter().map(|v| v * v).sum::<f64>()).sqrt() as f32;
            let whole = st
                .iter()
                .any(|&(a, b)| close(a, pi) && close(b, pj) && (dist(a, b) - len_min).abs() < 1e-4);
            let end_i: [f32; 3] = [0, 1, 2].map(|k| (f64::from(pi[k]) + 0.5 * dm[k]) as f32);
            let end_j: [f32; 3] = [0, 1, 2].map(|k| (f64::from(pj[k]) - 0.5 * dm[k]) as f32);
            let two_halves = st.iter().any(|&(a, b)| close(a, pi) && close(b, end_i))
                && st.iter().any(|&(a, b)| close(a, pj) && close(b, end_j));
            assert!(whole || two_halves, "case {case}: bond {i}-{j} not drawn");
        }
    }
}

#[test]
fn the_cell_is_drawn_as_its_twelve_edges() {
    let m = split_water();
    let s = Scene::build(Isa::Scalar, &m, &settings(false, false, true)).unwrap();
    let md = s.model.as_ref().unwrap();
    let g = &md.geometry;
    let cell_sticks: Vec<([f32; 3], [f32; 3])> = (0..g.sticks.len())
        .filter(|&j| g.endpoint_color(g.sticks.a[j]) == Some(CELL_COLOR) && g.sticks.a[j] >= 3)
        .map(|j| (g.endpoint(g.sticks.a[j]), g.endpoint(g.sticks.b[j])))
        .collect();
    assert_eq!(cell_sticks.len(), 12);
    for (a, b) in &cell_sticks {
        assert!((dist(*a, *b) - 10.0).abs() < 1e-5, "{a:?} {b:?}");
        for p in [a, b] {
            assert!(p.iter().all(|&v| v == 0.0 || v == 10.0), "corner {p:?}");
        }
    }
    // The camera's sphere holds the whole box (its corners are 8.66 Å from the centre).
    assert!(s.sphere.radius >= 8.66, "{:?}", s.sphere);
    // An input without a cell is an error, not a silent omission.
    let mut nocell = m.clone();
    nocell.cell = None;
    let e = Scene::build(Isa::Scalar, &nocell, &settings(false, false, true)).unwrap_err();
    assert!(matches!(e, SceneError::NoCell), "{e}");
}

#[test]
fn colour_range_is_the_columns_own_or_the_one_given() {
    let mut m = split_water();
    m.scalars.push(("q".into(), vec![-0.8, 0.4, 0.4]));
    let mut st = settings(false, false, false);
    let by = |range| ColorBy::Column {
        name: "q".into(),
        colormap: Colormap::Viridis,
        range,
    };
    st.model.as_mut().unwrap().color = by(None);
    let s = Scene::build(Isa::Scalar, &m, &st).unwrap();
    assert_eq!(s.model.as_ref().unwrap().color_range, Some((-0.8, 0.4)));
    st.model.as_mut().unwrap().color = by(Some((-1.0, 1.0)));
    let s = Scene::build(Isa::Scalar, &m, &st).unwrap();
    let md = s.model.as_ref().unwrap();
    assert_eq!(md.color_range, Some((-1.0, 1.0)));
    // The atoms' colours follow the given range: q = 0.4 is 70 % of the way from -1 to 1.
    let [r, g, b] = Colormap::Viridis.map(0.7);
    assert_eq!(md.geometry.balls.color[1], scene::rgba(r, g, b, 255));
    for bad in [
        (1.0, -1.0),
        (0.5, 0.5),
        (f32::NAN, 1.0),
        (0.0, f32::INFINITY),
    ] {
        st.model.as_mut().unwrap().color = by(Some(bad));
        let e = Scene::build(Isa::Scalar, &m, &st).unwrap_err();
        assert!(
            matches!(e, SceneError::BadColorRange { .. }),
            "{bad:?}: {e}"
        );
    }
}
