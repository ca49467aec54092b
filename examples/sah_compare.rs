//! SAH cost of the binned builder against the full-sweep builder (the paper's, §4.1) on the
//! reference scenes, with the geometry `bnsview render` builds by default (balls of 0.5 ×
//! covalent radius, sticks of 0.15 Å):
//!
//! `cargo run --release --example sah_compare -- [SCENE ...]` (default nanobowl ns90k ns740k).
//!
//! The full sweep sorts every candidate split, so it takes minutes on sio2/anp3.
use bvh::{Bvh, Geometry};
use molecule::{bonds, elements, scenes};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let names: Vec<String> = if args.is_empty() {
        ["nanobowl", "ns90k", "ns740k"].map(String::from).to_vec()
    } else {
        args
    };
    println!("| scene | prims | binned SAH | binned s | full-sweep SAH | full-sweep s | binned ÷ sweep |");
    println!("|---|---|---|---|---|---|---|");
    for name in names {
        let scene: scenes::SceneName = name.parse()?;
        let m = scenes::generate(scene, None, 1);
        let b = bonds::build_bonds(&m, &bonds::BondOptions::default());
        let r: Vec<f32> = m
            .elements
            .iter()
            .map(|&z| 0.5 * elements::element(z).covalent_radius)
            .collect();
        let g = Geometry::from_atoms(&m.x, &m.y, &m.z, &r, &[], &b, 0.15);
        let binned = Bvh::build(&g).stats;
        let sweep = Bvh::build_full_sweep(&g).stats;
        println!(
            "| {name} | {} | {:.1} | {:.2} | {:.1} | {:.2} | {:.4} |",
            binned.prims,
            binned.sah_cost,
            binned.build_time.as_secs_f64(),
            sweep.sah_cost,
            sweep.build_time.as_secs_f64(),
            binned.sah_cost / sweep.sah_cost
        );
    }
    Ok(())
}
