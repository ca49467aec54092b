//! Parse throughput (MB/s) for XYZ and LAMMPS dump text, and bond-build time.
//! Inputs are generated in memory from the ns90k scene (~92K atoms).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use molecule::bonds::{build_bonds, BondOptions};
use molecule::read::{parse_bytes, Format, ReadOptions};
use molecule::scenes::{generate, SceneName};
use molecule::write::{write_lammps_dump, write_xyz};
use std::hint::black_box;
use std::time::Duration;

fn parse(c: &mut Criterion) {
    let m = generate(SceneName::Ns90k, None, 1);
    let mut xyz = Vec::new();
    write_xyz(&mut xyz, &m, "bench").unwrap();
    let mut dump = Vec::new();
    write_lammps_dump(&mut dump, &m, 0).unwrap();
    let mut g = c.benchmark_group("parse");
    g.measurement_time(Duration::from_secs(4)).sample_size(20);
    for (name, data, fmt) in [
        ("xyz", &xyz, Format::Xyz),
        ("lammps-dump", &dump, Format::LammpsDump),
    ] {
        g.throughput(Throughput::Bytes(data.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| parse_bytes(black_box(data), fmt, &ReadOptions::default()).unwrap())
        });
    }
    g.finish();
}

fn bonds(c: &mut Criterion) {
    let mut g = c.benchmark_group("bonds");
    g.measurement_time(Duration::from_secs(4)).sample_size(10);
    for s in [SceneName::Nanobowl, SceneName::Ns90k] {
        let m = generate(s, None, 1);
        g.bench_function(s.name(), |b| {
            b.iter(|| build_bonds(black_box(&m), &BondOptions::default()))
        });
    }
    g.finish();
}

criterion_group!(benches, parse, bonds);
criterion_main!(benches);
