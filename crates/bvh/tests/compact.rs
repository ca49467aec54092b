//! The compact tree (issue #19) against brute force over its own kernels (the same hits bit
//! for bit, on every backend) and against the reference tree with stored records (the same
//! surfaces: `t` within 1e-4 relative; the stick test has no unit axis, so the last bits
//! differ), with the degenerate cases.

use bvh::compact::{CompactBvh, LEAF};
use bvh::scenes::{random_molecule, test_rays, Rng};
use bvh::{intersect_ball, intersect_bond, load_packet, Bvh, Geometry, PacketHit, Prim, Ray};
use spmd::{Isa, Scalar, Simd};

/// Nearest `(t, prim)` of one ray over every primitive with the compact layout's kernels.
fn brute(c: &CompactBvh, ray: &Ray) -> Option<(f32, Prim)> {
    let s = Scalar;
    let p = load_packet(s, std::slice::from_ref(ray));
    let mut h = PacketHit {
        t: s.select(p.active, p.tmax, f32::NEG_INFINITY),
        slot: std::num::Wrapping(-1),
    };
    let n = c.prim_ids.len() as u32;
    for id in 0..n {
        if id < c.n_balls {
            let q = c.points[id as usize];
            intersect_ball(s, &p, p.active, [q[0], q[1], q[2]], q[3], id as i32, &mut h);
        } else {
            let (x, y) = c.stick_ends((id - c.n_balls) as usize);
            intersect_bond(
                s,
                &p,
                p.active,
                x,
                y,
                c.stick_radius,
                c.capped,
                id as i32,
                &mut h,
            );
        }
    }
    (h.slot.0 >= 0).then(|| {
        let id = h.slot.0 as u32;
        let prim = if id < c.n_balls {
            Prim::Ball(id)
        } else {
            Prim::Stick(id - c.n_balls)
        };
        (h.t, prim)
    })
}

/// Every ray's nearest `t` through the compact tree equals brute force's, and it is occluded
/// exactly where brute force hits, on every backend under test.
fn assert_t_matches_brute(c: &CompactBvh, rays: &[Ray]) {
    let truth: Vec<_> = rays.iter().map(|r| brute(c, r).map(|h| h.0)).collect();
    for isa in Isa::under_test() {
        let got = c.intersect_rays(isa, rays);
        for (i, (a, b)) in got.iter().zip(&truth).enumerate() {
            assert_eq!(a.map(|h| h.0), *b, "{isa} ray {i}");
        }
        let occ = occluded(c, isa, rays);
        for (i, (o, t)) in occ.iter().zip(&truth).enumerate() {
            assert_eq!(*o, t.is_some(), "{isa} ray {i}: occlusion");
        }
    }
}

/// Builds both trees over `g` and compares: compact against brute force on every backend
/// (same `t` bit for bit; ties between primitives may pick either), against the reference
/// tree within 1e-4 relative in `t`, and occlusion against the nearest hit.
fn compare(g: &Geometry, nrays: usize, seed: u64) {
    let bvh = Bvh::build(g);
    bvh.validate(g).unwrap();
    let c = CompactBvh::new(g, &bvh).unwrap();
    c.validate(g).unwrap();
    let rays = test_rays(g, &bvh.bounds, nrays, seed);
    let truth: Vec<_> = rays.iter().map(|r| brute(&c, r)).collect();
    let reference = bvh.intersect_rays(Isa::Scalar, &rays);
    let nhit = truth.iter().filter(|h| h.is_some()).count();
    assert!(nhit > nrays / 10, "test scene too sparse: {nhit} hits");
    let mut far = 0;
    for (t, r) in truth.iter().zip(&reference) {
        match (t, r) {
            (None, None) => {}
            (Some((a, _)), Some(b)) if (a - b.t).abs() <= 1e-4 * b.t.abs().max(1.0) => {}
            _ => far += 1,
        }
    }
    eprintln!("{far} of {nrays} rays ({nhit} hits) beyond 1e-4 of the reference tree");
    // Grazing rays may hit by one kernel and miss by the other.
    assert!(
        far * 1000 <= nrays,
        "{far} of {nrays} rays differ from the reference tree"
    );
    for isa in Isa::under_test() {
        let got = c.intersect_rays(isa, &rays);
        for (i, (a, b)) in got.iter().zip(&truth).enumerate() {
            assert_eq!(a.map(|h| h.0), b.map(|h| h.0), "{isa} ray {i}");
            if let (Some(a), Some(b)) = (a, b) {
                if a.1 != b.1 {
                    // A tie: the other primitive is hit at the same t.
                    let r = Ray {
                        tmax: a.0 * (1.0 + 1e-6),
                        ..rays[i]
                    };
                    assert!(brute(&c, &r).is_some(), "{isa} ray {i}: {a:?} vs {b:?}");
                }
            }
        }
        let occ = occluded(&c, isa, &rays);
        for (i, (o, t)) in occ.iter().zip(&truth).enumerate() {
            assert_eq!(*o, t.is_some(), "{isa} ray {i}: occlusion");
        }
    }
}

/// Occlusion of each ray through the compact tree on backend `isa`.
fn occluded(c: &CompactBvh, isa: Isa, rays: &[Ray]) -> Vec<bool> {
    struct K<'a>(&'a CompactBvh, &'a [Ray]);
    impl spmd::Kernel for K<'_> {
        type Output = Vec<bool>;
        fn run<S: Simd>(self, s: S) -> Vec<bool> {
            let mut stack = vec![(0u32, 0u32); self.0.stack_size()];
            let mut out = Vec::new();
            for chunk in self.1.chunks(S::LANES) {
                let p = load_packet(s, chunk);
                let m = s.bitmask(self.0.occluded_packet(s, &p, &mut stack));
                out.extend((0..chunk.len()).map(|i| m >> i & 1 == 1));
            }
            out
        }
    }
    isa.dispatch(K(c, rays))
}

