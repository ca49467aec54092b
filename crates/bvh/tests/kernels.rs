//! Intersection kernels against an f64 reference on random rays with log-scale parameters
//! (pbrt style): grazing rays, rays from inside, degenerate sticks, huge and tiny coordinates,
//! and the pbrt check that rays spawned at a hit never re-hit the surface. Every backend.

use bvh::scenes::Rng;
use bvh::{Bvh, Geometry, Hit, Ray};
use spmd::Isa;

type V = [f64; 3];
fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: V, k: f64) -> V {
    [a[0] * k, a[1] * k, a[2] * k]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn len(a: V) -> f64 {
    dot(a, a).sqrt()
}
fn up(a: [f32; 3]) -> V {
    [a[0] as f64, a[1] as f64, a[2] as f64]
}
fn down(a: V) -> [f32; 3] {
    [a[0] as f32, a[1] as f32, a[2] as f32]
}

/// Reference answer: `None` when the case is too close to a decision boundary for f32 inputs
/// (tangent, a root near 0, a hit near a cylinder end) to say; else the nearest hit.
type Reference = Option<Option<(f64, V)>>;

/// Roots of |f + t·d − axis·((f + t·d)·axis)|² = r² (axis = 0: a sphere), in f64 via the
/// closest approach, with the decision margins.
fn quad(f: V, d: V, axis: V, r: f64, tol: f64) -> Option<Option<(f64, f64)>> {
    let fp = sub(f, mul(axis, dot(f, axis)));
    let dp = sub(d, mul(axis, dot(d, axis)));
    let a = dot(dp, dp);
    if a < 1e-14 {
        return if a == 0.0 { Some(None) } else { None };
    }
    let tc = -dot(fp, dp) / a;
    let l = len(add(fp, mul(dp, tc)));
    if (l - r).abs() <= tol {
        return None;
    }
    if l > r {
        return Some(None);
    }
    let s = ((r * r - l * l) / a).sqrt();
    Some(Some((tc - s, tc + s)))
}

fn sphere_ref(o: V, d: V, c: V, r: f64, tol: f64) -> Reference {
    let f = sub(o, c);
    let roots = quad(f, d, [0.0; 3], r, tol)?;
    let Some((t0, t1)) = roots else {
        return Some(None);
    };
    for t in [t0, t1] {
        if t.abs() <= tol {
            return None;
        }
        if t > 0.0 {
            return Some(Some((t, mul(add(f, mul(d, t)), 1.0 / r))));
        }
    }
    Some(None)
}

fn cylinder_ref(o: V, d: V, p0: V, p1: V, r: f64, tol: f64) -> Reference {
    let lv = sub(p1, p0);
    let l = len(lv);
    if l == 0.0 {
        return Some(None);
    }
    let axis = mul(lv, 1.0 / l);
    let f = sub(o, p0);
    let roots = quad(f, d, axis, r, tol)?;
    let Some((t0, t1)) = roots else {
        return Some(None);
    };
    for t in [t0, t1] {
        if t < -tol {
            continue;
        }
        let z = dot(add(f, mul(d, t)), axis);
        // Near an end the f32 axis decides (its error grows with t); near t = 0 the origin.
        let ztol = tol * (2.0 + t.abs() / l.max(r));
        if z.abs() <= ztol || (z - l).abs() <= ztol {
            return None;
        }
        if t.abs() <= tol && z > 0.0 && z < l {
            return None;
        }
        if t > 0.0 && z > 0.0 && z < l {
            let p = add(f, mul(d, t));
            let n = mul(sub(p, mul(axis, z)), 1.0 / r);
            return Some(Some((t, n)));
        }
    }
    Some(None)
}

/// Hemisphere cap: sphere roots with `(p − c)·axis·side ≥ 0` only.
fn cap_ref(o: V, d: V, c: V, axis: V, side: f64, r: f64, tol: f64) -> Reference {
    let f = sub(o, c);
    let roots = quad(f, d, [0.0; 3], r, tol)?;
    let Some((t0, t1)) = roots else {
        return Some(None);
    };
    for t in [t0, t1] {
        if t < -tol {
            continue;
        }
        let z = dot(add(f, mul(d, t)), axis) * side;
        if z.abs() <= tol * 10.0 {
            return None;
        }
        if t.abs() <= tol && z > 0.0 {
            return None;
        }
        if t > 0.0 && z > 0.0 {
            return Some(Some((t, mul(add(f, mul(d, t)), 1.0 / r))));
        }
    }
    Some(None)
}

fn capsule_ref(o: V, d: V, p0: V, p1: V, r: f64, tol: f64) -> Reference {
    let lv = sub(p1, p0);
    let l = len(lv);
    if l == 0.0 {
        return sphere_ref(o, d, p0, r, tol);
    }
    let axis = mul(lv, 1.0 / l);
    let parts = [
        cylinder_ref(o, d, p0, p1, r, tol)?,
        cap_ref(o, d, p0, axis, -1.0, r, tol)?,
        cap_ref(o, d, p1, axis, 1.0, r, tol)?,
    ];
    let best = parts
        .into_iter()
        .flatten()
        .min_by(|a, b| a.0.total_cmp(&b.0));
    // Two parts hit at nearly the same t (the seam): the normal is ambiguous.
    let hits: Vec<f64> = parts.iter().flatten().map(|h| h.0).collect();
    if hits.len() > 1 {
        let mut h = hits.clone();
        h.sort_by(f64::total_cmp);
        if (h[1] - h[0]).abs() <= tol {
            return None;
        }
    }
    Some(best)
}

fn log_uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    10f64.powf(rng.range(lo, hi))
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Sphere,
    Cylinder,
    Capsule,
}

