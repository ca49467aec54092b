//! Sticks trimmed to the part outside their end balls (`geometry/stick.rs`): what is cut lies
//! inside both balls, the colour still changes at the bond's midpoint, and no ray from outside
//! the balls meets anything else than with whole sticks (brute force over untrimmed cylinders),
//! on every backend.

use bvh::scenes::{random_molecule, test_rays, Rng};
use bvh::{load_packet, ray_cylinder, ray_sphere, BuildOptions, Bvh, Geometry, Prim, Ray};
use spmd::{Isa, Scalar};

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn f64s(p: [f32; 3]) -> [f64; 3] {
    p.map(|v| v as f64)
}

/// A unit vector perpendicular to `a` (unit).
fn perpendicular(a: [f64; 3]) -> [f64; 3] {
    let h = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let c = [
        a[1] * h[2] - a[2] * h[1],
        a[2] * h[0] - a[0] * h[2],
        a[0] * h[1] - a[1] * h[0],
    ];
    let n = dist(c, [0.0; 3]);
    c.map(|v| v / n)
}

/// Two atoms and their bond with radii drawn on a log scale (balls 0.05-3 Å, the stick
/// 0.02-1 Å, the bond 0.1-6 Å long, any direction): the trimmed record's cut ends lie inside
/// both balls (points of the cylinder's surface sampled along them), the cut is the same at
/// both ends and no longer than the bond's half, and nothing is cut without balls or with caps.
#[test]
fn the_cut_ends_lie_inside_both_balls_and_the_midpoint_stays() {
    let mut rng = Rng(7);
    let log = |rng: &mut Rng, lo: f64, hi: f64| (rng.range(lo.ln(), hi.ln())).exp();
    let mut trimmed = 0;
    for case in 0..2000 {
        let (ra, rb, rs) = (
            log(&mut rng, 0.05, 3.0),
            log(&mut rng, 0.05, 3.0),
            log(&mut rng, 0.02, 1.0),
        );
        let len = log(&mut rng, 0.1, 6.0);
        let dir = rng.dir();
        let p = [rng.range(-50.0, 50.0), rng.range(-50.0, 50.0), 0.0];
        let q = [0, 1, 2].map(|k| p[k] + dir[k] * len);
        let (p, q) = (p.map(|v| v as f32), q.map(|v| v as f32));
        let mut g = Geometry::from_atoms(
            &[p[0], q[0]],
            &[p[1], q[1]],
            &[p[2], q[2]],
            &[ra as f32, rb as f32],
            &[],
            &[[0, 1]],
            rs as f32,
        );
        let (p, q) = (f64s(p), f64s(q));
        let full = dist(p, q);
        for (show_balls, capped) in [(false, false), (false, true), (true, true), (true, false)] {
            (g.show_balls, g.capped) = (show_balls, capped);
            let rec = g.record(g.prim_count() as u32 - 1);
            let start = f64s(rec.p0);
            let cut = dist(start, p);
            let tol = 1e-5 * (1.0 + p[0].abs().max(p[1].abs()));
            assert!(
                (rec.len as f64 + 2.0 * cut - full).abs() <= tol,
                "case {case}: the same cut at both ends"
            );
            if !show_balls || capped {
                assert!(
                    cut <= tol,
                    "case {case}: cut {cut} without balls or with caps"
                );
                continue;
            }
            assert!(cut <= full / 2.0 + tol, "case {case}: cut {cut} of {full}");
            if cut == 0.0 {
                continue; // a ball no wider than the stick hides none of it
            }
            trimmed += 1;
            // The cylinder's surface over the cut, at both ends, is inside the balls.
            let axis = f64s(rec.axis);
            let n = perpendicular(axis);
            for k in 0..=8 {
                let s = cut * k as f64 / 8.0;
                let near_a = [0, 1, 2].map(|i| p[i] + axis[i] * s + n[i] * rs);
                let near_b = [0, 1, 2].map(|i| q[i] - axis[i] * s + n[i] * rs);
                assert!(dist(near_a, p) <= ra + tol, "case {case}: outside ball a");
                assert!(dist(near_b, q) <= rb + tol, "case {case}: outside ball b");
            }
            // The colour changes halfway along the drawn stick: the bond's midpoint.
            let mid = [0, 1, 2].map(|i| start[i] + axis[i] * rec.len as f64 / 2.0);
            let want = [0, 1, 2].map(|i| (p[i] + q[i]) / 2.0);
            assert!(dist(mid, want) <= tol, "case {case}: midpoint moved");
        }
    }
    assert!(trimmed > 500, "only {trimmed} sticks trimmed");
}

