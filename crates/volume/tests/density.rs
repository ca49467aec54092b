//! Density grid against a double-precision brute-force sum, u8 quantisation bound, backend
//! agreement, determinism, memory refusal and macrocell ranges.

mod common;

use common::*;
use spmd::Isa;
use volume::*;

fn params(vpa: f32, format: VolumeFormat) -> DensityParams {
    DensityParams {
        voxels_per_angstrom: vpa,
        format,
        budget_bytes: Some(1 << 32),
    }
}

fn build(isa: Isa, a: &Atoms, p: &DensityParams) -> Volume {
    build_density(isa, &a.x, &a.y, &a.z, &a.r, p, None).unwrap()
}

/// Tolerance of the f32 grid against the f64 sum: 2e-6 absolute + 1e-5 relative (f32 exp is
/// within 2e-7 relative, the sum of a few dozen terms adds a few ulp).
fn tol(reference: f64) -> f64 {
    2e-6 + 1e-5 * reference.abs()
}

#[test]
fn grid_matches_brute_force_at_random_voxels_on_every_backend() {
    let a = random_atoms(400, 14.0, 7);
    for isa in Isa::supported() {
        let v = build(isa, &a, &params(4.0, VolumeFormat::F32));
        let g = v.grid;
        let mut rng = Rng(99);
        let (mut checked, mut nonzero) = (0, 0);
        while checked < 3000 {
            let i = (rng.next_u64() % g.dims[0] as u64) as usize;
            let j = (rng.next_u64() % g.dims[1] as u64) as usize;
            let k = (rng.next_u64() % g.dims[2] as u64) as usize;
            let p = g.point(i, j, k).map(|c| c as f64);
            if near_cutoff(&a, p) {
                continue;
            }
            let want = phi(&a, p);
            let got = v.get(i, j, k) as f64;
            assert!(
                (got - want).abs() <= tol(want),
                "{isa}: voxel ({i},{j},{k}) = {got}, brute force {want}"
            );
            checked += 1;
            nonzero += (want > 0.0) as usize;
        }
        assert!(
            nonzero > 1000,
            "test must exercise occupied voxels ({nonzero})"
        );
    }
}

#[test]
fn every_voxel_near_atoms_matches_brute_force() {
    // Exhaustive on a small set: every lattice point, including grid borders.
    let a = random_atoms(12, 5.0, 3);
    let v = build(Isa::detect(), &a, &params(5.0, VolumeFormat::F32));
    let g = v.grid;
    for k in 0..g.dims[2] {
        for j in 0..g.dims[1] {
            for i in 0..g.dims[0] {
                let p = g.point(i, j, k).map(|c| c as f64);
                if near_cutoff(&a, p) {
                    continue;
                }
                let want = phi(&a, p);
                let got = v.get(i, j, k) as f64;
                assert!(
                    (got - want).abs() <= tol(want),
                    "({i},{j},{k}): {got} vs {want}"
                );
            }
        }
    }
    // Padded: the boundary planes are empty.
    for j in 0..g.dims[1] {
        for i in 0..g.dims[0] {
            assert_eq!(v.get(i, j, 0), 0.0);
            assert_eq!(v.get(i, j, g.dims[2] - 1), 0.0);
        }
    }
}

#[test]
fn backends_agree_with_scalar() {
    let a = random_atoms(300, 12.0, 11);
    let p = params(4.0, VolumeFormat::F32);
    let reference = build(Isa::Scalar, &a, &p);
    let VolumeData::F32(rv) = &reference.data else {
        unreachable!()
    };
    for isa in Isa::supported() {
        let v = build(isa, &a, &p);
        assert_eq!(v.grid, reference.grid);
        let VolumeData::F32(vv) = &v.data else {
            unreachable!()
        };
        let worst = rv
            .iter()
            .zip(vv)
            .map(|(x, y)| (x - y).abs() / (1.0 + x.abs()))
            .fold(0.0f32, f32::max);
        assert!(
            worst <= 1e-6,
            "{isa}: max relative difference {worst} from scalar"
        );
    }
}