struct Case {
    g: Geometry,
    ray: Ray,
    reference: Reference,
    outside: bool,
}

fn make_case(rng: &mut Rng, kind: Kind) -> Case {
    let r = log_uniform(rng, -3.0, 3.0);
    // Centre far from the origin relative to r (huge coordinates) or near it.
    let cdist = r * log_uniform(rng, -2.0, 4.5);
    let c = mul(rng.dir(), cdist);
    let (p0, p1) = match kind {
        Kind::Sphere => (c, c),
        _ => {
            let l = if rng.below(20) == 0 {
                0.0
            } else {
                r * log_uniform(rng, -1.0, 2.0)
            };
            (c, add(c, mul(rng.dir(), l)))
        }
    };
    let (p0, p1) = (up(down(p0)), up(down(p1)));
    let rr = r as f32 as f64;
    let axis = sub(p1, p0);
    let mode = rng.below(4);
    let o = if mode == 0 {
        // Inside (most of the time).
        add(
            add(p0, mul(axis, rng.f64())),
            mul(rng.dir(), rr * rng.range(0.0, 0.95)),
        )
    } else {
        add(p0, mul(rng.dir(), rr * log_uniform(rng, 0.0, 4.0)))
    };
    // Aim near the primitive's surface: grazing when the offset is close to r.
    let target = add(
        add(p0, mul(axis, rng.range(-0.2, 1.2))),
        mul(
            rng.dir(),
            rr * (1.0
                + if mode == 3 {
                    rng.range(-1.0, 1.0) * log_uniform(rng, -6.0, -1.0)
                } else {
                    rng.range(-1.0, 0.3)
                }),
        ),
    );
    let mut dir = sub(target, o);
    if kind != Kind::Sphere && mode == 2 && len(axis) > 0.0 {
        // Nearly parallel to the stick.
        dir = add(
            mul(axis, 1.0 / len(axis)),
            mul(rng.dir(), log_uniform(rng, -6.0, -1.0)),
        );
    }
    let ray = Ray::new(down(o), down(dir));
    let (o, d) = (up(ray.o), up(ray.d));
    let scale = len(o).max(len(p0)).max(len(p1)) + rr + len(axis);
    let tol = 1e-5 * scale;
    let reference = match kind {
        Kind::Sphere => sphere_ref(o, d, p0, rr, tol),
        Kind::Cylinder => cylinder_ref(o, d, p0, p1, rr, tol),
        Kind::Capsule => capsule_ref(o, d, p0, p1, rr, tol),
    };
    let outside = match kind {
        Kind::Sphere => len(sub(o, p0)) > rr * (1.0 + 1e-4),
        Kind::Cylinder => {
            // Outside the infinite cylinder: the hit is on the convex outer wall.
            let l = len(axis);
            let f = sub(o, p0);
            let q = if l > 0.0 {
                mul(axis, dot(f, axis) / (l * l))
            } else {
                [0.0; 3]
            };
            len(sub(f, q)) > rr * (1.0 + 1e-4)
        }
        Kind::Capsule => {
            let l = len(axis);
            let z = if l > 0.0 {
                (dot(sub(o, p0), axis) / l).clamp(0.0, l)
            } else {
                0.0
            };
            let q = if l > 0.0 {
                add(p0, mul(axis, z / l))
            } else {
                p0
            };
            len(sub(o, q)) > rr * (1.0 + 1e-4)
        }
    };
    let pf = |v: V| down(v);
    let (a, b) = (pf(p0), pf(p1));
    let g = match kind {
        Kind::Sphere => {
            Geometry::from_atoms(&[a[0]], &[a[1]], &[a[2]], &[rr as f32], &[], &[], 0.0)
        }
        _ => {
            let mut g = Geometry::from_atoms(
                &[a[0], b[0]],
                &[a[1], b[1]],
                &[a[2], b[2]],
                &[0.0; 2],
                &[],
                &[[0, 1]],
                rr as f32,
            );
            g.show_balls = false;
            g.capped = kind == Kind::Capsule;
            g
        }
    };
    Case {
        g,
        ray,
        reference,
        outside,
    }
}

