//! Times the binned builders, clustered (default) and per-primitive (reference):
//! `cargo run --release -p bvh --example build_time -- [atoms] [reps] [both|clustered|reference]`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a.get(1).and_then(|a| a.parse().ok()).unwrap_or(500_000);
    let reps: usize = a.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let g = bvh::scenes::random_molecule(n, false, 7);
    let which = a.get(3).map(String::as_str).unwrap_or("both");
    for clustered in [true, false] {
        if (which == "clustered" && !clustered) || (which == "reference" && clustered) {
            continue;
        }
        let opt = bvh::BuildOptions {
            cluster_above: if clustered { 0 } else { usize::MAX },
            ..Default::default()
        };
        let mut best = f64::MAX;
        let mut sah = 0.0;
        for _ in 0..reps {
            let b = bvh::Bvh::build_with(&g, &opt);
            best = best.min(b.stats.build_time.as_secs_f64());
            sah = b.stats.sah_cost;
        }
        println!(
            "{} {} prims: best {:.1} ms = {:.2} M prims/s, SAH {:.2}",
            if clustered { "clustered" } else { "per-prim " },
            g.prim_count(),
            best * 1e3,
            g.prim_count() as f64 / best * 1e-6,
            sah
        );
    }
}