#[test]
fn compact_matches_brute_force_and_the_reference_tree() {
    for (n, seed) in [(300, 1), (3000, 2), (20_000, 3)] {
        compare(&random_molecule(n, n > 1000, seed), 2000, seed);
    }
}

#[test]
fn compact_licorice_capsules_and_extra_ends() {
    let mut g = random_molecule(2000, true, 4);
    g.show_balls = false;
    g.capped = true;
    // Half-sticks to points that are not atoms, as periodic bonds and cell edges draw.
    for i in 0..50u32 {
        let p = g.balls.center(i as usize);
        let e = g.push_end([p[0] + 1.2, p[1], p[2] + 0.3], 0);
        g.sticks.a.push(i);
        g.sticks.b.push(e);
    }
    compare(&g, 2000, 5);
}

#[test]
fn compact_degenerate_scenes() {
    // All atoms in one place (zero-length sticks), on a line, and one atom (a one-leaf tree).
    let mut same = random_molecule(500, false, 6);
    for v in [&mut same.balls.x, &mut same.balls.y, &mut same.balls.z] {
        v.iter_mut().for_each(|x| *x = 1.0);
    }
    let mut line = random_molecule(500, false, 7);
    line.balls.y.iter_mut().for_each(|y| *y = 0.0);
    line.balls.z.iter_mut().for_each(|z| *z = 0.0);
    let mut one = random_molecule(1, false, 8);
    one.sticks = Default::default();
    for g in [&same, &line, &one] {
        let bvh = Bvh::build(g);
        let c = CompactBvh::new(g, &bvh).unwrap();
        c.validate(g).unwrap();
        assert_t_matches_brute(&c, &test_rays(g, &bvh.bounds, 500, 9));
    }
    let empty = Geometry::default();
    let c = CompactBvh::new(&empty, &Bvh::build(&empty)).unwrap();
    c.validate(&empty).unwrap();
    assert_eq!(
        c.intersect_rays(Isa::Scalar, &test_rays(&one, &c.bounds, 10, 1)),
        vec![None; 10]
    );
}

#[test]
fn compact_nan_and_zero_rays_miss() {
    let g = random_molecule(2000, true, 10);
    let bvh = Bvh::build(&g);
    let c = CompactBvh::new(&g, &bvh).unwrap();
    let b = bvh.bounds.center();
    let bad = [
        Ray::new([f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]),
        Ray::new(b, [f32::NAN, 1.0, 0.0]),
        Ray {
            tmax: f32::NAN,
            ..Ray::new(b, [0.0, 0.0, 1.0])
        },
        Ray {
            d: [0.0; 3],
            ..Ray::new(b, [0.0, 0.0, 1.0])
        },
        Ray::new([f32::INFINITY, 0.0, 0.0], [-1.0, 0.0, 0.0]),
    ];
    assert_t_matches_brute(&c, &bad);
}

#[test]
fn validate_catches_a_broken_tree() {
    let g = random_molecule(3000, true, 11);
    let c = CompactBvh::new(&g, &Bvh::build(&g)).unwrap();
    // A child box shrunk to nothing no longer holds what is below it.
    let mut shrunk = c.clone();
    let q = &mut shrunk.nodes[0];
    (q.lo[0][0], q.hi[0][0]) = (0, 0);
    assert!(shrunk.validate(&g).is_err());
    // A leaf that points past the slots.
    let mut wild = c.clone();
    let at = wild
        .nodes
        .iter()
        .position(|q| q.child[0] & LEAF != 0)
        .unwrap();
    wild.nodes[at].child[0] = LEAF | 1 << 28 | wild.prim_ids.len() as u32;
    assert!(wild.validate(&g).is_err());
    // Geometry that is not the tree's.
    assert!(c.validate(&random_molecule(3000, true, 12)).is_err());
}

/// Secondary rays leaving surfaces (shadow, AO and path rays start there, a hair off the
/// surface): the compact tree's box test (fused multiply-add, not the reference's exact
/// form) must not cull a primitive such a ray hits.
#[test]
fn compact_rays_from_surfaces() {
    let g = random_molecule(20_000, true, 13);
    let bvh = Bvh::build(&g);
    let c = CompactBvh::new(&g, &bvh).unwrap();
    let primary = test_rays(&g, &bvh.bounds, 3000, 14);
    let hits = bvh.intersect_rays(Isa::Scalar, &primary);
    let mut rng = Rng(15);
    let secondary: Vec<Ray> = primary
        .iter()
        .zip(&hits)
        .filter_map(|(r, h)| {
            let h = h.as_ref()?;
            let o = bvh.spawn_point(r, h);
            // Into the hemisphere the ray came from, as a bounce or a light ray would go.
            let mut d = rng.dir().map(|v| v as f32);
            let dn: f32 = (0..3).map(|k| d[k] * h.n[k]).sum();
            let side: f32 = (0..3).map(|k| r.d[k] * h.n[k]).sum();
            if dn * side > 0.0 {
                d = d.map(|v| -v);
            }
            Some(Ray::new(o, d))
        })
        .collect();
    assert!(secondary.len() > 1000, "{} secondary rays", secondary.len());
    let hits = secondary.iter().filter(|r| brute(&c, r).is_some()).count();
    assert!(hits > secondary.len() / 10, "{hits} hits");
    assert_t_matches_brute(&c, &secondary);
}
