//! Packet, single-ray and wide-BVH traversal against brute force, on every backend.

use bvh::scenes::{random_molecule, test_rays};
use bvh::{Bvh, Geometry, Ray, WideBvh};
use spmd::Isa;

/// Both builders (per primitive, and over Morton clusters as big scenes get by default), every
/// backend: packets, single rays and the wide tree against brute force.
fn compare(g: &Geometry, nrays: usize, seed: u64) {
    for cluster_above in [usize::MAX, 0] {
        let opt = bvh::BuildOptions {
            cluster_above,
            ..Default::default()
        };
        compare_tree(g, &Bvh::build_with(g, &opt), nrays, seed);
    }
}

fn compare_tree(g: &Geometry, bvh: &Bvh, nrays: usize, seed: u64) {
    bvh.validate(g).unwrap();
    let rays = test_rays(g, &bvh.bounds, nrays, seed);
    let reference = bvh.intersect_rays_brute(Isa::Scalar, &rays);
    let nhit = reference.iter().filter(|h| h.is_some()).count();
    assert!(nhit > nrays / 10, "test scene too sparse: {nhit} hits");
    for isa in Isa::supported() {
        let got = bvh.intersect_rays(isa, &rays);
        let brute = bvh.intersect_rays_brute(isa, &rays);
        for (i, ((r, a), b)) in reference.iter().zip(&got).zip(&brute).enumerate() {
            // Same backend, brute force vs BVH: identical (same kernel, same arithmetic).
            // Ties (capsules of two bonds share a cap sphere) may pick either primitive.
            assert_eq!(a.map(|h| h.t), b.map(|h| h.t), "{isa} ray {i}");
            // Across backends: identical too (the kernels use no fma).
            match (r, a) {
                (None, None) => {}
                (Some(r), Some(a)) => {
                    assert!(
                        (r.t - a.t).abs() <= 1e-5 * r.t.abs().max(1.0),
                        "{isa} ray {i}: t {} vs {}",
                        a.t,
                        r.t
                    );
                    let tie = bvh.intersect_rays(
                        Isa::Scalar,
                        &[Ray {
                            tmax: a.t * (1.0 + 1e-5),
                            ..rays[i]
                        }],
                    );
                    assert!(
                        r.prim == a.prim || tie[0].is_some(),
                        "{isa} ray {i}: prim {} vs {}",
                        a.prim,
                        r.prim
                    );
                }
                _ => panic!("{isa} ray {i}: {a:?} vs reference {r:?}"),
            }
        }
        // Single-ray traversal agrees too.
        for (i, r) in rays.iter().enumerate().step_by(7) {
            assert_eq!(
                bvh.intersect_ray(r).map(|h| h.t),
                reference[i].map(|h| h.t),
                "single ray {i}"
            );
        }
        check_wide(g, bvh, &rays, &reference, isa);
    }
}

/// The wide BVH finds the brute-force nearest hit (same leaf kernel, so the same `t` bit for
/// bit; ties may pick the other primitive) and reports occlusion exactly where it hits.
fn check_wide(g: &Geometry, bvh: &Bvh, rays: &[Ray], reference: &[Option<bvh::Hit>], isa: Isa) {
    let wide = WideBvh::new(bvh);
    wide.validate(bvh, g).unwrap();
    let got = wide.intersect_rays(isa, bvh, rays);
    let occ = wide.occluded_rays(isa, bvh, rays);
    for (i, (r, (t, slot))) in reference.iter().zip(&got).enumerate() {
        match r {
            None => {
                assert_eq!(
                    *slot, -1,
                    "{isa} wide ray {i}: hit at {t}, brute force misses"
                );
                assert_eq!(t.to_bits(), rays[i].tmax.to_bits(), "{isa} wide ray {i}");
            }
            Some(h) => {
                assert!(
                    *slot >= 0,
                    "{isa} wide ray {i}: miss, brute force hits at {}",
                    h.t
                );
                assert_eq!(*t, h.t, "{isa} wide ray {i}");
            }
        }
        assert_eq!(
            occ[i].1 == 1,
            r.is_some(),
            "{isa} wide occlusion of ray {i}"
        );
    }
}

