//! The library's front door: load a molecule file, build its scene, render it, save a PNG.
//!
//! `cargo run --release --example render_file -- [FILE] [OUT.png]` (default: the adenylate
//! kinase sample `../shared/data/adk_open.pdb` → `render_file.png`).
use render::{render_scene, RenderSettings, SceneFrame};
use scene::{CameraChoice, Input, Orbit, Progress, Scene, SceneSettings, View};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let file = args.next().unwrap_or("../shared/data/adk_open.pdb".into());
    let out = args.next().unwrap_or("render_file.png".into());
    let size = (800, 600); // pixels

    // Read the first frame; the format comes from the file name or content.
    let input = Input::File {
        path: file.clone().into(),
        options: Default::default(),
    };
    let frame = input.load(0, false, &Progress::none())?;

    // Bonds, balls and sticks, their BVH (no volume: `SceneSettings::volume` is `None`).
    let isa = spmd::Isa::select(None)?; // BNS_ISA, else the widest this CPU has
    let scene = Scene::build(isa, &frame.molecule, &SceneSettings::default())?;

    // The paper's far view around the bounding sphere, headlight shading on white.
    let (view, orbit, fov_deg) = (View::Far, Orbit::default(), 45.0);
    let camera = CameraChoice::Fit {
        view,
        orbit,
        fov_deg,
    }
    .camera(scene.sphere, size);
    let settings = RenderSettings::headlight([255, 255, 255]);
    let job = SceneFrame {
        scene: &scene,
        camera: &camera,
        settings: &settings,
        size,
        legend_ink: None,
        isa,
    };
    let image = render_scene(&job, None)?;
    image.frame.save_png(&out)?;
    println!(
        "{file}: {} atoms → {out} ({:.1} Mrays/s, {})",
        frame.molecule.len(),
        image.stats.mrays_per_s(),
        isa.name()
    );
    Ok(())
}
