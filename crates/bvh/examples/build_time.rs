//! Times the binned builders, clustered (default above `bvh::CLUSTER_ABOVE` primitives) and
//! per-primitive (reference), and the packet traversal of each tree for the camera rays of a
//! far and a 4× zoomed view (1024², 4×4 pixel blocks, the widest backend) and of eight
//! cameras inside the atoms (384² each). Inside views depend on where the eye sits, so it also
//! counts, for 32 eyes inside the atoms, the nodes and primitives a ray must visit (those whose
//! box it enters before its hit): a measure of the tree without timing noise. Each tree is
//! also collapsed into the compact tree (`bvh::compact`) and its bytes and ray times printed.
//! `cargo run --release -p bvh --example build_time -- [atoms] [reps] [both|clustered|reference]`.
use std::time::Instant;

use bvh::scenes::camera_rays;
use bvh::{Aabb, Bvh, Ray};

/// Best of `reps` wall times (ms) of `f`.
fn best_ms(reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::MAX, f64::min)
}

/// Rays of eye `e` (0..32) inside `b`: 45° pinhole, `w`² pixels in 4×4 blocks, looking at the
/// centre from 5-33 % of the largest extent away, along one of four directions.
fn inside_rays(b: &Aabb, w: usize, e: usize) -> Vec<Ray> {
    let c = glam::Vec3::from(b.center());
    let ext = (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0f32, f32::max);
    let ring = (e / 4) as f32;
    let dir = [
        [1.0, 0.5, -0.7],
        [-0.3, 0.8, 0.2],
        [0.6, -0.2, 0.9],
        [-0.7, -0.6, -0.4],
    ][e % 4];
    let f = (glam::Vec3::from(dir) + glam::Vec3::new(0.1, -0.07, 0.0) * ring).normalize();
    let dist = [0.33, 0.18, 0.25, 0.1, 0.3, 0.05, 0.22, 0.15][e / 4] * ext;
    let eye = c - f * dist;
    let right = f.cross(glam::Vec3::Y).normalize();
    let up = right.cross(f);
    let half = 22.5f32.to_radians().tan();
    let mut rays = Vec::with_capacity(w * w);
    for by in (0..w).step_by(4) {
        for bx in (0..w).step_by(4) {
            for i in 0..16 {
                let (x, y) = (bx + i % 4, by + i / 4);
                let u = ((x as f32 + 0.5) / w as f32 * 2.0 - 1.0) * half;
                let v = (1.0 - (y as f32 + 0.5) / w as f32 * 2.0) * half;
                rays.push(Ray::new(eye.into(), (f + u * right + v * up).into()));
            }
        }
    }
    rays
}

/// Nodes plus primitives per ray whose box the ray enters before its nearest hit: the work
/// of a traversal that knew the hit in advance.
fn visits(b: &Bvh, rays: &[Ray], isa: spmd::Isa) -> f64 {
    let hits = b.intersect_rays(isa, rays);
    let mut v = 0u64;
    let mut stack = Vec::new();
    for (r, h) in rays.iter().zip(&hits) {
        let t_hit = h.as_ref().map_or(f32::INFINITY, |h| h.t);
        stack.push(0usize);
        while let Some(i) = stack.pop() {
            let n = &b.nodes[i];
            let (mut t0, mut t1) = (0.0f32, t_hit);
            for k in 0..3 {
                let (a, c) = ((n.min[k] - r.o[k]) / r.d[k], (n.max[k] - r.o[k]) / r.d[k]);
                t0 = t0.max(a.min(c));
                t1 = t1.min(a.max(c));
            }
            if t0 > t1 {
                continue;
            }
            v += 1 + n.count() as u64;
            if !n.is_leaf() {
                stack.extend([n.first as usize, n.first as usize + 1]);
            }
        }
    }
    v as f64 / rays.len() as f64
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a.get(1).and_then(|a| a.parse().ok()).unwrap_or(500_000);
    let reps: usize = a.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let which = a.get(3).map(String::as_str).unwrap_or("both");
    let g = bvh::scenes::random_molecule(n, false, 7);
    let isa = spmd::Isa::detect();
    let mut eyes: Vec<Vec<f64>> = Vec::new();
    for clustered in [true, false] {
        if (which == "clustered" && !clustered) || (which == "reference" && clustered) {
            continue;
        }
        let opt = bvh::BuildOptions {
            cluster_above: if clustered { 0 } else { usize::MAX },
            ..Default::default()
        };
        let mut best = f64::MAX;
        let mut b = Bvh::build_with(&g, &opt);
        for _ in 0..reps {
            b = Bvh::build_with(&g, &opt);
            best = best.min(b.stats.build_time.as_secs_f64());
        }
        let (far, close) = (
            camera_rays(&b.bounds, 1024, 1.0),
            camera_rays(&b.bounds, 1024, 4.0),
        );
        let inside: Vec<Ray> = (0..8)
            .flat_map(|e| inside_rays(&b.bounds, 384, e))
            .collect();
        let far_ms = best_ms(reps, || drop(b.intersect_rays(isa, &far)));
        let close_ms = best_ms(reps, || drop(b.intersect_rays(isa, &close)));
        let inside_ms = best_ms(reps, || drop(b.intersect_rays(isa, &inside)));
        let per_eye: Vec<f64> = (0..32)
            .map(|e| visits(&b, &inside_rays(&b.bounds, 128, e), isa))
            .collect();
        println!(
            "{} {} prims: build best {:.1} ms = {:.2} M prims/s, SAH {:.2}; rays ({isa}) far {far_ms:.1} ms, zoom 4 {close_ms:.1} ms, inside {inside_ms:.1} ms; visits per inside ray {:.1}",
            if clustered { "clustered" } else { "per-prim " },
            g.prim_count(),
            best * 1e3,
            g.prim_count() as f64 / best * 1e-6,
            b.stats.sah_cost,
            per_eye.iter().sum::<f64>() / per_eye.len() as f64,
        );
        eyes.push(per_eye);
        let t = Instant::now();
        let c = bvh::compact::CompactBvh::new(&g, &b).expect("compact tree");
        let collapse_ms = t.elapsed().as_secs_f64() * 1e3;
        let far_c = best_ms(reps, || drop(c.intersect_rays(isa, &far)));
        let close_c = best_ms(reps, || drop(c.intersect_rays(isa, &close)));
        let inside_c = best_ms(reps, || drop(c.intersect_rays(isa, &inside)));
        let atoms = g.balls.len() as f64;
        println!(
            "  compact: collapsed in {collapse_ms:.1} ms, {:.1} B/atom (tree {:.1}); rays far {far_c:.1} ms, zoom 4 {close_c:.1} ms, inside {inside_c:.1} ms",
            c.bytes() as f64 / atoms,
            b.stats.bytes as f64 / atoms,
        );
    }
    if let [c, r] = &eyes[..] {
        let ratio: Vec<f64> = c.iter().zip(r).map(|(c, r)| c / r).collect();
        println!(
            "inside visits, clustered / per-primitive over 32 eyes: total {:.3}, best eye {:.3}, worst eye {:.3}",
            c.iter().sum::<f64>() / r.iter().sum::<f64>(),
            ratio.iter().copied().fold(f64::MAX, f64::min),
            ratio.iter().copied().fold(0.0, f64::max),
        );
    }
}