/// Nearest `(t, primitive id)` of `ray` over `g`'s balls and whole, untrimmed sticks (open
/// cylinders from atom centre to atom centre), scalar.
fn brute_whole(g: &Geometry, ray: &Ray) -> Option<(f32, u32)> {
    let s = Scalar;
    let p = load_packet(s, std::slice::from_ref(ray));
    let mut best: Option<(f32, u32)> = None;
    let keep = |best: &mut Option<(f32, u32)>, hit: bool, t: f32, id: u32| {
        if hit && best.is_none_or(|b| t < b.0) {
            *best = Some((t, id));
        }
    };
    let tmax = |best: Option<(f32, u32)>| best.map_or(p.tmax, |b| b.0);
    for i in 0..g.balls.len() {
        let (h, t) = ray_sphere(
            s,
            p.o,
            p.d,
            g.balls.center(i),
            g.balls.radius[i],
            p.tmin,
            tmax(best),
        );
        keep(&mut best, h, t, i as u32);
    }
    for j in 0..g.sticks.len() {
        let (a, b) = (g.endpoint(g.sticks.a[j]), g.endpoint(g.sticks.b[j]));
        let d = [0, 1, 2].map(|k| b[k] as f64 - a[k] as f64);
        let len = dist(d, [0.0; 3]);
        let axis = d.map(|v| (v / len) as f32);
        let (h, t) = ray_cylinder(
            s,
            p.o,
            p.d,
            a,
            axis,
            len as f32,
            g.sticks.radius,
            p.tmin,
            tmax(best),
        );
        keep(&mut best, h, t, (g.balls.len() + j) as u32);
    }
    best
}

/// Whether the point of `ray` at `tmin` (where it starts to count) lies outside every ball.
fn starts_outside(g: &Geometry, ray: &Ray) -> bool {
    let o = [0, 1, 2].map(|k| ray.o[k] as f64 + ray.d[k] as f64 * ray.tmin as f64);
    (0..g.balls.len()).all(|i| dist(o, f64s(g.balls.center(i))) > g.balls.radius[i] as f64)
}

/// The trimmed sticks change no ray's nearest hit: through the BVH, on every backend, the same
/// `t` as brute force over whole sticks (within 1e-5, the cylinder test starting from the cut
/// point instead of the atom), the same primitive unless another one is hit at that `t`, and
/// the same stick half, for rays starting outside every ball.
#[test]
fn trimming_changes_no_hit_of_a_ray_from_outside_the_balls() {
    for (n, clustered, seed) in [(400, false, 1), (3000, true, 2), (20000, true, 3)] {
        let g = random_molecule(n, clustered, seed);
        assert!(g.show_balls && !g.capped);
        for cluster_above in [usize::MAX, 0] {
            let bvh = Bvh::build_with(
                &g,
                &BuildOptions {
                    cluster_above,
                    ..Default::default()
                },
            );
            bvh.validate(&g).unwrap();
            let rays: Vec<Ray> = test_rays(&g, &bvh.bounds, 4000, seed)
                .into_iter()
                .filter(|r| starts_outside(&g, r))
                .collect();
            let truth: Vec<_> = rays.iter().map(|r| brute_whole(&g, r)).collect();
            let sticks_hit = truth
                .iter()
                .filter(|h| h.is_some_and(|h| h.1 as usize >= g.balls.len()))
                .count();
            assert!(sticks_hit > rays.len() / 40, "{sticks_hit} stick hits");
            for isa in Isa::under_test() {
                let got = bvh.intersect_rays(isa, &rays);
                for (i, (a, b)) in got.iter().zip(&truth).enumerate() {
                    let (Some(a), Some(b)) = (a, b) else {
                        assert_eq!(a.is_some(), b.is_some(), "{n} atoms, {isa} ray {i}");
                        continue;
                    };
                    assert!(
                        (a.t - b.0).abs() <= 1e-5 * b.0.max(1.0),
                        "{n} atoms, {isa} ray {i}: t {} against {}",
                        a.t,
                        b.0
                    );
                    if a.prim != b.1 {
                        continue; // a tie: both primitives are hit at this t
                    }
                    if let Prim::Stick(j) = g.prim(a.prim) {
                        // The half from the hit point, with whole sticks.
                        let j = j as usize;
                        let (pa, pb) = (g.endpoint(g.sticks.a[j]), g.endpoint(g.sticks.b[j]));
                        let r = &rays[i];
                        let x = [0, 1, 2].map(|k| r.o[k] as f64 + r.d[k] as f64 * a.t as f64);
                        let (da, db) = (dist(x, f64s(pa)), dist(x, f64s(pb)));
                        if (da - db).abs() > 1e-3 {
                            assert_eq!(a.second_half, db < da, "{n} atoms, {isa} ray {i}: half");
                        }
                    }
                }
            }
        }
    }
}
