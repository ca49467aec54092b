//! The library's front door: load a molecule file, build its scene, render it, save a PNG.
//!
//! `cargo run --release --example render_file -- [FILE] [OUT.png]` (default: the adenylate
//! kinase sample `../shared/data/adk_open.pdb` → `render_file.png`).
use render::{render_frame, FrameInputs, Framebuffer, RenderSettings};
use scene::{Camera, Orbit, Scene, SceneSettings, View};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let file = args.next().unwrap_or("../shared/data/adk_open.pdb".into());
    let out = args.next().unwrap_or("render_file.png".into());
    let (width, height) = (800, 600);

    // Read the first frame; the format comes from the file name or content.
    let mut traj = molecule::read::open(file.as_ref(), &Default::default())?;
    let atoms = traj.read_frame(0)?;

    // Bonds, balls and sticks, their BVH (no volume: `SceneSettings::volume` is `None`).
    let isa = spmd::Isa::select(None)?; // BNS_ISA, else the widest this CPU has
    let scene = Scene::build(isa, &atoms, &SceneSettings::default())?;

    // The paper's far view around the bounding sphere, headlight shading on white.
    let camera = Camera::fit(
        View::Far,
        scene.sphere,
        45.0,
        width as f32 / height as f32,
        Orbit::default(),
    );
    let settings = RenderSettings::headlight([255, 255, 255]);
    let inputs = FrameInputs {
        model: scene.model.as_ref(),
        volume: None,
        camera: &camera,
    };
    let mut fb = Framebuffer::new(width, height, settings.background_packed())?;
    let stats = render_frame(&inputs, &settings, &mut fb, isa)?;
    fb.save_png(&out)?;
    println!(
        "{file}: {} atoms → {out} ({:.1} Mrays/s, {})",
        atoms.len(),
        stats.mrays_per_s(),
        isa.name()
    );
    Ok(())
}
