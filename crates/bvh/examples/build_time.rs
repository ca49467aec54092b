//! Times the binned builder: `cargo run --release -p bvh --example build_time -- [atoms] [reps]`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a.get(1).and_then(|a| a.parse().ok()).unwrap_or(500_000);
    let reps: usize = a.get(2).and_then(|a| a.parse().ok()).unwrap_or(5);
    let g = bvh::scenes::random_molecule(n, false, 7);
    for _ in 0..reps {
        let b = bvh::Bvh::build(&g);
        println!(
            "{} prims: {:.1} ms = {:.2} M prims/s, SAH {:.2}",
            b.stats.prims,
            b.stats.build_time.as_secs_f64() * 1e3,
            b.stats.prims_per_second() * 1e-6,
            b.stats.sah_cost
        );
    }
}
