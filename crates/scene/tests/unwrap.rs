//! `BondSettings::unwrap` in the scene (issue #15): the model, bonds and camera sphere of a
//! split molecule built with unwrapping equal those of the same molecule put together by hand
//! and built without it; bonds of a molecule bonded to its own image; errors.

use molecule::bonds::BondOptions;
use molecule::unwrap::UnwrapMethod;
use molecule::{Cell, Molecule};
use scene::{
    BondSettings, MemoryEstimate, Model, ModelSettings, Scene, SceneError, SceneSettings,
    UnwrapReport,
};
use spmd::Isa;

fn molecule(atoms: &[(u8, [f32; 3])], cell: Option<Cell>) -> Molecule {
    let mut m = Molecule::default();
    for &(z, p) in atoms {
        m.push(p, z);
    }
    m.cell = cell;
    m
}

fn settings(unwrap: bool, pbc: bool, model: bool) -> SceneSettings {
    SceneSettings {
        model: model.then(|| ModelSettings {
            periodic_bonds: pbc,
            ..ModelSettings::default()
        }),
        bonds: BondSettings {
            options: BondOptions {
                pbc,
                ..BondOptions::default()
            },
            unwrap,
            ..BondSettings::default()
        },
        volume: (!model).then(scene::VolumeSettings::default),
        budget_bytes: Some(u64::MAX),
        ..SceneSettings::default()
    }
}

fn box10() -> Option<Cell> {
    Some(Cell::orthogonal([0.0; 3], [10.0; 3]))
}

/// A water molecule split by the x boundary of a 10 Å box (O–H1 crosses it).
fn split_water() -> Molecule {
    molecule(
        &[
            (8, [0.3, 5.0, 5.0]),
            (1, [9.8, 5.3, 5.0]),
            (1, [0.9, 5.6, 5.0]),
        ],
        box10(),
    )
}

/// The same water put together by hand: H1 at 9.8 - 10.
fn whole_water() -> Molecule {
    molecule(
        &[
            (8, [0.3, 5.0, 5.0]),
            (1, [9.8f32 - 10.0, 5.3, 5.0]),
            (1, [0.9, 5.6, 5.0]),
        ],
        box10(),
    )
}

/// Every stick as (first endpoint, second endpoint) in Å.
fn sticks(md: &Model) -> Vec<([f32; 3], [f32; 3])> {
    let g = &md.geometry;
    (0..g.sticks.len())
        .map(|j| (g.endpoint(g.sticks.a[j]), g.endpoint(g.sticks.b[j])))
        .collect()
}

fn assert_same_model(a: &Scene, b: &Scene) {
    let (ma, mb) = (a.model.as_ref().unwrap(), b.model.as_ref().unwrap());
    assert_eq!(sticks(ma), sticks(mb));
    assert_eq!(ma.geometry.balls.x, mb.geometry.balls.x);
    assert_eq!(ma.geometry.balls.y, mb.geometry.balls.y);
    assert_eq!(a.sphere, b.sphere, "camera fitted to the unwrapped atoms");
    assert_eq!(a.bonds, b.bonds);
}

#[test]
fn unwrapped_water_is_drawn_whole() {
    let m = split_water();
    // Reference: the hand-made whole molecule without unwrapping and without pbc.
    let want = Scene::build(Isa::Scalar, &whole_water(), &settings(false, false, true)).unwrap();
    assert_eq!(want.bonds, vec![[0, 1], [0, 2]]);
    for pbc in [false, true] {
        let s = Scene::build(Isa::Scalar, &m, &settings(true, pbc, true)).unwrap();
        assert_same_model(&s, &want);
        assert_eq!(
            s.unwrap,
            Some(UnwrapReport {
                method: UnwrapMethod::Bonds,
                crossing: 0,
                crossing_drawn: pbc,
            })
        );
        let st = sticks(s.model.as_ref().unwrap());
        assert_eq!(st.len(), 2, "no half-sticks with --pbc --unwrap: {st:?}");
        assert!(s.stage_report()[0].contains("minimum image along the bonds"));
    }
    // Without unwrapping and without pbc the crossing bond is missing and the camera sphere
    // spans the box.
    let s = Scene::build(Isa::Scalar, &m, &settings(false, false, true)).unwrap();
    assert_eq!(s.bonds, vec![[0, 2]]);
    assert!(s.sphere.radius > 4.0, "{:?}", s.sphere);
    assert!(want.sphere.radius < 2.0, "{:?}", want.sphere);
}

