//! Kernel benchmarks per ISA: trilinear sampling, transfer-function lookup, density build,
//! and march throughput on a synthetic nanosphere-like shell (with and without macrocells
//! and pre-integration). Ids like `density_build/avx512`.

#[path = "synthetic.rs"]
mod synthetic;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use spmd::Isa;
use volume::*;

fn scene() -> (synthetic::Atoms, Volume, Macrocells, ClassifiedTf) {
    let a = synthetic::nanosphere(30_000, 20.0);
    let p = DensityParams {
        voxels_per_angstrom: 4.0,
        format: VolumeFormat::U8,
        budget_bytes: None,
    };
    let v = build_density(Isa::detect(), &a.x, &a.y, &a.z, &a.r, &p, None).unwrap();
    let mc = Macrocells::build(&v);
    let tf = ClassifiedTf::new(
        &TransferFunction::preset(Preset::CoolWarm),
        0.0,
        v.max_value,
        0.5,
    );
    (a, v, mc, tf)
}

fn benches(c: &mut Criterion) {
    let (atoms, v, mc, tf) = scene();

    // Random points inside the shell region.
    let n = 1 << 16;
    let mut seed = 1u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    };
    let (mut x, mut y, mut z) = (vec![], vec![], vec![]);
    for _ in 0..n {
        x.push(rnd() * 40.0);
        y.push(rnd() * 40.0);
        z.push(rnd() * 40.0);
    }
    let values: Vec<f32> = (0..n).map(|_| (rnd() * 0.5 + 0.5) * v.max_value).collect();

    let mut g = c.benchmark_group("trilinear");
    g.throughput(Throughput::Elements(n as u64));
    for isa in Isa::supported() {
        let mut out = vec![0.0; n];
        g.bench_function(BenchmarkId::from_parameter(isa), |b| {
            b.iter(|| sample_points(isa, &v, &x, &y, &z, &mut out))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("tf_lookup");
    g.throughput(Throughput::Elements(n as u64));
    for isa in Isa::supported() {
        let mut out = vec![[0.0; 4]; n];
        g.bench_function(BenchmarkId::from_parameter(isa), |b| {
            b.iter(|| classify_values(isa, &tf, &values, &mut out))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("density_build");
    g.sample_size(10);
    g.throughput(Throughput::Elements(atoms.x.len() as u64));
    let p = DensityParams {
        voxels_per_angstrom: 4.0,
        format: VolumeFormat::F32,
        budget_bytes: None,
    };
    for isa in Isa::supported() {
        g.bench_function(BenchmarkId::from_parameter(isa), |b| {
            b.iter(|| build_density(isa, &atoms.x, &atoms.y, &atoms.z, &atoms.r, &p, None).unwrap())
        });
    }
    g.finish();

    // 128² camera rays at the whole shell, single thread (one batch per 256 rays).
    let size = 128;
    let extent = atoms.x.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    let dist = extent / 20f32.to_radians().tan() * 1.1;
    let rays = synthetic::camera_rays(size, size, [0.0, 0.3 * dist, dist]);
    let tmax = vec![f32::INFINITY; size * size];
    let mut g = c.benchmark_group("march");
    g.sample_size(10);
    g.throughput(Throughput::Elements((size * size) as u64));
    for isa in Isa::supported() {
        let empty = EmptySpace::build(&mc, &tf);
        for (name, macrocells, jumps, preintegrated) in [
            ("jumps+preint", true, true, true),
            ("cells+preint", true, false, true),
            ("nocells+preint", false, false, true),
            ("jumps+post", true, true, false),
        ] {
            let opts = MarchOptions {
                macrocells,
                preintegrated,
                ..Default::default()
            };
            let mut sc = VolumeScene::new(&v, &mc, &tf, opts);
            if jumps {
                sc = sc.with_empty_space(&empty);
            }
            let mut out = vec![[0.0f32; 4]; size * size];
            g.bench_function(BenchmarkId::new(name, isa), |b| {
                b.iter(|| {
                    for (c, o) in out.chunks_mut(256).enumerate() {
                        let r = c * 256..c * 256 + o.len();
                        let rs = Rays {
                            origin: [
                                &rays[0][r.clone()],
                                &rays[1][r.clone()],
                                &rays[2][r.clone()],
                            ],
                            dir: [
                                &rays[3][r.clone()],
                                &rays[4][r.clone()],
                                &rays[5][r.clone()],
                            ],
                            tmax: &tmax[r],
                        };
                        march_rays(isa, &sc, &rs, o);
                    }
                })
            });
        }
    }
    g.finish();
}

criterion_group!(volume_benches, benches);
criterion_main!(volume_benches);