#[test]
fn wide_tree_of_tiny_and_one_leaf_scenes() {
    for n in [1usize, 2, 5, 9, 40] {
        let g = random_molecule(n, true, 20 + n as u64);
        let bvh = Bvh::build(&g);
        let rays = test_rays(&g, &bvh.bounds, 500, n as u64);
        let reference = bvh.intersect_rays_brute(Isa::Scalar, &rays);
        for isa in Isa::supported() {
            check_wide(&g, &bvh, &rays, &reference, isa);
        }
    }
    // Empty geometry: an empty tree that misses everything.
    let g = Geometry::from_atoms(&[], &[], &[], &[], &[], &[], 0.15);
    let bvh = Bvh::build(&g);
    let wide = WideBvh::new(&bvh);
    wide.validate(&bvh, &g).unwrap();
    let r = Ray::new([0.0; 3], [0.0, 0.0, 1.0]);
    assert_eq!(wide.intersect_rays(Isa::Scalar, &bvh, &[r])[0].1, -1);
}

/// The SAH collapse fills the wide nodes: at most one per five binary leaves (a full tree
/// has one per seven; the greedy collapse made one per 2.4 on a balanced crystal), also in a
/// degenerate scene (every atom at one point, zero-area boxes: 65 nodes, 58 if all full).
#[test]
fn wide_nodes_are_well_filled() {
    let check_filled = |g: &Geometry, label: &str| {
        let bvh = Bvh::build(g);
        let wide = WideBvh::new(&bvh);
        wide.validate(&bvh, g).unwrap();
        let per_leaf = wide.nodes.len() as f64 / bvh.stats.leaves as f64;
        assert!(per_leaf < 0.2, "{label}: {per_leaf:.3} wide nodes per leaf");
    };
    for (n, seed) in [(20_000usize, 31u64), (3_000, 32)] {
        check_filled(&random_molecule(n, true, seed), &format!("{n} atoms"));
    }
    let (x, y, z) = ([1.0f32; 500], [2.0f32; 500], [3.0f32; 500]);
    let one_point = Geometry::from_atoms(&x, &y, &z, &[0.0; 500], &[0; 500], &[], 0.15);
    check_filled(&one_point, "one point");
}

#[test]
fn packets_match_brute_force_balls_and_sticks() {
    compare(&random_molecule(3_000, false, 11), 4_000, 5);
    compare(&random_molecule(3_000, true, 12), 4_000, 6);
}

#[test]
fn packets_match_brute_force_licorice() {
    let mut g = random_molecule(2_000, true, 13);
    g.show_balls = false;
    g.capped = true;
    compare(&g, 3_000, 7);
    g.capped = false;
    compare(&g, 3_000, 8);
}

#[test]
fn nan_and_inf_rays_do_not_panic() {
    let g = random_molecule(500, false, 14);
    let bvh = Bvh::build(&g);
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 1e38];
    let mut rays = Vec::new();
    for &a in &bad {
        for &b in &bad {
            rays.push(Ray {
                o: [a, 1.0, b],
                d: [0.0, 0.0, 1.0],
                tmin: 0.0,
                tmax: f32::INFINITY,
            });
            rays.push(Ray {
                o: [1.0, 2.0, 3.0],
                d: [a, b, 0.5],
                tmin: 0.0,
                tmax: f32::INFINITY,
            });
            rays.push(Ray {
                o: [1.0, 2.0, 3.0],
                d: [0.0, 0.0, 1.0],
                tmin: a,
                tmax: b,
            });
        }
    }
    let wide = WideBvh::new(&bvh);
    for isa in Isa::supported() {
        let _ = bvh.intersect_rays(isa, &rays);
        let _ = wide.intersect_rays(isa, &bvh, &rays);
        let _ = wide.occluded_rays(isa, &bvh, &rays);
    }
}
