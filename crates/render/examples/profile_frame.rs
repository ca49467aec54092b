//! Renders frames in a loop for profiling: `profile_frame [atoms] [frames] [isa] [regs]`.
use bvh::scenes::random_molecule;
use render::{render_frame, Camera, FrameInputs, Framebuffer, Model, RenderSettings, View};
use spmd::Isa;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let atoms = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(500_000);
    let frames = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let isas: Vec<Isa> = match a.get(3).map(|s| s.as_str()) {
        None | Some("all") => Isa::supported(),
        Some(s) => vec![s.parse().unwrap()],
    };
    let regs: Vec<usize> = match a.get(4) {
        Some(r) => vec![r.parse().unwrap()],
        None => vec![1, 2, 4],
    };
    let scene = Model::from_geometry(random_molecule(atoms, false, 7), None).unwrap();
    let mut fb = Framebuffer::new(1024, 1024, 0).unwrap();
    // Configurations are interleaved frame by frame so load from other processes hits them
    // alike; min and median per configuration.
    for view in [View::Far, View::Close] {
        let cam = Camera::view(view, scene.center, scene.radius, 45.0, 1.0);
        let configs: Vec<(Isa, usize)> = isas
            .iter()
            .flat_map(|&i| regs.iter().map(move |&r| (i, r)))
            .collect();
        let mut times = vec![Vec::new(); configs.len()];
        for _ in 0..frames {
            for (c, &(isa, r)) in configs.iter().enumerate() {
                let ro = RenderSettings {
                    packet_registers: r,
                    ..Default::default()
                };
                times[c].push(
                    render_frame(&FrameInputs::geometry(&scene, &cam), &ro, &mut fb, isa)
                        .unwrap()
                        .time
                        .as_secs_f64(),
                );
            }
        }
        for (c, &(isa, r)) in configs.iter().enumerate() {
            let t = &mut times[c];
            t.sort_by(f64::total_cmp);
            let (min, med) = (t[0], t[t.len() / 2]);
            println!(
                "{view:?} {isa:7} regs {r}: min {:.1} ms ({:.2} Mrays/s), median {:.1} ms ({:.2} Mrays/s)",
                min * 1e3,
                1.048576 / min,
                med * 1e3,
                1.048576 / med
            );
        }
    }
}
