//! Measures BVH build rate, SAH vs full sweep and primary-ray throughput per ISA.
//! `cargo run --release -p render --example bs_figures -- [atoms] [out.png]`

use bvh::scenes::random_molecule;
use bvh::Bvh;
use render::{render_frame, Camera, FrameInputs, Framebuffer, Model, RenderSettings, View};
use spmd::Isa;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let atoms: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(500_000);
    // SAH quality on ~100K primitives.
    for clustered in [false, true] {
        let g = random_molecule(45_000, clustered, 1);
        let b = Bvh::build(&g);
        let f = Bvh::build_full_sweep(&g);
        println!(
            "SAH {} prims clustered={clustered}: binned {:.3} ({:.1} ms), full sweep {:.3} ({:.1} ms), ratio {:.4}",
            g.prim_count(),
            b.stats.sah_cost,
            b.stats.build_time.as_secs_f64() * 1e3,
            f.stats.sah_cost,
            f.stats.build_time.as_secs_f64() * 1e3,
            b.stats.sah_cost / f.stats.sah_cost
        );
    }
    let g = random_molecule(atoms, false, 7);
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let b = Bvh::build(&g);
        best = best.min(b.stats.build_time.as_secs_f64());
    }
    let scene = Model::from_geometry(g, None).unwrap();
    let st = scene.bvh.stats;
    println!(
        "BVH {} prims ({} atoms): best of 3 {:.1} ms = {:.2} M prims/s; {} nodes, depth {}, SAH {:.2}, {:.1} bytes/atom",
        st.prims,
        st.atoms,
        best * 1e3,
        st.prims as f64 / best * 1e-6,
        st.nodes,
        st.max_depth,
        st.sah_cost,
        st.bytes_per_atom()
    );
    let ro = RenderSettings::default();
    let mut fb = Framebuffer::new(1024, 1024, 0).unwrap();
    // ISAs interleaved frame by frame (other processes load them alike); 10 frames after one
    // warm-up frame each; median and best.
    for view in [View::Far, View::Close] {
        let cam = Camera::view(view, scene.center, scene.radius, 45.0, 1.0);
        let isas = Isa::supported();
        let mut times = vec![Vec::new(); isas.len()];
        for isa in &isas {
            render_frame(&FrameInputs::geometry(&scene, &cam), &ro, &mut fb, *isa).unwrap();
        }
        for _ in 0..10 {
            for (k, isa) in isas.iter().enumerate() {
                times[k].push(
                    render_frame(&FrameInputs::geometry(&scene, &cam), &ro, &mut fb, *isa)
                        .unwrap()
                        .time
                        .as_secs_f64(),
                );
            }
        }
        for (k, isa) in isas.iter().enumerate() {
            let t = &mut times[k];
            t.sort_by(f64::total_cmp);
            let (best, med) = (t[0], t[t.len() / 2]);
            println!(
                "{view:?} 1024² {isa:7}: median {:.1} ms = {:.2} Mrays/s = {:.1} fps (best {:.2} Mrays/s)",
                med * 1e3,
                1.048576 / med,
                1.0 / med,
                1.048576 / best
            );
        }
        if let Some(out) = args.get(2) {
            render_frame(
                &FrameInputs::geometry(&scene, &cam),
                &ro,
                &mut fb,
                Isa::detect(),
            )
            .unwrap();
            fb.save_png(format!("{out}-{view:?}.png")).unwrap();
        }
    }
}
