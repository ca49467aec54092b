//! The peak term of the memory estimate (issue #20): `MemoryEstimate::peak_bytes` models
//! the worst moment of a `render` process, not just the scene at rest, and is the figure
//! the budget check uses. Measured peaks are in BENCHMARKS.md; no timing or RSS here.

use molecule::scenes::{generate, SceneName};
use scene::{
    retained_bytes, BondSettings, BondSource, MemoryEstimate, ModelSettings, PeakPhase, Scene,
    SceneError, SceneSettings, Style, VolumeSettings, BASELINE_BYTES, BVH_NODES_PER_PRIM,
};
use spmd::Isa;

fn model_only(style: Style, bonds: BondSource) -> SceneSettings {
    SceneSettings {
        model: Some(ModelSettings {
            style,
            ..ModelSettings::default()
        }),
        bonds: BondSettings {
            source: bonds,
            ..BondSettings::default()
        },
        budget_bytes: Some(u64::MAX),
        frame: Some((64, 48)),
        ..SceneSettings::default()
    }
}

/// Spheres without bonds: the peak by hand. The BVH build holds nothing beyond the scene at
/// rest (records written over the builder's references, the model's scaled radii and colours
/// moved into the balls), so the peak is the frame: the molecule (13 B/atom), the scene's
/// radius and colour scratch (8), the balls (20) and slot colours (8), the BVH (32 B/node, 36
/// B/primitive) and the framebuffer; then the allocator's retention of the freed per-subtree
/// node arrays (32 B/node) and the baseline.
#[test]
fn peak_of_spheres_by_hand() {
    let m = generate(SceneName::Nanobowl, Some(3000), 1);
    let n = m.len() as u64;
    let st = model_only(Style::Spheres, BondSource::None);
    let e = MemoryEstimate::new(&m, 0, &st).unwrap();
    let nodes = (n as f64 * BVH_NODES_PER_PRIM).ceil() as u64;
    let live = 13 * n + 8 * n + (20 * n + 8 * n) + (32 * nodes + 36 * n) + 64 * 48 * 4;
    assert_eq!(e.peak.phase, PeakPhase::Frame);
    assert_eq!(e.peak.live, live);
    assert_eq!(e.peak.retained, retained_bytes(n));
    assert_eq!(e.peak.retained, 32 * nodes);
    assert_eq!(e.peak.baseline, BASELINE_BYTES);
    assert_eq!(e.peak_bytes(), live + retained_bytes(n) + BASELINE_BYTES);
    assert_eq!(e.total(), live);
}

/// Spheres above `bvh::CLUSTER_ABOVE` primitives: the clustered build holds a second copy of
/// the nodes and 4 B per primitive beside the model, more than the frame adds, so its phase
/// is the peak; the same scene below the threshold peaks at the frame.
#[test]
fn peak_of_the_clustered_build_by_hand() {
    let n_big = bvh::CLUSTER_ABOVE as u64 + 1000;
    let m = generate(SceneName::Nanobowl, Some(n_big as usize), 1);
    let n = m.len() as u64;
    assert!(n > bvh::CLUSTER_ABOVE as u64, "{n} atoms");
    let st = model_only(Style::Spheres, BondSource::None);
    let e = MemoryEstimate::new(&m, 0, &st).unwrap();
    let nodes = (n as f64 * BVH_NODES_PER_PRIM).ceil() as u64;
    let rest = 13 * n + 8 * n + (20 * n + 8 * n) + (32 * nodes + 36 * n);
    assert_eq!(e.peak.phase, PeakPhase::BvhBuild);
    assert_eq!(e.peak.live, rest + 32 * nodes + 4 * n);
    assert_eq!(e.total(), rest + 64 * 48 * 4);
    let small = generate(SceneName::Nanobowl, Some(3000), 1);
    let e = MemoryEstimate::new(&small, 0, &st).unwrap();
    assert_eq!(e.peak.phase, PeakPhase::Frame);
}

/// The peak is above the scene at rest, and above what the built scene measures, for every
/// kind of scene: dropping the peak term (or a phase of it) fails here.
#[test]
fn peak_exceeds_the_components_of_built_scenes() {
    let m = generate(SceneName::Ns90k, Some(20_000), 1);
    let volume = Some(VolumeSettings {
        voxels_per_angstrom: 2.0,
        ..VolumeSettings::default()
    });
    let cases = [
        (
            model_only(Style::BallAndStick, BondSource::Auto),
            PeakPhase::Frame,
        ),
        (
            SceneSettings {
                model: None,
                volume: volume.clone(),
                ..model_only(Style::BallAndStick, BondSource::Auto)
            },
            PeakPhase::Volume,
        ),
        (
            SceneSettings {
                volume,
                ..model_only(Style::Licorice, BondSource::Auto)
            },
            PeakPhase::Volume,
        ),
    ];
    for (st, phase) in cases {
        let s = Scene::build(Isa::Scalar, &m, &st).unwrap();
        let e = MemoryEstimate::new(&m, s.bonds.len(), &st).unwrap();
        let real = MemoryEstimate::measured(&s, &m);
        assert_eq!(e.peak.phase, phase, "{st:?}");
        assert!(e.peak.live >= e.total(), "{st:?}: {e:?}");
        assert!(e.peak_bytes() >= e.total() + BASELINE_BYTES, "{st:?}");
        assert!(e.peak_bytes() > real.total(), "{st:?}");
        // A model build leaves its freed node arrays with the allocator: as many bytes as
        // the built tree's nodes, within the estimate's node count.
        if st.model.is_some() {
            let bvh = &s.model.as_ref().unwrap().bvh;
            let built = 32 * bvh.nodes.len() as u64;
            assert!(
                e.peak.retained.abs_diff(built) * 5 < built,
                "{e:?} vs {built}"
            );
        }
        assert_eq!(real.peak, Default::default());
    }
}

/// The budget check uses the peak: a budget between the scene at rest and its peak (less
/// what is resident before the check) is refused.
#[test]
fn budget_check_uses_the_peak() {
    let m = generate(SceneName::Nanobowl, Some(5000), 1);
    let st = model_only(Style::BallAndStick, BondSource::Auto);
    let bonds = st.bonds.build(&m).unwrap();
    let e = MemoryEstimate::new(&m, bonds.len(), &st).unwrap();
    let resident = e.peak.baseline + e.atoms + bonds.len() as u64 * 8;
    let needed = e.peak_bytes() - resident;
    assert!(needed > e.total() - e.atoms - e.bonds);
    let tight = SceneSettings {
        budget_bytes: Some(needed - 1),
        ..st.clone()
    };
    match Scene::build(Isa::Scalar, &m, &tight) {
        Err(SceneError::TooLarge { needed: n, .. }) => assert_eq!(n, needed),
        other => panic!("expected TooLarge, got {other:?}"),
    }
    let enough = SceneSettings {
        budget_bytes: Some(needed),
        ..st
    };
    assert!(Scene::build(Isa::Scalar, &m, &enough).is_ok());
}

#[test]
fn retention_is_the_node_arrays_and_zero_without_primitives() {
    assert_eq!(retained_bytes(0), 0);
    let nodes = (1_000_000f64 * BVH_NODES_PER_PRIM).ceil() as u64;
    assert_eq!(retained_bytes(1_000_000), 32 * nodes);
}
