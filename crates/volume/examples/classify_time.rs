//! Times `ClassifiedTf::new` (cool-warm preset, range [0, 1], steps of 0.5 voxel) 15 times
//! and prints the minimum and median wall time. `cargo run --release -p volume --example
//! classify_time`.

use std::time::Instant;

use volume::{ClassifiedTf, Preset, TransferFunction};

fn main() {
    let tf = TransferFunction::preset(Preset::CoolWarm);
    // One untimed run to start rayon's threads and warm the caches.
    std::hint::black_box(ClassifiedTf::new(&tf, 0.0, 1.0, 0.5));
    let mut ms: Vec<f64> = (0..15)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(ClassifiedTf::new(&tf, 0.0, 1.0, 0.5));
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    println!(
        "ClassifiedTf::new: min {:.2} ms, median {:.2} ms ({} threads)",
        ms[0],
        ms[ms.len() / 2],
        rayon::current_num_threads()
    );
}