#[test]
fn u8_error_within_half_a_quantisation_step() {
    let a = random_atoms(300, 12.0, 5);
    for isa in Isa::supported() {
        let f = build(isa, &a, &params(4.0, VolumeFormat::F32));
        let q = build(isa, &a, &params(4.0, VolumeFormat::U8));
        let scale = q.scale().unwrap();
        assert_eq!(q.max_value, f.max_value);
        assert!((scale - f.max_value / 255.0).abs() <= 1e-6 * scale);
        let VolumeData::F32(fv) = &f.data else {
            unreachable!()
        };
        let VolumeData::U8 { data, .. } = &q.data else {
            unreachable!()
        };
        assert_eq!(data.len(), fv.len() + 4);
        let mut distinct = [false; 256];
        for (x, &b) in fv.iter().zip(data.iter()) {
            let err = (b as f32 * scale - x).abs();
            assert!(
                err <= 0.5 * scale * (1.0 + 1e-5),
                "{isa}: {x} stored as {b}: error {err}, step {scale}"
            );
            distinct[b as usize] = true;
        }
        assert!(distinct.iter().filter(|d| **d).count() > 200);
        assert_eq!(data.iter().copied().max(), Some(255));
    }
}

#[test]
fn build_is_deterministic_across_thread_counts() {
    let a = random_atoms(500, 15.0, 21);
    let p = params(4.0, VolumeFormat::F32);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| build(Isa::detect(), &a, &p))
    };
    let (one, two) = (run(1), run(3));
    let (VolumeData::F32(x), VolumeData::F32(y)) = (&one.data, &two.data) else {
        unreachable!()
    };
    assert!(x.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits()));
}

#[test]
fn refuses_over_budget_with_a_resolution_that_fits() {
    let a = shell(30.0);
    let mut p = params(4.0, VolumeFormat::F32);
    let grid = Grid::for_atoms(&a.x, &a.y, &a.z, &a.r, 4.0).unwrap();
    let need = estimate_bytes(&grid, VolumeFormat::F32);
    assert!(need >= grid.voxel_count() * 4);
    p.budget_bytes = Some(need / 10);
    let err = build_density(Isa::Scalar, &a.x, &a.y, &a.z, &a.r, &p, None).unwrap_err();
    let msg = err.to_string();
    let VolumeError::TooLarge {
        suggested_voxels_per_angstrom: s,
        ..
    } = err
    else {
        panic!("expected TooLarge, got {err:?}")
    };
    assert!(
        msg.contains("--voxels-per-angstrom") && msg.contains("MB"),
        "{msg}"
    );
    assert!(s > 0.0 && s < 4.0, "suggested {s}");
    let g2 = Grid::for_atoms(&a.x, &a.y, &a.z, &a.r, s).unwrap();
    assert!(estimate_bytes(&g2, VolumeFormat::F32) <= need / 10);
    p.voxels_per_angstrom = s;
    assert!(build_density(Isa::Scalar, &a.x, &a.y, &a.z, &a.r, &p, None).is_ok());
}

