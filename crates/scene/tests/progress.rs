//! Scene::build_with's progress: every stage that starts is announced with its units of work,
//! and its counter ends exactly there (so a bar reaches 100 % and never passes it), for both
//! volume formats and with unwrapping; the scene is the same as without progress. A build
//! whose cancel test turns true stops at the next stage, slab pass, chunk of the bond search
//! or piece of the BVH with `Cancelled`.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

mod common;

use molecule::scenes::{generate, SceneName};
use molecule::Cell;
use scene::{BondSettings, ModelSettings, Progress, Scene, SceneError, SceneSettings, Stage};
use spmd::Isa;
use volume::VolumeFormat;

/// Builds `st` over `m` and returns each stage with its announced units and the units it
/// counted (read as the next stage is announced, before the count is reset, or at the end).
fn stages(m: &molecule::Molecule, st: &SceneSettings) -> (Scene, Vec<(Stage, u64, u64)>) {
    with_stages(|p| Scene::build_with(Isa::Scalar, m, st, p).unwrap())
}

/// Runs `work` with a progress that records each stage, its units and the units counted.
fn with_stages<T>(work: impl FnOnce(&Progress) -> T) -> (T, Vec<(Stage, u64, u64)>) {
    let done = Arc::new(AtomicU64::new(0));
    let seen: Mutex<Vec<(Stage, u64, u64)>> = Mutex::new(Vec::new());
    let stage = |s: Stage, units: u64| {
        let mut v = seen.lock().unwrap();
        if let Some(last) = v.last_mut() {
            last.2 = done.load(Ordering::Relaxed);
        }
        v.push((s, units, 0));
    };
    let progress = Progress::new(&stage, done.clone());
    let out = work(&progress);
    let mut v = seen.into_inner().unwrap();
    if let Some(last) = v.last_mut() {
        last.2 = done.load(Ordering::Relaxed);
    }
    (out, v)
}

fn settings(format: VolumeFormat, unwrap: bool) -> SceneSettings {
    SceneSettings {
        model: Some(ModelSettings::default()),
        bonds: BondSettings {
            unwrap,
            ..BondSettings::default()
        },
        volume: Some(common::lit_volume(format)),
        budget_bytes: Some(u64::MAX),
        ..SceneSettings::default()
    }
}

#[test]
fn every_stage_counts_up_to_its_announced_units() {
    let m = generate(SceneName::Nanobowl, Some(3000), 1);
    for format in [VolumeFormat::U8, VolumeFormat::F32] {
        let st = settings(format, false);
        let (scene, v) = stages(&m, &st);
        let names: Vec<Stage> = v.iter().map(|s| s.0).collect();
        assert_eq!(
            names,
            [
                Stage::Bonds,
                Stage::Model,
                Stage::Volume,
                Stage::Macrocells,
                Stage::LightVolume
            ]
        );
        for &(s, units, counted) in &v {
            assert!(units > 0, "{s}: no units announced");
            assert_eq!(
                counted, units,
                "{s} ({format:?}): counted {counted} of {units}"
            );
        }
        // The announced units are the work itself: atoms, primitives, z-planes.
        assert_eq!(v[0].1, m.len() as u64);
        let md = scene.model.as_ref().unwrap();
        assert_eq!(v[1].1, md.bvh.stats.prims as u64);
        let lv = scene.light_volume.as_ref().unwrap();
        assert_eq!(v[4].1, lv.grid.dims[2] as u64);
        // Reporting changes nothing: the same scene as a plain build.
        let plain = Scene::build(Isa::Scalar, &m, &st).unwrap();
        assert_eq!(plain.bonds, scene.bonds);
        assert_eq!(plain.model.unwrap().bvh.nodes, md.bvh.nodes);
        let plain_volume = plain.volume.unwrap();
        let (a, b) = (
            plain_volume.density.grid().unwrap(),
            scene.volume.as_ref().unwrap().density.grid().unwrap(),
        );
        assert_eq!(a.data, b.data);
    }
}