fn check_kind(kind: Kind, n: usize, seed: u64) {
    let mut rng = Rng(seed);
    let (mut checked, mut hits, mut skipped, mut spawned) = (0, 0, 0, 0);
    for i in 0..n {
        let case = make_case(&mut rng, kind);
        let bvh = Bvh::build(&case.g);
        bvh.validate(&case.g).unwrap();
        let Some(expect) = case.reference else {
            skipped += 1;
            continue;
        };
        checked += 1;
        let o = up(case.ray.o);
        let scale = len(o)
            + case
                .g
                .sticks
                .radius
                .max(case.g.balls.radius.first().copied().unwrap_or(0.0)) as f64
            + len(up([
                case.g.balls.x[0],
                case.g.balls.y[0],
                case.g.balls.z[0],
            ]));
        for isa in Isa::supported() {
            let got: Vec<Option<Hit>> = [
                bvh.intersect_rays(isa, &[case.ray]),
                bvh.intersect_rays_brute(isa, &[case.ray]),
            ]
            .concat();
            for h in got {
                match (expect, h) {
                    (None, None) => {}
                    (Some((t, n)), Some(h)) => {
                        let tol = 1e-5 * (scale + t);
                        assert!((h.t as f64 - t).abs() <= tol, "{kind:?} case {i} {isa}: t {} vs {t} (tol {tol}) {:?}", h.t, case.ray);
                        // The normal is as accurate as the hit point relative to the radius.
                        let r = case.g.sticks.radius.max(case.g.balls.radius[0]) as f64;
                        let ntol = 1e-3_f64.max(1e-5 * (scale + t) / r * 4.0);
                        if ntol < 0.1 {
                            for k in 0..3 {
                                assert!((h.n[k] as f64 - n[k]).abs() <= ntol, "{kind:?} case {i} {isa}: n {:?} vs {n:?} t {} {t} ray {:?} g {:?}", h.n, h.t, case.ray, case.g);
                            }
                        }
                    }
                    (e, h) => panic!("{kind:?} case {i} {isa}: got {h:?}, reference {e:?}, ray {:?}, geometry {:?}", case.ray, case.g),
                }
            }
        }
        if let Some((_, n)) = expect {
            hits += 1;
            // Front-facing hits from outside (an open cylinder can be hit on its inner wall).
            if case.outside && dot(n, up(case.ray.d)) < 0.0 {
                // pbrt: a ray spawned at the hit into the outer hemisphere never re-hits.
                let h = bvh.intersect_ray(&case.ray).unwrap();
                let p = bvh.spawn_point(&case.ray, &h);
                for _ in 0..8 {
                    let mut d = rng.dir();
                    if dot(d, n) < 0.0 {
                        d = mul(d, -1.0);
                    }
                    let r2 = Ray::new(p, down(d));
                    for isa in Isa::supported() {
                        let again = bvh.intersect_rays(isa, &[r2]);
                        assert!(again[0].is_none(), "{kind:?} case {i} {isa}: spawned ray {r2:?} re-hit at {:?}; first {:?} hit {h:?} g {:?}", again[0], case.ray, case.g);
                    }
                    spawned += 1;
                }
            }
        }
    }
    eprintln!("{kind:?}: {checked} checked ({hits} hits), {skipped} ambiguous skipped, {spawned} spawned rays");
    assert!(
        checked > n * 3 / 4 && hits > n / 5,
        "{kind:?}: too few decisive cases"
    );
}

#[test]
fn sphere_matches_f64_reference() {
    check_kind(Kind::Sphere, 3000, 1);
}

#[test]
fn cylinder_matches_f64_reference() {
    check_kind(Kind::Cylinder, 3000, 2);
}

#[test]
fn capsule_matches_f64_reference() {
    check_kind(Kind::Capsule, 3000, 3);
}
