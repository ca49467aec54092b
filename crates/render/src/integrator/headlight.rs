//! Headlight integrator: the paper's b&s, volume and vol+b&s modes (§4.2 passes, §4.5 "b&s"):
//! `N` registers of camera rays per packet, headlight diffuse shading, the volume composited
//! in front of the opaque hit. Packed RGBA8 output.

use bvh::{surface, RayPacket};
use scene::Model;
use spmd::{Simd, V3};

use super::{TileJob, TILE_PIXELS};
use crate::camera_rays::block_width;
use crate::TILE;

/// Headlight modes: one tile of packed pixels.
#[inline(always)]
pub(super) fn tile<S: Simd>(s: S, k: &TileJob<'_>) -> Vec<u32> {
    let mut out = vec![0u32; TILE_PIXELS];
    {
        let out = &mut out[..];
        match k.set.packet_registers {
            2 => render_tile::<S, 2>(s, k, out),
            4 => render_tile::<S, 4>(s, k, out),
            1 => render_tile::<S, 1>(s, k, out),
            // Default from measurements (1024², 500K-atom random molecule, 1 thread, min of 7
            // interleaved frames, far / close, Mrays/s for 1 / 2 / 4 registers):
            //   scalar  2.96 / 3.27 / 4.11   1.59 / 1.51 / 2.23   -> 4 registers
            //   sse4.1  6.76 / 6.17 / 6.52   4.32 / 4.41 / 4.30   -> 1 (no clear gain)
            //   avx2    9.02 / 8.12 / 8.41   8.05 / 6.85 / 6.90   -> 1
            //   avx512 10.58 /10.04 /10.00   9.70 / 9.12 / 8.56   -> 1
            // Wider packets lose more to divergence than they save in traversal overhead.
            _ => {
                if S::LANES == 1 {
                    render_tile::<S, 4>(s, k, out)
                } else {
                    render_tile::<S, 1>(s, k, out)
                }
            }
        }
    }
    out
}

/// Renders one 16×16 tile (§4.2 `renderTile`): groups of `N` pixel blocks of `LANES` primary
/// rays each, traced as one packet (§4.3), shaded with a headlight (§4.5 "b&s").
#[inline(always)]
fn render_tile<S: Simd, const N: usize>(s: S, k: &TileJob<'_>, out: &mut [u32]) {
    let v = k.view;
    let mut stack = vec![0u32; k.model.map_or(0, |sc| sc.bvh.stack_size())];
    // One register covers bw × bh pixels; N registers a gw × gh grid of those.
    let bw = block_width(S::LANES);
    let bh = S::LANES / bw;
    let (mut gw, mut gh) = (N, 1);
    for cand in [1, 2, 4] {
        let (w, h) = (cand, N / cand);
        if cand <= N && w * h == N && (w * bw).abs_diff(h * bh) < (gw * bw).abs_diff(gh * bh) {
            (gw, gh) = (w, h);
        }
    }
    let mut lx = [0.0f32; spmd::MAX_LANES];
    let mut ly = [0.0f32; spmd::MAX_LANES];
    for i in 0..S::LANES {
        lx[i] = (i % bw) as f32 + 0.5;
        ly[i] = (i / bw) as f32 + 0.5;
    }
    let (lx, ly) = (s.load(&lx), s.load(&ly));
    let zero = s.splat(0.0);
    let bg = s.splat_i(k.set.background_packed() as i32);
    let mut px_buf = [0i32; spmd::MAX_LANES];
    let mut rays = [RayPacket {
        o: V3::splat(s, [0.0; 3]),
        d: V3::splat(s, [0.0; 3]),
        tmin: zero,
        tmax: zero,
        active: s.splat_m(false),
    }; N];
    let mut offs = [(0usize, 0usize); N];
    for gy in (0..TILE).step_by(bh * gh) {
        for gx in (0..TILE).step_by(bw * gw) {
            let mut any = false;
            for j in 0..N {
                let (bx, by) = (gx + (j % gw) * bw, gy + (j / gw) * bh);
                offs[j] = (bx, by);
                let px = lx + s.splat((k.x0 + bx) as f32);
                let py = ly + s.splat((k.y0 + by) as f32);
                let active = v.inside(s, px, py);
                any |= s.any(active);
                rays[j] = v.rays(s, px, py, active);
            }
            if !any {
                continue;
            }
            // Pass 1 (§4.2): opaque geometry, shaded; the hit depth bounds the volume pass.
            // (No closure here: closures do not inherit the entry point's target features.)
            #[allow(clippy::manual_map)]
            let hits = match k.model {
                Some(sc) => Some(sc.bvh.traverse_packets::<S, N>(s, &rays, &mut stack)),
                None => None,
            };
            for j in 0..N {
                let ray = &rays[j];
                let (color, depth) = match (k.model, &hits) {
                    (Some(sc), Some(hits)) => shade_bs(s, sc, k.set.ambient, ray, &hits[j], bg),
                    _ => (bg, s.splat(f32::INFINITY)),
                };
                // Pass 2 (§4.2, §4.4): the volume in front of the opaque hit, composited over it.
                let color = match k.volume {
                    Some(vs) => {
                        let c = vs.march(s, ray.o, ray.d, depth, ray.active);
                        s.select_i(ray.active, over(s, c, color), color)
                    }
                    None => color,
                };
                s.store_i(color, &mut px_buf);
                let (bx, by) = offs[j];
                for (i, p) in px_buf.iter().enumerate().take(S::LANES) {
                    let (x, y) = (bx + i % bw, by + i / bw);
                    out[y * TILE + x] = *p as u32;
                }
            }
        }
    }
}

