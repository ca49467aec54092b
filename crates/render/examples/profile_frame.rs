//! Renders frames in a loop for profiling: `profile_frame [atoms] [frames] [isa]`.
use bvh::scenes::random_molecule;
use render::{render_bs_into, Camera, Framebuffer, RenderOptions, Scene, View};
use spmd::Isa;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let atoms = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(500_000);
    let frames = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let isa: Isa = a
        .get(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or_else(Isa::detect);
    let scene = Scene::from_geometry(random_molecule(atoms, false, 7));
    let cam = Camera::view(View::Far, scene.center, scene.radius, 45.0, 1.0);
    let mut fb = Framebuffer::new(1024, 1024, 0).unwrap();
    for _ in 0..frames {
        let st = render_bs_into(&scene, &cam, &mut fb, &RenderOptions::default(), isa);
        println!(
            "{isa}: {:.1} ms {:.2} Mrays/s",
            st.time.as_secs_f64() * 1e3,
            st.mrays_per_s()
        );
    }
}