/// Resolutions and extents whose lattice does not fit 2³¹ points, up to past `usize`
/// (which once wrapped to a 2-point axis and built a silently empty grid): refused, with a
/// suggested resolution that itself fits (checked by building at it where that is cheap).
#[test]
fn refuses_lattices_past_the_index_limit_whatever_their_size() {
    let (x, y, z, r) = ([0.0f32, 3.0], [0.0f32, 1.0], [0.0f32, -2.0], [1.0f32, 0.7]);
    for vpa in [2e3f32, 1e9, 1e30, f32::MAX] {
        let mut p = params(vpa, VolumeFormat::U8);
        p.budget_bytes = Some(u64::MAX);
        let err = build_density(Isa::Scalar, &x, &y, &z, &r, &p, None).unwrap_err();
        let VolumeError::TooLarge {
            suggested_voxels_per_angstrom: s,
            index_limit: true,
            ..
        } = err
        else {
            panic!("{vpa} voxels/Å: expected TooLarge at the index limit, got {err:?}")
        };
        assert!(s > 1.0 && s < 2e3, "{vpa} voxels/Å: suggested {s}");
        p.voxels_per_angstrom = s;
        let v = build_density(Isa::Scalar, &x, &y, &z, &r, &p, None).unwrap();
        assert!(v.grid.voxel_count() < 1 << 31 && v.max_value > 0.0);
    }
    // Atoms 10³⁸ Å apart: no lattice of any use; refused, suggesting a (tiny) resolution.
    let p = params(4.0, VolumeFormat::U8);
    let err = build_density(
        Isa::Scalar,
        &[0.0, 1e38],
        &[0.0; 2],
        &[0.0; 2],
        &[1.0; 2],
        &p,
        None,
    )
    .unwrap_err();
    assert!(
        matches!(err, VolumeError::TooLarge { suggested_voxels_per_angstrom: s, .. } if s > 0.0 && s < 1e-9),
        "{err:?}"
    );
    assert!(
        Grid::for_atoms(&[0.0, 1e38], &[0.0; 2], &[0.0; 2], &[1.0; 2], 4.0)
            .unwrap()
            .voxel_count()
            >= 1 << 31
    );
}

#[test]
fn rejects_bad_input() {
    let p = params(4.0, VolumeFormat::F32);
    let e = |x: &[f32], r: &[f32]| {
        build_density(Isa::Scalar, x, &[0.0], &[0.0], r, &p, None).unwrap_err()
    };
    assert!(matches!(
        e(&[0.0, 1.0], &[1.0]),
        VolumeError::LengthMismatch { .. }
    ));
    assert!(matches!(
        e(&[f32::NAN], &[1.0]),
        VolumeError::NonFinite { atom: 0 }
    ));
    assert!(matches!(
        e(&[0.0], &[0.0]),
        VolumeError::BadRadius { atom: 0, .. }
    ));
    assert!(matches!(
        build_density(Isa::Scalar, &[], &[], &[], &[], &p, None),
        Err(VolumeError::NoAtoms)
    ));
    let bad = DensityParams {
        voxels_per_angstrom: 0.0,
        ..p
    };
    assert!(matches!(
        build_density(Isa::Scalar, &[0.0], &[0.0], &[0.0], &[1.0], &bad, None),
        Err(VolumeError::BadResolution(_))
    ));
    assert_eq!("u8".parse::<VolumeFormat>().unwrap(), VolumeFormat::U8);
    assert!("f16".parse::<VolumeFormat>().is_err());
}

#[test]
fn macrocells_hold_min_max_of_the_touched_lattice_points() {
    let a = random_atoms(200, 12.0, 8);
    for format in [VolumeFormat::F32, VolumeFormat::U8] {
        let v = build(Isa::detect(), &a, &params(3.0, format));
        let mc = Macrocells::build(&v);
        let g = v.grid;
        for a in 0..3 {
            assert_eq!(mc.dims[a], (g.dims[a] - 1).div_ceil(MACROCELL));
        }
        for k in 0..mc.dims[2] {
            for j in 0..mc.dims[1] {
                for i in 0..mc.dims[0] {
                    let (mut mn, mut mx) = (f32::INFINITY, f32::NEG_INFINITY);
                    for z in k * 8..=(k * 8 + 8).min(g.dims[2] - 1) {
                        for y in j * 8..=(j * 8 + 8).min(g.dims[1] - 1) {
                            for x in i * 8..=(i * 8 + 8).min(g.dims[0] - 1) {
                                mn = mn.min(v.get(x, y, z));
                                mx = mx.max(v.get(x, y, z));
                            }
                        }
                    }
                    assert_eq!(mc.range(i, j, k), (mn, mx), "{format} cell ({i},{j},{k})");
                }
            }
        }
    }
}
