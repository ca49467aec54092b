//! SPMD-layer kernels per ISA: `cargo bench --bench kernels` (ids `<kernel>/<isa>`).
//! `cargo xtask matrix` reads the results and prints speedups over scalar.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use spmd::{math, Isa, Kernel, Simd};

/// Sums `exp(-x²)` over a batch: the Gaussian of the density build, compute-bound.
struct ExpBatch<'a>(&'a [f32]);

impl Kernel for ExpBatch<'_> {
    type Output = f32;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> f32 {
        let mut acc = s.splat(0.0);
        for chunk in self.0.chunks_exact(S::LANES) {
            let x = s.load(chunk);
            acc += math::exp(s, -(x * x));
        }
        s.reduce_add(acc)
    }
}

/// Sums `table[idx]` over pseudo-random indices: the gather behind trilinear sampling.
struct GatherBatch<'a> {
    table: &'a [f32],
    idx: &'a [i32],
}

impl Kernel for GatherBatch<'_> {
    type Output = f32;
    #[inline(always)]
    fn run<S: Simd>(self, s: S) -> f32 {
        let mut acc = s.splat(0.0);
        let on = s.splat_m(true);
        for chunk in self.idx.chunks_exact(S::LANES) {
            acc += s.gather(self.table, s.load_i(chunk), on, s.splat(0.0));
        }
        s.reduce_add(acc)
    }
}

fn bench(c: &mut Criterion) {
    let n = 1 << 16;
    let xs: Vec<f32> = (0..n).map(|i| (i as f32 / n as f32) * 4.0 - 2.0).collect();
    let mut g = c.benchmark_group("spmd_exp");
    g.throughput(Throughput::Elements(n as u64));
    for isa in Isa::under_test() {
        g.bench_function(BenchmarkId::from_parameter(isa), |b| {
            b.iter(|| isa.dispatch(ExpBatch(&xs)))
        });
    }
    g.finish();

    let table: Vec<f32> = (0..(1 << 20)).map(|i| i as f32).collect();
    let idx: Vec<i32> = (0..n as u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 12) as i32)
        .collect();
    let mut g = c.benchmark_group("spmd_gather");
    g.throughput(Throughput::Elements(n as u64));
    for isa in Isa::under_test() {
        g.bench_function(BenchmarkId::from_parameter(isa), |b| {
            b.iter(|| {
                isa.dispatch(GatherBatch {
                    table: &table,
                    idx: &idx,
                })
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
