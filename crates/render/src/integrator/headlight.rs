//! Headlight integrator: the paper's b&s, volume and vol+b&s modes (§4.2 passes, §4.5 "b&s"):
//! `N` registers of camera rays per packet, headlight diffuse shading, the volume composited
//! in front of the opaque hit. Packed RGBA8 output.

use bvh::{surface, Corners, Frusta, PacketHit, RayPacket};
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
            // On AVX-512, one walk of the tree for the tile's 16 packets, nodes tested
            // against each packet's frustum (`render_tile_blocks`), is 1.1-1.6× faster
            // (ns740k / nanobowl at 1024², AMD EPYC Zen 4, 2026-12-07); on AVX2 (8×8-pixel
            // groups) it was 5-10 % slower, and with the hand-off to packets below (bvh's
            // `handoff_blocks`) still 13-24 % slower close up, so narrower backends keep one
            // walk per packet.
            _ => match k.model {
                Some(sc) if S::LANES >= 16 => render_tile_blocks(s, k, sc, out),
                _ if S::LANES == 1 => render_tile::<S, 4>(s, k, out),
                _ => render_tile::<S, 1>(s, k, out),
            },
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
    let (lx, ly) = lane_offsets(s, bw);
    let zero = s.splat(0.0);
    let bg = s.splat_i(k.set.background_packed() as i32);
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
                #[allow(clippy::manual_map)]
                let hit = match &hits {
                    Some(h) => Some(&h[j]),
                    None => None,
                };
                finish_packet(s, k, &rays[j], hit, bg, offs[j], out);
            }
        }
    }
}

/// Renders one 16×16 tile with one walk of the tree per group of packets
/// ([`bvh::Bvh::traverse_blocks`]): `LANES` blocks of `LANES` camera rays (the whole tile on
/// AVX-512, 8×8 pixels on AVX2), each block's nearest hits the packet traversal's, then
/// shaded as [`render_tile`] does.
#[inline(always)]
fn render_tile_blocks<S: Simd>(s: S, k: &TileJob<'_>, sc: &Model, out: &mut [u32]) {
    let v = k.view;
    let mut stack = vec![0u32; sc.bvh.stack_size()];
    let bw = block_width(S::LANES);
    let bh = S::LANES / bw;
    // The group: gw × gh = LANES blocks of bw × bh pixels, square (16×16, 8×8, 4×4 pixels).
    let (gw, gh) = (bh, bw);
    let (lx, ly) = lane_offsets(s, bw);
    let zero = s.splat(0.0);
    let bg = s.splat_i(k.set.background_packed() as i32);
    let empty = RayPacket {
        o: V3::splat(s, [0.0; 3]),
        d: V3::splat(s, [0.0; 3]),
        tmin: zero,
        tmax: zero,
        active: s.splat_m(false),
    };
    let mut rays = [empty; spmd::MAX_LANES];
    let mut hits = [PacketHit {
        t: zero,
        slot: s.splat_i(-1),
    }; spmd::MAX_LANES];
    let none = Corners {
        o: [[0.0; 3]; 4],
        d: [[0.0; 3]; 4],
    };
    let mut corners = [none; spmd::MAX_LANES];
    let mut offs = [(0usize, 0usize); spmd::MAX_LANES];
    for gy in (0..TILE).step_by(bh * gh) {
        for gx in (0..TILE).step_by(bw * gw) {
            let mut present = 0u32;
            for b in 0..S::LANES {
                let (bx, by) = (gx + (b % gw) * bw, gy + (b / gw) * bh);
                offs[b] = (bx, by);
                let (x, y) = ((k.x0 + bx) as f32, (k.y0 + by) as f32);
                let (px, py) = (lx + s.splat(x), ly + s.splat(y));
                let active = v.inside(s, px, py);
                rays[b] = v.rays(s, px, py, active);
                if s.any(active) {
                    present |= 1 << b;
                }
                let (x, y) = (x as f64, y as f64);
                corners[b] = v.corners(x, y, x + bw as f64, y + bh as f64);
            }
            if present == 0 {
                continue;
            }
            let (cx, cy) = (k.x0 + gx + bw * gw / 2, k.y0 + gy + bh * gh / 2);
            let centre = v.direction(cx as f32, cy as f32);
            let fr = Frusta::new(s, &corners[..S::LANES], present, v.origin(), centre);
            let (rays, hits) = (&rays[..S::LANES], &mut hits[..S::LANES]);
            sc.bvh.traverse_blocks(s, &fr, rays, hits, &mut stack);
            for b in 0..S::LANES {
                if present >> b & 1 == 1 {
                    finish_packet(s, k, &rays[b], Some(&hits[b]), bg, offs[b], out);
                }
            }
        }
    }
}

/// Pixel offsets of the lanes of a `bw`-wide block (pixel centres).
#[inline(always)]
fn lane_offsets<S: Simd>(s: S, bw: usize) -> (S::F32, S::F32) {
    let mut lx = [0.0f32; spmd::MAX_LANES];
    let mut ly = [0.0f32; spmd::MAX_LANES];
    for i in 0..S::LANES {
        lx[i] = (i % bw) as f32 + 0.5;
        ly[i] = (i / bw) as f32 + 0.5;
    }
    (s.load(&lx), s.load(&ly))
}

/// One packet's pixels: the b&s hit shaded (background where none), the volume in front of
/// it composited over it (§4.2, §4.4), stored into the tile at block offset `off`.
#[inline(always)]
fn finish_packet<S: Simd>(
    s: S,
    k: &TileJob<'_>,
    ray: &RayPacket<S>,
    hit: Option<&PacketHit<S>>,
    bg: S::I32,
    (bx, by): (usize, usize),
    out: &mut [u32],
) {
    let bw = block_width(S::LANES);
    let (color, depth) = match (k.model, hit) {
        (Some(sc), Some(hit)) => shade_bs(s, sc, k.set.ambient, ray, hit, bg),
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
    let mut px_buf = [0i32; spmd::MAX_LANES];
    s.store_i(color, &mut px_buf);
    for (i, p) in px_buf.iter().enumerate().take(S::LANES) {
        let (x, y) = (bx + i % bw, by + i / bw);
        out[y * TILE + x] = *p as u32;
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
