//! The sample loop of the ray-traced modalities (Direct, AO, Path): per pixel block of `LANES`
//! camera rays, `spp` samples (jittered for path tracing, the pixel centre otherwise) shaded
//! by the modality's integrator and summed.

use spmd::{Simd, V3};

use super::{ao, direct, path, query, stacks, TileJob, TILE_PIXELS};
use crate::camera_rays::block_width;
use crate::rng::Rng;
use crate::settings::Modality;
use crate::TILE;

#[inline(always)]
pub(super) fn tile<S: Simd>(s: S, k: &TileJob<'_>) -> Vec<f32> {
    let mut out = vec![0.0f32; 3 * TILE_PIXELS];
    let model = k
        .model
        .expect("validated: ray-traced modalities have a model");
    let v = k.view;
    let mut stack = stacks(model, k.set.uses_wide());
    let wide = k.set.uses_wide();
    let sec = query(model, k.set.secondary, wide);
    let bounce = query(model, k.set.bounces, wide);
    let bw = block_width(S::LANES);
    let bh = S::LANES / bw;
    let mut lx = [0.0f32; spmd::MAX_LANES];
    let mut ly = [0.0f32; spmd::MAX_LANES];
    let mut li = [0i32; spmd::MAX_LANES];
    for i in 0..S::LANES {
        lx[i] = (i % bw) as f32;
        ly[i] = (i / bw) as f32;
        li[i] = ((i / bw) * k.width + i % bw) as i32;
    }
    let (lx, ly, li) = (s.load(&lx), s.load(&ly), s.load_i(&li));
    let path = matches!(k.set.modality, Modality::Path { .. });
    let mut buf = [[0.0f32; spmd::MAX_LANES]; 3];
    for by in (0..TILE).step_by(bh) {
        for bx in (0..TILE).step_by(bw) {
            let px0 = lx + s.splat((k.x0 + bx) as f32);
            let py0 = ly + s.splat((k.y0 + by) as f32);
            let active = v.inside(s, px0, py0);
            if s.none(active) {
                continue;
            }
            let pixel = li + s.splat_i(((k.y0 + by) * k.width + k.x0 + bx) as i32);
            let mut sum = V3::splat(s, [0.0; 3]);
            let samples = if path { k.spp } else { 1 };
            for j in 0..samples {
                let sample = k.first_sample + j;
                let mut rng = Rng::new(s, k.set.seed, pixel, sample);
                let (jx, jy) = if path {
                    (rng.next(s), rng.next(s))
                } else {
                    (s.splat(0.5), s.splat(0.5))
                };
                let ray = v.rays(s, px0 + jx, py0 + jy, active);
                let c = match k.set.modality {
                    Modality::Path { .. } => {
                        path::sample(s, k, model, &bounce, &sec, &ray, &mut rng, &mut stack)
                    }
                    Modality::Ao { .. } => {
                        ao::sample(s, k, model, &sec, &ray, &mut rng, &mut stack)
                    }
                    _ => direct::sample(s, k, model, &sec, &ray, &mut stack),
                };
                sum = sum + c;
            }
            // Direct/AO: one sample stands for all `spp`.
            let w = s.splat(if path { 1.0 } else { k.spp as f32 });
            s.store(sum.x * w, &mut buf[0]);
            s.store(sum.y * w, &mut buf[1]);
            s.store(sum.z * w, &mut buf[2]);
            for (i, ((r, g), b)) in buf[0]
                .iter()
                .zip(&buf[1])
                .zip(&buf[2])
                .take(S::LANES)
                .enumerate()
            {
                let (x, y) = (bx + i % bw, by + i / bw);
                let o = 3 * (y * TILE + x);
                out[o] += r;
                out[o + 1] += g;
                out[o + 2] += b;
            }
        }
    }
    out
}
