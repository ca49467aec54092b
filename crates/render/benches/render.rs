//! Whole-frame benchmark per ISA: `render_bs/<isa>` (primary rays, headlight shading, 512²,
//! far view of a 100K-atom random molecule).

use std::hint::black_box;

use bvh::scenes::random_molecule;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use render::{render_frame, Camera, FrameInputs, Framebuffer, Model, RenderSettings, View};
use spmd::Isa;

fn render(c: &mut Criterion) {
    let scene = Model::from_geometry(random_molecule(100_000, false, 7), None).unwrap();
    let cam = Camera::view(View::Far, scene.center, scene.radius, 45.0, 1.0);
    let mut fb = Framebuffer::new(512, 512, 0).unwrap();
    let ro = RenderSettings::default();
    let mut grp = c.benchmark_group("render_bs");
    grp.throughput(Throughput::Elements(512 * 512));
    grp.sample_size(10);
    for isa in Isa::supported() {
        grp.bench_function(isa.name(), |b| {
            b.iter(|| {
                black_box(
                    render_frame(&FrameInputs::geometry(&scene, &cam), &ro, &mut fb, isa).unwrap(),
                )
            })
        });
    }
    grp.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);
