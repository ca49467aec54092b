//! Measures the density build and march throughput on a synthetic 742K-atom nanosphere
//! (nested shells) at 4 voxels/Å, per ISA. `cargo run --release -p volume --example ns740k
//! [atoms] [voxels_per_angstrom] [image_size]`.

#[path = "../benches/synthetic.rs"]
mod synthetic;

use std::time::Instant;

use rayon::prelude::*;
use spmd::Isa;
use volume::*;

/// CPU seconds (user + system) this process has used, from /proc/self/stat; timings on a
/// shared machine are steadier in CPU time than in wall time.
fn cpu_secs() -> f64 {
    // Sum over this process's threads (rayon workers persist between measurements).
    let mut ticks = 0.0;
    for task in std::fs::read_dir("/proc/self/task")
        .into_iter()
        .flatten()
        .flatten()
    {
        let stat = std::fs::read_to_string(task.path().join("stat")).unwrap_or_default();
        let after = stat.rsplit(')').next().unwrap_or("");
        let f: Vec<&str> = after.split_whitespace().collect();
        // Fields 14 and 15 (utime, stime; the list after ')' starts at field 3), in clock
        // ticks of 10 ms.
        let tick = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
        ticks += tick(11) + tick(12);
    }
    ticks / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(742_000, |s| s.parse().unwrap());
    let vpa: f32 = args.get(2).map_or(4.0, |s| s.parse().unwrap());
    let size: usize = args.get(3).map_or(512, |s| s.parse().unwrap());
    let a = synthetic::nanosphere(n, 20.0);
    let extent = a.x.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    println!(
        "{} atoms, outer radius {extent:.1} Å, {} threads",
        a.x.len(),
        rayon::current_num_threads()
    );
    let p = DensityParams {
        voxels_per_angstrom: vpa,
        format: VolumeFormat::U8,
        budget_bytes: None,
    };
    // BNS_ISA=name limits the run to one backend.
    let isas = match std::env::var("BNS_ISA") {
        Ok(_) => vec![Isa::select(None).unwrap()],
        Err(_) => Isa::supported(),
    };
    let mut vol = None;
    for &isa in &isas {
        let (t, c) = (Instant::now(), cpu_secs());
        let v = build_density(isa, &a.x, &a.y, &a.z, &a.r, &p, None).unwrap();
        let (dt, dc) = (t.elapsed().as_secs_f64(), cpu_secs() - c);
        println!(
            "density_build {isa:>7}: {dt:.2} s wall, {dc:.2} s CPU  grid {:?} = {:.0} MB u8 (scale {:.3e}, max {:.3})",
            v.grid.dims,
            v.bytes() as f64 / 1e6,
            v.scale().unwrap(),
            v.max_value
        );
        vol = Some(v);
    }
    let v = vol.unwrap();
    let t = Instant::now();
    let mc = Macrocells::build(&v);
    println!(
        "macrocells: {:?} = {:.1} MB in {:.2} s",
        mc.dims,
        mc.bytes() as f64 / 1e6,
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    // VOLUME_OPACITY=k scales the preset's opacity; VOLUME_LIT=1 adds headlight shading.
    let k: f32 = std::env::var("VOLUME_OPACITY")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let lighting = if std::env::var("VOLUME_LIT").is_ok() {
        Lighting::Headlight
    } else {
        Lighting::Unlit
    };
    let ctf = ClassifiedTf::new(
        &TransferFunction::preset(Preset::CoolWarm).scale_opacity(k),
        0.0,
        v.max_value,
        0.5,
    );
    println!(
        "classified TF (pre-integration table): {:.3} s",
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let empty = EmptySpace::build(&mc, &ctf);
    println!(
        "empty-space distances: {} kB in {:.1} ms",
        empty.bytes() / 1000,
        t.elapsed().as_secs_f64() * 1e3
    );

    // Far: whole sphere in view; close: a quarter of the distance.
    let far = extent / (20.0f32).to_radians().tan() * 1.1;
    for (view, dist) in [("far", far), ("close", far * 0.25)] {
        let rays = synthetic::camera_rays(size, size, [0.0, 0.3 * dist, dist]);
        let tmax = vec![f32::INFINITY; size * size];
        for &isa in &isas {
            // Macrocells with empty-space jumps (the renderer's default), walked cell by
            // cell, none; post-classification.
            for (macrocells, jumps, preintegrated) in [
                (true, true, true),
                (true, false, true),
                (false, false, true),
                (true, true, false),
            ] {
                let opts = MarchOptions {
                    macrocells,
                    preintegrated,
                    lighting,
                    ..Default::default()
                };
                let mut sc = VolumeScene::new(&v, &mc, &ctf, opts);
                if jumps {
                    sc = sc.with_empty_space(&empty);
                }
                let mut out = vec![[0.0f32; 4]; size * size];
                let (mut best, mut cpu) = (f64::INFINITY, 0.0);
                for _ in 0..3 {
                    let (t, c) = (Instant::now(), cpu_secs());
                    // Rows of 16 pixels × 16 lines as tasks, as the renderer's tiles.
                    out.par_chunks_mut(256).enumerate().for_each(|(c, o)| {
                        let r = c * 256..(c * 256 + o.len());
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
                    });
                    let dt = t.elapsed().as_secs_f64();
                    if dt < best {
                        (best, cpu) = (dt, cpu_secs() - c);
                    }
                }
                let dt = best;
                if let Ok(dir) = std::env::var("VOLUME_PNG_DIR") {
                    // Premultiplied RGBA over a dark background.
                    let bg = [0.05f32, 0.05, 0.08];
                    let px: Vec<u8> = out
                        .iter()
                        .flat_map(|c| {
                            (0..3).map(move |k| {
                                ((c[k] + (1.0 - c[3]) * bg[k]).clamp(0.0, 1.0) * 255.0 + 0.5) as u8
                            })
                        })
                        .collect();
                    let name = format!(
                        "{dir}/ns_{view}_{isa}_cells{macrocells}_jumps{jumps}_preint{preintegrated}.png"
                    );
                    image::save_buffer(
                        &name,
                        &px,
                        size as u32,
                        size as u32,
                        image::ColorType::Rgb8,
                    )
                    .unwrap();
                }
                let cover = out.iter().map(|c| c[3] as f64).sum::<f64>() / out.len() as f64;
                println!(
                    "march {view:>5} {isa:>7} cells {macrocells:<5} jumps {jumps:<5} preint {preintegrated:<5}: {:6.2} Mrays/s wall (best of 3, {:.0} ms), {:5.2} Mrays/CPU-s, mean α {cover:.3}",
                    out.len() as f64 / dt / 1e6, dt * 1e3, out.len() as f64 / cpu.max(1e-3) / 1e6
                );
            }
        }
    }
}