#[test]
fn unwrapping_also_moves_the_volume() {
    let want = Scene::build(Isa::Scalar, &whole_water(), &settings(false, false, false)).unwrap();
    let s = Scene::build(Isa::Scalar, &split_water(), &settings(true, false, false)).unwrap();
    assert!(s.model.is_none() && s.bonds.is_empty());
    assert_eq!(s.sphere, want.sphere);
    let (a, b) = (s.volume.unwrap().density, want.volume.unwrap().density);
    let (a, b) = (a.grid().unwrap(), b.grid().unwrap());
    assert_eq!(a.grid.dims, b.grid.dims);
    assert_eq!(a.grid.origin, b.grid.origin);
}

#[test]
fn image_flags_come_first() {
    // Flags that contradict the geometry: H1 is moved by +a although -a joins it to the O.
    let mut m = split_water();
    for (name, v) in [("ix", [0.0, 1.0, 0.0]), ("iy", [0.0; 3]), ("iz", [0.0; 3])] {
        m.scalars.push((name.into(), v.to_vec()));
    }
    let s = Scene::build(Isa::Scalar, &m, &settings(true, false, true)).unwrap();
    let u = s.unwrap.unwrap();
    assert_eq!(u.method, UnwrapMethod::ImageFlags);
    assert_eq!(s.model.as_ref().unwrap().geometry.balls.x[1], 9.8f32 + 10.0);
    // The O–H1 bond now spans 19.5 Å: crossing, so left out without --pbc.
    assert_eq!((u.crossing, s.bonds.clone()), (1, vec![[0, 2]]));
    assert!(s.stage_report()[0].contains("image flags"));
}

#[test]
fn a_chain_bonded_to_its_own_image_keeps_one_crossing_bond() {
    // Carbons 1.5 Å apart along x in a 4.5 Å box: 0-1, 1-2 and 2-0 through the boundary.
    let cell = Some(Cell::orthogonal([0.0; 3], [4.5, 10.0, 10.0]));
    let m = molecule(
        &[
            (6, [0.75, 5.0, 5.0]),
            (6, [2.25, 5.0, 5.0]),
            (6, [3.75, 5.0, 5.0]),
        ],
        cell,
    );
    let s = Scene::build(Isa::Scalar, &m, &settings(true, false, true)).unwrap();
    let u = s.unwrap.unwrap();
    // BFS from atom 0: atom 1 stays at 2.25, atom 2 goes to -0.75; 1-2 (3 Å) still crosses.
    assert_eq!(
        s.model.as_ref().unwrap().geometry.balls.x,
        vec![0.75, 2.25, -0.75]
    );
    assert_eq!((u.crossing, u.crossing_drawn), (1, false));
    assert_eq!(s.bonds, vec![[0, 1], [0, 2]]);
    assert!(s.stage_report()[0].contains("not drawn"));
    // With --pbc it is kept and drawn as two half-sticks: 4 sticks.
    let s = Scene::build(Isa::Scalar, &m, &settings(true, true, true)).unwrap();
    assert_eq!(s.bonds, vec![[0, 1], [0, 2], [1, 2]]);
    assert_eq!(s.model.as_ref().unwrap().geometry.sticks.len(), 4);
    let longest = sticks(s.model.as_ref().unwrap())
        .iter()
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>().sqrt())
        .fold(0.0, f32::max);
    assert!(longest < 1.6, "{longest}");
}

#[test]
fn no_cell_is_an_error_naming_the_cell() {
    let mut m = split_water();
    m.cell = None;
    for model in [true, false] {
        match Scene::build(Isa::Scalar, &m, &settings(true, false, model)) {
            Err(e @ SceneError::Unwrap(_)) => {
                let msg = e.to_string();
                assert!(msg.contains("--unwrap") && msg.contains("cell"), "{msg}");
            }
            other => panic!("expected an unwrap error, got {other:?}"),
        }
    }
}

#[test]
fn rebuild_unwraps_every_frame_and_the_estimate_counts_the_copy() {
    let st = settings(true, false, true);
    let mut s = Scene::build(Isa::Scalar, &whole_water(), &st).unwrap();
    s.rebuild(Isa::Scalar, &split_water()).unwrap();
    let want = Scene::build(Isa::Scalar, &whole_water(), &settings(false, false, true)).unwrap();
    assert_same_model(&s, &want);
    let m = split_water();
    let with = MemoryEstimate::new(&m, 2, &st).unwrap();
    let without = MemoryEstimate::new(&m, 2, &settings(false, false, true)).unwrap();
    assert_eq!(with.atoms, 2 * without.atoms);
    // BondSettings::prepare (what `info` uses) agrees with the scene.
    let p = st.bonds.prepare(&m, false).unwrap();
    assert_eq!(p.bonds, want.bonds);
    assert_eq!(p.unwrapped.unwrap().x, whole_water().x);
}
