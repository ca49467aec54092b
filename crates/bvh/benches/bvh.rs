//! Kernel benchmarks per ISA: ray-sphere batches, coherent packet traversal, incoherent rays
//! (packets vs the wide BVH), BVH builds. Ids: `ray_sphere/<isa>`, `packet_traversal/<isa>`,
//! `incoherent/{packet,wide}_<isa>`, `bvh_build/<builder>`.

use std::hint::black_box;

use bvh::scenes::{camera_rays, random_molecule, Rng};
use bvh::{Bvh, Geometry, Ray, WideBvh};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use spmd::Isa;

fn ray_sphere(c: &mut Criterion) {
    // 64 spheres, 4096 rays: the kernel alone (brute force, no BVH).
    let mut rng = Rng(5);
    let n = 64;
    let xs: Vec<f32> = (0..n).map(|_| rng.range(-10.0, 10.0) as f32).collect();
    let ys: Vec<f32> = (0..n).map(|_| rng.range(-10.0, 10.0) as f32).collect();
    let zs: Vec<f32> = (0..n).map(|_| rng.range(-10.0, 10.0) as f32).collect();
    let g = Geometry::from_atoms(&xs, &ys, &zs, &vec![1.0; n], &[], &[], 0.1);
    let bvh = Bvh::build(&g);
    let rays: Vec<Ray> = (0..4096)
        .map(|_| {
            let d = rng.dir();
            Ray::new(
                [0.0, 0.0, 40.0],
                [d[0] as f32 * 0.3, d[1] as f32 * 0.3, -1.0],
            )
        })
        .collect();
    let mut grp = c.benchmark_group("ray_sphere");
    grp.throughput(Throughput::Elements((rays.len() * n) as u64));
    for isa in Isa::supported() {
        grp.bench_function(isa.name(), |b| {
            b.iter(|| black_box(bvh.intersect_chunk(isa, black_box(&rays), true)))
        });
    }
    grp.finish();
}

fn packet_traversal(c: &mut Criterion) {
    let g = random_molecule(100_000, false, 7);
    let bvh = Bvh::build(&g);
    let rays = camera_rays(&bvh.bounds, 256, 1.0);
    let mut grp = c.benchmark_group("packet_traversal");
    grp.throughput(Throughput::Elements(rays.len() as u64));
    grp.sample_size(20);
    for isa in Isa::supported() {
        grp.bench_function(isa.name(), |b| {
            b.iter(|| black_box(bvh.intersect_chunk(isa, black_box(&rays), false)))
        });
    }
    grp.finish();
}

/// Rays like a path tracer's bounces: each from a random atom's surface in a random outward
/// direction, so neighbouring rays (one packet) share little.
fn incoherent_rays(g: &Geometry, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let a = rng.below(g.balls.len());
            let d = rng.dir();
            let r = g.balls.radius[a] as f64 * 1.001;
            let c = g.balls.center(a);
            Ray::new(
                [
                    (c[0] as f64 + d[0] * r) as f32,
                    (c[1] as f64 + d[1] * r) as f32,
                    (c[2] as f64 + d[2] * r) as f32,
                ],
                [d[0] as f32, d[1] as f32, d[2] as f32],
            )
        })
        .collect()
}

fn incoherent(c: &mut Criterion) {
    let g = random_molecule(100_000, false, 7);
    let bvh = Bvh::build(&g);
    let wide = WideBvh::new(&bvh);
    let rays = incoherent_rays(&g, 16_384, 3);
    let mut grp = c.benchmark_group("incoherent");
    grp.throughput(Throughput::Elements(rays.len() as u64));
    grp.sample_size(20);
    for isa in Isa::supported() {
        grp.bench_function(format!("packet_{}", isa.name()), |b| {
            b.iter(|| black_box(bvh.intersect_chunk(isa, black_box(&rays), false)))
        });
        grp.bench_function(format!("wide_{}", isa.name()), |b| {
            b.iter(|| black_box(wide.intersect_rays(isa, &bvh, black_box(&rays))))
        });
    }
    grp.finish();
}

fn bvh_build(c: &mut Criterion) {
    let g = random_molecule(100_000, false, 7);
    let mut grp = c.benchmark_group("bvh_build");
    grp.throughput(Throughput::Elements(g.prim_count() as u64));
    grp.sample_size(10);
    grp.bench_function("binned", |b| {
        b.iter(|| black_box(Bvh::build(black_box(&g))))
    });
    let small = random_molecule(20_000, false, 7);
    grp.throughput(Throughput::Elements(small.prim_count() as u64));
    grp.bench_function("full_sweep_20k_atoms", |b| {
        b.iter(|| black_box(Bvh::build_full_sweep(black_box(&small))))
    });
    grp.finish();
}

criterion_group!(benches, ray_sphere, packet_traversal, incoherent, bvh_build);
criterion_main!(benches);