/// Headlight-shaded colour of the b&s hits of one packet (background where missed) and the
/// hit depth (+inf where missed).
#[inline(always)]
fn shade_bs<S: Simd>(
    s: S,
    scene: &Model,
    ambient: f32,
    ray: &RayPacket<S>,
    hit: &bvh::PacketHit<S>,
    bg: S::I32,
) -> (S::I32, S::F32) {
    let bvh = &scene.bvh;
    let m = hit.hit_mask(s) & ray.active;
    if s.none(m) {
        return (bg, s.splat(f32::INFINITY));
    }
    let srf = surface(s, &bvh.records, ray.o, ray.d, hit.t, hit.slot, m);
    let zi = s.splat_i(0);
    let ca = s.gather_i(&scene.slot_color_a, hit.slot, m, zi);
    let cb = s.gather_i(&scene.slot_color_b, hit.slot, m, zi);
    let c = s.select_i(srf.second_half, cb, ca);
    // Headlight: the light is at the eye, so the cosine is |n·d|.
    let shade = s.splat(ambient) + s.splat(1.0 - ambient) * s.abs(srf.n.dot(ray.d));
    let rgb = channel(s, c, 0, shade)
        | channel(s, c, 8, shade)
        | channel(s, c, 16, shade)
        | s.splat_i(0xff << 24);
    (
        s.select_i(m, rgb, bg),
        s.select(m, hit.t, s.splat(f32::INFINITY)),
    )
}

/// Premultiplied volume colour `c` (`[r, g, b, a]` in [0, 1]) over packed opaque colours
/// `under`: `c·255 + (1 − a)·under` per channel, rounded; alpha 255.
#[inline(always)]
fn over<S: Simd>(s: S, c: [S::F32; 4], under: S::I32) -> S::I32 {
    let t = s.splat(1.0) - c[3];
    let mut out = s.splat_i(0xff << 24);
    for (ch, shift) in [(0usize, 0u32), (1, 8), (2, 16)] {
        let u = s.to_f32(s.shr(under, shift) & s.splat_i(255));
        let v = s.fma(c[ch], s.splat(255.0), u * t) + s.splat(0.5);
        let v = s.min(s.max(v, s.splat(0.0)), s.splat(255.0));
        out = out | s.shl(s.to_i32(v), shift);
    }
    out
}

/// One 8-bit channel of packed colours `c` at bit `shift`, scaled by `shade` and rounded.
/// (A function, not a closure: closures would not inherit the entry point's target features.)
#[inline(always)]
fn channel<S: Simd>(s: S, c: S::I32, shift: u32, shade: S::F32) -> S::I32 {
    let k = s.to_f32(s.shr(c, shift) & s.splat_i(255));
    let v = s.min(
        s.max(k * shade + s.splat(0.5), s.splat(0.0)),
        s.splat(255.0),
    );
    s.shl(s.to_i32(v), shift)
}