#[test]
fn unwrapping_counts_the_bond_search_once() {
    // In a periodic box around the atoms, unwrapping searches bonds with the minimum image.
    let mut m = generate(SceneName::Ns90k, Some(4000), 1);
    let (lo, hi) = m.bounds();
    m.cell = Some(Cell::orthogonal(lo, hi.map(|v| v + 1.0)));
    let st = SceneSettings {
        volume: None,
        ..settings(VolumeFormat::U8, true)
    };
    let (_, v) = stages(&m, &st);
    assert_eq!(v[0], (Stage::Bonds, m.len() as u64, m.len() as u64));
    assert_eq!(v[1].0, Stage::Model);
    assert_eq!(v[1].1, v[1].2);
}

#[test]
fn loading_counts_the_file_bytes_read_and_scanned() {
    let dir = std::env::temp_dir().join(format!("bns_progress_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("three.xyz");
    let m = generate(SceneName::Nanobowl, Some(500), 1);
    let mut text = Vec::new();
    for k in 0..3 {
        molecule::write::write_xyz(&mut text, &m, &format!("frame {k}")).unwrap();
    }
    std::fs::write(&path, &text).unwrap();
    let input = scene::Input::File {
        path: path.clone(),
        options: Default::default(),
    };
    let bytes = text.len() as u64;
    let (l, v) = with_stages(|p| input.load(-1, true, p).unwrap());
    assert_eq!(l.frames, Some(3));
    assert_eq!(l.molecule.len(), m.len());
    // The count scans the whole file, exactly its bytes; the read then seeks to the last
    // frame and reads it, never more than the file.
    assert_eq!(v[0], (Stage::CountFrames, bytes, bytes));
    assert_eq!(v[1].0, Stage::Read);
    assert_eq!(v[1].1, bytes);
    assert!(v[1].2 > 0 && v[1].2 <= bytes / 2, "{v:?}");
    let (_, v) = with_stages(|p| input.load(1, false, p).unwrap());
    assert_eq!(v.len(), 1);
    assert!(v[0].2 > bytes / 2 && v[0].2 <= bytes, "{v:?}");
    let builtin = scene::Input::Builtin {
        name: SceneName::Nanobowl,
        atoms: Some(100),
        seed: 1,
    };
    let (l, v) = with_stages(|p| builtin.load(0, true, p).unwrap());
    assert_eq!((l.frames, v), (Some(1), vec![(Stage::Generate, 1, 0)]));
    let e = builtin.load(1, false, &Progress::none()).unwrap_err();
    assert!(e.to_string().contains("single frame"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Builds `st` over `m` with the cancel test `stop(stage announced last, units done)` and
/// returns the outcome, the stages announced and the units done when it returned.
fn build_until(
    m: &molecule::Molecule,
    st: &SceneSettings,
    stop: impl Fn(Option<Stage>, u64) -> bool + Sync,
) -> (Result<Scene, SceneError>, Vec<Stage>, u64) {
    let done = Arc::new(AtomicU64::new(0));
    let seen: Mutex<Vec<Stage>> = Mutex::new(Vec::new());
    let stage = |s: Stage, _| seen.lock().unwrap().push(s);
    let cancelled = || {
        stop(
            seen.lock().unwrap().last().copied(),
            done.load(Ordering::Relaxed),
        )
    };
    let progress = Progress {
        cancelled: &cancelled,
        ..Progress::new(&stage, done.clone())
    };
    let out = Scene::build_with(Isa::Scalar, m, st, &progress);
    let counted = done.load(Ordering::Relaxed);
    (out, seen.into_inner().unwrap(), counted)
}

#[test]
fn a_cancelled_build_stops_at_the_next_stage() {
    let m = generate(SceneName::Nanobowl, Some(3000), 1);
    let st = settings(VolumeFormat::U8, false);
    // Cancelled before it starts: nothing is announced.
    let (r, seen, _) = build_until(&m, &st, |_, _| true);
    assert!(matches!(r, Err(SceneError::Cancelled)), "{:?}", r.err());
    assert!(seen.is_empty(), "{seen:?}");
    // Cancelled once the BVH has started: the volume never starts.
    let (r, seen, _) = build_until(&m, &st, |s, _| s == Some(Stage::Model));
    assert!(matches!(r, Err(SceneError::Cancelled)), "{:?}", r.err());
    assert_eq!(seen, [Stage::Bonds, Stage::Model]);
    let e = r.err().unwrap().to_string();
    assert!(e.contains("cancelled"), "{e}");
    // Never cancelled: every stage, and a scene.
    let (r, seen, _) = build_until(&m, &st, |_, _| false);
    assert!(r.is_ok());
    assert_eq!(seen.len(), 5, "{seen:?}");
}

#[test]
fn a_build_cancelled_inside_the_bond_search_or_the_bvh_skips_the_rest_of_it() {
    // 30K atoms: 8 chunks of the bond search; ~75K primitives, a clustered BVH.
    let m = generate(SceneName::Ns90k, Some(30_000), 1);
    let st = SceneSettings {
        volume: None,
        ..settings(VolumeFormat::U8, false)
    };
    let prims = Scene::build(Isa::Scalar, &m, &st)
        .unwrap()
        .model
        .unwrap()
        .bvh
        .stats
        .prims as u64;
    assert!(prims as usize > bvh::CLUSTER_ABOVE, "{prims}");
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    // Cancelled as soon as the stage has finished some work: on one thread it stops
    // after that piece (a chunk of 4096 atoms; a group of clusters), not at the stage's end.
    for (stage, total) in [(Stage::Bonds, m.len() as u64), (Stage::Model, prims)] {
        let stop = |s: Option<Stage>, done: u64| s == Some(stage) && done >= 1;
        let (r, seen, counted) = one.install(|| build_until(&m, &st, stop));
        assert!(matches!(r, Err(SceneError::Cancelled)), "{:?}", r.err());
        assert_eq!(seen.last(), Some(&stage));
        assert!(
            counted >= 1 && counted <= total / 4,
            "{stage}: {counted} of {total}"
        );
    }
}

#[test]
fn a_build_cancelled_inside_the_density_skips_its_remaining_slab_passes() {
    let m = generate(SceneName::Nanobowl, Some(3000), 1);
    for format in [VolumeFormat::U8, VolumeFormat::F32] {
        let st = settings(format, false);
        let units = Scene::build(Isa::Scalar, &m, &st)
            .unwrap()
            .estimate
            .volume_dims
            .map(|d| volume::density_work(d, format))
            .unwrap();
        let stop = |s: Option<Stage>, done: u64| s == Some(Stage::Volume) && done >= 1;
        // Cancelled as soon as one slab pass of the density is done: on one thread, no
        // other slab pass runs.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let (r, seen, counted) = one.install(|| build_until(&m, &st, stop));
        assert!(matches!(r, Err(SceneError::Cancelled)), "{:?}", r.err());
        assert_eq!(seen.last(), Some(&Stage::Volume), "{format:?}");
        assert!(units > 2, "{format:?}: {units}");
        assert_eq!(counted, 1, "{format:?}: {counted} of {units} slab passes");
        // On every thread, those in flight finish; for u8, which takes two passes over the
        // slabs (the maximum, then the values), the second never starts.
        let (r, _, counted) = build_until(&m, &st, stop);
        assert!(matches!(r, Err(SceneError::Cancelled)), "{:?}", r.err());
        if format == VolumeFormat::U8 {
            assert!(
                counted <= units / 2,
                "{format:?}: {counted} of {units} slab passes"
            );
        }
    }
}
