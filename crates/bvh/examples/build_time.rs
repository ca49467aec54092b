//! Times the binned builder: `cargo run --release -p bvh --example build_time -- [atoms] [reps]`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a.get(1).and_then(|a| a.parse().ok()).unwrap_or(500_000);
    let reps: usize = a.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let g = bvh::scenes::random_molecule(n, false, 7);
    let mut best = f64::MAX;
    let mut sah = 0.0;
    for _ in 0..reps {
        let b = bvh::Bvh::build(&g);
        best = best.min(b.stats.build_time.as_secs_f64());
        sah = b.stats.sah_cost;
    }
    println!(
        "{} prims: best {:.1} ms = {:.2} M prims/s, SAH {:.2}",
        g.prim_count(),
        best * 1e3,
        g.prim_count() as f64 / best * 1e-6,
        sah
    );
}
