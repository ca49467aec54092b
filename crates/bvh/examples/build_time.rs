//! Times the binned builders, clustered (default above `bvh::CLUSTER_ABOVE` primitives) and
//! per-primitive (reference), and the packet traversal of each tree for the camera rays of a
//! far and a 4× zoomed view (1024², 4×4 pixel blocks, the widest backend):
//! `cargo run --release -p bvh --example build_time -- [atoms] [reps] [both|clustered|reference]`.
use std::time::Instant;

use bvh::scenes::camera_rays;
use bvh::Bvh;

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

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a.get(1).and_then(|a| a.parse().ok()).unwrap_or(500_000);
    let reps: usize = a.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let which = a.get(3).map(String::as_str).unwrap_or("both");
    let g = bvh::scenes::random_molecule(n, false, 7);
    let isa = spmd::Isa::detect();
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
        let far_ms = best_ms(reps, || drop(b.intersect_rays(isa, &far)));
        let close_ms = best_ms(reps, || drop(b.intersect_rays(isa, &close)));
        println!(
            "{} {} prims: build best {:.1} ms = {:.2} M prims/s, SAH {:.2}; rays ({isa}) far {far_ms:.1} ms, zoom 4 {close_ms:.1} ms",
            if clustered { "clustered" } else { "per-prim " },
            g.prim_count(),
            best * 1e3,
            g.prim_count() as f64 / best * 1e-6,
            b.stats.sah_cost
        );
    }
}
